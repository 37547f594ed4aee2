//! Per-triangle candidates: the worst sample of a triangle, found by scanning
//! its rows with incremental integer barycentrics, and their priority order.

use crate::predicates::Pt;
use crate::samples::ChunkSamples;

/// The worst sample of a triangle, as a 16-byte heap entry ordered by one
/// tuple comparison: larger error first, then the lower sample index, then
/// the lower triangle, so the insertion order is a pure function of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Candidate {
    /// Bits of the error `num / den` as a positive `f64`: they order like the
    /// value, and distinct errors (denominators < 2^16) stay distinct.
    key: u64,
    /// `(!sample) << 48 | (!tri) << 32 | stamp` (16-bit sample and triangle
    /// indices: a 128-chunk has 16 641 samples and at most 32 768 triangles).
    aux: u64,
}

impl Candidate {
    /// A candidate of error `num / den` height units (`den` > 0) at `sample`
    /// (chunk sample index) of triangle `tri`, scanned at `stamp`.
    pub fn new(num: i64, den: i64, sample: u32, tri: u32, stamp: u32) -> Self {
        let aux = (u64::from(!(sample as u16)) << 48)
            | (u64::from(!(tri as u16)) << 32)
            | u64::from(stamp);
        Candidate {
            key: (num as f64 / den as f64).to_bits(),
            aux,
        }
    }
    /// The error in height units.
    pub fn error(&self) -> f64 {
        f64::from_bits(self.key)
    }
    /// The worst sample's index in the chunk (row-major, stride `size + 1`).
    pub fn sample(&self) -> u32 {
        u32::from(!((self.aux >> 48) as u16))
    }
    /// The triangle's slot in the [`Triangulation`](crate::triangulation::Triangulation).
    pub fn tri(&self) -> u32 {
        u32::from(!((self.aux >> 32) as u16))
    }
    /// The triangle's stamp when scanned; stale entries are skipped.
    pub fn stamp(&self) -> u32 {
        self.aux as u32
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
/// separately) and inside or on the boundary of triangle `(a, b, c)`, with
/// vertex values `zs`. Returns `(num, den, sample index)`; `num == 0` when
/// nothing deviates. Ties go to the first sample in row-major order.
pub fn scan(pts: [Pt; 3], zs: [[u8; 3]; 3], chunk: &ChunkSamples) -> (i64, i64, u32) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { scan_avx2(pts, zs, chunk) };
    }
    scan_generic(pts, zs, chunk)
}

/// The same code compiled with AVX2, so the row kernels vectorise.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn scan_avx2(pts: [Pt; 3], zs: [[u8; 3]; 3], chunk: &ChunkSamples) -> (i64, i64, u32) {
    scan_generic(pts, zs, chunk)
}

/// A scan's twice-area and its bounding box clipped to the chunk's inner
/// samples, or the scan's answer when no sample lies strictly inside.
#[inline(always)]
fn scan_setup(pts: [Pt; 3], chunk: &ChunkSamples) -> Result<(i32, [i32; 4]), (i64, i64, u32)> {
    let [a, b, c] = pts;
    let den = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    // Pick's theorem: a lattice triangle of area 1/2 holds no sample but its
    // vertices, and those interpolate exactly. Common in a fine fit.
    if den <= 1 {
        return Err((0, 1, 0));
    }
    let (sx, sy) = (chunk.size_x as i32, chunk.size_y as i32);
    let x0 = a[0].min(b[0]).min(c[0]).max(1);
    let x1 = a[0].max(b[0]).max(c[0]).min(sx - 1);
    let y0 = a[1].min(b[1]).min(c[1]).max(1);
    let y1 = a[1].max(b[1]).max(c[1]).min(sy - 1);
    if x0 > x1 || y0 > y1 {
        return Err((0, i64::from(den), 0));
    }
    Ok((den, [x0, y0, x1, y1]))
}

#[inline(always)]
fn scan_generic(pts: [Pt; 3], zs: [[u8; 3]; 3], chunk: &ChunkSamples) -> (i64, i64, u32) {
    let (den, [x0, y0, x1, y1]) = match scan_setup(pts, chunk) {
        Ok(setup) => setup,
        Err(nothing) => return nothing,
    };
    // Where the vertices and every sample are single, mid = high = low and
    // the three fields have identical errors: scan one.
    let single =
        zs.iter().all(|z| z[0] == z[1] && z[1] == z[2]) && chunk.duals_in(x0, y0, x1, y1) == 0;
    if (x1 - x0 + 1) * (y1 - y0 + 1) <= SMALL {
        let bbox = [x0, y0, x1, y1];
        let (best, at) = if single {
            scan_small::<1>(pts, zs, den, bbox, chunk)
        } else {
            scan_small::<3>(pts, zs, den, bbox, chunk)
        };
        return (i64::from(best), i64::from(den), at);
    }
    let (best, at) = if single {
        scan_rows::<1>(pts, zs, den, [x0, y0, x1, y1], chunk)
    } else {
        scan_rows::<3>(pts, zs, den, [x0, y0, x1, y1], chunk)
    };
    (i64::from(best), i64::from(den), at)
}

const NUDGE: f64 = 1.0 / 4096.0;

/// Bounding boxes up to this many samples are scanned directly (most
/// triangles of a fine fit): no span arithmetic, no per-row setup.
const SMALL: i32 = 48;

/// How each edge function of the triangle changes per sample step in x and
/// in y (`w_i(x, y) = w_i(x0, y0) + dx[i] (x - x0) + dy[i] (y - y0)`).
#[inline(always)]
fn edge_steps(pts: [Pt; 3]) -> ([i32; 3], [i32; 3]) {
    let mut dx = [0i32; 3];
    let mut dy = [0i32; 3];
    for i in 0..3 {
        let (u, v) = (pts[(i + 1) % 3], pts[(i + 2) % 3]);
        dx[i] = u[1] - v[1];
        dy[i] = v[0] - u[0];
    }
    (dx, dy)
}

/// A small bounding box sample by sample; `F` as in [`row_max`].
#[inline(always)]
fn scan_small<const F: usize>(
    pts: [Pt; 3],
    zs: [[u8; 3]; 3],
    den: i32,
    bbox: [i32; 4],
    chunk: &ChunkSamples,
) -> (i32, u32) {
    let [a, b, c] = pts;
    let [x0, y0, x1, y1] = bbox;
    let stride = chunk.stride();
    // Edge functions and interpolant numerators, stepped per sample.
    let (dx, dy) = edge_steps(pts);
    let z = |f: usize| {
        [
            i32::from(zs[0][f]),
            i32::from(zs[1][f]),
            i32::from(zs[2][f]),
        ]
    };
    let (z0, z1, z2) = (z(0), z(1), z(2));
    let dot = |w: [i32; 3], z: [i32; 3]| w[0] * z[0] + w[1] * z[1] + w[2] * z[2];
    let (dn0, dn1, dn2) = (dot(dx, z0), dot(dx, z1), dot(dx, z2));
    let (en0, en1, en2) = (dot(dy, z0), dot(dy, z1), dot(dy, z2));
    let mut w_row = barycentric(a, b, c, [x0, y0]);
    let mut n_row = [dot(w_row, z0), dot(w_row, z1), dot(w_row, z2)];
    let mut best = (0i32, 0u32);
    for y in y0..=y1 {
        let (mut w, mut n) = (w_row, n_row);
        let row = y as usize * stride;
        for x in x0..=x1 {
            if (w[0] | w[1] | w[2]) >= 0 {
                let i = row + x as usize;
                let s = chunk.samples[i].z;
                let e0 = || (n[0] - i32::from(s[0]) * den).abs();
                let e12 = || {
                    (n[1] - i32::from(s[1]) * den)
                        .abs()
                        .max((n[2] - i32::from(s[2]) * den).abs())
                };
                let e = match F {
                    1 => e0(),
                    2 => e12(),
                    _ => e0().max(e12()),
                };
                if e > best.0 {
                    best = (e, i as u32);
                }
            }
            for k in 0..3 {
                w[k] += dx[k];
            }
            n[0] += dn0;
            n[1] += dn1;
            n[2] += dn2;
        }
        for k in 0..3 {
            w_row[k] += dy[k];
        }
        n_row[0] += en0;
        n_row[1] += en1;
        n_row[2] += en2;
    }
    best
}

/// 1 / |d| per edge step (0 where d is 0), for [`row_span`].
#[inline(always)]
fn reciprocals(dx: [i32; 3]) -> [f64; 3] {
    dx.map(|d| {
        if d == 0 {
            0.0
        } else {
            1.0 / f64::from(d.abs())
        }
    })
}

/// How much each field's interpolant numerator changes per step in x.
#[inline(always)]
fn numerator_steps(dx: [i32; 3], zs: [[u8; 3]; 3]) -> [i32; 3] {
    std::array::from_fn(|f| (0..3).map(|i| dx[i] * i32::from(zs[i][f])).sum())
}

/// The span `lo..=hi` of x in `x0..=x1` where all three barycentric weights
/// of the row (`w_row` at x0, `dx` per step) are >= 0: exact integer bounds
/// (empty when `lo > hi`). Quotients via reciprocals: |d| <= 2^8 and
/// |w| < 2^20, so a non-integer quotient is >= 2^-8 from an integer while the
/// float error is < 2^-30; the 2^-12 nudge makes ceil/floor exact.
#[inline(always)]
fn row_span(w_row: [i32; 3], dx: [i32; 3], inv: [f64; 3], x0: i32, x1: i32) -> (i32, i32) {
    let (mut lo, mut hi) = (x0, x1);
    for i in 0..3 {
        let (w, d) = (w_row[i], dx[i]);
        if w >= 0 {
            if d < 0 {
                hi = hi.min(x0 + (f64::from(w) * inv[i] + NUDGE).floor() as i32);
            }
        } else if d > 0 {
            lo = lo.max(x0 + (f64::from(-w) * inv[i] - NUDGE).ceil() as i32);
        } else {
            hi = -1;
        }
    }
    (lo, hi)
}

#[inline(always)]
fn scan_rows<const F: usize>(
    pts: [Pt; 3],
    zs: [[u8; 3]; 3],
    den: i32,
    bbox: [i32; 4],
    chunk: &ChunkSamples,
) -> (i32, u32) {
    let [a, b, c] = pts;
    let [x0, y0, x1, y1] = bbox;
    let stride = chunk.stride();
    // w_i(x, y) = w_i(x0, y0) + dx[i] (x - x0) + dy[i] (y - y0).
    let (dx, dy) = edge_steps(pts);
    let mut w_row = barycentric(a, b, c, [x0, y0]);
    let inv = reciprocals(dx);
    // Interpolant numerators change by a constant per step in x.
    let dn = numerator_steps(dx, zs);
    let mut best = (0i32, 0u32);
    for y in y0..=y1 {
        let (lo, hi) = row_span(w_row, dx, inv, x0, x1);
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
            let start = y as usize * stride + lo as usize;
            let len = (hi - lo + 1) as usize;
            let rows = [
                &chunk.planes[0][start..start + len],
                &chunk.planes[1][start..start + len],
                &chunk.planes[2][start..start + len],
            ];
            let m = row_max::<F>(rows, n, dn, den);
            if m > best.0 {
                // Rare: locate the first sample of the row with that error.
                let k = (0..len)
                    .find(|&k| err_at::<F>(rows, n, dn, den, k) == m)
                    .unwrap_or(0);
                best = (m, (start + k) as u32);
            }
        }
        for i in 0..3 {
            w_row[i] += dy[i];
        }
    }
    best
}

#[inline(always)]
fn err_at<const F: usize>(rows: [&[u8]; 3], n: [i32; 3], dn: [i32; 3], den: i32, k: usize) -> i32 {
    let kk = k as i32;
    let e0 = || (n[0] + kk * dn[0] - i32::from(rows[0][k]) * den).abs();
    let e12 = || {
        (n[1] + kk * dn[1] - i32::from(rows[1][k]) * den)
            .abs()
            .max((n[2] + kk * dn[2] - i32::from(rows[2][k]) * den).abs())
    };
    match F {
        1 => e0(),
        2 => e12(),
        _ => e0().max(e12()),
    }
}

/// Largest error of a row span: branch-free so that it vectorises. `F`: 1
/// measures `low`, 2 `mid` and `high`, 3 all three.
#[inline(always)]
fn row_max<const F: usize>(rows: [&[u8]; 3], n: [i32; 3], dn: [i32; 3], den: i32) -> i32 {
    let len = rows[0].len();
    let (r0, r1, r2) = (rows[0], &rows[1][..len], &rows[2][..len]);
    let mut m = 0;
    if F == 1 {
        for (k, &z) in r0.iter().enumerate() {
            let kk = k as i32;
            m = m.max((n[0] + kk * dn[0] - i32::from(z) * den).abs());
        }
    } else if F == 2 {
        for k in 0..len {
            let kk = k as i32;
            let e1 = (n[1] + kk * dn[1] - i32::from(r1[k]) * den).abs();
            let e2 = (n[2] + kk * dn[2] - i32::from(r2[k]) * den).abs();
            m = m.max(e1.max(e2));
        }
    } else {
        for k in 0..len {
            let kk = k as i32;
            let e0 = (n[0] + kk * dn[0] - i32::from(r0[k]) * den).abs();
            let e1 = (n[1] + kk * dn[1] - i32::from(r1[k]) * den).abs();
            let e2 = (n[2] + kk * dn[2] - i32::from(r2[k]) * den).abs();
            m = m.max(e0.max(e1).max(e2));
        }
    }
    m
}

/// [`scan`] for the slab triangulation of the outline fit, whose slab
/// triangles (`slab`: see
/// [`crate::triangulation::Triangulation::is_slab`]) draw only the slab (`mid`, `high`): the
/// floor has its own triangulation. A slab triangle is measured on `mid`
/// and `high` at every sample it covers (a single sample under it by how
/// far the drawn slab is from its one surface); any other triangle draws
/// nothing of this triangulation, so only its dual samples count, by the
/// whole slab they miss (`high - low`), unless they are vertices or lie on
/// a slab edge (`covered[k]` for the edge opposite vertex `k`: the slab
/// triangle across draws them).
/// Single samples outside slab triangles cost nothing here: the floor
/// triangulation draws them. Same answer as a per-sample loop over
/// [`slab_error`] (ties: the first sample in row-major order).
pub fn scan_slab(
    pts: [Pt; 3],
    zs: [[u8; 3]; 3],
    slab: bool,
    covered: [bool; 3],
    chunk: &ChunkSamples,
) -> (i64, i64, u32) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { scan_slab_avx2(pts, zs, slab, covered, chunk) };
    }
    scan_slab_generic(pts, zs, slab, covered, chunk)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn scan_slab_avx2(
    pts: [Pt; 3],
    zs: [[u8; 3]; 3],
    slab: bool,
    covered: [bool; 3],
    chunk: &ChunkSamples,
) -> (i64, i64, u32) {
    scan_slab_generic(pts, zs, slab, covered, chunk)
}

#[inline(always)]
fn scan_slab_generic(
    pts: [Pt; 3],
    zs: [[u8; 3]; 3],
    slab: bool,
    covered: [bool; 3],
    chunk: &ChunkSamples,
) -> (i64, i64, u32) {
    let (den, [x0, y0, x1, y1]) = match scan_setup(pts, chunk) {
        Ok(setup) => setup,
        Err(nothing) => return nothing,
    };
    let duals_in = chunk.duals_in(x0, y0, x1, y1);
    if !slab && duals_in == 0 {
        return (0, i64::from(den), 0);
    }
    let bbox = [x0, y0, x1, y1];
    let area = (x1 - x0 + 1) * (y1 - y0 + 1);
    // Under a slab triangle a single sample has mid = high = low, so one
    // kernel measures both classes; under any other only dual samples count.
    let (best, at) = match (slab, area <= SMALL) {
        (true, true) => scan_small::<2>(pts, zs, den, bbox, chunk),
        (true, false) => scan_rows::<2>(pts, zs, den, bbox, chunk),
        (false, small) => scan_missing_slab(pts, den, covered, bbox, chunk, !small),
    };
    (i64::from(best), i64::from(den), at)
}

/// The error numerator of sample `s` (barycentric numerators `w`) in a
/// triangle of the outline fit's slab triangulation (see [`scan_slab`]).
#[inline]
pub fn slab_error(
    w: [i32; 3],
    den: i32,
    zs: [[u8; 3]; 3],
    s: &crate::samples::Sample,
    slab: bool,
    covered: [bool; 3],
) -> i32 {
    if slab {
        let e = errors(w, den, zs, s.z);
        return e[1].max(e[2]);
    }
    if !s.dual() {
        return 0;
    }
    if drawn_across(w, covered) {
        0
    } else {
        (i32::from(s.z[2]) - i32::from(s.z[0])) * den
    }
}

/// Is a point of a triangle that draws no slab (barycentric numerators
/// `w`) drawn by a neighbour: a vertex, or on a slab edge (`covered`)?
#[inline(always)]
fn drawn_across(w: [i32; 3], covered: [bool; 3]) -> bool {
    w.iter().filter(|&&v| v == 0).count() >= 2 || (0..3).any(|k| w[k] == 0 && covered[k])
}

/// [`scan_slab`] under a triangle that draws no slab: row by row, visiting
/// only the dual samples (bits of [`ChunkSamples::dual_bits`]), each by the
/// whole slab it misses unless the slab across draws it. `spans`: cut each
/// row to the triangle's exact span first (large boxes); otherwise each
/// dual sample of the box is tested against the triangle.
#[inline(always)]
fn scan_missing_slab(
    pts: [Pt; 3],
    den: i32,
    covered: [bool; 3],
    bbox: [i32; 4],
    chunk: &ChunkSamples,
    spans: bool,
) -> (i32, u32) {
    let [a, b, c] = pts;
    let [x0, y0, x1, y1] = bbox;
    let stride = chunk.stride();
    let words = chunk.words_per_row();
    let (dx, dy) = edge_steps(pts);
    let mut w_row = barycentric(a, b, c, [x0, y0]);
    let inv = reciprocals(dx);
    let mut best = (0i32, 0u32);
    // Bits lo..=hi of word `word` of a row.
    let span_bits = |dual: u64, word: usize, lo: i32, hi: i32| {
        let base = word as i32 * 64;
        let from = (lo - base).clamp(0, 64) as u32;
        let to = (hi - base + 1).clamp(0, 64) as u32;
        dual & u64::MAX.checked_shl(from).unwrap_or(0) & u64::MAX.checked_shr(64 - to).unwrap_or(0)
    };
    let (first, last) = (x0 as usize / 64, x1 as usize / 64);
    for y in y0..=y1 {
        let row = &chunk.dual_bits[y as usize * words..(y as usize + 1) * words];
        let mut box_bits = [0u64; 3];
        let mut any = 0;
        let mut word = first;
        while word <= last {
            box_bits[word - first] = span_bits(row[word], word, x0, x1);
            any |= box_bits[word - first];
            word += 1;
        }
        // Rows with no dual sample in the box cost nothing more.
        if any != 0 {
            let (lo, hi) = if spans {
                row_span(w_row, dx, inv, x0, x1)
            } else {
                (x0, x1)
            };
            let mut word = first;
            while word <= last && lo <= hi {
                let base = word as i32 * 64;
                let mut bits = span_bits(box_bits[word - first], word, lo, hi);
                word += 1;
                while bits != 0 {
                    let x = base + bits.trailing_zeros() as i32;
                    bits &= bits - 1;
                    let i = y as usize * stride + x as usize;
                    let s = &chunk.samples[i];
                    let e = (i32::from(s.z[2]) - i32::from(s.z[0])) * den;
                    if e <= best.0 {
                        continue;
                    }
                    let off = x - x0;
                    let w = [0, 1, 2].map(|k| w_row[k] + dx[k] * off);
                    if (w[0] | w[1] | w[2]) < 0 {
                        continue;
                    }
                    if !drawn_across(w, covered) {
                        best = (e, i as u32);
                    }
                }
            }
        }
        for i in 0..3 {
            w_row[i] += dy[i];
        }
    }
    best
}
