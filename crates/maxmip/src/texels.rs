//! The texel plane beside the pyramids: one byte per texel, the column's
//! top where the column is a single floor, [`DECODE`] where the march must
//! decode the column itself (it has a slab, or its top is 255). With it, a
//! ray's walk over the texels of a 4x4 tile reads the tile's sixteen bytes
//! at once (four words, one per row) and tests each single-floor column
//! from them, instead of waiting on a terrain fetch per texel.

use crate::{DirtyRect, Level, decode_column};
use rayon::prelude::*;

/// The byte of a texel whose column must be decoded from the terrain: a
/// column with a slab, or a single floor of height 255 (decoding that one
/// is slower but gives the same answer).
pub const DECODE: u8 = 255;

/// A row-major byte plane of the map, as little-endian words four texels a
/// word (what the GPU holds), wrapping in x and y like the map.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TexelTops {
    /// Texels across (a power of two, at least 4).
    pub width: u32,
    /// Texels down.
    pub height: u32,
    /// One byte per texel, row-major.
    pub data: Vec<u8>,
}

/// Texel (x, y)'s byte: its top when its column is a single floor below
/// 255, else [`DECODE`].
#[inline]
fn texel_byte(level: &Level, x: u32, y: u32) -> u8 {
    let (h, m) = level.row(y);
    let c = decode_column(h, m, x as usize, level.mid_rule);
    if c.dual { DECODE } else { c.low }
}

impl TexelTops {
    /// Whether a map of this size has a texel plane: rows of whole words,
    /// and sides that are powers of two (the GPU wraps with masks).
    pub fn fits(width: u32, height: u32) -> bool {
        width >= 4 && width.is_power_of_two() && height.is_power_of_two()
    }

    /// Build the plane of `level` (whose width [`TexelTops::fits`]).
    pub fn new(level: &Level) -> Self {
        let (width, height) = (level.width(), level.height());
        assert!(
            Self::fits(width, height),
            "{width}x{height}: no texel plane"
        );
        let mut p = TexelTops {
            width,
            height,
            data: vec![0; (width * height) as usize],
        };
        p.update(
            level,
            &DirtyRect {
                x: 0,
                y: 0,
                width,
                height,
            },
        );
        p
    }

    /// Rewrite the texels of `rect` (already changed in `level`), widened
    /// to whole words as the GPU rewrites them.
    pub fn update(&mut self, level: &Level, rect: &DirtyRect) {
        let w = self.width as usize;
        let (x0, x1) = (rect.x / 4 * 4, (rect.x + rect.width).div_ceil(4) * 4);
        let (y0, y1) = (rect.y, rect.y + rect.height);
        self.data[y0 as usize * w..y1 as usize * w]
            .par_chunks_mut(w)
            .enumerate()
            .for_each(|(i, row)| {
                let y = y0 + i as u32;
                for x in x0..x1.min(self.width) {
                    row[x as usize] = texel_byte(level, x, y);
                }
            });
    }

    /// Texel (x, y)'s byte, wrapping around the map.
    #[inline]
    pub fn get(&self, x: i64, y: i64) -> u8 {
        let x = x.rem_euclid(i64::from(self.width)) as usize;
        let y = y.rem_euclid(i64::from(self.height)) as usize;
        self.data[y * self.width as usize + x]
    }

    /// The plane as little-endian words (what the GPU holds).
    pub fn words(&self) -> Vec<u32> {
        crate::le_words(&self.data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_floors_keep_their_top_and_slabs_ask_for_a_decode() {
        let mut level = Level::flat(8, 4, 40, 1).unwrap();
        let mut tops = TexelTops::new(&level);
        assert!(tops.data.iter().all(|&b| b == 40));
        let (heights, _) = level.planes_mut();
        heights[2 * 8 + 5] = 255;
        heights[3 * 8 + 1] = 7;
        let dirty = DirtyRect {
            x: 1,
            y: 2,
            width: 5,
            height: 2,
        };
        tops.update(&level, &dirty);
        assert_eq!(tops, TexelTops::new(&level));
        assert_eq!(tops.get(5, 2), DECODE);
        assert_eq!(tops.get(1 - 8, 3 + 4), 7);
        assert_eq!(
            tops.words()[2 * 2 + 1],
            u32::from_le_bytes([40, 255, 40, 40])
        );
        assert!(!TexelTops::fits(6, 4) && !TexelTops::fits(2, 2) && TexelTops::fits(4, 1));
    }
}
