//! One ray against the two-interval column model: the float steps both CPU
//! ray tracers take (the reference tracer, `strata-reference`, and the
//! game collider, `strata-collide`), kept in one place so that their hits
//! agree bit for bit.

/// The texel holding `p + eps d` along one axis: a point exactly on a texel
/// line belongs to the side the ray moves into. `floor` without
/// `f64::floor` (a libm call on baseline x86-64): exact for |p| < 2^63.
#[inline]
pub fn texel_after(p: f64, d: f64) -> i64 {
    let mut c = p as i64;
    if c as f64 > p {
        c -= 1;
    }
    if c as f64 == p && d < 0.0 { c - 1 } else { c }
}

/// Ray parameter where it leaves cell `c` (of side `size`) along one axis.
/// Computed from the boundary's own coordinate, never accumulated, so the
/// same texel line gives the same float at every level and subdivision.
#[inline]
pub fn boundary_t(o: f64, d: f64, c: i64, size: f64) -> f64 {
    if d > 0.0 {
        ((c + 1) as f64 * size - o) / d
    } else if d < 0.0 {
        (c as f64 * size - o) / d
    } else {
        f64::INFINITY
    }
}

/// First `t` in `[t0, t1]` with `a <= oz + t dz <= b`, if any.
#[inline]
pub fn interval_entry(a: f64, b: f64, oz: f64, dz: f64, t0: f64, t1: f64) -> Option<f64> {
    if t1 < t0 {
        return None;
    }
    let (lo, hi) = if dz == 0.0 {
        if a <= oz && oz <= b {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return None;
        }
    } else {
        let (ta, tb) = ((a - oz) / dz, (b - oz) / dz);
        (ta.min(tb), ta.max(tb))
    };
    let enter = lo.max(t0);
    (enter <= hi.min(t1)).then_some(enter)
}

/// The first `t` in `[t0, t1]` at which `oz + t dz` is solid in a column
/// with floor `[.., low]` and, when `slab` is given, the slab `[mid, high]`,
/// and whether that point is in the slab. The earlier entry wins; on a tie
/// the floor (the lower interval).
#[inline]
pub fn column_entry(
    low: u8,
    slab: Option<(u8, u8)>,
    oz: f64,
    dz: f64,
    t0: f64,
    t1: f64,
) -> Option<(f64, bool)> {
    let floor = interval_entry(f64::NEG_INFINITY, f64::from(low), oz, dz, t0, t1);
    let slab = slab
        .and_then(|(mid, high)| interval_entry(f64::from(mid), f64::from(high), oz, dz, t0, t1));
    match (floor, slab) {
        (Some(f), Some(s)) if s < f => Some((s, true)),
        (Some(f), _) => Some((f, false)),
        (None, Some(s)) => Some((s, true)),
        (None, None) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_after_is_floor_except_on_lines_moving_back() {
        for &p in &[-3.5, -3.0, -0.25, 0.0, 0.75, 2.0, 1e12 + 0.5] {
            let f = f64::floor(p) as i64;
            assert_eq!(texel_after(p, 1.0), f, "{p}");
            let back = if p == f64::floor(p) { f - 1 } else { f };
            assert_eq!(texel_after(p, -1.0), back, "{p}");
        }
    }

    #[test]
    fn the_earlier_interval_wins_and_a_tie_goes_to_the_floor() {
        // Falling from 100 at 1 per t: the slab [60, 80] is met at t = 20,
        // the floor [.., 10] at t = 90.
        assert_eq!(
            column_entry(10, Some((60, 80)), 100.0, -1.0, 0.0, 200.0),
            Some((20.0, true))
        );
        assert_eq!(
            column_entry(10, None, 100.0, -1.0, 0.0, 200.0),
            Some((90.0, false))
        );
        // Inside both at t0 (slab touching the floor): the floor.
        assert_eq!(
            column_entry(50, Some((50, 60)), 50.0, 0.0, 3.0, 4.0),
            Some((3.0, false))
        );
        assert_eq!(
            column_entry(10, Some((60, 80)), 100.0, 1.0, 0.0, 200.0),
            None
        );
    }
}
