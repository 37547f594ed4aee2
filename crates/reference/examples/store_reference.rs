//! Time the CPU reference over a world loaded whole against the same views
//! over a store read through its chunk cache (bench/store-read): per view,
//! the seconds to trace, and for a store the cache's hits, misses and peak
//! bytes; at the end the process's peak RSS.
//!
//! `cargo run --release -p strata-reference --example store_reference --
//! DIR [WxH] [BUDGET_MIB] [memory|store]`
//!
//! DIR is a Vangers world or a store (`memory` loads a store whole).
//! `spread` as a fifth argument moves view k by whole periods of the
//! default world (k·5 mod 32 times 2048 in x, k mod 4 times 16384 in y):
//! on a store tiled from it (`store_tile`) the pictures stay the same but
//! the views lie far apart, so each reads its own chunks.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use strata_level::MidRule;
use strata_level::source::ColumnSource;
use strata_reference::{ReferenceSettings, Tracer, camera_for_view};
use strata_store::fs::{DirKind, dir_kind};
use strata_store::{ChunkCache, DirStore, load_any};

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(0.0, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        eprintln!("usage: store_reference DIR [WxH] [BUDGET_MIB] [memory|store]");
        std::process::exit(2);
    };
    let (w, h) = args
        .get(1)
        .and_then(|s| s.split_once('x'))
        .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
        .unwrap_or((320u32, 200u32));
    let budget_mib: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(512);
    let is_store = matches!(dir_kind(&dir), Ok(DirKind::Store));
    let tiled = is_store && args.get(3).map(String::as_str) != Some("memory");
    let t0 = Instant::now();
    let (world, cache);
    let source: &dyn ColumnSource = if tiled {
        let store = DirStore::open(&dir).expect("opening the store");
        world = store.store().world_shell().expect("the world's attributes");
        cache = Some(ChunkCache::new(
            Arc::clone(store.store()),
            budget_mib << 20,
            MidRule::Original,
        ));
        cache.as_ref().unwrap()
    } else {
        world = load_any(&dir, MidRule::Original).expect("loading the world");
        cache = None;
        &world.level
    };
    let open_s = t0.elapsed().as_secs_f64();
    let t = Instant::now();
    let tracer = Tracer::over(source).expect("the tracer");
    let prepare_s = t.elapsed().as_secs_f64();
    let (mw, mh) = source.size();
    println!(
        "{} {mw}x{mh} ({}): open/load {open_s:.3} s, tracer {prepare_s:.3} s, {w}x{h}, {} views",
        dir.display(),
        if tiled {
            "store through the chunk cache"
        } else {
            "in memory"
        },
        world.views.len()
    );
    let spread = args.get(4).map(String::as_str) == Some("spread");
    let mut total = 0.0;
    for (k, view) in world.views.iter().enumerate() {
        let mut view = view.clone();
        if spread {
            view.x += ((k * 5) % 32 * 2048) as f32;
            view.y += ((k % 4) * 16384) as f32;
        }
        let view = &view;
        let camera = camera_for_view(source, view, w, h).expect("the camera");
        let t = Instant::now();
        let r = tracer
            .try_render(&camera, &ReferenceSettings::default())
            .expect("the reference");
        let s = t.elapsed().as_secs_f64();
        total += s;
        let stats = cache.as_ref().map_or(String::new(), |c| {
            let st = c.stats();
            format!(
                "  cache: {} hits {} misses ({:.2} % hit), peak {:.1} MiB",
                st.hits,
                st.misses,
                st.hit_rate(),
                st.peak_bytes as f64 / f64::from(1u32 << 20)
            )
        });
        println!(
            "{:<12} {s:>7.3} s  sky {:>5.1} %{stats}",
            view.name,
            r.sky_fraction()
        );
    }
    println!(
        "total {total:.3} s over {} views (+ tracer {prepare_s:.3} s), wall {:.3} s, peak RSS {:.0} MiB",
        world.views.len(),
        t0.elapsed().as_secs_f64(),
        peak_rss_mib()
    );
}
