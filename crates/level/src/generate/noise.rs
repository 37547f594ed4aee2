//! Seeded hash noise that wraps with the map (the world is a torus), cheap
//! enough to evaluate several times per texel. Pure functions of position and
//! seed, so the generator gives the same bytes at any thread count.

/// A 32-bit integer hash with good avalanche (lowbias32).
#[inline]
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Hash of a seed and two integer coordinates.
#[inline]
pub fn hash2(seed: u32, a: u32, b: u32) -> u32 {
    hash32(seed ^ hash32(a.wrapping_mul(0x9e37_79b9) ^ hash32(b.wrapping_add(0x632b_e5ab))))
}

/// A hash mapped to [0, 1).
#[inline]
pub fn unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Value noise on a square lattice of `cell` texels, in [0, 1]. The lattice
/// period divides the map size, so the noise wraps seamlessly.
#[derive(Clone, Copy, Debug)]
pub struct ValueNoise {
    seed: u32,
    inv_cell: f32,
    mask_x: u32,
    mask_y: u32,
}

impl ValueNoise {
    /// `cell_log2` is clamped so a cell never exceeds the map.
    pub fn new(seed: u32, cell_log2: u32, width: u32, height: u32) -> Self {
        let shift = cell_log2
            .min(width.trailing_zeros())
            .min(height.trailing_zeros());
        ValueNoise {
            seed: hash32(seed),
            inv_cell: 1.0 / (1u32 << shift) as f32,
            mask_x: (width >> shift).max(1) - 1,
            mask_y: (height >> shift).max(1) - 1,
        }
    }

    #[inline]
    fn corner(&self, ix: i32, iy: i32) -> f32 {
        // One hash of premixed coordinates: plenty for value noise, and the
        // corner lookups are most of the generator's time.
        let a = (ix as u32 & self.mask_x).wrapping_mul(0x8da6_b343);
        let b = (iy as u32 & self.mask_y).wrapping_mul(0xd816_3841);
        unit(hash32(a ^ b ^ self.seed))
    }

    /// Two independent noises from one set of corner hashes (high and low
    /// 16 bits), for the price of one.
    #[inline]
    pub fn at2(&self, x: f32, y: f32) -> (f32, f32) {
        let fx = x * self.inv_cell;
        let fy = y * self.inv_cell;
        let (ix, iy) = (fast_floor(fx), fast_floor(fy));
        let (tx, ty) = (smooth(fx - ix as f32), smooth(fy - iy as f32));
        let h = |dx: i32, dy: i32| {
            let a = ((ix + dx) as u32 & self.mask_x).wrapping_mul(0x8da6_b343);
            let b = ((iy + dy) as u32 & self.mask_y).wrapping_mul(0xd816_3841);
            hash32(a ^ b ^ self.seed)
        };
        let (a, b, c, d) = (h(0, 0), h(1, 0), h(0, 1), h(1, 1));
        let lerp = |a: f32, b: f32, c: f32, d: f32| {
            let top = a + (b - a) * tx;
            top + (c + (d - c) * tx - top) * ty
        };
        let hi = |v: u32| (v >> 16) as f32 * (1.0 / 65536.0);
        let lo = |v: u32| (v & 0xffff) as f32 * (1.0 / 65536.0);
        (
            lerp(hi(a), hi(b), hi(c), hi(d)),
            lerp(lo(a), lo(b), lo(c), lo(d)),
        )
    }

    #[inline]
    pub fn at(&self, x: f32, y: f32) -> f32 {
        let fx = x * self.inv_cell;
        let fy = y * self.inv_cell;
        let (ix, iy) = (fast_floor(fx), fast_floor(fy));
        let (tx, ty) = (smooth(fx - ix as f32), smooth(fy - iy as f32));
        let a = self.corner(ix, iy);
        let b = self.corner(ix + 1, iy);
        let c = self.corner(ix, iy + 1);
        let d = self.corner(ix + 1, iy + 1);
        let top = a + (b - a) * tx;
        let bottom = c + (d - c) * tx;
        top + (bottom - top) * ty
    }
}

/// A smooth field sampled every `2^step_log2` texels and interpolated
/// bilinearly: for low-frequency inputs (warps, masks, regions) it is
/// indistinguishable from evaluating them per texel, at a fraction of the cost.
/// `N` fields share one grid so one lookup interpolates them all.
///
/// The lattice covers the whole (wrapping) map, but only a *window* of it
/// is held: the whole map for a world made in memory, a chunk and its
/// margins for one generated chunk by chunk. A lattice value outside the
/// window is computed on the spot by the same function at the same point,
/// so every lookup gives the same bits whatever the window: the window
/// decides the speed, never the bytes.
#[derive(Clone)]
pub struct Coarse<const N: usize = 1> {
    values: Vec<[f32; N]>,
    /// The whole map's lattice (powers of two).
    cols: usize,
    rows: usize,
    /// The window: first lattice column and row held, and how many.
    i0: usize,
    j0: usize,
    wcols: usize,
    wrows: usize,
    step_log2: u32,
    f: std::sync::Arc<dyn Fn(f32, f32) -> [f32; N] + Send + Sync>,
}

impl<const N: usize> std::fmt::Debug for Coarse<N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Coarse")
            .field("lattice", &(self.cols, self.rows))
            .field("window", &(self.i0, self.j0, self.wcols, self.wrows))
            .finish()
    }
}

impl Coarse<1> {
    #[inline]
    pub fn at(&self, x: f32, y: f32) -> f32 {
        self.all(x, y)[0]
    }
}

impl<const N: usize> Coarse<N> {
    /// The field with an empty window: every lookup computes its lattice
    /// values (for the few lookups made before any chunk is generated).
    pub fn lazy(
        width: u32,
        height: u32,
        step_log2: u32,
        f: impl Fn(f32, f32) -> [f32; N] + Send + Sync + 'static,
    ) -> Self {
        let step_log2 = step_log2
            .min(width.trailing_zeros())
            .min(height.trailing_zeros());
        Coarse {
            values: Vec::new(),
            cols: (width >> step_log2) as usize,
            rows: (height >> step_log2) as usize,
            i0: 0,
            j0: 0,
            wcols: 0,
            wrows: 0,
            step_log2,
            f: std::sync::Arc::new(f),
        }
    }

    /// The same field holding the lattice values that lookups at texel
    /// positions `x0 .. x1`, `y0 .. y1` (any integers; they wrap) need.
    pub fn window(&self, x0: i64, y0: i64, x1: i64, y1: i64) -> Self {
        let s = self.step_log2;
        // Cells [floor(x0 / step), floor((x1 - 1) / step)] and one more corner.
        let (ci0, cj0) = (x0 >> s, y0 >> s);
        let wcols = (((x1 - 1) >> s) - ci0 + 2).clamp(0, self.cols as i64) as usize;
        let wrows = (((y1 - 1) >> s) - cj0 + 2).clamp(0, self.rows as i64) as usize;
        let mut c = Coarse {
            values: Vec::new(),
            cols: self.cols,
            rows: self.rows,
            i0: 0,
            j0: 0,
            wcols: 0,
            wrows: 0,
            step_log2: s,
            f: self.f.clone(),
        };
        c.fill(
            ci0.rem_euclid(self.cols as i64) as usize,
            cj0.rem_euclid(self.rows as i64) as usize,
            wcols,
            wrows,
        );
        c
    }

    /// Compute the window of `wcols x wrows` lattice values from (i0, j0).
    fn fill(&mut self, i0: usize, j0: usize, wcols: usize, wrows: usize) {
        use rayon::prelude::*;
        let step = (1u32 << self.step_log2) as f32;
        let (cols, rows) = (self.cols, self.rows);
        let mut values = vec![[0f32; N]; wcols * wrows];
        let f = &*self.f;
        let row = |(j, row): (usize, &mut [[f32; N]])| {
            let gj = (j0 + j) & (rows - 1);
            for (i, v) in row.iter_mut().enumerate() {
                let gi = (i0 + i) & (cols - 1);
                *v = f(gi as f32 * step, gj as f32 * step);
            }
        };
        // A whole map's lattice is worth all cores; a chunk's window is
        // made inside a parallel loop over chunks already.
        if wcols * wrows >= 1 << 16 {
            values
                .par_chunks_mut(wcols.max(1))
                .enumerate()
                .for_each(row);
        } else {
            values.chunks_mut(wcols.max(1)).enumerate().for_each(row);
        }
        (self.values, self.i0, self.j0, self.wcols, self.wrows) = (values, i0, j0, wcols, wrows);
    }

    /// The lattice value at global lattice column `gi`, row `gj`.
    #[inline]
    fn value(&self, gi: usize, gj: usize) -> [f32; N] {
        let li = gi.wrapping_sub(self.i0) & (self.cols - 1);
        let lj = gj.wrapping_sub(self.j0) & (self.rows - 1);
        if li < self.wcols && lj < self.wrows {
            self.values[lj * self.wcols + li]
        } else {
            let step = (1u32 << self.step_log2) as f32;
            (self.f)(gi as f32 * step, gj as f32 * step)
        }
    }

    #[inline]
    pub fn all(&self, x: f32, y: f32) -> [f32; N] {
        let inv = 1.0 / (1u32 << self.step_log2) as f32;
        let (fx, fy) = (x * inv, y * inv);
        let (x0, y0) = (fast_floor(fx), fast_floor(fy));
        let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
        // Both counts are powers of two: wrap with masks.
        let (mx, my) = (self.cols - 1, self.rows - 1);
        let (i0, j0) = (x0 as usize & mx, y0 as usize & my);
        let (li, lj) = (i0.wrapping_sub(self.i0) & mx, j0.wrapping_sub(self.j0) & my);
        let (a, b, c, d) = if li + 1 < self.wcols && lj + 1 < self.wrows {
            // All four corners in the window, side by side (the usual case).
            let k = lj * self.wcols + li;
            (
                self.values[k],
                self.values[k + 1],
                self.values[k + self.wcols],
                self.values[k + self.wcols + 1],
            )
        } else {
            let (i1, j1) = ((i0 + 1) & mx, (j0 + 1) & my);
            (
                self.value(i0, j0),
                self.value(i1, j0),
                self.value(i0, j1),
                self.value(i1, j1),
            )
        };
        std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * tx;
            let bottom = c[k] + (d[k] - c[k]) * tx;
            top + (bottom - top) * ty
        })
    }
}

/// `floor` without the libm call the baseline x86-64 target makes of it.
#[inline]
pub fn fast_floor(v: f32) -> i32 {
    let i = v as i32;
    i - ((i as f32) > v) as i32
}

/// Round half up, without a libm call.
#[inline]
pub fn fast_round(v: f32) -> i32 {
    fast_floor(v + 0.5)
}

#[inline]
fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// A few octaves of value noise, weights halving, normalised to [0, 1].
#[derive(Clone, Debug)]
pub struct Fbm {
    octaves: Vec<ValueNoise>,
    norm: f32,
}

impl Fbm {
    pub fn new(seed: u32, cell_log2: u32, octaves: u32, width: u32, height: u32) -> Self {
        Self::octaves(seed, cell_log2, 0..octaves, octaves, width, height)
    }

    /// Octaves `range` of a `total`-octave sum, weighted and normalised as
    /// in the whole, so sums over disjoint ranges add up to the whole.
    pub fn octaves(
        seed: u32,
        cell_log2: u32,
        range: std::ops::Range<u32>,
        total: u32,
        width: u32,
        height: u32,
    ) -> Self {
        let first = range.start;
        let octaves: Vec<ValueNoise> = range
            .map(|i| {
                ValueNoise::new(
                    seed.wrapping_add(i * 7919),
                    cell_log2.saturating_sub(i).max(1),
                    width,
                    height,
                )
            })
            .collect();
        let norm =
            0.5f32.powi(first as i32) / (0..total).map(|i| 0.5f32.powi(i as i32)).sum::<f32>();
        Fbm { octaves, norm }
    }

    #[inline]
    pub fn at(&self, x: f32, y: f32) -> f32 {
        let mut sum = 0.0;
        let mut w = 1.0;
        for o in &self.octaves {
            sum += o.at(x, y) * w;
            w *= 0.5;
        }
        sum * self.norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_noise_wraps_and_stays_in_range() {
        let n = ValueNoise::new(7, 5, 256, 512);
        for i in 0..200 {
            let (x, y) = (i as f32 * 3.7, i as f32 * 11.3);
            let v = n.at(x, y);
            assert!((0.0..=1.0).contains(&v));
            assert!((v - n.at(x + 256.0, y - 512.0)).abs() < 1e-4);
        }
    }
}
