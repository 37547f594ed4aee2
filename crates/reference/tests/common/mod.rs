//! Hand-built levels for the reference's tests.
#![allow(dead_code)] // each test binary uses a different part

use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT};
use strata_level::{Level, MidRule};

/// Set a single-level texel.
pub fn set_single(level: &mut Level, x: u32, y: u32, height: u8, terrain: u8) {
    let w = level.width() as usize;
    let (h, m) = level.planes_mut();
    let k = x as usize + y as usize * w;
    h[k] = height;
    m[k] = (terrain & 7) << META_TERRAIN_SHIFT;
}

/// Make the pair containing texel x a dual column: floor `low` (type
/// `lower`), slab top `high` (type `upper`), gap code `code` (0..15).
#[allow(clippy::too_many_arguments)]
pub fn set_dual(
    level: &mut Level,
    x: u32,
    y: u32,
    low: u8,
    high: u8,
    code: u8,
    lower: u8,
    upper: u8,
) {
    let w = level.width() as usize;
    let even = (x & !1) as usize + y as usize * w;
    let (h, m) = level.planes_mut();
    h[even] = low;
    h[even + 1] = high;
    m[even] = META_DOUBLE_LEVEL | ((lower & 7) << META_TERRAIN_SHIFT) | ((code >> 2) & 3);
    m[even + 1] = META_DOUBLE_LEVEL | ((upper & 7) << META_TERRAIN_SHIFT) | (code & 3);
}

/// Fill a rectangle `[x0, x1) x [y0, y1)` with one single height.
pub fn fill(level: &mut Level, x0: u32, x1: u32, y0: u32, y1: u32, height: u8, terrain: u8) {
    for y in y0..y1 {
        for x in x0..x1 {
            set_single(level, x, y, height, terrain);
        }
    }
}

/// A small deterministic generator (xorshift64*), so tests need no crate.
pub struct Rng(u64);
impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// A rough 256x256 level: random terraces (steps of 4..40 units, plateaus of
/// 1..16 texels) with cliffs, single spikes, and rectangles of slabs over caves.
pub fn rough_level(seed: u64) -> Level {
    let n = 256u32;
    let mut rng = Rng::new(seed);
    let mut level = Level::from_planes(
        n,
        n,
        vec![0; (n * n) as usize],
        vec![0; (n * n) as usize],
        MidRule::Original,
    )
    .unwrap();
    // Terraces: overlapping random rectangles, each raising to a level.
    for _ in 0..400 {
        let (x0, y0) = (
            rng.below(u64::from(n)) as u32,
            rng.below(u64::from(n)) as u32,
        );
        let (w, h) = (1 + rng.below(40) as u32, 1 + rng.below(40) as u32);
        let height = (rng.below(24) * 6) as u8;
        let t = rng.below(8) as u8;
        for y in y0..y0 + h {
            for x in x0..x0 + w {
                set_single(&mut level, x % n, y % n, height, t);
            }
        }
    }
    for _ in 0..300 {
        let (x, y) = (
            rng.below(u64::from(n)) as u32,
            rng.below(u64::from(n)) as u32,
        );
        set_single(
            &mut level,
            x,
            y,
            100 + rng.below(150) as u8,
            rng.below(8) as u8,
        );
    }
    // Slabs over whatever floor is there.
    for _ in 0..60 {
        let (x0, y0) = (
            rng.below(u64::from(n)) as u32 & !1,
            rng.below(u64::from(n)) as u32,
        );
        let (w, h) = (2 + 2 * rng.below(12) as u32, 1 + rng.below(24) as u32);
        let code = rng.below(16) as u8;
        let thick = 4 + rng.below(40) as u32;
        let (lower, upper) = (rng.below(8) as u8, rng.below(8) as u8);
        for y in y0..y0 + h {
            for x in (x0..x0 + w).step_by(2) {
                let (xx, yy) = (x % n, y % n);
                let c = level.column(i64::from(xx), i64::from(yy));
                let low = c.low.min(120);
                let high = (u32::from(low) + 8 * (u32::from(code) + 1) + thick).min(250) as u8;
                set_dual(&mut level, xx, yy, low, high, code, lower, upper);
            }
        }
    }
    level
}
