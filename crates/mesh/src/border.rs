//! Chunk borders: a 1D greedy fit of the three fields along each chunk edge.
//!
//! A border's vertex set is a pure function of the samples on that edge and
//! the finest tolerance, so the two chunks sharing the edge compute the same
//! set, and every LOD of both uses it: the seam is the same polyline on both
//! sides at every LOD pair, with no skirts.

use crate::samples::Sample;

/// Does an error of `num / den` height units exceed `tol`? The single
/// comparison both the border and the interior fit use.
#[inline]
pub fn exceeds(num: i64, den: i64, tol: f64) -> bool {
    num as f64 / den as f64 > tol
}

/// Indices (strictly between 0 and `edge.len() - 1`, ascending) of the
/// samples the border keeps so that linear interpolation between consecutive
/// kept samples is within `tol` of `low`, `mid` and `high` everywhere.
/// Greedy split at the worst sample (ties: the lowest index); in 1D the
/// segments are independent, so this equals global greedy insertion.
pub fn fit_border(edge: &[Sample], tol: f64, out: &mut Vec<u32>) {
    out.clear();
    if edge.len() < 3 {
        return;
    }
    split_greedily(edge, tol, out, |ends, s, (a, b), len| {
        let mut e = 0;
        for f in 0..3 {
            let interp = i64::from(ends[0].z[f]) * a + i64::from(ends[1].z[f]) * b;
            e = e.max((interp - i64::from(s.z[f]) * len).abs());
        }
        e
    });
}

/// [`fit_border`] for the outline fit's slab triangulation: a segment
/// between two dual samples is a slab edge, measured on `mid` and `high`
/// (a single sample on it by how far the slab is from its surface); any
/// other segment draws nothing of the slab, so only a dual sample on it
/// counts, by its whole missing slab (`high - low`). The rules of
/// [`crate::candidate::slab_error`]; a pure function of the edge's samples.
/// An edge without dual samples keeps no vertex.
pub fn fit_border_slab(edge: &[Sample], tol: f64, out: &mut Vec<u32>) {
    out.clear();
    if edge.len() < 3 || !edge.iter().any(Sample::dual) {
        return;
    }
    split_greedily(edge, tol, out, |ends, s, (a, b), len| {
        if ends[0].dual() && ends[1].dual() {
            (1..3)
                .map(|f| {
                    let interp = i64::from(ends[0].z[f]) * a + i64::from(ends[1].z[f]) * b;
                    (interp - i64::from(s.z[f]) * len).abs()
                })
                .max()
                .unwrap_or(0)
        } else if s.dual() {
            (i64::from(s.z[2]) - i64::from(s.z[0])) * len
        } else {
            0
        }
    });
}

/// The greedy split both border fits share: keep the worst sample of a
/// segment while its error exceeds `tol`, then split there. `error(ends, s,
/// (a, b), len)` is `len` times the error at sample `s` between the
/// segment's `ends`, where `s` interpolates as `(a · end0 + b · end1) / len`.
#[inline(always)]
fn split_greedily(
    edge: &[Sample],
    tol: f64,
    out: &mut Vec<u32>,
    error: impl Fn([&Sample; 2], &Sample, (i64, i64), i64) -> i64,
) {
    let mut stack = vec![(0usize, edge.len() - 1)];
    while let Some((i, j)) = stack.pop() {
        let len = (j - i) as i64;
        let ends = [&edge[i], &edge[j]];
        let mut best = (0i64, 0usize);
        for (k, s) in edge.iter().enumerate().take(j).skip(i + 1) {
            let e = error(ends, s, ((j - k) as i64, (k - i) as i64), len);
            if e > best.0 {
                best = (e, k);
            }
        }
        if best.1 != 0 && exceeds(best.0, len, tol) {
            out.push(best.1 as u32);
            stack.push((i, best.1));
            stack.push((best.1, j));
        }
    }
    out.sort_unstable();
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edge(zs: &[u8]) -> Vec<Sample> {
        zs.iter()
            .map(|&z| Sample {
                z: [z, z, z],
                ..Sample::default()
            })
            .collect()
    }

    #[test]
    fn straight_edges_need_nothing_and_steps_are_kept() {
        let mut out = Vec::new();
        fit_border(&edge(&[0, 2, 4, 6, 8, 10, 12, 14, 16]), 1.0, &mut out);
        assert!(out.is_empty());
        fit_border(&edge(&[0, 0, 0, 0, 100, 100, 100, 100, 100]), 4.0, &mut out);
        assert_eq!(out, vec![3, 4]);
    }

    #[test]
    fn result_is_within_tolerance() {
        let zs: Vec<u8> = (0..129)
            .map(|i| ((i * 37 % 101) as u8).wrapping_mul(3))
            .collect();
        let e = edge(&zs);
        let mut out = Vec::new();
        fit_border(&e, 4.0, &mut out);
        let mut kept = vec![0u32];
        kept.extend(&out);
        kept.push(128);
        for w in kept.windows(2) {
            let (i, j) = (w[0] as usize, w[1] as usize);
            for k in i..=j {
                let t = (k - i) as f64 / (j - i) as f64;
                let interp = f64::from(zs[i]) * (1.0 - t) + f64::from(zs[j]) * t;
                assert!((interp - f64::from(zs[k])).abs() <= 4.0 + 1e-9);
            }
        }
    }
}
