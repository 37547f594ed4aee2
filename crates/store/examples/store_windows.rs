//! Does a big generated store look like a big world? Samples square
//! windows of a store (2048x2048 by default, at chunk-aligned places spread
//! over the whole map), and prints per window the dual fraction and the
//! roughness (`strata_level::stats`) against the default world's
//! (2048x16384, seed 1997, generated here in memory: the whole world and
//! its eight 2048x2048 windows), and checks that no two windows have the
//! same bytes. Exits 1 when two windows are equal or a window's figures,
//! or their mean, are off by more than the tolerances below.
//!
//! `cargo run --release -p strata-store --example store_windows -- DIR [WINDOWS] [SIDE]`
//! (`strata generate --to store --size 65536x65536 --out DIR` makes one).

use std::collections::HashMap;
use std::path::PathBuf;
use strata_level::generate::{GenerateParams, generate};
use strata_level::stats::LevelStats;
use strata_level::{Level, MidRule};
use strata_store::DirStore;

/// Largest relative difference from the default world's whole-map figure
/// a window may show. The default world's own 2048² windows spread about
/// ±6 % in dual fraction and ±5 % in roughness around it; a big world's
/// spread wider and sit higher in dual fraction (+6 % on average for
/// 65536², bench/store-gen): most of its windows have no river valley,
/// which crosses every window of the 2048-wide default world and holds
/// fewer slabs than the districts it displaces.
const DUAL_TOLERANCE: f64 = 0.25;
const ROUGHNESS_TOLERANCE: f64 = 0.10;
/// The same for the mean over all windows.
const MEAN_DUAL_TOLERANCE: f64 = 0.10;
const MEAN_ROUGHNESS_TOLERANCE: f64 = 0.05;

/// A window of the store as a level (wrapping at its own edges, which
/// moves the roughness by well under 0.1 %).
fn read_window(store: &DirStore, x0: u32, y0: u32, side: u32) -> Level {
    let s = store.store();
    let (ch, cw) = s.chunk_shape();
    let n = side as usize;
    let (mut heights, mut metas) = (vec![0u8; n * n], vec![0u8; n * n]);
    for cy in 0..side / ch {
        for cx in 0..side / cw {
            let c = s
                .read_chunk(u64::from(y0 / ch + cy), u64::from(x0 / cw + cx))
                .expect("reading a chunk");
            for r in 0..ch as usize {
                let dst = (cy * ch) as usize * n + r * n + (cx * cw) as usize;
                let src = r * cw as usize..(r + 1) * cw as usize;
                heights[dst..dst + cw as usize].copy_from_slice(&c.heights[src.clone()]);
                metas[dst..dst + cw as usize].copy_from_slice(&c.metas[src]);
            }
        }
    }
    Level::from_planes(side, side, heights, metas, MidRule::Original).expect("a square window")
}

/// Window corners: a fixed pseudo-random sequence of chunk-aligned places
/// (the same for every run), distinct.
fn places(width: u32, height: u32, side: u32, count: usize, align: u32) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = Vec::new();
    let mut state = 0x5eed_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 33) as u32
    };
    let (xs, ys) = ((width - side) / align + 1, (height - side) / align + 1);
    let possible = xs as usize * ys as usize;
    while out.len() < count.min(possible) {
        let p = ((next() % xs) * align, (next() % ys) * align);
        if !out.contains(&p) {
            out.push(p);
        }
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        eprintln!("usage: store_windows DIR [WINDOWS] [SIDE]");
        std::process::exit(2);
    };
    let count: usize = args.get(1).map_or(16, |s| s.parse().expect("WINDOWS"));
    let store = DirStore::open(&dir).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let (w, h) = (store.store().width(), store.store().height());
    let side: u32 = args
        .get(2)
        .map_or(2048, |s| s.parse().expect("SIDE"))
        .min(w)
        .min(h);
    let (ch, cw) = store.store().chunk_shape();
    assert!(
        side.is_power_of_two() && side.is_multiple_of(ch) && side.is_multiple_of(cw),
        "SIDE must be a power of two, whole chunks"
    );

    let default = generate(&GenerateParams::default()).expect("the default world");
    let reference = LevelStats::compute(&default.level);
    let own: Vec<LevelStats> = (0..8)
        .map(|i| {
            let d = &default.level;
            let rows = 2048 * d.width() as usize;
            let (hs, ms) = (d.heights(), d.metas());
            let span = i * rows..(i + 1) * rows;
            let l = Level::from_planes(
                2048,
                2048,
                hs[span.clone()].to_vec(),
                ms[span].to_vec(),
                MidRule::Original,
            )
            .expect("a window of the default world");
            LevelStats::compute(&l)
        })
        .collect();
    let range = |f: fn(&LevelStats) -> f64| {
        let v: Vec<f64> = own.iter().map(f).collect();
        (
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let (dlo, dhi) = range(|s| s.dual_percent);
    let (rlo, rhi) = range(|s| s.roughness_floor);
    println!(
        "default world 2048x16384 seed 1997: dual {:.2} % (its 2048² windows {dlo:.2} .. {dhi:.2}), floor roughness {:.3} ({rlo:.3} .. {rhi:.3}), surface {:.3}",
        reference.dual_percent, reference.roughness_floor, reference.roughness_surface
    );
    println!(
        "store {} ({w}x{h}): {count} windows of {side}x{side}",
        dir.display()
    );
    println!("| x | y | dual % | vs default | floor roughness | vs default | surface | hash |");
    println!("|---|---|---|---|---|---|---|---|");
    let rel = |v: f64, r: f64| (v - r) / r;
    let mut hashes: HashMap<String, (u32, u32)> = HashMap::new();
    let (mut bad, mut sum_dual, mut sum_rough) = (0, 0.0, 0.0);
    let spots = places(w, h, side, count, ch.max(cw));
    for &(x, y) in &spots {
        let level = read_window(&store, x, y, side);
        let s = LevelStats::compute(&level);
        let hash = level.content_hash();
        let (dd, dr) = (
            rel(s.dual_percent, reference.dual_percent),
            rel(s.roughness_floor, reference.roughness_floor),
        );
        sum_dual += s.dual_percent;
        sum_rough += s.roughness_floor;
        let off = dd.abs() > DUAL_TOLERANCE || dr.abs() > ROUGHNESS_TOLERANCE;
        println!(
            "| {x} | {y} | {:.2} | {:+.1} % | {:.3} | {:+.1} % | {:.3} | {}{} |",
            s.dual_percent,
            dd * 100.0,
            s.roughness_floor,
            dr * 100.0,
            s.roughness_surface,
            &hash[..12],
            if off { " OFF" } else { "" }
        );
        bad += usize::from(off);
        if let Some(other) = hashes.insert(hash, (x, y)) {
            println!("EQUAL: window ({x}, {y}) has the bytes of window {other:?}");
            bad += 1;
        }
    }
    let n = spots.len() as f64;
    println!(
        "mean of {} windows: dual {:.2} % ({:+.1} %), floor roughness {:.3} ({:+.1} %); {} distinct hashes",
        spots.len(),
        sum_dual / n,
        rel(sum_dual / n, reference.dual_percent) * 100.0,
        sum_rough / n,
        rel(sum_rough / n, reference.roughness_floor) * 100.0,
        hashes.len()
    );
    let (mean_dual, mean_rough) = (
        rel(sum_dual / n, reference.dual_percent),
        rel(sum_rough / n, reference.roughness_floor),
    );
    if mean_dual.abs() > MEAN_DUAL_TOLERANCE || mean_rough.abs() > MEAN_ROUGHNESS_TOLERANCE {
        println!("the mean is off by more than the tolerances");
        bad += 1;
    }
    if bad > 0 {
        println!("FAIL: {bad} windows equal or off by more than the tolerances");
        std::process::exit(1);
    }
    println!(
        "OK: all windows distinct, each within {:.0} % (dual) and {:.0} % (roughness) of the default world, the mean within {:.0} % and {:.0} %",
        DUAL_TOLERANCE * 100.0,
        ROUGHNESS_TOLERANCE * 100.0,
        MEAN_DUAL_TOLERANCE * 100.0,
        MEAN_ROUGHNESS_TOLERANCE * 100.0
    );
}
