//! Time the fit and a crater refit on a synthetic level:
//! `cargo run --release -p strata-mesh --example fit_synthetic -- [W H [TOL] | WORLD_DIR - [TOL]]`.

use std::time::Instant;

use strata_level::EditSite;
use strata_level::edit::crater;
use strata_mesh::cpu_time::process_cpu_seconds;
use strata_mesh::synthetic::synthetic_level;
use strata_mesh::{LevelMesh, timed_fit};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let tol = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(4.0f64);
    let t = Instant::now();
    // A world directory, or the synthetic level's size.
    let mut site = None;
    let level = match args.get(1).map(std::path::Path::new) {
        Some(dir) if dir.is_dir() => {
            let world =
                strata_level::io::load_world(dir, strata_level::MidRule::Original).expect("world");
            site = world.edit;
            world.level
        }
        _ => {
            let w = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2048u32);
            let h = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(16384u32);
            synthetic_level(w, h, 1)
        }
    };
    let (w, h) = (level.width(), level.height());
    println!(
        "loaded {w}x{h} in {:.2} s, dual texels {:.1}%",
        t.elapsed().as_secs_f64(),
        100.0 * level.dual_texel_count() as f64 / (f64::from(w) * f64::from(h))
    );
    // Start the pool first so its threads exist for both CPU readings.
    rayon::broadcast(|_| ());
    let cpu0 = process_cpu_seconds().unwrap_or(0.0);
    let (mesh, secs) = timed_fit(&level, tol);
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
    // Crater refits: the world's edit site, and the paper's (1024, 8192),
    // a chunk corner, so four chunks (the worst case for r = 48).
    let mut sites = Vec::new();
    sites.extend(site.clone());
    let mut centre = EditSite::fostral();
    (centre.centre_x, centre.centre_y) = (i64::from(w / 2), i64::from(h / 2));
    sites.push(centre);
    for site in sites {
        let mut edited = level.clone();
        let mut refit = mesh.clone();
        let dirty = crater(&mut edited, &site);
        let changed = refit.refit(&edited, &dirty);
        // Repeat (same work: the dirty chunks are refitted and compared) to
        // average out timer granularity and the shared machine.
        const REPEAT: u32 = 20;
        let mut walls = Vec::new();
        let cpu0 = process_cpu_seconds().unwrap_or(0.0);
        for _ in 0..REPEAT {
            let t = Instant::now();
            refit.refit(&edited, &dirty);
            walls.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let cpu = (process_cpu_seconds().unwrap_or(0.0) - cpu0) * 1e3 / f64::from(REPEAT);
        walls.sort_by(f64::total_cmp);
        println!(
            "crater ({}, {}) r {}: {} chunks changed; refit median {:.2} ms wall (min {:.2}), {:.2} ms CPU mean",
            site.centre_x,
            site.centre_y,
            site.radius,
            changed.len(),
            walls[walls.len() / 2],
            walls[0],
            cpu
        );
        let fresh = LevelMesh::fit(&edited, tol);
        println!("refit == fresh fit: {}", fresh == refit);
    }
}
