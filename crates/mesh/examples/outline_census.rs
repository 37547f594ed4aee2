//! Issue 17: where the outline fit's vertices go, and what the single/double
//! outline of a world costs at the least.
//!
//! `cargo run --release -p strata-mesh --example outline_census -- [WORLD_DIR | gen[:DUAL[:ROUGH]] [W H]] [TOL]`
//!
//! `gen` (the default) generates the built-in world (2048x16384, seed
//! 1997); `gen:0.2` turns `--dual-fraction 0.2`, `gen:0.2:1` also
//! `--floor-roughness 1`. Prints, per fit (plain, outline): triangles planar
//! and drawn per LOD, the insertion causes, fit CPU seconds, and the finest
//! vertices by the class of their sample (single or dual, on the outline or
//! not); then the census of the outline itself.

// Parallel per-class and per-cause tables, indexed together.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;
use strata_level::Level;
use strata_level::generate::{GenerateParams, Knobs, generate_with};
use strata_mesh::cpu_time::process_cpu_seconds;
use strata_mesh::samples::{ChunkLayout, ChunkSamples, DUAL};
use strata_mesh::{CAUSES, ChunkFitter, FitOptions, LODS, LevelMesh};

fn load(args: &[String]) -> Level {
    let spec = args.get(1).map(String::as_str).unwrap_or("gen");
    if let Some(rest) = spec.strip_prefix("gen") {
        let mut parts = rest.split(':').skip(1);
        let knobs = Knobs {
            dual_fraction: parts.next().map(|s| s.parse().expect("dual fraction")),
            floor_roughness: parts.next().map(|s| s.parse().expect("floor roughness")),
        };
        let mut params = GenerateParams::default();
        if let (Some(w), Some(h)) = (args.get(2), args.get(3)) {
            params.width = w.parse().expect("width");
            params.height = h.parse().expect("height");
        }
        return generate_with(&params, &knobs).expect("generate").level;
    }
    strata_level::io::load_world(std::path::Path::new(spec), strata_level::MidRule::Original)
        .expect("world")
        .level
}

/// Sample classes: 0 single interior, 1 single on the outline (a dual
/// 8-neighbour), 2 dual on the outline (a single 8-neighbour), 3 dual interior.
fn class(s: &ChunkSamples, x: i32, y: i32) -> usize {
    let d = s.at(x, y).flags & DUAL != 0;
    let (sx, sy) = (s.size_x as i32, s.size_y as i32);
    let mut other = false;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (u, v) = (x + dx, y + dy);
            if (0..=sx).contains(&u) && (0..=sy).contains(&v) {
                other |= (s.at(u, v).flags & DUAL != 0) != d;
            }
        }
    }
    match (d, other) {
        (false, false) => 0,
        (false, true) => 1,
        (true, true) => 2,
        (true, false) => 3,
    }
}

/// One chunk's vertices and samples by class, its non-Delaunay edges, and
/// its dual-outline vertices off / at a row-run end and all run ends.
type ChunkCensus = ([u64; 4], [u64; 4], u64, [u64; 3]);

fn census(level: &Level, tol: f64, options: FitOptions, name: &str) {
    let layout = ChunkLayout::of(level);
    rayon::broadcast(|_| ());
    let cpu0 = process_cpu_seconds().unwrap_or(0.0);
    let t0 = std::time::Instant::now();
    let per: Vec<ChunkCensus> = (0..layout.count())
        .into_par_iter()
        .map_init(
            || (ChunkFitter::default(), ChunkSamples::default()),
            |(f, s), i| {
                let (cx, cy) = layout.coords(i);
                f.fit_with(level, &layout, cx, cy, tol, options);
                s.load(level, &layout, cx, cy);
                let mut verts = [0u64; 4];
                let mut ends = [0u64; 2];
                for p in &f.triangulation().pts {
                    let k = class(s, p[0], p[1]);
                    verts[k] += 1;
                    if k == 2 {
                        ends[usize::from(run_end(s, p[0], p[1]))] += 1;
                    }
                }
                let mut samples = [0u64; 4];
                for y in 0..s.size_y as i32 {
                    for x in 0..s.size_x as i32 {
                        samples[class(s, x, y)] += 1;
                    }
                }
                let tr = f.triangulation();
                let mut bad = tr.delaunay_violations() as u64;
                if !tr.is_consistent() {
                    bad += 1 << 32;
                }
                if options.outline {
                    bad += f.floor_triangulation().delaunay_violations() as u64;
                }
                let mut all_ends = 0u64;
                for y in 0..s.size_y as i32 {
                    for x in 0..s.size_x as i32 {
                        if class(s, x, y) == 2 && run_end(s, x, y) {
                            all_ends += 1;
                        }
                    }
                }
                (verts, samples, bad, [ends[0], ends[1], all_ends])
            },
        )
        .collect();
    let census_secs = t0.elapsed().as_secs_f64();
    let cpu = process_cpu_seconds().unwrap_or(0.0) - cpu0;
    let mut verts = [0u64; 4];
    let mut samples = [0u64; 4];
    let bad: u64 = per.iter().map(|p| p.2).sum();
    let mut ends = [0u64; 3];
    for p in &per {
        for k in 0..3 {
            ends[k] += p.3[k];
        }
    }
    for (v, s, _, _) in &per {
        for k in 0..4 {
            verts[k] += v[k];
            samples[k] += s[k];
        }
    }
    // The fit alone, for its time and stats.
    let cpu1 = process_cpu_seconds().unwrap_or(0.0);
    let t1 = std::time::Instant::now();
    let mesh = LevelMesh::fit_with_options(level, tol, options, &|_, _| {});
    let fit_secs = t1.elapsed().as_secs_f64();
    let fit_cpu = process_cpu_seconds().unwrap_or(0.0) - cpu1;
    let st = mesh.stats();
    println!("== {name} (tol {tol})");
    for k in 0..LODS {
        let l = &st.lods[k];
        println!(
            "  LOD {k}: planar {:>10}  slab {:>10}  wall {:>10}  drawn {:>10}",
            l.planar, l.slab, l.wall, l.emitted
        );
    }
    let total: u64 = st.causes.iter().sum();
    let names = ["floor", "slab interior", "boundary", "border"];
    for k in 0..CAUSES {
        println!(
            "  {:<14} {:>9} ({:.1} %)",
            names[k],
            st.causes[k],
            100.0 * st.causes[k] as f64 / total.max(1) as f64
        );
    }
    println!(
        "  fit: {fit_secs:.2} s wall, {fit_cpu:.2} s CPU ({} threads); census pass {census_secs:.2} s / {cpu:.2} s CPU",
        rayon::current_num_threads()
    );
    let cls = [
        "single interior",
        "single outline",
        "dual outline",
        "dual interior",
    ];
    let vt: u64 = verts.iter().sum();
    for k in 0..4 {
        println!(
            "  vertices {:<16} {:>9} ({:>5.1} % of vertices, {:>5.1} % of those samples)",
            cls[k],
            verts[k],
            100.0 * verts[k] as f64 / vt as f64,
            100.0 * verts[k] as f64 / samples[k].max(1) as f64
        );
    }
    println!("  samples by class (chunk-local, each texel once): {samples:?}");
    println!(
        "  dual-outline vertices at a row-run end (a single left or right neighbour) {} of {} such samples; elsewhere on the outline {}",
        ends[1], ends[2], ends[0]
    );
    println!(
        "  non-Delaunay edges off the constraints (both triangulations), + 2^32 per inconsistent one: {bad}"
    );
}

/// Whether dual sample `(x, y)` ends a row run (a single sample, in the
/// chunk, left or right of it).
fn run_end(s: &ChunkSamples, x: i32, y: i32) -> bool {
    let single = |u: i32| (0..=s.size_x as i32).contains(&u) && s.at(u, y).flags & DUAL == 0;
    single(x - 1) || single(x + 1)
}

/// The outline itself on the texel grid: runs of dual samples per row and
/// column, their ends, and the corners of the pair-grid outline.
fn outline(level: &Level) {
    let layout = ChunkLayout::of(level);
    let per: Vec<[u64; 5]> = (0..layout.count())
        .into_par_iter()
        .map_init(ChunkSamples::default, |s, i| {
            let (cx, cy) = layout.coords(i);
            s.load(level, &layout, cx, cy);
            let d = |x: i32, y: i32| s.at(x, y).flags & DUAL != 0;
            let (sx, sy) = (s.size_x as i32, s.size_y as i32);
            let mut c = [0u64; 5];
            for y in 0..sy {
                for x in 0..sx {
                    c[0] += u64::from(d(x, y));
                    // Row runs start here.
                    if d(x, y) && (x == 0 || !d(x - 1, y)) {
                        c[1] += 1;
                    }
                    // Cell corners of the digital outline: a 2x2 block of
                    // samples with 1 or 3 duals, or 2 diagonal ones.
                    let n = [d(x, y), d(x + 1, y), d(x, y + 1), d(x + 1, y + 1)];
                    let k = n.iter().filter(|&&b| b).count();
                    if k == 1 || k == 3 || (k == 2 && n[0] == n[3]) {
                        c[2] += 1;
                    }
                    // Isolated one-row runs (no dual above or below): no
                    // slab triangle can have area there.
                    if d(x, y)
                        && y > 0
                        && !d(x, y - 1)
                        && !d(x, y + 1)
                        && !(x > 0 && (d(x - 1, y - 1) || d(x - 1, y + 1)))
                        && !(d(x + 1, y - 1) || d(x + 1, y + 1))
                    {
                        c[3] += 1;
                    }
                    c[4] += 1;
                }
            }
            c
        })
        .collect();
    let mut c = [0u64; 5];
    for p in per {
        for k in 0..5 {
            c[k] += p[k];
        }
    }
    println!("== outline census");
    println!(
        "  dual samples {} ({:.2} % of {}), row runs {}, outline corners (2x2 cells with 1 or 3 duals or a diagonal pair) {}, dual samples with no dual 8-neighbour above or below {}",
        c[0],
        100.0 * c[0] as f64 / c[4] as f64,
        c[4],
        c[1],
        c[2],
        c[3]
    );
}

/// What a per-chunk choice between the two fits could reach: each chunk
/// fitted both ways, the one drawing fewer finest triangles kept (an upper
/// bound on the gain: it ignores that neighbours choosing differently would
/// need a common border vertex set).
fn best_of_both(level: &Level, tol: f64) {
    let layout = ChunkLayout::of(level);
    let per: Vec<[u64; 5]> = (0..layout.count())
        .into_par_iter()
        .map_init(ChunkFitter::default, |f, i| {
            let (cx, cy) = layout.coords(i);
            let p = f.fit_with(level, &layout, cx, cy, tol, FitOptions::default());
            let o = f.fit_with(level, &layout, cx, cy, tol, FitOptions { outline: true });
            let (p, o) = (p.stats.lods[0], o.stats.lods[0]);
            // The chunk's raggedness: the share of its dual samples on the
            // outline, in percent (a cheap statistic to choose by).
            let s = f.samples();
            let (mut dual, mut edge) = (0u64, 0u64);
            for y in 0..=s.size_y as i32 {
                for x in 0..=s.size_x as i32 {
                    let k = class(s, x, y);
                    dual += u64::from(k >= 2);
                    edge += u64::from(k == 2);
                }
            }
            let ragged = (100 * edge).checked_div(dual).unwrap_or(0);
            if o.emitted() < p.emitted() {
                let planar = u64::from(o.planar + o.slab / 2);
                [planar, u64::from(o.emitted()), 1, ragged, dual]
            } else {
                [u64::from(p.planar), u64::from(p.emitted()), 0, ragged, dual]
            }
        })
        .collect();
    let mut t = [0u64; 5];
    for c in &per {
        for k in 0..3 {
            t[k] += c[k];
        }
    }
    // How well "outline where at least R % of the dual samples are on the
    // outline" reproduces the choice, for chunks with a slab.
    for r in [50, 60, 70, 80, 90] {
        let agree = per
            .iter()
            .filter(|c| c[4] > 0)
            .filter(|c| (c[3] >= r) == (c[2] == 1))
            .count();
        let with = per.iter().filter(|c| c[4] > 0).count();
        println!("  rule ragged >= {r} %: agrees in {agree} of {with} chunks with a slab");
    }
    println!("== best of both per chunk (tol {tol})");
    println!(
        "  LOD 0: planar {:>10}  drawn {:>10}; outline chosen in {} of {} chunks",
        t[0],
        t[1],
        t[2],
        layout.count()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let tol: f64 = args
        .iter()
        .skip(1)
        .filter_map(|a| a.strip_prefix("tol=").and_then(|t| t.parse().ok()))
        .next()
        .unwrap_or(4.0);
    let args: Vec<String> = args
        .into_iter()
        .filter(|a| !a.starts_with("tol="))
        .collect();
    let t = std::time::Instant::now();
    let level = load(&args);
    println!(
        "level {}x{} ready in {:.1} s",
        level.width(),
        level.height(),
        t.elapsed().as_secs_f64()
    );
    outline(&level);
    let only = std::env::var("CENSUS_ONLY").unwrap_or_default();
    if only == "probe" {
        // Lines `TAG X Y ...` on stdin: count TAGs by the column's class
        // (chunk-local 8-neighbourhood as in `class`).
        use std::io::BufRead;
        let layout = ChunkLayout::of(&level);
        let mut s = ChunkSamples::default();
        let mut counts = std::collections::BTreeMap::<(String, usize), u64>::new();
        for line in std::io::stdin().lock().lines().map_while(Result::ok) {
            let f: Vec<&str> = line.split_whitespace().collect();
            let (Some(tag), Some(x), Some(y)) = (f.first(), f.get(1), f.get(2)) else {
                continue;
            };
            let (Ok(x), Ok(y)) = (x.parse::<u32>(), y.parse::<u32>()) else {
                continue;
            };
            let (cx, cy) = (x / layout.size_x, y / layout.size_y);
            s.load(&level, &layout, cx, cy);
            let k = class(&s, (x % layout.size_x) as i32, (y % layout.size_y) as i32);
            *counts.entry((tag.to_string(), k)).or_default() += 1;
        }
        println!("(tag, class 0 single 1 single-outline 2 dual-outline 3 dual): {counts:?}");
        return;
    }
    if only.is_empty() || only == "plain" {
        census(&level, tol, FitOptions::default(), "plain");
    }
    if only.is_empty() || only == "outline" {
        census(&level, tol, FitOptions { outline: true }, "outline");
    }
    if only.is_empty() || only == "best" {
        best_of_both(&level, tol);
    }
    if only.is_empty() || only == "floor" {
        // The floor alone: every dual pair made single at its `low`.
        let mut floor = level.clone();
        let (heights, metas) = floor.planes_mut();
        for i in (0..heights.len()).step_by(2) {
            if strata_level::model::pair_is_dual(metas[i], metas[i + 1]) {
                heights[i + 1] = heights[i];
                metas[i] &= !strata_level::model::META_DOUBLE_LEVEL;
                metas[i + 1] &= !strata_level::model::META_DOUBLE_LEVEL;
            }
        }
        census(
            &floor,
            tol,
            FitOptions::default(),
            "floor alone (low of every column, plain fit)",
        );
    }
}
