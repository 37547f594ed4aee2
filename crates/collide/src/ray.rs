//! The exact ray cast: the CPU reference's traversal (`strata_reference`'s
//! `raycast.rs`) over the collider's packed columns. A hierarchical 2D grid
//! walk over the max-height pyramid (a tile the ray passes above holds
//! nothing it can touch), then, in each texel column the ray crosses, the
//! first point of its segment inside `[0, low]` or `[mid, high]`.
//!
//! Every float is computed as the reference computes it (the segment ends
//! from the crossed texel line's own coordinate, f64 throughout), so a hit
//! here is the reference's hit: same column, same distance. The float
//! steps themselves (`texel_after`, `boundary_t`, the column entry) are
//! `strata_level::ray`, which both tracers call.

use crate::columns::{Columns, LOG_RATIO, Packed};
use strata_level::ray;

/// How a ray met a column: what [`crate::RayHit::normal`] is made from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Face {
    /// The top of the floor `[0, low]`.
    Floor,
    /// The top of a slab `[mid, high]`, from above.
    SlabTop,
    /// The underside of a slab (a cave's ceiling), from below.
    Ceiling,
    /// A column's side, entered across a texel line of x (`true`) or y.
    Wall {
        /// Entered across a line of constant x.
        across_x: bool,
    },
}

/// A hit of the traversal (the column's coordinates unwrapped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Hit {
    pub t: f64,
    pub face: Face,
    pub column: [i64; 2],
    pub terrain: u8,
}

/// The first solid point of the segment `[t0, t1]` in column `c`; `entry`
/// says `t0` is where the ray entered the column (solid there: a wall).
#[inline]
fn column_hit(
    c: Packed,
    oz: f64,
    dz: f64,
    t0: f64,
    t1: f64,
    entry: bool,
) -> Option<(f64, Face, u8)> {
    let slab = c.dual().then(|| (c.mid(), c.high()));
    let (t, is_slab) = ray::column_entry(c.low(), slab, oz, dz, t0, t1)?;
    let face = if entry && t <= t0 {
        Face::Wall { across_x: false }
    } else if !is_slab {
        Face::Floor
    } else if dz < 0.0 {
        Face::SlabTop
    } else {
        Face::Ceiling
    };
    let terrain = if is_slab {
        c.upper_type()
    } else {
        c.lower_type()
    };
    Some((t, face, terrain))
}

impl Columns {
    /// The first solid point along `o + t d`, `t` in `[0, t_max]` (`d` a
    /// unit vector, everything finite: the caller checks).
    pub(crate) fn cast(&self, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<Hit> {
        let ceiling = f64::from(self.global_max());
        let mut t = 0.0f64;
        let mut t_end = t_max;
        if o[2] > ceiling {
            if d[2] >= 0.0 {
                return None;
            }
            t = (ceiling - o[2]) / d[2];
        }
        if d[2] > 0.0 {
            t_end = t_end.min((ceiling - o[2]) / d[2]);
        }
        if t > t_end {
            return None;
        }
        let t_start = t;
        let top = self.top_level();
        let step_x: i64 = if d[0] > 0.0 { 1 } else { -1 };
        let step_y: i64 = if d[1] > 0.0 { 1 } else { -1 };
        let (tx0, ty0) = (
            ray::texel_after(o[0] + d[0] * t, d[0]),
            ray::texel_after(o[1] + d[1] * t, d[1]),
        );
        let mut lvl = top;
        let mut cx = tx0 >> (LOG_RATIO as usize * lvl);
        let mut cy = ty0 >> (LOG_RATIO as usize * lvl);
        let mut across_x = false;
        // The exit parameters of the current cell along x and y, kept while
        // the cell's coordinate on that axis and the level stay the same
        // (the same float the reference recomputes each step).
        let (mut tx, mut ty) = (0.0, 0.0);
        let (mut new_x, mut new_y) = (true, true);
        loop {
            let shift = LOG_RATIO as usize * lvl;
            let size = (1i64 << shift) as f64;
            if new_x {
                tx = ray::boundary_t(o[0], d[0], cx, size);
            }
            if new_y {
                ty = ray::boundary_t(o[1], d[1], cy, size);
            }
            (new_x, new_y) = (false, false);
            let t_exit = tx.min(ty);
            let t_out = t_exit.min(t_end);
            if lvl > 0 {
                let z_min = (o[2] + d[2] * t).min(o[2] + d[2] * t_out);
                if z_min <= f64::from(self.tile_max(lvl, cx, cy)) {
                    // Descend to the child tile the ray is in at `t`.
                    lvl -= 1;
                    let child_shift = shift - LOG_RATIO as usize;
                    let (ax, ay) = (
                        ray::texel_after(o[0] + d[0] * t, d[0]),
                        ray::texel_after(o[1] + d[1] * t, d[1]),
                    );
                    let first = |c: i64| c << LOG_RATIO;
                    let last = |c: i64| (c << LOG_RATIO) + (1 << LOG_RATIO) - 1;
                    cx = (ax >> child_shift).clamp(first(cx), last(cx));
                    cy = (ay >> child_shift).clamp(first(cy), last(cy));
                    (new_x, new_y) = (true, true);
                    continue;
                }
            } else {
                let c = self.get(cx, cy);
                if let Some((t_hit, mut face, terrain)) =
                    column_hit(c, o[2], d[2], t, t_out, t > t_start)
                {
                    if let Face::Wall { .. } = face {
                        face = Face::Wall { across_x };
                    }
                    return Some(Hit {
                        t: t_hit,
                        face,
                        column: [cx, cy],
                        terrain,
                    });
                }
            }
            if t_exit >= t_end {
                return None;
            }
            t = t_exit;
            let (old_x, old_y) = (cx, cy);
            across_x = tx <= ty;
            if tx <= ty {
                cx += step_x;
                new_x = true;
            }
            if ty <= tx {
                cy += step_y;
                new_y = true;
            }
            if lvl < top
                && (old_x >> LOG_RATIO != cx >> LOG_RATIO || old_y >> LOG_RATIO != cy >> LOG_RATIO)
            {
                lvl += 1;
                cx >>= LOG_RATIO;
                cy >>= LOG_RATIO;
                (new_x, new_y) = (true, true);
            }
        }
    }
}
