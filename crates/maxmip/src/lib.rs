//! The max-height pyramid of column tops behind the exact ray cast: level `k`
//! (1..=[`MAX_LEVEL`]) holds, for each tile of `2^k x 2^k` texels, the highest
//! top (`Column::top`) of its columns. A ray that stays above a tile's maximum
//! touches nothing in it (above a column's top nothing is solid, slab or not),
//! so skipping the tile is exact. Level 0 is the map itself (each column's top
//! is read from the terrain where it is needed).
//!
//! One layout ([`Layout`]) serves the CPU reference (`strata-reference`) and the
//! GPU exact march (`strata-render`'s `ray-exact`): every level is a row-major
//! byte plane, wrapping in x and y like the map, the planes back to back, each
//! starting on a 4-byte boundary so the GPU can hold them as `u32` words
//! (little-endian: byte `i` of the buffer is bits `8 (i % 4)..` of word `i / 4`).
//! [`Pyramid`] is the CPU build and incremental update, the twin the GPU build
//! is tested against bit for bit. No GPU dependency.
//!
//! # Example: build, update after an edit, query
//!
//! ```
//! use strata_level::{DirtyRect, Level};
//! use strata_maxmip::Pyramid;
//!
//! let mut level = Level::flat(64, 64, 40, 1).unwrap();
//! let mut pyramid = Pyramid::new(&level);
//! assert_eq!(pyramid.top(), 6); // tiles of 2..64 texels on a 64 x 64 map
//! assert_eq!(pyramid.global_max(), 40);
//!
//! // Raise one texel, then refresh only the tiles above it.
//! let (heights, _metas) = level.planes_mut();
//! heights[10 * 64 + 20] = 200;
//! let dirty = DirtyRect { x: 20, y: 10, width: 1, height: 1 };
//! pyramid.update(&level, &dirty);
//! assert_eq!(pyramid.get(1, 10, 5), 200); // level 1 tile (10, 5) holds texel (20, 10)
//! assert_eq!(pyramid.get(1, 11, 5), 40);
//! assert_eq!(pyramid.global_max(), 200);
//! assert_eq!(pyramid, Pyramid::new(&level)); // same bytes as a fresh build
//! ```
//!
//! # Stability
//!
//! The stable surface is [`Pyramid`] (`new`, `update`, `get`, `top`,
//! `global_max`) and [`MAX_LEVEL`]. The byte layout ([`Layout`],
//! [`LevelInfo`], [`TileRect`], [`Pyramid::words`] and the public `data`)
//! is shared with the GPU shaders of `strata-render` and may change with
//! them; treat it as internal to Strata.

#![warn(missing_docs)]

mod cave;
mod texels;
pub use cave::{CavePyramid, NO_SLAB};
pub use texels::{DECODE as TEXEL_DECODE, TexelTops};

use rayon::prelude::*;
use strata_level::model::decode_column;
use strata_level::{DirtyRect, Level};

/// The coarsest level: tiles of 2^8 = 256 texels. Coarser tiles are almost
/// never entirely below a ray that is close enough to the ground to matter.
pub const MAX_LEVEL: u32 = 8;

/// Where level `k` lies in the buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelInfo {
    /// Tile side in texels is `1 << log2_tile`.
    pub log2_tile: u32,
    /// Tiles across (`map width >> k`), a power of two.
    pub width: u32,
    /// Tiles down (`map height >> k`), a power of two.
    pub height: u32,
    /// First byte of the plane (a multiple of 4).
    pub offset: u32,
}

impl LevelInfo {
    /// Bytes of the plane (one per tile), before the padding to 4.
    pub fn bytes(&self) -> u32 {
        self.width * self.height
    }

    /// Byte index of tile (tx, ty), wrapping around the map.
    #[inline]
    pub fn index(&self, tx: i64, ty: i64) -> usize {
        self.offset as usize
            + (tx & i64::from(self.width - 1)) as usize
            + (ty & i64::from(self.height - 1)) as usize * self.width as usize
    }
}

/// The levels of a `width x height` map: every `step`-th one, so
/// `levels[i]` is level `step (i + 1)` (level 1 first in the dense layout).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Map width in texels (a power of two).
    pub map_width: u32,
    /// Map height in texels (a power of two).
    pub map_height: u32,
    /// The levels kept are the multiples of `step` (1: every level; 2: tiles
    /// of 4, 16, 64, 256, all a traversal visiting every other level reads).
    pub step: u32,
    /// The kept levels, finest first, up to level [`Layout::top`].
    pub levels: Vec<LevelInfo>,
    /// Total bytes, a multiple of 4.
    pub bytes: u32,
}

/// Tiles of one level covering a dirty rectangle: `x0..=x1`, `y0..=y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRect {
    /// First tile column.
    pub x0: u32,
    /// First tile row.
    pub y0: u32,
    /// Last tile column (inclusive).
    pub x1: u32,
    /// Last tile row (inclusive).
    pub y1: u32,
}

impl Layout {
    /// Levels 1..=min(MAX_LEVEL, log2 width, log2 height). Both sides must be
    /// powers of two (as every map's are).
    ///
    /// # Panics
    ///
    /// When a side is not a power of two.
    pub fn new(width: u32, height: u32) -> Self {
        Self::with_step(width, height, 1)
    }

    /// Levels `step, 2 step, ..` up to min(MAX_LEVEL, log2 width, log2
    /// height): each built from the level `step` below it (the first from
    /// the texels), for a traversal that never reads the others.
    ///
    /// # Panics
    ///
    /// When a side is not a power of two, or `step` is 0.
    pub fn with_step(width: u32, height: u32, step: u32) -> Self {
        assert!(step > 0, "the level step must be positive");
        assert!(
            width.is_power_of_two() && height.is_power_of_two(),
            "map sides must be powers of two"
        );
        let top = MAX_LEVEL
            .min(width.trailing_zeros())
            .min(height.trailing_zeros());
        let mut levels = Vec::new();
        let mut offset = 0u32;
        for k in (step..=top).step_by(step as usize) {
            let info = LevelInfo {
                log2_tile: k,
                width: width >> k,
                height: height >> k,
                offset,
            };
            offset += info.bytes().next_multiple_of(4);
            levels.push(info);
        }
        Layout {
            map_width: width,
            map_height: height,
            step,
            levels,
            bytes: offset,
        }
    }

    /// The coarsest level's number (0 when the map has no tiles).
    pub fn top(&self) -> u32 {
        self.levels.len() as u32 * self.step
    }

    /// Level `k` (a multiple of the step, from 1).
    ///
    /// # Panics
    ///
    /// When `k` is not a kept level.
    pub fn level(&self, k: u32) -> &LevelInfo {
        assert!(
            k.is_multiple_of(self.step),
            "level {k} is not kept (step {})",
            self.step
        );
        &self.levels[(k / self.step) as usize - 1]
    }

    /// Tiles of level `k` that hold a texel of `rect` (inside the map).
    pub fn dirty_tiles(&self, k: u32, rect: &DirtyRect) -> TileRect {
        TileRect {
            x0: rect.x >> k,
            y0: rect.y >> k,
            x1: (rect.x + rect.width.max(1) - 1) >> k,
            y1: (rect.y + rect.height.max(1) - 1) >> k,
        }
    }
}

/// The pyramid's bytes, laid out by [`Layout`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pyramid {
    /// Where each level lies in `data`.
    pub layout: Layout,
    /// Every level's tile maxima (altitude 0..=255), back to back; public for
    /// the GPU upload and tests, written only by [`Pyramid::update`].
    pub data: Vec<u8>,
    /// Highest top anywhere on the map.
    global_max: u8,
}

/// Top of the pair of texels `2 px, 2 px + 1` in row `y`: a dual pair's columns
/// both reach `high`; single texels their own heights.
#[inline]
fn pair_top(level: &Level, px: u32, y: u32) -> u8 {
    let (h, m) = level.row(y);
    let x = 2 * px as usize;
    let a = decode_column(h, m, x, level.mid_rule).top();
    let b = decode_column(h, m, x + 1, level.mid_rule).top();
    a.max(b)
}

/// Rebuild the tiles of every kept level of `layout` over `rect` in `data`
/// (one `T` per tile; the layout's byte offsets read as tile indices),
/// finest first: the first kept level folds the texel pairs' values
/// (`pair(px, y)`: the pair of texels `2 px, 2 px + 1` in row `y`), each
/// coarser one the tiles of the level below, with `fold` from `empty`. The
/// walk [`Pyramid`] and [`CavePyramid`] share.
pub(crate) fn update_levels<T: Copy + Send + Sync>(
    layout: &Layout,
    data: &mut [T],
    rect: &DirtyRect,
    empty: T,
    pair: impl Fn(u32, u32) -> T + Sync,
    fold: impl Fn(T, T) -> T + Sync,
) {
    for info in &layout.levels {
        let k = info.log2_tile;
        let r = layout.dirty_tiles(k, rect);
        let w = info.width as usize;
        let start = info.offset as usize + r.y0 as usize * w;
        let end = info.offset as usize + (r.y1 as usize + 1) * w;
        let (done, rest) = data.split_at_mut(start);
        let rows = &mut rest[..end - start];
        let s = layout.step;
        let child = (k > s).then(|| *layout.level(k - s));
        // A tile is `n x n` tiles of the level `s` below (texels for the first).
        let n = 1u32 << s;
        rows.par_chunks_mut(w).enumerate().for_each(|(i, row)| {
            let ty = r.y0 + i as u32;
            for tx in r.x0..=r.x1 {
                let (x0, y0) = (n * tx, n * ty);
                row[tx as usize] = match child {
                    // The first level: the pairs of its texel rows.
                    None => (y0..y0 + n)
                        .flat_map(|y| (x0 / 2..(x0 + n) / 2).map(move |px| (px, y)))
                        .map(|(px, y)| pair(px, y))
                        .fold(empty, &fold),
                    Some(c) => (y0..y0 + n)
                        .flat_map(|y| (x0..x0 + n).map(move |x| (x, y)))
                        .map(|(x, y)| done[c.index(i64::from(x), i64::from(y))])
                        .fold(empty, &fold),
                };
            }
        });
    }
}

impl Pyramid {
    /// Build every level from `level`.
    pub fn new(level: &Level) -> Self {
        Self::with_step(level, 1)
    }

    /// Build levels `step, 2 step, ..` from `level` ([`Layout::with_step`]).
    pub fn with_step(level: &Level, step: u32) -> Self {
        let layout = Layout::with_step(level.width(), level.height(), step);
        let mut p = Pyramid {
            data: vec![0u8; layout.bytes as usize],
            layout,
            global_max: 0,
        };
        let all = DirtyRect {
            x: 0,
            y: 0,
            width: level.width(),
            height: level.height(),
        };
        p.update(level, &all);
        if p.layout.levels.is_empty() {
            // No tiles: the map's own maximum.
            p.global_max = (0..level.height())
                .flat_map(|y| (0..level.width()).map(move |x| (x, y)))
                .map(|(x, y)| level.column(i64::from(x), i64::from(y)).top())
                .max()
                .unwrap_or(0);
        }
        p
    }

    /// Rebuild the tiles over `rect` (already changed in `level`) and their
    /// ancestors, level by level.
    pub fn update(&mut self, level: &Level, rect: &DirtyRect) {
        update_levels(
            &self.layout,
            &mut self.data,
            rect,
            0,
            |px, y| pair_top(level, px, y),
            u8::max,
        );
        if let Some(top) = self.layout.levels.last() {
            let plane = &self.data[top.offset as usize..(top.offset + top.bytes()) as usize];
            self.global_max = plane.iter().copied().max().unwrap_or(0);
        }
    }

    /// The coarsest level's number.
    pub fn top(&self) -> u32 {
        self.layout.top()
    }

    /// Highest top anywhere on the map.
    pub fn global_max(&self) -> u8 {
        self.global_max
    }

    /// Max top of tile (tx, ty) of level `k` (a kept level), wrapping around the map.
    #[inline]
    pub fn get(&self, k: u32, tx: i64, ty: i64) -> u8 {
        self.data[self.layout.level(k).index(tx, ty)]
    }

    /// The buffer as little-endian words (what the GPU holds).
    pub fn words(&self) -> Vec<u32> {
        le_words(&self.data)
    }
}

/// Bytes as the little-endian `u32` words the GPU holds them in (a length
/// that is a multiple of 4).
fn le_words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::MidRule;
    use strata_level::model::META_DOUBLE_LEVEL;

    pub(crate) fn level(w: u32, h: u32, seed: u32) -> Level {
        let n = (w * h) as usize;
        let heights: Vec<u8> = (0..n as u32)
            .map(|i| ((i.wrapping_mul(2654435761) ^ seed) >> 7) as u8)
            .collect();
        let metas: Vec<u8> = (0..n as u32)
            .map(|i| {
                if ((i / 2).wrapping_mul(40503) ^ seed).is_multiple_of(3) {
                    META_DOUBLE_LEVEL | (i as u8 & 3)
                } else {
                    0
                }
            })
            .collect();
        Level::from_planes(w, h, heights, metas, MidRule::Original).unwrap()
    }

    fn brute(l: &Level, k: u32, tx: i64, ty: i64) -> u8 {
        let s = 1i64 << k;
        let mut m = 0;
        for y in ty * s..(ty + 1) * s {
            for x in tx * s..(tx + 1) * s {
                m = m.max(l.column(x, y).top());
            }
        }
        m
    }

    #[test]
    fn levels_hold_tile_maxima_and_wrap() {
        let l = level(64, 32, 7);
        let p = Pyramid::new(&l);
        assert_eq!(p.top(), 5, "32 rows allow tiles up to 32");
        assert_eq!(p.layout.bytes % 4, 0);
        for k in 1..=p.top() {
            let info = p.layout.level(k);
            for ty in 0..i64::from(info.height) {
                for tx in 0..i64::from(info.width) {
                    let m = brute(&l, k, tx, ty);
                    assert_eq!(p.get(k, tx, ty), m, "level {k} tile {tx},{ty}");
                    let (w, h) = (i64::from(info.width), i64::from(info.height));
                    assert_eq!(p.get(k, tx - w, ty + 3 * h), m);
                }
            }
        }
        let max = (0..32)
            .flat_map(|y| (0..64).map(move |x| (x, y)))
            .map(|(x, y)| l.column(x, y).top())
            .max()
            .unwrap();
        assert_eq!(p.global_max(), max);
    }

    #[test]
    fn every_other_level_holds_the_same_maxima_in_less_memory() {
        let l = level(256, 128, 5);
        let (dense, sparse) = (Pyramid::new(&l), Pyramid::with_step(&l, 2));
        assert_eq!(sparse.top(), 6, "levels 2, 4, 6 (7 is not a multiple of 2)");
        assert_eq!(sparse.layout.levels.len(), 3);
        for k in [2, 4, 6] {
            let info = sparse.layout.level(k);
            for ty in 0..i64::from(info.height) {
                for tx in 0..i64::from(info.width) {
                    assert_eq!(sparse.get(k, tx, ty), dense.get(k, tx, ty), "level {k}");
                }
            }
        }
        assert!(sparse.layout.bytes * 4 < dense.layout.bytes);
        let mut edited = l.clone();
        edited.planes_mut().0[(70 * 256 + 33) as usize] = 250;
        let mut p = sparse.clone();
        p.update(
            &edited,
            &DirtyRect {
                x: 33,
                y: 70,
                width: 1,
                height: 1,
            },
        );
        assert_eq!(p, Pyramid::with_step(&edited, 2));
        assert_eq!(Layout::with_step(2048, 16384, 2).top(), MAX_LEVEL);
    }

    #[test]
    fn an_update_equals_a_fresh_build() {
        let l = level(512, 256, 3);
        let mut p = Pyramid::new(&l);
        let mut edited = l.clone();
        let rect = DirtyRect {
            x: 100,
            y: 37,
            width: 30,
            height: 90,
        };
        for (x, y) in rect.texels() {
            edited.planes_mut().0[(y * 512 + x) as usize] = 255 - (x as u8 ^ y as u8);
        }
        p.update(&edited, &rect);
        assert_eq!(p, Pyramid::new(&edited));
    }

    #[test]
    fn layout_clamps_to_the_map_and_aligns_planes() {
        let layout = Layout::new(2048, 16384);
        assert_eq!(layout.top(), MAX_LEVEL);
        assert_eq!(layout.level(1).width, 1024);
        assert!(layout.levels.iter().all(|l| l.offset % 4 == 0));
        // About a third of the map's texel count, in bytes.
        assert!(layout.bytes < 2048 * 16384 / 3 + 64);
        let tiny = Layout::new(4, 2);
        assert_eq!(tiny.top(), 1);
        assert_eq!(tiny.bytes, 4);
    }
}
