//! A synthetic Vangers-like level for tests and timing before (and besides)
//! the world generator: terraced hills, cliffs, and rectangular slab regions
//! (about a tenth of the texels dual) with varying cave gaps.

use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT};
use strata_level::{Level, MidRule};

fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// A `width x height` level (powers of two, width >= 2) from `seed`.
pub fn synthetic_level(width: u32, height: u32, seed: u32) -> Level {
    let (w, h) = (width as usize, height as usize);
    let mut heights = vec![0u8; w * h];
    let mut metas = vec![0u8; w * h];
    let tau = std::f32::consts::TAU;
    let (fw, fh) = (width as f32, height as f32);
    for y in 0..h {
        for x in 0..w {
            // Periodic relief so the map wraps without a seam.
            let (u, v) = (x as f32 / fw * tau, y as f32 / fh * tau);
            let s = (seed % 7) as f32;
            let hills =
                60.0 * (u * 3.0 + s).sin() * (v * 5.0).cos() + 30.0 * (u * 11.0 + v * 7.0).sin();
            let fine = 6.0 * (u * 61.0).sin() * (v * 47.0 + s).sin();
            let mut z = 110.0 + hills + fine;
            // Terraces: steps of 16 with short ramps.
            let t = z / 16.0;
            let frac = t - t.floor();
            z = (t.floor() + ((frac - 0.8) * 5.0).clamp(0.0, 1.0)) * 16.0;
            // Cliffs: a sharp drop along a few lines.
            if (x as u32 / 97 + y as u32 / 131 + seed).is_multiple_of(5) {
                z -= 40.0;
            }
            heights[y * w + x] = z.clamp(0.0, 200.0) as u8;
            let terrain = 1 + (hash(seed ^ (x as u32 / 64) ^ ((y as u32 / 64) << 12)) % 7) as u8;
            metas[y * w + x] = terrain << META_TERRAIN_SHIFT;
        }
    }
    // Rectangular slabs over ~10% of the map.
    let area = (w * h) as u64;
    let mut covered = 0u64;
    let mut k = 0u32;
    while covered * 10 < area && k < 100_000 {
        let r = |i: u32| hash(seed.wrapping_mul(7919) ^ k.wrapping_mul(104_729) ^ i);
        let rw = (8 + r(1) % 56).min(width) as usize;
        let rh = (8 + r(2) % 56).min(height) as usize;
        let x0 = (r(3) % width) as usize & !1;
        let y0 = (r(4) % height) as usize;
        let thick = 10 + (r(5) % 30) as u8;
        let code = (r(6) % 16) as u8;
        let ramp = r(7).is_multiple_of(2);
        for dy in 0..rh {
            for dx in (0..rw).step_by(2) {
                let (x, y) = ((x0 + dx) % w, (y0 + dy) % h);
                let low = heights[y * w + x];
                let gap = MidRule::Original.gap(code) as u8;
                let base = if ramp { (dx as u8) / 2 } else { 0 };
                let high = low
                    .saturating_add(gap)
                    .saturating_add(thick)
                    .saturating_add(base);
                let even = y * w + x;
                let odd = even + 1;
                let te = metas[even] & 0x38;
                heights[even] = low;
                heights[odd] = high;
                metas[even] = META_DOUBLE_LEVEL | te | (code >> 2);
                metas[odd] = META_DOUBLE_LEVEL | (5 << META_TERRAIN_SHIFT) | (code & 3);
            }
        }
        covered += (rw * rh) as u64;
        k += 1;
    }
    Level::from_planes(width, height, heights, metas, MidRule::Original)
        .expect("power-of-two planes")
}
