//! The full CPU build on a Fostral-sized map: its time and buffer size.
//! Ignored by default (a 32 M texel build); run with `--ignored --nocapture`.

use std::time::Instant;
use strata_level::Level;
use strata_occupancy::{Pyramid, VoxelSize};

#[test]
#[ignore]
fn fostral_sized_full_build() {
    let level = Level::flat(2048, 16384, 80, 1).unwrap();
    for voxel in [VoxelSize::COARSE, VoxelSize::FINE] {
        let start = Instant::now();
        let p = Pyramid::build(&level, voxel).unwrap();
        println!(
            "({voxel}) 2048x16384: {:.2} MiB, {} levels, CPU build {:.0} ms",
            p.bytes() as f64 / (1024.0 * 1024.0),
            p.layout.levels.len(),
            start.elapsed().as_secs_f64() * 1e3
        );
    }
}
