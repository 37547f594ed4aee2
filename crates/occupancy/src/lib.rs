//! The voxel occupancy pyramid of the voxel-accelerated ray march (paper
//! §3.2): the layout the GPU shares ([`layout`]) and the CPU build and
//! incremental update ([`build`]), which is the twin the GPU build is tested
//! against. No GPU dependency.
//!
//! A level-0 cell is one voxel of [`VoxelSize`] (texels in x and y, altitude
//! units in z; altitudes span 0..256); it is occupied when a solid interval of
//! any of its columns (the floor `0..=low`, or the slab `mid..=high` of a dual
//! column) touches it, faces included. Each coarser level ORs 2x2x2 cells.
//!
//! # Example: build and update the pyramid
//!
//! ```
//! use strata_level::{DirtyRect, Level};
//! use strata_occupancy::{Pyramid, VoxelSize};
//!
//! // Flat ground at altitude 10 on the coarse grid (4 x 8 texels, 2 altitudes).
//! let mut level = Level::flat(64, 64, 10, 1).unwrap();
//! let mut pyramid = Pyramid::build(&level, VoxelSize::COARSE).unwrap();
//! assert!(pyramid.occupied(0, 3, 5, 5)); // voxel z 5 spans altitudes 10..=12
//! assert!(!pyramid.occupied(0, 3, 5, 6));
//!
//! // Raise a 4 x 8 patch (texels 12..16, 40..48) to 100 and update only it.
//! let (heights, _metas) = level.planes_mut();
//! for y in 40..48 {
//!     for x in 12..16 {
//!         heights[y * 64 + x] = 100;
//!     }
//! }
//! let dirty = DirtyRect { x: 12, y: 40, width: 4, height: 8 };
//! let stats = pyramid.update(&level, &[dirty]).unwrap();
//! assert_eq!(stats.leaf_columns, 1);
//! assert!(pyramid.occupied(0, 3, 5, 50)); // voxel (3, 5) now reaches altitude 100
//! assert_eq!(pyramid, Pyramid::build(&level, VoxelSize::COARSE).unwrap());
//! ```
//!
//! # Stability
//!
//! The stable surface is [`Pyramid`] (`build`, `update`, `occupied`, `count`,
//! `bytes`), [`VoxelSize`] (with its `X,Y,Z` text form), [`UpdateStats`] and
//! [`LayoutError`]. The bit layout ([`layout`]: [`Layout`], [`LevelInfo`],
//! [`TileRange`], the Morton helpers, the level table) and the public `words`
//! are shared with `strata-render`'s shaders and may change with them.

#![warn(missing_docs)]

pub mod build;
pub mod layout;

pub use build::{Pyramid, UpdateStats, column_voxel_ranges};
pub use layout::{
    LEVEL_TABLE_STRIDE, Layout, LayoutError, LevelInfo, TILE, TILE_WORDS, TileRange, VoxelSize,
    morton_decode, morton_encode,
};

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT};
    use strata_level::{DirtyRect, Level, MidRule};

    use strata_level::lcg::Lcg;

    /// Rolling hills with caves: a third of the pairs dual, some heights at
    /// the extremes 0 and 255.
    fn synthetic(width: u32, height: u32, seed: u64) -> Level {
        let mut rng = Lcg(seed);
        let n = (width * height) as usize;
        let (mut h, mut m) = (vec![0u8; n], vec![0u8; n]);
        for y in 0..height {
            for x in (0..width).step_by(2) {
                let i = (y * width + x) as usize;
                let base = 60.0
                    + 50.0 * ((x as f32) * 0.05).sin() * ((y as f32) * 0.03).cos()
                    + rng.below(20) as f32;
                let t = (rng.below(8) as u8) << META_TERRAIN_SHIFT;
                if rng.below(3) == 0 {
                    let low = (base as u32).min(200);
                    let high = (low + 20 + rng.below(80)).min(255);
                    h[i] = low as u8;
                    h[i + 1] = high as u8;
                    let code = rng.below(16) as u8;
                    m[i] = META_DOUBLE_LEVEL | t | (code >> 2);
                    m[i + 1] = META_DOUBLE_LEVEL | t | (code & 3);
                } else {
                    let v = match rng.below(50) {
                        0 => 0,
                        1 => 255,
                        _ => base as u8,
                    };
                    h[i] = v;
                    h[i + 1] = v.saturating_add(rng.below(4) as u8);
                    m[i] = t;
                    m[i + 1] = t;
                }
            }
        }
        Level::from_planes(width, height, h, m, MidRule::Original).unwrap()
    }

    /// Dig a crater like the design's edit fixture (lower the floor, remove
    /// the slab) and return its dirty rectangle.
    fn dig(level: &mut Level, cx: u32, cy: u32, r: u32) -> DirtyRect {
        let (w, hgt) = (level.width(), level.height());
        let x0 = cx.saturating_sub(r) & !1;
        let y0 = cy.saturating_sub(r);
        let x1 = (cx + r + 1).min(w);
        let y1 = (cy + r + 1).min(hgt);
        let (h, m) = level.planes_mut();
        for y in y0..y1 {
            for x in x0..x1 {
                let d2 = (x as f32 - cx as f32).powi(2) + (y as f32 - cy as f32).powi(2);
                if d2 < (r * r) as f32 {
                    let i = (y * w + x) as usize;
                    let depth = 90.0 * (1.0 - d2 / (r * r) as f32);
                    h[i] = (h[i] as f32 - depth).max(0.0) as u8;
                    m[i] &= !META_DOUBLE_LEVEL;
                }
            }
        }
        DirtyRect {
            x: x0,
            y: y0,
            width: x1 - x0,
            height: y1 - y0,
        }
    }

    /// Every solid point of the map lies in an occupied cell on every level.
    fn assert_conservative(level: &Level, p: &Pyramid, samples: u32, seed: u64) {
        let mut rng = Lcg(seed);
        let mut checked = 0;
        for i in 0..samples {
            let x = rng.below(level.width() * 16) as f32 / 16.0;
            let y = rng.below(level.height() * 16) as f32 / 16.0;
            let c = level.column_at(x, y);
            // Mix uniform altitudes with the interval ends themselves (faces).
            let z = match i % 4 {
                0 => f32::from(c.low),
                1 => f32::from(c.mid),
                2 => f32::from(c.high),
                _ => rng.below(256 * 8) as f32 / 8.0,
            };
            if !level.is_solid(x, y, z) || z >= 256.0 {
                continue;
            }
            checked += 1;
            for (l, info) in p.layout.levels.iter().enumerate() {
                let cx = (x / info.cell[0] as f32) as u32;
                let cy = (y / info.cell[1] as f32) as u32;
                let cz = (z / info.cell[2] as f32) as u32;
                assert!(
                    p.occupied(l, cx, cy, cz),
                    "solid ({x}, {y}, {z}) in empty cell ({cx}, {cy}, {cz}) of level {l}"
                );
            }
        }
        assert!(checked > samples / 4, "too few solid samples: {checked}");
    }

    #[test]
    fn conservative_on_both_grids() {
        let level = synthetic(256, 512, 7);
        for voxel in [VoxelSize::COARSE, VoxelSize::FINE] {
            let p = Pyramid::build(&level, voxel).unwrap();
            assert_conservative(&level, &p, 20_000, 11);
            // Not trivially conservative: plenty of empty air above the hills.
            let occ = p.count(0) as f64;
            let d = p.layout.levels[0].dims;
            let total = f64::from(d[0]) * f64::from(d[1]) * f64::from(d[2]);
            assert!(occ / total < 0.7, "{voxel}: {occ} of {total} occupied");
        }
    }

    #[test]
    fn coarser_levels_are_the_or_of_their_children() {
        let level = synthetic(128, 256, 3);
        let p = Pyramid::build(&level, VoxelSize::COARSE).unwrap();
        for l in 1..p.layout.levels.len() {
            let info = p.layout.levels[l];
            for z in 0..info.tiles[2] * 8 {
                for y in 0..info.tiles[1] * 8 {
                    for x in 0..info.tiles[0] * 8 {
                        let mut any = false;
                        for k in 0..8 {
                            any |= p.occupied(
                                l - 1,
                                2 * x + (k & 1),
                                2 * y + ((k >> 1) & 1),
                                2 * z + (k >> 2),
                            );
                        }
                        assert_eq!(p.occupied(l, x, y, z), any, "level {l} cell ({x},{y},{z})");
                    }
                }
            }
        }
        let top = p.layout.coarsest();
        assert!(p.count(top) > 0);
    }

    #[test]
    fn exact_voxel_rule_on_a_flat_map() {
        // Flat at 10 with Z = 2: voxels 0..=5 (5 starts at 10, touching the top face).
        let level = Level::flat(64, 64, 10, 1).unwrap();
        let p = Pyramid::build(&level, VoxelSize::COARSE).unwrap();
        for z in 0..128 {
            assert_eq!(p.occupied(0, 3, 5, z), z <= 5, "z {z}");
        }
        // Sea level: a map of height 0 still has its floor voxel.
        let sea = Level::flat(64, 64, 0, 0).unwrap();
        let p = Pyramid::build(&sea, VoxelSize::FINE).unwrap();
        assert!(p.occupied(0, 0, 0, 0) && !p.occupied(0, 0, 0, 1));
    }

    #[test]
    fn incremental_update_equals_full_rebuild() {
        for voxel in [VoxelSize::COARSE, VoxelSize::FINE] {
            let mut level = synthetic(256, 512, 5);
            let mut p = Pyramid::build(&level, voxel).unwrap();
            let rects = vec![
                dig(&mut level, 100, 300, 48),
                dig(&mut level, 3, 2, 10),
                dig(&mut level, 250, 505, 20),
            ];
            let stats = p.update(&level, &rects).unwrap();
            let fresh = Pyramid::build(&level, voxel).unwrap();
            assert!(
                p.words == fresh.words,
                "{voxel}: incremental differs from a full rebuild"
            );
            assert!(stats.leaf_columns > 0 && stats.reduced_columns > 0);
            let all = p.layout.levels[0].tiles[0] * p.layout.levels[0].tiles[1];
            assert!(stats.leaf_columns < all, "{voxel}: rebuilt everything");
        }
    }

    #[test]
    fn update_rejects_bad_rects_and_maps() {
        let level = synthetic(64, 64, 1);
        let mut p = Pyramid::build(&level, VoxelSize::COARSE).unwrap();
        let outside = DirtyRect {
            x: 60,
            y: 0,
            width: 8,
            height: 1,
        };
        assert!(p.update(&level, &[outside]).is_err());
        let other = synthetic(128, 64, 1);
        assert!(p.update(&other, &[]).is_err());
    }
}
