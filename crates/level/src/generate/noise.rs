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
#[derive(Clone, Debug)]
pub struct Coarse<const N: usize = 1> {
    values: Vec<[f32; N]>,
    cols: usize,
    rows: usize,
    step_log2: u32,
}

impl Coarse<1> {
    pub fn new(
        width: u32,
        height: u32,
        step_log2: u32,
        f: impl Fn(f32, f32) -> f32 + Sync,
    ) -> Self {
        Self::many(width, height, step_log2, move |x, y| [f(x, y)])
    }

    #[inline]
    pub fn at(&self, x: f32, y: f32) -> f32 {
        self.all(x, y)[0]
    }
}

impl<const N: usize> Coarse<N> {
    pub fn many(
        width: u32,
        height: u32,
        step_log2: u32,
        f: impl Fn(f32, f32) -> [f32; N] + Sync,
    ) -> Self {
        use rayon::prelude::*;
        let step_log2 = step_log2
            .min(width.trailing_zeros())
            .min(height.trailing_zeros());
        let (cols, rows) = (
            (width >> step_log2) as usize,
            (height >> step_log2) as usize,
        );
        let step = (1u32 << step_log2) as f32;
        let mut values = vec![[0f32; N]; cols * rows];
        values
            .par_chunks_mut(cols)
            .enumerate()
            .for_each(|(j, row)| {
                for (i, v) in row.iter_mut().enumerate() {
                    *v = f(i as f32 * step, j as f32 * step);
                }
            });
        Coarse {
            values,
            cols,
            rows,
            step_log2,
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
        let (i1, j1) = ((i0 + 1) & mx, (j0 + 1) & my);
        let (a, b) = (
            self.values[j0 * self.cols + i0],
            self.values[j0 * self.cols + i1],
        );
        let (c, d) = (
            self.values[j1 * self.cols + i0],
            self.values[j1 * self.cols + i1],
        );
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
