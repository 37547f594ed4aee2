//! A max-height pyramid of column tops: level 0 holds each texel's top,
//! level `l` the maximum over tiles of `4^l x 4^l` texels. A ray that stays
//! above a tile's maximum touches nothing in it (above the top of a column
//! nothing is solid, slab or not), so skipping such a tile is exact.

use rayon::prelude::*;
use strata_level::Level;
use strata_level::model::decode_column;

/// log2 of the tile ratio between consecutive levels (4 x 4 children).
pub(crate) const LOG_RATIO: u32 = 2;
/// Coarsest tile: 4^4 = 256 texels on a side. Coarser tiles are almost never
/// entirely below a ray that is close enough to the ground to matter.
const MAX_LEVEL: usize = 4;

struct Plane {
    width: usize,
    mask_x: i64,
    mask_y: i64,
    data: Vec<u8>,
}

pub(crate) struct Pyramid {
    planes: Vec<Plane>,
    global_max: u8,
}

impl Pyramid {
    pub(crate) fn new(level: &Level) -> Self {
        let (w, h) = (level.width() as usize, level.height() as usize);
        let mut tops = vec![0u8; w * h];
        tops.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
            let (heights, metas) = level.row(y as u32);
            for (x, top) in out.iter_mut().enumerate() {
                *top = decode_column(heights, metas, x, level.mid_rule).top();
            }
        });
        let global_max = tops.par_iter().copied().max().unwrap_or(0);
        let mut planes = vec![Plane {
            width: w,
            mask_x: w as i64 - 1,
            mask_y: h as i64 - 1,
            data: tops,
        }];
        let ratio = 1usize << LOG_RATIO;
        while planes.len() <= MAX_LEVEL {
            let prev = planes.last().expect("level 0 exists");
            let (pw, ph) = (prev.width, prev.data.len() / prev.width);
            if pw < ratio || ph < ratio {
                break;
            }
            let (nw, nh) = (pw / ratio, ph / ratio);
            let mut data = vec![0u8; nw * nh];
            data.par_chunks_mut(nw).enumerate().for_each(|(cy, out)| {
                for (cx, m) in out.iter_mut().enumerate() {
                    let mut best = 0u8;
                    for row in prev.data[cy * ratio * pw..].chunks(pw).take(ratio) {
                        for &v in &row[cx * ratio..cx * ratio + ratio] {
                            best = best.max(v);
                        }
                    }
                    *m = best;
                }
            });
            planes.push(Plane {
                width: nw,
                mask_x: nw as i64 - 1,
                mask_y: nh as i64 - 1,
                data,
            });
        }
        Pyramid { planes, global_max }
    }

    /// The coarsest level index.
    pub(crate) fn top_level(&self) -> usize {
        self.planes.len().saturating_sub(1)
    }

    /// No tiles, and the highest altitude any column can have: a tracer
    /// over it visits every texel column (nothing to build first).
    pub(crate) fn none() -> Self {
        Pyramid {
            planes: Vec::new(),
            global_max: u8::MAX,
        }
    }

    /// Highest solid altitude anywhere on the map.
    pub(crate) fn global_max(&self) -> u8 {
        self.global_max
    }

    /// Max top of tile (cx, cy) of `level`, wrapping around the map.
    #[inline]
    pub(crate) fn get(&self, level: usize, cx: i64, cy: i64) -> u8 {
        let p = &self.planes[level];
        p.data[(cx & p.mask_x) as usize + (cy & p.mask_y) as usize * p.width]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::MidRule;

    #[test]
    fn levels_hold_tile_maxima_and_wrap() {
        let (w, h) = (64u32, 16u32);
        let heights: Vec<u8> = (0..w * h).map(|i| ((i * 37) % 200) as u8).collect();
        let level = Level::from_planes(
            w,
            h,
            heights.clone(),
            vec![0; (w * h) as usize],
            MidRule::Original,
        )
        .unwrap();
        let p = Pyramid::new(&level);
        assert_eq!(p.top_level(), 2, "16 rows allow tiles of 1, 4 and 16");
        assert_eq!(p.global_max(), *heights.iter().max().unwrap());
        for l in 1..=2 {
            let s = 1i64 << (2 * l);
            for cy in 0..(i64::from(h) / s) {
                for cx in 0..(i64::from(w) / s) {
                    let mut m = 0;
                    for y in cy * s..(cy + 1) * s {
                        for x in cx * s..(cx + 1) * s {
                            m = m.max(heights[(x + y * i64::from(w)) as usize]);
                        }
                    }
                    assert_eq!(p.get(l, cx, cy), m);
                    assert_eq!(p.get(l, cx - i64::from(w) / s, cy + i64::from(h) / s), m);
                }
            }
        }
    }
}
