//! The cave pyramid beside the max pyramid: for each tile of a kept level,
//! the highest floor top (`Column::low`) of its columns and the lowest slab
//! bottom (`Column::mid`) of its columns that have a slab. A segment whose
//! altitudes over a tile stay above the first and below the second meets no
//! solid point there, even where the tile's maximum (a slab's top) is above
//! it: a ray through a cave, or under a bridge, skips the tile as a ray
//! above the ground skips one by the max pyramid.

use crate::{DirtyRect, Layout, Level, decode_column, update_levels};

/// A tile's slab bottom when none of its columns has a slab: no ray the
/// march tests (altitudes up to 255) is below it.
pub const NO_SLAB: u8 = 255;

/// Floor and slab bounds of every tile of a [`Layout`]'s levels, one `u16`
/// per tile: the highest floor top in the low byte, the lowest slab bottom
/// in the high byte. Tile `i` of the max pyramid's byte layout is `u16` `i`
/// here, so the GPU holds it as words of two tiles (the low tile in the low
/// half).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CavePyramid {
    /// The same layout as the max pyramid's (byte offsets read as tile
    /// indices).
    pub layout: Layout,
    /// `floor | slab_bottom << 8` per tile.
    pub data: Vec<u16>,
}

/// The bounds of the pair of texels `2 px, 2 px + 1` in row `y`: the
/// pair's highest floor top and lowest slab bottom.
#[inline]
fn pair_bounds(level: &Level, px: u32, y: u32) -> (u8, u8) {
    let (h, m) = level.row(y);
    let x = 2 * px as usize;
    let (a, b) = (
        decode_column(h, m, x, level.mid_rule),
        decode_column(h, m, x + 1, level.mid_rule),
    );
    let bottom = |c: &strata_level::model::Column| if c.dual { c.mid } else { NO_SLAB };
    (a.low.max(b.low), bottom(&a).min(bottom(&b)))
}

fn pack(floor: u8, bottom: u8) -> u16 {
    u16::from(floor) | u16::from(bottom) << 8
}

impl CavePyramid {
    /// Build levels `step, 2 step, ..` from `level`, as
    /// [`crate::Pyramid::with_step`] lays them out.
    pub fn with_step(level: &Level, step: u32) -> Self {
        let layout = Layout::with_step(level.width(), level.height(), step);
        let mut p = CavePyramid {
            data: vec![pack(0, NO_SLAB); layout.bytes as usize],
            layout,
        };
        let all = DirtyRect {
            x: 0,
            y: 0,
            width: level.width(),
            height: level.height(),
        };
        p.update(level, &all);
        p
    }

    /// Rebuild the tiles over `rect` (already changed in `level`) and their
    /// ancestors, level by level.
    pub fn update(&mut self, level: &Level, rect: &DirtyRect) {
        update_levels(
            &self.layout,
            &mut self.data,
            rect,
            pack(0, NO_SLAB),
            |px, y| {
                let (floor, bottom) = pair_bounds(level, px, y);
                pack(floor, bottom)
            },
            |a, b| pack((a as u8).max(b as u8), ((a >> 8) as u8).min((b >> 8) as u8)),
        );
    }

    /// Tile (tx, ty) of level `k` (a kept level), wrapping: its highest floor
    /// top and lowest slab bottom ([`NO_SLAB`] when it has no slab).
    #[inline]
    pub fn get(&self, k: u32, tx: i64, ty: i64) -> (u8, u8) {
        let v = self.data[self.layout.level(k).index(tx, ty)];
        (v as u8, (v >> 8) as u8)
    }

    /// The tiles as little-endian words of two (what the GPU holds).
    pub fn words(&self) -> Vec<u32> {
        self.data
            .chunks_exact(2)
            .map(|c| u32::from(c[0]) | u32::from(c[1]) << 16)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every column of a tile, by brute force.
    fn brute(l: &Level, k: u32, tx: i64, ty: i64) -> (u8, u8) {
        let s = 1i64 << k;
        let (mut floor, mut bottom) = (0u8, NO_SLAB);
        for y in ty * s..(ty + 1) * s {
            for x in tx * s..(tx + 1) * s {
                let c = l.column(x, y);
                floor = floor.max(c.low);
                if c.dual {
                    bottom = bottom.min(c.mid);
                }
            }
        }
        (floor, bottom)
    }

    #[test]
    fn tiles_hold_their_floor_and_slab_bounds_and_updates_equal_fresh_builds() {
        let mut l = crate::tests::level(128, 64, 11);
        // A cave under a slab over texels 0..32 x 0..32: floors at 20, slab
        // tops at 120, slab bottoms at 20 + 5 * 8 and more (code 5).
        for y in 0..32usize {
            for x in 0..32usize {
                let (h, m) = l.planes_mut();
                h[y * 128 + x] = if x % 2 == 0 { 20 } else { 120 };
                m[y * 128 + x] = strata_level::model::META_DOUBLE_LEVEL | 1;
            }
        }
        for step in [1, 2] {
            let p = CavePyramid::with_step(&l, step);
            assert_eq!(p.layout, Layout::with_step(128, 64, step));
            let mut slabs = 0;
            for info in &p.layout.levels {
                let k = info.log2_tile;
                for ty in 0..i64::from(info.height) {
                    for tx in 0..i64::from(info.width) {
                        let want = brute(&l, k, tx, ty);
                        assert_eq!(
                            p.get(k, tx, ty),
                            want,
                            "step {step} level {k} tile {tx},{ty}"
                        );
                        assert_eq!(
                            p.get(k, tx + i64::from(info.width), ty - i64::from(info.height)),
                            want
                        );
                        slabs += usize::from(want.1 != NO_SLAB && want.1 > want.0);
                    }
                }
            }
            assert!(slabs > 0, "the test map has tiles with a cave band");
            let mut edited = l.clone();
            let rect = DirtyRect {
                x: 30,
                y: 9,
                width: 21,
                height: 17,
            };
            for (x, y) in rect.texels() {
                let i = (y * 128 + x) as usize;
                let (h, m) = edited.planes_mut();
                h[i] = h[i].wrapping_add(77);
                m[i] ^= strata_level::model::META_DOUBLE_LEVEL;
            }
            let mut q = p.clone();
            q.update(&edited, &rect);
            assert_eq!(q, CavePyramid::with_step(&edited, step));
            assert_ne!(q, p);
        }
    }
}
