//! Exact geometric predicates on integer grid coordinates.
//!
//! The sample grid is massively cocircular (every grid square's four corners
//! lie on one circle), so floating-point predicates would flip edges back and
//! forth or disagree with themselves. Coordinates are small integers, so the
//! determinants are computed exactly in `i64`/`i128`.

/// A point of the chunk's sample grid (local coordinates).
pub type Pt = [i32; 2];

/// Twice the signed area of `(a, b, c)`: positive when counter-clockwise
/// (x right, y up), zero when collinear. Exact for any `i32` input.
#[inline]
pub fn orient2d(a: Pt, b: Pt, c: Pt) -> i64 {
    let (ax, ay) = (i64::from(a[0]), i64::from(a[1]));
    let (bx, by) = (i64::from(b[0]), i64::from(b[1]));
    let (cx, cy) = (i64::from(c[0]), i64::from(c[1]));
    (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
}

/// Positive when `d` lies strictly inside the circle through the
/// counter-clockwise triangle `(a, b, c)`, zero when the four points are
/// cocircular, negative outside. Exact: the terms are products of three
/// differences of `i32`s, which `i128` holds without overflow.
#[inline]
pub fn incircle(a: Pt, b: Pt, c: Pt, d: Pt) -> i128 {
    incircle_in::<i128>(a, b, c, d)
}

/// `incircle` for chunk-local coordinates (|x|, |y| <= 2^12), where every
/// intermediate fits in `i64`; the fitter's hot path.
#[inline]
pub fn incircle_small(a: Pt, b: Pt, c: Pt, d: Pt) -> i64 {
    incircle_in::<i64>(a, b, c, d)
}

/// The incircle determinant computed in `T` (exact where `T` holds its
/// products of three coordinate differences).
#[inline(always)]
fn incircle_in<T>(a: Pt, b: Pt, c: Pt, d: Pt) -> T
where
    T: Copy + From<i32> + std::ops::Add<Output = T> + std::ops::Sub<Output = T>,
    T: std::ops::Mul<Output = T>,
{
    let diff = |p: Pt, k: usize| T::from(p[k]) - T::from(d[k]);
    let (adx, ady) = (diff(a, 0), diff(a, 1));
    let (bdx, bdy) = (diff(b, 0), diff(b, 1));
    let (cdx, cdy) = (diff(c, 0), diff(c, 1));
    let alift = adx * adx + ady * ady;
    let blift = bdx * bdx + bdy * bdy;
    let clift = cdx * cdx + cdy * cdy;
    alift * (bdx * cdy - cdx * bdy)
        + blift * (cdx * ady - adx * cdy)
        + clift * (adx * bdy - bdx * ady)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_signs() {
        assert!(orient2d([0, 0], [1, 0], [0, 1]) > 0);
        assert!(orient2d([0, 0], [0, 1], [1, 0]) < 0);
        assert_eq!(orient2d([0, 0], [2, 2], [5, 5]), 0);
        assert_eq!(orient2d([0, 0], [128, 0], [0, 128]), 128 * 128);
    }

    #[test]
    fn square_corners_are_exactly_cocircular() {
        // Every axis-aligned square and rectangle of the grid, and a rotated square.
        for (w, h) in [(1, 1), (1, 2), (3, 7), (128, 128), (127, 1)] {
            let (a, b, c, d) = ([0, 0], [w, 0], [w, h], [0, h]);
            assert_eq!(incircle(a, b, c, d), 0, "{w}x{h}");
            assert_eq!(incircle_small(a, b, c, d), 0, "{w}x{h}");
        }
        assert_eq!(incircle([2, 0], [4, 2], [2, 4], [0, 2]), 0);
        // Points on a circle of radius 5 centred at the origin (3-4-5 triangles).
        assert_eq!(incircle([5, 0], [3, 4], [-4, 3], [0, -5]), 0);
        assert_eq!(incircle_small([5, 0], [3, 4], [-4, 3], [-3, -4]), 0);
    }

    #[test]
    fn inside_and_outside_are_strict() {
        let (a, b, c) = ([0, 0], [4, 0], [0, 4]);
        assert!(incircle(a, b, c, [1, 1]) > 0);
        assert!(incircle(a, b, c, [5, 5]) < 0);
        assert!(incircle(a, b, c, [4, 4]) == 0);
        // One unit off the circle either way: the predicate sees it.
        assert!(incircle([0, 0], [100, 0], [100, 100], [0, 99]) > 0);
        assert!(incircle([0, 0], [100, 0], [100, 100], [0, 101]) < 0);
    }

    #[test]
    fn small_and_wide_agree() {
        let pts: Vec<Pt> = (0..9)
            .flat_map(|i| (0..9).map(move |j| [i * 16, j * 16]))
            .collect();
        for (k, &a) in pts.iter().enumerate().step_by(7) {
            for &b in pts.iter().skip(k % 5).step_by(11) {
                for &c in pts.iter().skip(k % 3).step_by(13) {
                    if orient2d(a, b, c) <= 0 {
                        continue;
                    }
                    for &d in pts.iter().step_by(5) {
                        assert_eq!(i128::from(incircle_small(a, b, c, d)), incircle(a, b, c, d));
                    }
                }
            }
        }
    }
}
