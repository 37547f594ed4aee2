//! Time the fit and a crater refit on a synthetic level:
//! `cargo run --release -p strata-mesh --example fit_synthetic -- [W H [TOL] | WORLD_DIR - [TOL]]`.

use std::time::Instant;

use strata_level::DirtyRect;
use strata_level::model::META_DOUBLE_LEVEL;
use strata_mesh::cpu_time::process_cpu_seconds;
use strata_mesh::synthetic::synthetic_level;
use strata_mesh::{LevelMesh, timed_fit};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let tol = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(4.0f64);
    let t = Instant::now();
    // A world directory, or the synthetic level's size.
    let mut level = match args.get(1).map(std::path::Path::new) {
        Some(dir) if dir.is_dir() => {
            strata_level::io::load_world(dir, strata_level::MidRule::Original)
                .expect("world")
                .level
        }
        _ => {
            let w = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2048u32);
            let h = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(16384u32);
            synthetic_level(w, h, 1)
        }
    };
    let (w, h) = (level.width(), level.height());
    println!(
        "generated {w}x{h} in {:.2} s, dual texels {:.1}%",
        t.elapsed().as_secs_f64(),
        100.0 * level.dual_texel_count() as f64 / (f64::from(w) * f64::from(h))
    );
    // Start the pool first so its threads exist for both CPU readings.
    rayon::broadcast(|_| ());
    let cpu0 = process_cpu_seconds().unwrap_or(0.0);
    let (mut mesh, secs) = timed_fit(&level, tol);
    let cpu = process_cpu_seconds().unwrap_or(0.0) - cpu0;
    println!("fit cpu {cpu:.3} s (all threads)");
    let s = mesh.stats();
    println!(
        "fit {secs:.3} s on {} threads",
        rayon::current_num_threads()
    );
    println!("{s:#?}");
    let tris = s.lods[0].planar as f64;
    println!(
        "finest planar tris {tris}, tris/s/core {:.0}",
        tris / secs / rayon::current_num_threads() as f64
    );
    println!(
        "gpu bytes / finest planar tri {:.2}, / finest emitted tri {:.2}",
        s.gpu_bytes as f64 / tris,
        s.gpu_bytes as f64 / s.lods[0].emitted as f64
    );
    // Crater refit, r = 48 at the map centre.
    let (cx, cy, r) = (i64::from(w / 2), i64::from(h / 2), 48i64);
    {
        let (heights, metas) = level.planes_mut();
        for y in cy - r..=cy + r {
            for x in ((cx - r) & !1..=cx + r).step_by(2) {
                let d2 = ((x - cx).pow(2) + (y - cy).pow(2)) as f64;
                if d2 > (r * r) as f64 {
                    continue;
                }
                let i = (y * i64::from(w) + x) as usize;
                let low =
                    (f64::from(heights[i]) - 90.0 * (1.0 - d2 / (r * r) as f64)).max(0.0) as u8;
                heights[i] = low;
                heights[i + 1] = low;
                metas[i] &= !META_DOUBLE_LEVEL;
                metas[i + 1] &= !META_DOUBLE_LEVEL;
            }
        }
    }
    let dirty = [DirtyRect {
        x: (cx - r) as u32,
        y: (cy - r) as u32,
        width: 2 * r as u32 + 1,
        height: 2 * r as u32 + 1,
    }];
    let t = Instant::now();
    let cpu0 = process_cpu_seconds().unwrap_or(0.0);
    let changed = mesh.refit(&level, &dirty);
    let cpu = process_cpu_seconds().unwrap_or(0.0) - cpu0;
    println!(
        "crater refit {:.2} ms wall, {:.2} ms cpu, {} chunks changed",
        t.elapsed().as_secs_f64() * 1e3,
        cpu * 1e3,
        changed.len()
    );
    let fresh = LevelMesh::fit(&level, tol);
    println!("refit == fresh fit: {}", fresh == mesh);
}
