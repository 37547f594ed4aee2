//! The collider's copy of the terrain: every texel's decoded column packed
//! into one `u32` (4 bytes a texel), and a max-height pyramid of column tops
//! over tiles of 4, 16, 64 and 256 texels (the CPU reference's levels), both
//! updated in place by edits.
//!
//! A packed column is `low | mid << 8 | high << 16 | flags << 24`, flags
//! being bit 0 dual, bits 1..3 the floor's terrain type and bits 4..6 the
//! slab's (the decode of [`strata_level::model::decode_column`], done once
//! per texel at build and after edits instead of at every ray step).
//! Columns are stored in 4 x 4 blocks (one 64-byte cache line each, the
//! finest pyramid tile), blocks row-major: a ray descending into a tile
//! reads one line instead of four rows.

use rayon::prelude::*;
use strata_level::model::decode_column;
use strata_level::{Column, DirtyRect, Level, MidRule};

/// log2 of the tile ratio between pyramid levels (4 x 4 children), as the
/// CPU reference's traversal.
pub(crate) const LOG_RATIO: u32 = 2;
/// The coarsest level: tiles of 4^4 = 256 texels.
const MAX_LEVEL: u32 = 4;

/// Pack a decoded column.
#[inline]
pub(crate) fn pack(c: &Column) -> u32 {
    let flags =
        u32::from(c.dual) | u32::from(c.lower_type & 7) << 1 | u32::from(c.upper_type & 7) << 4;
    u32::from(c.low) | u32::from(c.mid) << 8 | u32::from(c.high) << 16 | flags << 24
}

/// A packed column's fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Packed(pub u32);

impl Packed {
    #[inline]
    pub fn low(self) -> u8 {
        self.0 as u8
    }
    #[inline]
    pub fn mid(self) -> u8 {
        (self.0 >> 8) as u8
    }
    #[inline]
    pub fn high(self) -> u8 {
        (self.0 >> 16) as u8
    }
    #[inline]
    pub fn dual(self) -> bool {
        self.0 & (1 << 24) != 0
    }
    #[inline]
    pub fn lower_type(self) -> u8 {
        ((self.0 >> 25) & 7) as u8
    }
    #[inline]
    pub fn upper_type(self) -> u8 {
        ((self.0 >> 28) & 7) as u8
    }
    /// Highest solid altitude.
    #[inline]
    pub fn top(self) -> u8 {
        if self.dual() { self.high() } else { self.low() }
    }
}

/// Index of texel (x, y) (inside the map) in the blocked layout of a map
/// `1 << log2_w` texels wide.
#[inline]
fn cell_index(x: i64, y: i64, log2_w: u32) -> usize {
    let block = (x >> 2) | (y >> 2) << (log2_w - 2);
    (block << 4 | (y & 3) << 2 | (x & 3)) as usize
}

/// One pyramid level: the tile maxima, row-major, wrapping.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Plane {
    /// log2 of tiles across.
    log2_w: u32,
    /// Tiles across - 1 and down - 1 (masks: both are powers of two).
    mask_x: i64,
    mask_y: i64,
    data: Vec<u8>,
}

impl Plane {
    #[inline]
    fn index(&self, tx: i64, ty: i64) -> usize {
        ((tx & self.mask_x) | (ty & self.mask_y) << self.log2_w) as usize
    }
}

/// The packed columns and their pyramid.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Columns {
    width: u32,
    height: u32,
    log2_w: u32,
    pub(crate) mid_rule: MidRule,
    cells: Vec<u32>,
    /// Levels 1..=top: tiles of 4^l texels.
    planes: Vec<Plane>,
    global_max: u8,
}

impl Columns {
    /// Decode every texel of `level` and build the pyramid (all cores).
    pub fn new(level: &Level) -> Self {
        let (w, h) = (level.width(), level.height());
        let mut cells = vec![0u32; w as usize * h as usize];
        let log2_w = w.trailing_zeros();
        if w < 4 || h < 4 {
            // Too small for blocks: row-major (`cell_index` is not used).
            for y in 0..h {
                let (hs, ms) = level.row(y);
                for x in 0..w as usize {
                    cells[x + (y as usize) * w as usize] =
                        pack(&decode_column(hs, ms, x, level.mid_rule));
                }
            }
        } else {
            // A band of 4 rows is a row of blocks.
            cells
                .par_chunks_mut(4 * w as usize)
                .enumerate()
                .for_each(|(by, band)| {
                    for dy in 0..4 {
                        let y = by as u32 * 4 + dy;
                        let (hs, ms) = level.row(y);
                        for x in 0..w as usize {
                            let i = cell_index(x as i64, i64::from(dy), log2_w);
                            band[i] = pack(&decode_column(hs, ms, x, level.mid_rule));
                        }
                    }
                });
        }
        let levels = MAX_LEVEL
            .min(w.trailing_zeros() / LOG_RATIO)
            .min(h.trailing_zeros() / LOG_RATIO);
        let planes = (1..=levels)
            .map(|l| {
                let s = LOG_RATIO * l;
                let (pw, ph) = (w >> s, h >> s);
                Plane {
                    log2_w: pw.trailing_zeros(),
                    mask_x: i64::from(pw - 1),
                    mask_y: i64::from(ph - 1),
                    data: vec![0; (pw * ph) as usize],
                }
            })
            .collect();
        let mut c = Columns {
            width: w,
            height: h,
            log2_w,
            mid_rule: level.mid_rule,
            cells,
            planes,
            global_max: 0,
        };
        c.build_pyramid();
        c
    }

    fn build_pyramid(&mut self) {
        for l in 0..self.planes.len() {
            let (done, rest) = self.planes.split_at_mut(l);
            let plane = &mut rest[0];
            let pw = 1usize << plane.log2_w;
            let child = done.last();
            let cells = &self.cells;
            let log2_w = self.log2_w;
            plane
                .data
                .par_chunks_mut(pw)
                .enumerate()
                .for_each(|(ty, row)| {
                    for (tx, v) in row.iter_mut().enumerate() {
                        *v = tile_max(cells, log2_w, child, tx as i64, ty as i64);
                    }
                });
        }
        self.update_global_max();
    }

    fn update_global_max(&mut self) {
        self.global_max = match self.planes.last() {
            Some(p) => p.data.iter().copied().max().unwrap_or(0),
            None => self
                .cells
                .iter()
                .map(|&c| Packed(c).top())
                .max()
                .unwrap_or(0),
        };
    }

    /// Map width, texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Map height, texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The coarsest pyramid level (0: none).
    #[inline]
    pub fn top_level(&self) -> usize {
        self.planes.len()
    }

    /// Highest solid altitude anywhere.
    #[inline]
    pub fn global_max(&self) -> u8 {
        self.global_max
    }

    /// Max top of tile (tx, ty) of level `l` (1..=top), wrapping.
    #[inline]
    pub fn tile_max(&self, l: usize, tx: i64, ty: i64) -> u8 {
        let p = &self.planes[l - 1];
        p.data[p.index(tx, ty)]
    }

    /// The packed column at texel (x, y), wrapping.
    #[inline]
    pub fn get(&self, x: i64, y: i64) -> Packed {
        let x = x & i64::from(self.width - 1);
        let y = y & i64::from(self.height - 1);
        Packed(self.cells[self.index(x, y)])
    }

    /// Where texel (x, y) (inside the map) is kept.
    #[inline]
    fn index(&self, x: i64, y: i64) -> usize {
        if self.width < 4 || self.height < 4 {
            (x + (y << self.log2_w)) as usize
        } else {
            cell_index(x, y, self.log2_w)
        }
    }

    /// Bytes held (columns and pyramid).
    pub fn memory_bytes(&self) -> usize {
        self.cells.capacity() * 4
            + self.planes.iter().map(|p| p.data.capacity()).sum::<usize>()
            + size_of::<Self>()
    }

    /// Re-decode the texels of `rect` from `level` (same size) and refresh
    /// the pyramid tiles over them. A rectangle reaching past the map wraps.
    pub fn update(&mut self, level: &Level, rect: &DirtyRect) {
        let (w, h) = (self.width, self.height);
        if rect.width == 0 || rect.height == 0 {
            return;
        }
        // Whole pairs (decode reads both texels of a pair).
        let x0 = i64::from(rect.x & !1);
        let x1 = (i64::from(rect.x) + i64::from(rect.width.min(w)) - 1) | 1;
        let y0 = i64::from(rect.y);
        let y1 = y0 + i64::from(rect.height.min(h)) - 1;
        let x1 = x1.min(x0 + i64::from(w) - 1);
        for y in y0..=y1 {
            let yw = (y & i64::from(h - 1)) as u32;
            let (hs, ms) = level.row(yw);
            for x in x0..=x1 {
                let xw = x & i64::from(w - 1);
                let i = self.index(xw, i64::from(yw));
                self.cells[i] = pack(&decode_column(hs, ms, xw as usize, self.mid_rule));
            }
        }
        for l in 0..self.planes.len() {
            let s = LOG_RATIO * (l as u32 + 1);
            let (done, rest) = self.planes.split_at_mut(l);
            let plane = &mut rest[0];
            let child = done.last();
            for ty in (y0 >> s)..=(y1 >> s) {
                for tx in (x0 >> s)..=(x1 >> s) {
                    let (tx, ty) = (tx & plane.mask_x, ty & plane.mask_y);
                    let i = plane.index(tx, ty);
                    plane.data[i] = tile_max(&self.cells, self.log2_w, child, tx, ty);
                }
            }
        }
        self.update_global_max();
    }
}

/// Max of tile (tx, ty) (inside the map) of the level above `child` (the
/// texels' tops when `child` is `None`).
fn tile_max(cells: &[u32], log2_w: u32, child: Option<&Plane>, tx: i64, ty: i64) -> u8 {
    let n = 1i64 << LOG_RATIO;
    let (x0, y0) = (tx * n, ty * n);
    let mut m = 0u8;
    for y in y0..y0 + n {
        for x in x0..x0 + n {
            let v = match child {
                // Levels exist only on maps of 4 x 4 texels or more: blocked.
                None => Packed(cells[cell_index(x, y, log2_w)]).top(),
                Some(c) => c.data[c.index(x, y)],
            };
            m = m.max(v);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(level: &Level, l: u32, tx: i64, ty: i64) -> u8 {
        let s = 1i64 << (LOG_RATIO * l);
        let mut m = 0;
        for y in ty * s..(ty + 1) * s {
            for x in tx * s..(tx + 1) * s {
                m = m.max(level.column(x, y).top());
            }
        }
        m
    }

    #[test]
    fn packed_columns_decode_like_the_level_and_tiles_hold_maxima() {
        let level = strata_mesh::synthetic::synthetic_level(128, 64, 5);
        let c = Columns::new(&level);
        assert_eq!(c.top_level(), 3, "64 rows: tiles of 4, 16, 64");
        for y in -3..70 {
            for x in -5..140 {
                let col = level.column(x, y);
                let p = c.get(x, y);
                assert_eq!(
                    (
                        p.low(),
                        p.mid(),
                        p.high(),
                        p.dual(),
                        p.lower_type(),
                        p.upper_type()
                    ),
                    (
                        col.low,
                        col.mid,
                        col.high,
                        col.dual,
                        col.lower_type,
                        col.upper_type
                    )
                );
            }
        }
        for l in 1..=3u32 {
            let s = 1i64 << (LOG_RATIO * l);
            for ty in 0..64 / s {
                for tx in 0..128 / s {
                    assert_eq!(c.tile_max(l as usize, tx, ty), brute(&level, l, tx, ty));
                }
            }
        }
    }

    #[test]
    fn maps_narrower_than_a_block_are_kept_row_major() {
        for (w, h) in [(2, 1), (2, 8), (8, 2), (4, 4)] {
            let level = strata_mesh::synthetic::synthetic_level(w, h, 1);
            let c = Columns::new(&level);
            for y in 0..i64::from(h) {
                for x in 0..i64::from(w) {
                    assert_eq!(c.get(x, y).low(), level.column(x, y).low, "{w}x{h}");
                }
            }
            let top = (0..i64::from(h))
                .flat_map(|y| (0..i64::from(w)).map(move |x| (x, y)))
                .map(|(x, y)| level.column(x, y).top())
                .max();
            assert_eq!(Some(c.global_max()), top);
        }
    }

    #[test]
    fn an_update_equals_a_fresh_build_even_across_the_edge() {
        let level = strata_mesh::synthetic::synthetic_level(128, 64, 2);
        let mut c = Columns::new(&level);
        let mut edited = level.clone();
        let rect = DirtyRect {
            x: 120,
            y: 60,
            width: 20,
            height: 9,
        };
        // The same rectangle wrapped onto the map.
        for y in 60..69u32 {
            for x in 120..140u32 {
                let i = ((y % 64) * 128 + x % 128) as usize;
                edited.planes_mut().0[i] = (x * 7 + y) as u8;
            }
        }
        c.update(&edited, &rect);
        assert_eq!(c, Columns::new(&edited));
    }
}
