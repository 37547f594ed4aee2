//! `strata collide`: build the terrain collider (issue 18) and report its
//! build time and memory, the refit after the world's crater, and ray-cast
//! throughput against the CPU reference tracer, one thread each.

use anyhow::{Context, bail};
use serde::Serialize;
use strata_collide::TerrainCollider;
use strata_level::EditSite;
use strata_mesh::{LevelMesh, tolerance_for_quality};
use strata_reference::{ReferenceSettings, Tracer};
use web_time::Instant;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    world: crate::world_arg::WorldArgs,
    /// Mesh quality q in [0, 1] (max vertical error 2^(4(1-q))).
    #[arg(long, value_name = "Q", default_value_t = 0.5)]
    quality: f64,
    /// Rays cast by each tracer for the throughput numbers.
    #[arg(long, value_name = "N", default_value_t = 20_000)]
    rays: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Instead of the ray-cast numbers: rigid bodies (rapier3d) on the
    /// collider, step time with each body count, then the crater dug under
    /// them (its collider swap inside the physics world).
    #[arg(long)]
    physics_bench: bool,
    /// With --physics-bench: the body counts, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "100,1000",
        requires = "physics_bench"
    )]
    bodies: Vec<usize>,
}

#[derive(Serialize)]
struct Report {
    world: String,
    width: u32,
    height: u32,
    quality: f64,
    max_error: f64,
    chunks: usize,
    triangles: usize,
    fit_seconds: f64,
    /// Building every chunk's parry3d mesh from the fit (all cores).
    build_seconds: f64,
    threads: usize,
    build_ms_per_chunk_per_core: f64,
    memory_bytes: usize,
    memory_bytes_per_chunk: f64,
    memory_bytes_per_triangle: f64,
    crater_chunks: usize,
    /// Refit + rebuild of the crater's chunks (all cores).
    crater_refit_ms: f64,
    rays: usize,
    /// One thread each, the same rays (down from 40 units above the top,
    /// 15..75 degrees below the horizon, as a camera sees the ground).
    collider_rays_per_second: f64,
    reference_rays_per_second: f64,
    /// Rays that hit in both.
    hits_both: usize,
}

/// A small deterministic generator (no dependency for a few numbers).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let Some(tolerance) = tolerance_for_quality(args.quality) else {
        bail!("--quality {} is outside [0, 1]", args.quality);
    };
    if args.rays == 0 {
        bail!("--rays 0: cast at least one ray");
    }
    let world = args.world.load()?;
    let mut level = world.level;
    let t = Instant::now();
    let mesh = LevelMesh::fit(&level, tolerance);
    let fit_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut collider = TerrainCollider::from_mesh(&level, &mesh);
    let build_seconds = t.elapsed().as_secs_f64();
    drop(mesh);
    if args.physics_bench {
        if args.bodies.contains(&0) {
            bail!("--bodies {:?}: each count must be at least 1", args.bodies);
        }
        let site = world.edit.clone().unwrap_or_else(EditSite::fostral);
        let report = crate::cmd::physics_bench::run(&mut level, collider, &site, &args.bodies)?;
        if args.json {
            println!(
                "{}",
                serde_json::to_string_pretty(&report).context("writing the report")?
            );
        } else {
            println!(
                "{} ({}x{}), q={} (max error {tolerance}), fit {fit_seconds:.2} s, collider {build_seconds:.2} s",
                world.name,
                level.width(),
                level.height(),
                args.quality
            );
            crate::cmd::physics_bench::print(&report);
        }
        return Ok(());
    }
    let stats = collider.stats();
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());

    // Throughput: the same rays through both, on this thread.
    let mut rng = Rng(1);
    let top = 300.0;
    let rays: Vec<([f64; 3], [f64; 3])> = (0..args.rays)
        .map(|_| {
            let o = [
                rng.next() * f64::from(level.width()),
                rng.next() * f64::from(level.height()),
                top,
            ];
            let az = rng.next() * std::f64::consts::TAU;
            let el = (15.0 + rng.next() * 60.0).to_radians();
            let d = [el.cos() * az.cos(), el.cos() * az.sin(), -el.sin()];
            (o, d)
        })
        .collect();
    let t = Instant::now();
    let ours: Vec<bool> = rays
        .iter()
        .map(|(o, d)| collider.cast_ray(*o, *d, 4000.0).is_some())
        .collect();
    let collider_seconds = t.elapsed().as_secs_f64();
    let tracer = Tracer::new(&level);
    let settings = ReferenceSettings::default();
    let t = Instant::now();
    let theirs: Vec<bool> = rays
        .iter()
        .map(|(o, d)| {
            tracer
                .trace((*o).into(), (*d).into(), 4000.0, &settings)
                .is_some()
        })
        .collect();
    let reference_seconds = t.elapsed().as_secs_f64();
    drop(tracer);
    let hits_both = ours.iter().zip(&theirs).filter(|(a, b)| **a && **b).count();

    let site = world.edit.clone().unwrap_or_else(EditSite::fostral);
    let dirty = strata_level::edit::crater(&mut level, &site);
    let t = Instant::now();
    let crater_chunks = collider.apply_edit(&level, &dirty).len();
    let crater_refit_ms = t.elapsed().as_secs_f64() * 1e3;

    let n = args.rays as f64;
    let report = Report {
        world: world.name,
        width: level.width(),
        height: level.height(),
        quality: args.quality,
        max_error: tolerance,
        chunks: stats.chunks,
        triangles: stats.triangles,
        fit_seconds,
        build_seconds,
        threads,
        build_ms_per_chunk_per_core: build_seconds * 1e3 * threads as f64 / stats.chunks as f64,
        memory_bytes: stats.memory_bytes,
        memory_bytes_per_chunk: stats.memory_bytes as f64 / stats.chunks as f64,
        memory_bytes_per_triangle: stats.memory_bytes as f64 / stats.triangles.max(1) as f64,
        crater_chunks,
        crater_refit_ms,
        rays: args.rays,
        collider_rays_per_second: n / collider_seconds,
        reference_rays_per_second: n / reference_seconds,
        hits_both,
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).context("writing the report")?
        );
        return Ok(());
    }
    let r = &report;
    println!(
        "{} ({}x{}), q={} (max error {})",
        r.world, r.width, r.height, r.quality, r.max_error
    );
    println!("collider: {} chunks, {} triangles", r.chunks, r.triangles);
    println!(
        "  build {:.2} s on {} threads ({:.2} ms per chunk per core), after a {:.2} s fit",
        r.build_seconds, r.threads, r.build_ms_per_chunk_per_core, r.fit_seconds
    );
    println!(
        "  memory {:.1} MiB ({:.0} KiB per chunk, {:.1} B per triangle)",
        r.memory_bytes as f64 / (1 << 20) as f64,
        r.memory_bytes_per_chunk / 1024.0,
        r.memory_bytes_per_triangle
    );
    println!(
        "crater refit: {} chunks in {:.1} ms",
        r.crater_chunks, r.crater_refit_ms
    );
    println!(
        "ray casts, one thread: collider {:.0} rays/s, CPU reference {:.0} rays/s ({} rays, {} hit in both)",
        r.collider_rays_per_second, r.reference_rays_per_second, r.rays, r.hits_both
    );
    Ok(())
}
