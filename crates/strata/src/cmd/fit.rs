//! `strata fit`: fit the TIN mesh (issue 7) and report its size, where the
//! vertex budget went, fit time and retained memory.

use anyhow::{Context, bail};
use serde::Serialize;
use strata_export::Region;
use strata_level::Level;
use strata_mesh::region::{cell_chunk, fit_stats_from, layout_for, region_cells};
use strata_mesh::synthetic::synthetic_level;
use strata_mesh::{FitOptions, LODS, MeshStats, fit_on_threads_with, tolerance_for_quality};
use strata_store::fs::{DirKind, dir_kind};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    world: crate::world_arg::WorldArgs,
    /// Mesh quality q in [0, 1]: max vertical error 2^(4(1-q)) height units.
    #[arg(long, value_name = "Q", default_value_t = 0.5)]
    quality: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Fit a synthetic WxH level (terraces, cliffs, ~10% slabs) instead of a world.
    #[arg(long, value_name = "WxH")]
    synthetic: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Constrain the triangulation to the single/double region outline (issue 17).
    #[arg(long)]
    outline: bool,
    /// Fit only the chunks under texels X0,Y0,X1,Y1 (half-open; X1/Y1 may pass the map edge, it wraps). A store is read through its chunk cache either way (bounded memory).
    #[arg(long, value_name = "X0,Y0,X1,Y1", conflicts_with = "synthetic")]
    region: Option<String>,
}

#[derive(Serialize)]
struct LodReport {
    max_error: f64,
    /// Planar triangles of the floor.
    triangles: u64,
    /// Distinct planar triangles drawn: the floor's, plus the slab tops' in
    /// the outline fit (where the slab has a triangulation of its own; in
    /// the plain fit a slab top lies on a floor triangle).
    footprint_triangles: u64,
    slab_triangles: u64,
    wall_triangles: u64,
    /// Everything drawn for this LOD.
    emitted_triangles: u64,
}

#[derive(Serialize)]
struct Causes {
    floor: u64,
    slab_interior: u64,
    single_double_boundary: u64,
    chunk_border: u64,
    /// Shares of all insertions, in percent, same order.
    shares_percent: [f64; 4],
}

#[derive(Serialize)]
struct Report {
    world: String,
    width: u32,
    height: u32,
    /// The texels fitted, `X0,Y0,X1,Y1`, when not the whole map.
    #[serde(skip_serializing_if = "Option::is_none")]
    region: Option<String>,
    /// A store's chunk cache after the fit (absent for a world in memory).
    #[serde(skip_serializing_if = "Option::is_none")]
    store_cache: Option<strata_store::CacheStats>,
    quality: f64,
    max_error: f64,
    /// The outline-constrained fit.
    outline: bool,
    chunks: usize,
    threads: usize,
    /// Sum over chunks of finest-LOD vertices (shared border vertices in both chunks).
    vertices: u64,
    /// Finest-LOD planar triangles of the floor.
    triangles: u64,
    /// Finest-LOD distinct planar triangles drawn (floor, and the outline
    /// fit's slab tops); the honest count to compare the two fits by, with
    /// `lods[0].emitted_triangles`.
    footprint_triangles: u64,
    /// 2 triangles per texel.
    full_grid_triangles: u64,
    reduction: f64,
    lods: Vec<LodReport>,
    insertions: Causes,
    fit_seconds: f64,
    /// CPU time of all threads during the fit (the machine may be shared).
    fit_cpu_seconds: Option<f64>,
    /// Finest triangles per wall second, divided by the threads.
    triangles_per_second_per_core: f64,
    /// Finest triangles per CPU second (robust on a shared machine).
    triangles_per_cpu_second: Option<f64>,
    gpu_bytes: u64,
    cpu_bytes: u64,
    gpu_bytes_per_triangle: f64,
    cpu_bytes_per_triangle: f64,
}

fn load(args: &Args) -> anyhow::Result<(String, Level)> {
    if let Some(spec) = &args.synthetic {
        let (w, h) = spec
            .split_once('x')
            .and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)))
            .context("--synthetic wants WxH, e.g. 2048x16384")?;
        if !w.is_power_of_two()
            || !h.is_power_of_two()
            || !(2..=1 << 15).contains(&w)
            || h > 1 << 15
        {
            bail!("--synthetic {w}x{h}: sides must be powers of two, 2..=32768");
        }
        return Ok((format!("synthetic-{w}x{h}"), synthetic_level(w, h, 1)));
    }
    let world = args.world.load()?;
    Ok((world.name, world.level))
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let Some(tolerance) = tolerance_for_quality(args.quality) else {
        bail!("--quality {} is outside [0, 1]", args.quality);
    };
    let options = FitOptions {
        outline: args.outline,
    };
    // A store, or any world with --region: the chunks under the region,
    // read through the source (a store's chunk cache: bounded memory),
    // keeping only the totals.
    let store = args.synthetic.is_none()
        && args
            .world
            .level
            .as_deref()
            .is_some_and(|d| matches!(dir_kind(d), Ok(DirKind::Store)));
    if store || args.region.is_some() {
        return run_region(&args, tolerance, options);
    }
    let (name, level) = load(&args)?;
    let (mesh, timing) = fit_on_threads_with(&level, tolerance, args.threads.unwrap_or(0), options)
        .context("starting the worker threads")?;
    let (seconds, cpu, threads) = (timing.wall_seconds, timing.cpu_seconds, timing.threads);
    let report = report(
        &name,
        (level.width(), level.height()),
        args.quality,
        &mesh.stats(),
        (seconds, cpu, threads),
        args.outline,
    );
    print(&report, args.json)
}

fn print(report: &Report, json: bool) -> anyhow::Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        print_text(report);
    }
    Ok(())
}

/// Chunks fitted per batch in a region fit: only their totals are kept.
const REGION_BATCH: usize = 256;

fn run_region(args: &Args, tolerance: f64, options: FitOptions) -> anyhow::Result<()> {
    let opened = args.world.open()?;
    let source = opened.source();
    let (w, h) = source.size();
    let region = match &args.region {
        Some(text) => Region::parse_in(text, w, h)?,
        None => Region::whole_of(w, h),
    };
    let layout = layout_for(w, h);
    let mut ids: Vec<usize> = region_cells(&layout, region.x0, region.y0, region.x1, region.y1)
        .into_iter()
        .map(|(gx, gy)| cell_chunk(&layout, gx, gy))
        .collect();
    // Row-major: neighbouring fits share the store's chunks in the cache.
    ids.sort_unstable();
    ids.dedup();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("starting the worker threads")?;
    pool.broadcast(|_| ());
    let (stats, seconds, cpu, threads) = pool.install(|| {
        let cpu0 = strata_mesh::cpu_time::process_cpu_seconds();
        let start = std::time::Instant::now();
        let stats = fit_stats_from(source, &layout, &ids, tolerance, options, REGION_BATCH);
        let seconds = start.elapsed().as_secs_f64();
        let cpu = strata_mesh::cpu_time::process_cpu_seconds()
            .zip(cpu0)
            .map(|(b, a)| b - a);
        (stats, seconds, cpu, rayon::current_num_threads())
    });
    let stats = stats.context("reading the map")?;
    let mut report = report(
        &opened.world().name,
        (w, h),
        args.quality,
        &stats,
        (seconds, cpu, threads),
        args.outline,
    );
    report.full_grid_triangles =
        2 * stats.chunks as u64 * u64::from(layout.size_x) * u64::from(layout.size_y);
    let tris = report.footprint_triangles;
    report.reduction = if tris == 0 {
        0.0
    } else {
        report.full_grid_triangles as f64 / tris as f64
    };
    report.region = args.region.clone();
    report.store_cache = opened.cache().map(|c| c.stats());
    print(&report, args.json)?;
    if let (Some(c), false) = (opened.cache(), args.json) {
        let st = c.stats();
        println!(
            "store cache: {} hits, {} misses ({:.1} % hit), {} evictions, peak {:.1} of {} MiB",
            st.hits,
            st.misses,
            st.hit_rate(),
            st.evictions,
            st.peak_bytes as f64 / f64::from(1u32 << 20),
            c.budget() >> 20
        );
    }
    Ok(())
}

fn report(
    name: &str,
    (width, height): (u32, u32),
    quality: f64,
    s: &MeshStats,
    (seconds, cpu, threads): (f64, Option<f64>, usize),
    outline: bool,
) -> Report {
    let footprints = |k: usize| s.lods[k].planar + if outline { s.lods[k].slab / 2 } else { 0 };
    let full = 2 * u64::from(width) * u64::from(height);
    // Reduction and rates count every planar triangle drawn.
    let tris = footprints(0);
    let total: u64 = s.causes.iter().sum();
    let share = |n: u64| {
        if total == 0 {
            0.0
        } else {
            100.0 * n as f64 / total as f64
        }
    };
    let per_tri = |b: u64| {
        if tris == 0 {
            0.0
        } else {
            b as f64 / tris as f64
        }
    };
    Report {
        world: name.to_string(),
        width,
        height,
        region: None,
        store_cache: None,
        quality,
        max_error: s.tolerance,
        outline,
        chunks: s.chunks,
        threads,
        vertices: s.planar_vertices,
        triangles: s.lods[0].planar,
        footprint_triangles: tris,
        full_grid_triangles: full,
        reduction: if tris == 0 {
            0.0
        } else {
            full as f64 / tris as f64
        },
        lods: (0..LODS)
            .map(|k| LodReport {
                max_error: s.tolerance * f64::from(1u32 << k),
                triangles: s.lods[k].planar,
                footprint_triangles: footprints(k),
                slab_triangles: s.lods[k].slab,
                wall_triangles: s.lods[k].wall,
                emitted_triangles: s.lods[k].emitted,
            })
            .collect(),
        insertions: Causes {
            floor: s.causes[0],
            slab_interior: s.causes[1],
            single_double_boundary: s.causes[2],
            chunk_border: s.causes[3],
            shares_percent: s.causes.map(share),
        },
        fit_seconds: seconds,
        fit_cpu_seconds: cpu,
        triangles_per_second_per_core: tris as f64 / seconds.max(1e-9) / threads.max(1) as f64,
        triangles_per_cpu_second: cpu.map(|c| tris as f64 / c.max(1e-9)),
        gpu_bytes: s.gpu_bytes,
        cpu_bytes: s.cpu_bytes,
        gpu_bytes_per_triangle: per_tri(s.gpu_bytes),
        cpu_bytes_per_triangle: per_tri(s.cpu_bytes),
    }
}

fn print_text(r: &Report) {
    let mib = |b: u64| b as f64 / (1024.0 * 1024.0);
    println!(
        "{} ({}x{}{}), q={} (max error {}){}, {} chunks",
        r.world,
        r.width,
        r.height,
        r.region
            .as_ref()
            .map_or(String::new(), |t| format!(", region {t}")),
        r.quality,
        r.max_error,
        if r.outline {
            ", outline-constrained"
        } else {
            ""
        },
        r.chunks
    );
    println!(
        "finest LOD: {} vertices, {} floor triangles ({} planar with the slab tops'); full grid {} -> reduction {:.1}x",
        r.vertices, r.triangles, r.footprint_triangles, r.full_grid_triangles, r.reduction
    );
    for (k, l) in r.lods.iter().enumerate() {
        println!(
            "  LOD {k} (max error {:>4}): {:>10} floor triangles, {:>10} planar, drawn {:>10} (slab {}, walls {})",
            l.max_error,
            l.triangles,
            l.footprint_triangles,
            l.emitted_triangles,
            l.slab_triangles,
            l.wall_triangles
        );
    }
    let c = &r.insertions;
    let s = c.shares_percent;
    println!(
        "insertions: floor {} ({:.1}%), slab interior {} ({:.1}%), single/double boundary {} ({:.1}%), chunk border {} ({:.1}%)",
        c.floor, s[0], c.slab_interior, s[1], c.single_double_boundary, s[2], c.chunk_border, s[3]
    );
    let cpu = match (r.fit_cpu_seconds, r.triangles_per_cpu_second) {
        (Some(c), Some(t)) => format!("CPU {c:.2} s, {t:.0} triangles per CPU second"),
        _ => String::from("CPU n/a"),
    };
    println!(
        "fit: {:.2} s wall on {} threads ({:.0} triangles/s per core; {cpu})",
        r.fit_seconds, r.threads, r.triangles_per_second_per_core
    );
    println!(
        "retained: GPU {:.1} MiB ({:.1} B/triangle, all LODs), CPU {:.2} MiB ({:.2} B/triangle)",
        mib(r.gpu_bytes),
        r.gpu_bytes_per_triangle,
        mib(r.cpu_bytes),
        r.cpu_bytes_per_triangle
    );
}
