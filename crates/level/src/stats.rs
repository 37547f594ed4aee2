//! `LevelStats`: the figures `strata info` prints and the generator is tuned
//! against (size, dual fraction, height range, terrain types, roughness).
//!
//! Roughness is the mean absolute 4-neighbour discrete Laplacian
//! `|v(x-1,y) + v(x+1,y) + v(x,y-1) + v(x,y+1) - 4 v(x,y)|`, wrapping:
//! - `roughness_floor`: of `low` (the floor) per texel;
//! - `roughness_surface`: of the composite surface the mesh fitter sees,
//!   defined as the per-texel mean of the three interval bounds,
//!   `(|lap low| + |lap mid| + |lap high|) / 3` (single texels have
//!   `low = mid = high`, so away from slabs it equals the floor figure).
//!
//! Paper figures for Fostral: floor 3.44, surface 6.54.

use crate::model::{Level, TERRAIN_TYPES, decode_column};
use rayon::prelude::*;
use serde::Serialize;

/// What `strata info` reports about a map (see the module docs for the
/// roughness figures).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelStats {
    /// Map width, texels.
    pub width: u32,
    /// Map height, texels.
    pub height: u32,
    /// Percent of texels in dual pairs.
    pub dual_percent: f64,
    /// Lowest `low` over the map.
    pub height_min: u8,
    /// Highest top (`high` of dual texels, `low` of single ones).
    pub height_max: u8,
    /// Percent of all texels per floor (lower) terrain type 0..7.
    pub floor_type_percent: [f64; TERRAIN_TYPES],
    /// Percent of dual texels per slab (upper) terrain type 0..7.
    pub slab_type_percent: [f64; TERRAIN_TYPES],
    /// Mean |discrete Laplacian| of `low`.
    pub roughness_floor: f64,
    /// Mean of (|lap low| + |lap mid| + |lap high|) / 3.
    pub roughness_surface: f64,
    /// Pairs whose two texels disagree about the dual flag.
    pub pair_disagreements: u64,
}

/// Per-band partial sums, merged across threads.
#[derive(Clone, Default)]
struct Acc {
    dual: u64,
    min: u8,
    max: u8,
    floor_types: [u64; TERRAIN_TYPES],
    slab_types: [u64; TERRAIN_TYPES],
    lap_low: u64,
    lap_all: u64,
}

impl Acc {
    fn new() -> Self {
        Acc {
            min: u8::MAX,
            ..Default::default()
        }
    }
    fn merge(mut self, o: Acc) -> Acc {
        self.dual += o.dual;
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
        for t in 0..TERRAIN_TYPES {
            self.floor_types[t] += o.floor_types[t];
            self.slab_types[t] += o.slab_types[t];
        }
        self.lap_low += o.lap_low;
        self.lap_all += o.lap_all;
        self
    }
}

/// One decoded row as three planes.
struct Row {
    low: Vec<i32>,
    mid: Vec<i32>,
    high: Vec<i32>,
}

/// Accumulate the per-texel figures of row `y` into `acc`.
fn count_row(level: &Level, y: u32, acc: &mut Acc) {
    let (hr, mr) = level.row(y);
    for x in 0..hr.len() {
        let c = decode_column(hr, mr, x, level.mid_rule);
        acc.min = acc.min.min(c.low);
        acc.max = acc.max.max(c.top());
        acc.floor_types[usize::from(c.lower_type & 7)] += 1;
        if c.dual {
            acc.dual += 1;
            acc.slab_types[usize::from(c.upper_type & 7)] += 1;
        }
    }
}

fn decode_row(level: &Level, y: u32) -> Row {
    let (h, m) = level.row(y & (level.height() - 1));
    let w = h.len();
    let mut row = Row {
        low: Vec::with_capacity(w),
        mid: Vec::with_capacity(w),
        high: Vec::with_capacity(w),
    };
    for x in 0..w {
        let c = decode_column(h, m, x, level.mid_rule);
        row.low.push(c.low.into());
        row.mid.push(c.mid.into());
        row.high.push(c.high.into());
    }
    row
}

/// Sum over a row of |lap| of one plane, given the rows above and below.
fn lap_sum(up: &[i32], cur: &[i32], down: &[i32]) -> u64 {
    let w = cur.len();
    let lap =
        |l: i32, r: i32, x: usize| u64::from((l + r + up[x] + down[x] - 4 * cur[x]).unsigned_abs());
    if w < 2 {
        return (0..w).map(|x| lap(cur[x], cur[x], x)).sum();
    }
    // Interior without wrap arithmetic; the two edge texels wrap.
    let mut sum = lap(cur[w - 1], cur[1], 0) + lap(cur[w - 2], cur[0], w - 1);
    for x in 1..w - 1 {
        sum += lap(cur[x - 1], cur[x + 1], x);
    }
    sum
}

/// Rows per parallel band: each band decodes two extra rows for its edges.
const BAND: u32 = 64;

impl LevelStats {
    /// Scan the whole map (in parallel bands of rows).
    pub fn compute(level: &Level) -> LevelStats {
        let (w, h) = (level.width(), level.height());
        let bands = h.div_ceil(BAND);
        let acc = (0..bands)
            .into_par_iter()
            .map(|b| {
                let mut acc = Acc::new();
                let y0 = b * BAND;
                let y1 = (y0 + BAND).min(h);
                let mut up = decode_row(level, y0.wrapping_add(h - 1));
                let mut cur = decode_row(level, y0);
                for y in y0..y1 {
                    let down = decode_row(level, y + 1);
                    count_row(level, y, &mut acc);
                    let low = lap_sum(&up.low, &cur.low, &down.low);
                    acc.lap_low += low;
                    acc.lap_all += low
                        + lap_sum(&up.mid, &cur.mid, &down.mid)
                        + lap_sum(&up.high, &cur.high, &down.high);
                    up = std::mem::replace(&mut cur, down);
                }
                acc
            })
            .reduce(Acc::new, Acc::merge);
        let n = f64::from(w) * f64::from(h);
        let pct = |c: u64, of: f64| if of > 0.0 { 100.0 * c as f64 / of } else { 0.0 };
        LevelStats {
            width: w,
            height: h,
            dual_percent: pct(acc.dual, n),
            height_min: acc.min,
            height_max: acc.max,
            floor_type_percent: acc.floor_types.map(|c| pct(c, n)),
            slab_type_percent: acc.slab_types.map(|c| pct(c, acc.dual as f64)),
            roughness_floor: acc.lap_low as f64 / n,
            roughness_surface: acc.lap_all as f64 / (3.0 * n),
            pair_disagreements: level.pair_disagreement_count(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT, MidRule};

    #[test]
    fn flat_level_is_smooth() {
        let level = Level::flat(16, 8, 50, 3).unwrap();
        let s = LevelStats::compute(&level);
        assert_eq!(
            (s.width, s.height, s.height_min, s.height_max),
            (16, 8, 50, 50)
        );
        assert_eq!(
            (s.roughness_floor, s.roughness_surface, s.dual_percent),
            (0.0, 0.0, 0.0)
        );
        assert_eq!(s.floor_type_percent[3], 100.0);
        assert_eq!(s.pair_disagreements, 0);
    }

    #[test]
    fn one_spike_and_one_slab() {
        // 8x4 level at 10; texel (4,1) is 18: |lap| = 32 there, 8 at each of
        // its 4 neighbours -> sum 64 over 32 texels = 2.0.
        let mut level = Level::flat(8, 4, 10, 1).unwrap();
        let (h, m) = level.planes_mut();
        h[8 + 4] = 18;
        // A dual pair at (0,3),(1,3): low 10, high 60, code 0 -> mid 18 (original).
        h[24 + 1] = 60;
        m[24] = META_DOUBLE_LEVEL | (2 << META_TERRAIN_SHIFT);
        m[25] = META_DOUBLE_LEVEL | (6 << META_TERRAIN_SHIFT);
        // A disagreeing pair.
        m[26] |= META_DOUBLE_LEVEL;
        let s = LevelStats::compute(&level);
        assert_eq!(s.roughness_floor, 2.0);
        assert!((s.dual_percent - 100.0 * 2.0 / 32.0).abs() < 1e-9);
        assert_eq!((s.height_min, s.height_max), (10, 60));
        assert_eq!(s.slab_type_percent[6], 100.0);
        assert!((s.floor_type_percent[2] - 100.0 * 2.0 / 32.0).abs() < 1e-9);
        assert_eq!(s.pair_disagreements, 1);
        // Surface: the definition, evaluated texel by texel through `column`.
        let mut total = 0f64;
        for y in 0..4i64 {
            for x in 0..8i64 {
                let c = |dx: i64, dy: i64| level.column(x + dx, y + dy);
                let lap = |f: &dyn Fn(crate::Column) -> u8| {
                    let v = |dx, dy| i32::from(f(c(dx, dy)));
                    (v(-1, 0) + v(1, 0) + v(0, -1) + v(0, 1) - 4 * v(0, 0)).abs() as f64
                };
                total += (lap(&|c| c.low) + lap(&|c| c.mid) + lap(&|c| c.high)) / 3.0;
            }
        }
        assert!((s.roughness_surface - total / 32.0).abs() < 1e-9);
        assert!(s.roughness_surface > s.roughness_floor);
        assert_eq!(level.mid_rule, MidRule::Original);
    }
}
