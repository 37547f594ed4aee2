//! Write a large store chunk by chunk in bounded memory (a cheap synthetic
//! pattern, not the world generator), then time what `strata info` does on
//! it: open the store and read every chunk summary (no chunk read).
//!
//! `cargo run -p strata-store --example store_big -- [WxH] [DIR]`
//! (default 65536x65536 in a temporary directory, removed afterwards
//! unless DIR is given).

use std::path::PathBuf;
use std::time::Instant;
use strata_level::{Level, World, WorldConfig};
use strata_store::{Chunk, DirStore, Layout};

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
    let (w, h) =
        strata_level::generate::parse_size(args.first().map_or("65536x65536", String::as_str))
            .expect("size WxH");
    let keep = args.get(1).is_some();
    let dir = args.get(1).map(PathBuf::from).unwrap_or_else(|| {
        std::env::temp_dir().join(format!("strata-store-big-{}", std::process::id()))
    });
    let _ = std::fs::remove_dir_all(&dir);
    // Everything but the planes; the level is a stand-in (not read).
    let config = WorldConfig {
        map_power_x: w.trailing_zeros(),
        map_power_y: h.trailing_zeros(),
        ..WorldConfig::default()
    };
    let world = World {
        name: format!("synthetic-{w}x{h}"),
        level: Level::flat(2, 1, 0, 0).unwrap(),
        config,
        palette: strata_level::Palette {
            colors: [[0; 3]; 256],
        },
        water: None,
        views: Vec::new(),
        edit: None,
        source: Default::default(),
    };
    let layout = Layout::default();
    let (ch, cw) = layout.chunk_for(w, h);
    // Rolling hills with a slab band: cheap, varied, compressible like terrain.
    let make = |cy: u64, cx: u64| {
        let n = (ch * cw) as usize;
        let (mut heights, mut metas) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for r in 0..u64::from(ch) {
            for c in 0..u64::from(cw) {
                let (x, y) = (cx * u64::from(cw) + c, cy * u64::from(ch) + r);
                let v = ((x as f64 * 0.013).sin() * 40.0 + (y as f64 * 0.007).cos() * 50.0 + 100.0)
                    as u8;
                heights.push(v);
                metas.push((((x >> 9) ^ (y >> 9)) as u8 & 7) << 3);
            }
        }
        Ok(Chunk {
            rows: ch,
            cols: cw,
            heights,
            metas,
        })
    };
    let parent = dir.parent().unwrap().to_path_buf();
    let t = Instant::now();
    DirStore::create_with(&dir, &world, (w, h), &layout, &make).expect("writing the store");
    println!(
        "wrote {w}x{h} ({} chunks of {cw}x{ch}) in {:.1} s, peak RSS {:.0} MiB, into {}",
        (u64::from(w) / u64::from(cw)) * (u64::from(h) / u64::from(ch)),
        t.elapsed().as_secs_f64(),
        peak_rss_mib(),
        parent.display()
    );
    let t = Instant::now();
    let store = DirStore::open(&dir).expect("opening");
    let open_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let sums = store.store().summaries().expect("summaries");
    let dual: u64 = sums.iter().map(|s| u64::from(s.dual_texels)).sum();
    println!(
        "info from summaries: open {open_ms:.1} ms, {} summaries read in {:.1} ms (dual texels {dual}, top max {})",
        sums.len(),
        t.elapsed().as_secs_f64() * 1e3,
        sums.iter().map(|s| s.top_max).max().unwrap_or(0)
    );
    if !keep {
        let _ = std::fs::remove_dir_all(&dir);
    }
}
