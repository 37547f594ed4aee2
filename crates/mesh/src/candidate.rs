//! Per-triangle candidates: the worst sample of a triangle, found by scanning
//! its rows with incremental integer barycentrics, and their priority order.

use std::cmp::Ordering;

use crate::predicates::Pt;
use crate::samples::Sample;

/// The worst sample of a triangle. Its error is `num / den` height units
/// (`den` is twice the triangle's area), compared exactly across triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Candidate {
    pub num: i64,
    pub den: i64,
    /// Sample index in the chunk grid.
    pub sample: u32,
    pub tri: u32,
    /// The triangle's stamp when scanned; stale entries are skipped.
    pub stamp: u32,
}

impl Ord for Candidate {
    /// Larger error first; ties go to the lower sample index, then the lower
    /// triangle, so the insertion order is a pure function of the input.
    fn cmp(&self, other: &Self) -> Ordering {
        (self.num * other.den)
            .cmp(&(other.num * self.den))
            .then_with(|| other.sample.cmp(&self.sample))
            .then_with(|| other.tri.cmp(&self.tri))
            .then_with(|| other.stamp.cmp(&self.stamp))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Integer barycentric numerators of `p` in the counter-clockwise triangle
/// `(a, b, c)`: `w[i]` is twice the area opposite vertex `i`.
#[inline]
pub fn barycentric(a: Pt, b: Pt, c: Pt, p: Pt) -> [i32; 3] {
    let edge = |u: Pt, v: Pt| (v[0] - u[0]) * (p[1] - u[1]) - (v[1] - u[1]) * (p[0] - u[0]);
    [edge(b, c), edge(c, a), edge(a, b)]
}

/// Per-field error numerators (`|interpolant - value| * den`) of a sample
/// with barycentric numerators `w` against vertex samples `zs`.
#[inline]
pub fn errors(w: [i32; 3], den: i32, zs: [[u8; 3]; 3], s: [u8; 3]) -> [i32; 3] {
    let mut e = [0; 3];
    for f in 0..3 {
        let n =
            w[0] * i32::from(zs[0][f]) + w[1] * i32::from(zs[1][f]) + w[2] * i32::from(zs[2][f]);
        e[f] = (n - i32::from(s[f]) * den).abs();
    }
    e
}

/// The worst sample strictly inside the chunk (borders are fitted
/// separately) and inside or on the boundary of triangle `(a, b, c)`.
/// Returns `(num, den, sample index)`; `num == 0` when nothing deviates.
/// `limit` is the chunk side `(sx, sy)`; `stride` the sample row stride.
pub fn scan(
    pts: [Pt; 3],
    zs: [[u8; 3]; 3],
    samples: &[Sample],
    stride: usize,
    limit: [i32; 2],
) -> (i64, i64, u32) {
    let [a, b, c] = pts;
    let den = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if den <= 0 {
        return (0, 1, 0);
    }
    let x0 = a[0].min(b[0]).min(c[0]).max(1);
    let x1 = a[0].max(b[0]).max(c[0]).min(limit[0] - 1);
    let y0 = a[1].min(b[1]).min(c[1]).max(1);
    let y1 = a[1].max(b[1]).max(c[1]).min(limit[1] - 1);
    if x0 > x1 || y0 > y1 {
        return (0, i64::from(den), 0);
    }
    // w_i(x, y) = w_i(x0, y0) + dx[i] (x - x0) + dy[i] (y - y0).
    let verts = [a, b, c];
    let mut dx = [0i32; 3];
    let mut dy = [0i32; 3];
    for i in 0..3 {
        let (u, v) = (verts[(i + 1) % 3], verts[(i + 2) % 3]);
        dx[i] = u[1] - v[1];
        dy[i] = v[0] - u[0];
    }
    let mut w_row = barycentric(a, b, c, [x0, y0]);
    // Interpolant numerators change by a constant per step in x.
    let mut dn = [0i32; 3];
    for (f, d) in dn.iter_mut().enumerate() {
        *d = (0..3).map(|i| dx[i] * i32::from(zs[i][f])).sum();
    }
    let mut best = (0i32, 0u32);
    for y in y0..=y1 {
        // The span of x where all three w_i >= 0 (exact integer bounds).
        let (mut lo, mut hi) = (x0, x1);
        for i in 0..3 {
            let (w, d) = (w_row[i], dx[i]);
            if d > 0 {
                if w < 0 {
                    lo = lo.max(x0 + (-w + d - 1) / d);
                }
            } else if d < 0 {
                if w < 0 {
                    hi = -1;
                } else {
                    hi = hi.min(x0 + w / -d);
                }
            } else if w < 0 {
                hi = -1;
            }
        }
        if lo <= hi {
            let off = lo - x0;
            let w = [
                w_row[0] + dx[0] * off,
                w_row[1] + dx[1] * off,
                w_row[2] + dx[2] * off,
            ];
            let mut n = [0i32; 3];
            for (f, nf) in n.iter_mut().enumerate() {
                *nf = (0..3).map(|i| w[i] * i32::from(zs[i][f])).sum();
            }
            let row = y as usize * stride;
            for x in lo..=hi {
                let s = &samples[row + x as usize].z;
                let e0 = (n[0] - i32::from(s[0]) * den).abs();
                let e1 = (n[1] - i32::from(s[1]) * den).abs();
                let e2 = (n[2] - i32::from(s[2]) * den).abs();
                let e = e0.max(e1).max(e2);
                if e > best.0 {
                    best = (e, (row + x as usize) as u32);
                }
                n[0] += dn[0];
                n[1] += dn[1];
                n[2] += dn[2];
            }
        }
        for i in 0..3 {
            w_row[i] += dy[i];
        }
    }
    (i64::from(best.0), i64::from(den), best.1)
}
