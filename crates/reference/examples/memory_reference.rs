//! Time the in-memory CPU reference (the whole-map pyramid path) over a
//! world's own views, through the API the reference has always had, so the
//! same program builds against older revisions for a before/after check.
//!
//! `cargo run --release -p strata-reference --example memory_reference -- DIR [WxH] [ROUNDS]`

use std::path::PathBuf;
use std::time::Instant;
use strata_camera::Camera;
use strata_level::MidRule;
use strata_reference::{ReferenceSettings, Tracer};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        eprintln!("usage: memory_reference DIR [WxH] [ROUNDS]");
        std::process::exit(2);
    };
    let (w, h) = args
        .get(1)
        .and_then(|s| s.split_once('x'))
        .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
        .unwrap_or((320u32, 200u32));
    let rounds: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    let world = strata_store::load_any(&dir, MidRule::Original).expect("loading the world");
    let tracer = Tracer::new(&world.level);
    let cameras: Vec<Camera> = world
        .views
        .iter()
        .map(|v| Camera::from_view(&world.level, v, w, h).expect("camera"))
        .collect();
    let mut best = f64::MAX;
    let mut hash = 0u64;
    for _ in 0..rounds {
        let t = Instant::now();
        for c in &cameras {
            let r = tracer.render(c, &ReferenceSettings::default());
            hash = r
                .distance
                .iter()
                .fold(hash, |a, d| a.rotate_left(5) ^ u64::from(d.to_bits()));
        }
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!(
        "{} views at {w}x{h}: best of {rounds} rounds {best:.3} s (checksum {hash:016x})",
        cameras.len()
    );
}
