//! A max-height pyramid of column tops: level `l` holds the maximum over
//! tiles of `4^l x 4^l` texels (level 0, the texels, is the map itself). A ray that stays
//! above a tile's maximum touches nothing in it (above the top of a column
//! nothing is solid, slab or not), so skipping such a tile is exact.

use strata_level::Level;

/// log2 of the tile ratio between consecutive levels (4 x 4 children).
pub(crate) const LOG_RATIO: u32 = 2;

/// The tracer's view of the shared max pyramid (`strata_maxmip`, levels of
/// `2^k` texels): its level `l` is the shared level `2 l`, tiles of `4^l`
/// texels, up to 4^4 = 256.
pub(crate) struct Pyramid {
    shared: Option<strata_maxmip::Pyramid>,
    top: usize,
    global_max: u8,
}

impl Pyramid {
    pub(crate) fn new(level: &Level) -> Self {
        let shared = strata_maxmip::Pyramid::new(level);
        let top = (shared.top() / LOG_RATIO) as usize;
        let global_max = shared.global_max();
        Pyramid {
            shared: Some(shared),
            top,
            global_max,
        }
    }

    /// The coarsest level index.
    pub(crate) fn top_level(&self) -> usize {
        self.top
    }

    /// No tiles, and the highest altitude any column can have: a tracer
    /// over it visits every texel column (nothing to build first).
    pub(crate) fn none() -> Self {
        Pyramid {
            shared: None,
            top: 0,
            global_max: u8::MAX,
        }
    }

    /// Highest solid altitude anywhere on the map.
    pub(crate) fn global_max(&self) -> u8 {
        self.global_max
    }

    /// Max top of tile (cx, cy) of `level` (1..=top), wrapping around the map.
    #[inline]
    pub(crate) fn get(&self, level: usize, cx: i64, cy: i64) -> u8 {
        let shared = self.shared.as_ref().expect("levels exist below top_level");
        shared.get(LOG_RATIO * level as u32, cx, cy)
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
        for l in 1..=2usize {
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
