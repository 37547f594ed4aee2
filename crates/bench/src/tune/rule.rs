//! The paper's one-point rule: among a method's sweep, the cheapest setting
//! whose combined error is within one percentage point of the method's best.

/// Combined error allowance over the best, percentage points.
pub const TOLERANCE_POINTS: f64 = 1.0;

/// Index of the chosen point of `(cost, error)` pairs: the lowest cost among
/// the points with `error <= best + tolerance`; equal costs go to the lower
/// error, then to the earlier point. Points with a non-finite cost or error
/// (a failed measurement) never win. `None` when no point is usable.
pub fn choose(points: &[(f64, f64)], tolerance: f64) -> Option<usize> {
    let usable = |&(c, e): &(f64, f64)| c.is_finite() && e.is_finite();
    let best = points
        .iter()
        .filter(|p| usable(p))
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min);
    if !best.is_finite() {
        return None;
    }
    let mut chosen: Option<usize> = None;
    for (i, p) in points.iter().enumerate() {
        if !usable(p) || p.1 > best + tolerance {
            continue;
        }
        let better = match chosen {
            None => true,
            Some(j) => {
                let q = points[j];
                p.0 < q.0 || (p.0 == q.0 && p.1 < q.1)
            }
        };
        if better {
            chosen = Some(i);
        }
    }
    chosen
}

/// Index of the lowest error (the earliest on ties).
pub fn best(points: &[(f64, f64)]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, p) in points.iter().enumerate() {
        if !(p.0.is_finite() && p.1.is_finite()) {
            continue;
        }
        if best.is_none_or(|j| p.1 < points[j].1) {
            best = Some(i);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cheapest_point_within_one_point_of_the_best_wins() {
        // Error falls with cost; 64 steps is within 1 point of 256's best.
        let sweep = [(1.0, 9.0), (2.0, 3.5), (4.0, 2.9), (8.0, 2.6), (16.0, 2.5)];
        assert_eq!(choose(&sweep, 1.0), Some(1));
        assert_eq!(best(&sweep), Some(4));
        // Exactly one point over the best is still within.
        let edge = [(1.0, 3.5), (2.0, 2.5)];
        assert_eq!(choose(&edge, 1.0), Some(0));
        // Zero tolerance: the best itself.
        assert_eq!(choose(&sweep, 0.0), Some(4));
    }

    #[test]
    fn ties_go_to_the_lower_error_then_the_earlier_point() {
        // Equal costs: the lower error.
        let same_cost = [(2.0, 3.0), (2.0, 2.5), (5.0, 2.4)];
        assert_eq!(choose(&same_cost, 1.0), Some(1));
        // Equal cost and error: the earlier.
        let identical = [(3.0, 1.0), (3.0, 1.0)];
        assert_eq!(choose(&identical, 1.0), Some(0));
        // Equal best errors: best() takes the earlier.
        assert_eq!(best(&identical), Some(0));
    }

    #[test]
    fn non_monotone_sweeps_and_failed_points() {
        // More slices only move the error: the best is in the middle, and
        // a cheaper point past it (by cost order) can still qualify.
        let moving = [(1.0, 6.0), (2.0, 4.0), (4.0, 3.0), (8.0, 3.8), (16.0, 5.0)];
        assert_eq!(best(&moving), Some(2));
        assert_eq!(choose(&moving, 1.0), Some(1));
        // Cost not monotone in the knob either: a cheaper later point wins.
        let odd_cost = [(5.0, 2.0), (3.0, 2.8), (4.0, 2.1)];
        assert_eq!(choose(&odd_cost, 1.0), Some(1));
        // Failed points (NaN, infinite) never win and never set the best.
        let failed = [(f64::NAN, 0.0), (2.0, 3.0), (1.0, f64::INFINITY)];
        assert_eq!(choose(&failed, 1.0), Some(1));
        assert_eq!(choose(&[(f64::NAN, 1.0)], 1.0), None);
        assert_eq!(choose(&[], 1.0), None);
    }
}
