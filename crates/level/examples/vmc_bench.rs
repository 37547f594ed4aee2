//! Time `.vmc` encode and decode of a world's map (or, with no argument, of
//! a synthetic 2048 x 16384 map), without the GPU-dependent binary:
//! `cargo run --release -p strata-level --example vmc_bench [-- DIR]`.

use std::path::Path;
use std::time::Instant;
use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT, MidRule};
use strata_level::{Level, io, vmc};

/// Terraces with small noise and about 10 % dual texels.
fn synthetic(w: u32, h: u32) -> Level {
    let mut state = 0x1234_5678_9abc_def0u64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let n = (w * h) as usize;
    let (mut hs, mut ms) = (vec![0u8; n], vec![0u8; n]);
    for i in (0..n).step_by(2) {
        let (x, y) = (i % w as usize, i / w as usize);
        let base = (((x / 24 + y / 40) % 6) * 25 + 40) as u8 + (rand() % 3) as u8;
        let t = ((x / 64 + y / 96) % 8) as u8;
        hs[i] = base;
        ms[i] = t << META_TERRAIN_SHIFT;
        ms[i + 1] = t << META_TERRAIN_SHIFT;
        hs[i + 1] = base;
        if (x / 8 + y / 8) % 10 == 0 {
            hs[i + 1] = base + 60;
            ms[i] |= META_DOUBLE_LEVEL | 1;
            ms[i + 1] |= META_DOUBLE_LEVEL | 2;
        }
    }
    Level::from_planes(w, h, hs, ms, MidRule::Original).expect("size")
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let level = match std::env::args().nth(1) {
        Some(dir) => {
            let (world, load) = io::load_world_timed(Path::new(&dir), MidRule::Original)?;
            println!(
                "file {}: {} bytes, read {:.1} ms, decode {:.1} ms",
                load.path.display(),
                load.bytes,
                load.read_ms,
                load.decode_ms
            );
            world.level
        }
        None => synthetic(2048, 16384),
    };
    let path = Path::new("mem.vmc");
    for _ in 0..3 {
        let t = Instant::now();
        let bytes = vmc::encode_vmc(&level, path)?;
        let enc = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let back = vmc::decode_vmc(&bytes, level.width(), level.height(), level.mid_rule, path)?;
        let dec = t.elapsed().as_secs_f64() * 1e3;
        assert!(back == level, "round trip differs");
        println!(
            "{}x{}: .vmc {} bytes ({:.2} MB), encode {enc:.1} ms, decode {dec:.1} ms",
            level.width(),
            level.height(),
            bytes.len(),
            bytes.len() as f64 / 1e6
        );
    }
    Ok(())
}
