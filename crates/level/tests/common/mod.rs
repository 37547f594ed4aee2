//! Fixtures shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use strata_level::Level;
use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT, MidRule};

/// A small deterministic generator (splitmix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// A random-ish level with terraces, noise, a few shadow bits and dual pairs
/// (about a tenth of the pairs), valid under the pair rule.
pub fn synthetic(w: u32, h: u32, seed: u64) -> Level {
    let mut rng = Rng(seed);
    let n = (w * h) as usize;
    let mut heights = vec![0u8; n];
    let mut metas = vec![0u8; n];
    for y in 0..h as usize {
        for x in (0..w as usize).step_by(2) {
            let i = y * w as usize + x;
            let terrace = ((x / 16 + y / 16) % 5) as u8 * 30;
            let base = terrace.saturating_add(rng.below(4) as u8);
            let t = ((x / 32 + y / 8) % 8) as u8;
            if rng.below(10) == 0 {
                let code = rng.below(16) as u8;
                heights[i] = base;
                heights[i + 1] = base.saturating_add(40 + rng.below(100) as u8);
                metas[i] = META_DOUBLE_LEVEL | (t << META_TERRAIN_SHIFT) | (code >> 2);
                metas[i + 1] =
                    META_DOUBLE_LEVEL | (((t + 3) & 7) << META_TERRAIN_SHIFT) | (code & 3);
            } else {
                heights[i] = base;
                heights[i + 1] = base.saturating_add(rng.below(3) as u8);
                let shadow = if rng.below(7) == 0 { 0x80 } else { 0 };
                metas[i] = (t << META_TERRAIN_SHIFT) | shadow;
                metas[i + 1] = t << META_TERRAIN_SHIFT;
            }
        }
    }
    Level::from_planes(w, h, heights, metas, MidRule::Original).expect("valid size")
}

/// A fresh empty directory under the target's temp area.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir()
        .join(format!("strata-level-tests-{}", std::process::id()))
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The real Fostral files: `$STRATA_FOSTRAL_DIR`, else `../shared/data/fostral`.
pub fn fostral_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("STRATA_FOSTRAL_DIR") {
        return d.into();
    }
    let beside = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/fostral");
    if beside.exists() {
        beside
    } else {
        PathBuf::from("/work/shared/data/fostral")
    }
}
