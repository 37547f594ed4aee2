//! `strata collide`: build the terrain collider (issues 18, 35) and report
//! its build time and memory, the refit after the world's crater and after
//! frames of small gameplay edits, ray-cast throughput against the CPU
//! reference tracer (one thread each), and how often the two agree (same
//! column, same distance) on the same rays and on grazing rays.

use anyhow::{Context, bail};
use serde::Serialize;
use strata_collide::TerrainCollider;
use strata_level::{EditSite, Level};
use strata_reference::{ReferenceSettings, Tracer};
use web_time::Instant;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    world: crate::world_arg::WorldArgs,
    /// Rays cast by each tracer for the throughput numbers (and as many
    /// grazing rays for the agreement).
    #[arg(long, value_name = "N", default_value_t = 20_000)]
    rays: usize,
    /// Small edits per frame for the gameplay refit numbers (tracks of
    /// radius 2..6 texels).
    #[arg(long, value_name = "K", default_value_t = 64)]
    edits: usize,
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
    /// With --physics-bench: spacing of the terrain surface's samples in
    /// the physics world (1: every texel centre, exact; 2, 4: cheaper).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1,
        requires = "physics_bench",
        value_parser = clap::value_parser!(u32).range(1..=128)
    )]
    surface_step: u32,
}

#[derive(Serialize)]
struct Report {
    world: String,
    width: u32,
    height: u32,
    /// Building the collider: decode every column, build the pyramid (all cores).
    build_seconds: f64,
    threads: usize,
    memory_bytes: usize,
    memory_mib: f64,
    memory_bytes_per_texel: f64,
    crater_chunks: usize,
    /// The collider's update after the world's crater (one thread).
    crater_refit_ms: f64,
    /// Small edits per frame.
    edits_per_frame: usize,
    /// Frames of edits timed.
    edit_frames: usize,
    /// The collider's update for one frame's edits (one thread; the level
    /// edits themselves not counted): median, 99th percentile and worst frame.
    edit_frame_refit_ms_median: f64,
    edit_frame_refit_ms_p99: f64,
    edit_frame_refit_ms_max: f64,
    rays: usize,
    /// One thread each, the same rays (down from 300, 15..75 degrees below
    /// the horizon, as a camera sees the ground); the best of 5 interleaved
    /// rounds each.
    collider_rays_per_second: f64,
    reference_rays_per_second: f64,
    /// Rays that hit in both.
    hits_both: usize,
    /// Rays where both agree: both miss, or both hit the same column at the
    /// same distance (within 1e-9 relative).
    agree_percent: f64,
    /// Grazing rays (within 3 degrees of horizontal, from just above a
    /// column's top): how many, and the agreement.
    grazing_rays: usize,
    grazing_agree_percent: f64,
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

/// Timed rounds of the ray casts (the fastest counts).
const ROUNDS: usize = 5;

/// Same column (wrapped) and distance, or both none.
fn agree(
    level: &Level,
    a: Option<strata_collide::RayHit>,
    b: Option<strata_reference::RayHit>,
) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            (a.distance - b.distance).abs() <= 1e-9 * b.distance.max(1.0)
                && level.wrap(a.column[0], a.column[1]) == level.wrap(b.column[0], b.column[1])
        }
        _ => false,
    }
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.rays == 0 {
        bail!("--rays 0: cast at least one ray");
    }
    let world = args.world.load()?;
    let mut level = world.level;
    let t = Instant::now();
    let mut collider = TerrainCollider::new(&level);
    let build_seconds = t.elapsed().as_secs_f64();
    if args.physics_bench {
        if args.bodies.contains(&0) {
            bail!("--bodies {:?}: each count must be at least 1", args.bodies);
        }
        let site = world.edit.clone().unwrap_or_else(EditSite::fostral);
        let report = crate::cmd::physics_bench::run(
            &mut level,
            collider,
            &site,
            &args.bodies,
            args.surface_step,
        )?;
        if args.json {
            println!(
                "{}",
                serde_json::to_string_pretty(&report).context("writing the report")?
            );
        } else {
            println!(
                "{} ({}x{}), collider {build_seconds:.3} s",
                world.name,
                level.width(),
                level.height(),
            );
            crate::cmd::physics_bench::print(&report);
        }
        return Ok(());
    }
    let stats = collider.stats();
    let threads = rayon::current_num_threads();

    // Throughput: the same rays through both, on this thread.
    let mut rng = Rng(1);
    let top = 300.0;
    let (w, h) = (f64::from(level.width()), f64::from(level.height()));
    let rays: Vec<([f64; 3], [f64; 3])> = (0..args.rays)
        .map(|_| {
            let o = [rng.next() * w, rng.next() * h, top];
            let az = rng.next() * std::f64::consts::TAU;
            let el = (15.0 + rng.next() * 60.0).to_radians();
            let d = [el.cos() * az.cos(), el.cos() * az.sin(), -el.sin()];
            (o, d)
        })
        .collect();
    // Interleaved rounds, the best of each kept: on a busy machine a
    // round can lose its core for a while.
    let tracer = Tracer::new(&level);
    let settings = ReferenceSettings::default();
    let (mut collider_seconds, mut reference_seconds) = (f64::INFINITY, f64::INFINITY);
    let mut ours = Vec::new();
    let mut theirs = Vec::new();
    for _ in 0..ROUNDS {
        let t = Instant::now();
        ours = rays
            .iter()
            .map(|(o, d)| collider.cast_ray(*o, *d, 4000.0))
            .collect();
        collider_seconds = collider_seconds.min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        theirs = rays
            .iter()
            .map(|(o, d)| tracer.trace((*o).into(), (*d).into(), 4000.0, &settings))
            .collect::<Vec<_>>();
        reference_seconds = reference_seconds.min(t.elapsed().as_secs_f64());
    }
    let hits_both = ours
        .iter()
        .zip(&theirs)
        .filter(|(a, b)| a.is_some() && b.is_some())
        .count();
    let agreeing = ours
        .iter()
        .zip(&theirs)
        .filter(|(a, b)| agree(&level, **a, **b))
        .count();
    // Grazing rays: from a hair, half a unit or one unit above a column's
    // top, within 3 degrees of horizontal (a third exactly horizontal).
    let grazing: Vec<([f64; 3], [f64; 3])> = (0..args.rays)
        .map(|k| {
            let (x, y) = (rng.next() * w, rng.next() * h);
            let c = level.column(x.floor() as i64, y.floor() as i64);
            let z = f64::from(c.top()) + [1e-6, 0.5, 1.0][k % 3];
            let az = rng.next() * std::f64::consts::TAU;
            let el = [0.0, -0.05, 0.05][(k / 3) % 3] * rng.next();
            (
                [x, y, z],
                [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()],
            )
        })
        .collect();
    let grazing_agreeing = grazing
        .iter()
        .filter(|(o, d)| {
            let a = collider.cast_ray(*o, *d, 4000.0);
            let b = tracer.trace((*o).into(), (*d).into(), 4000.0, &settings);
            agree(&level, a, b)
        })
        .count();
    drop(tracer);

    let site = world.edit.clone().unwrap_or_else(EditSite::fostral);
    let dirty = strata_level::edit::crater(&mut level, &site);
    let t = Instant::now();
    let crater_chunks = collider.apply_edit(&level, &dirty).len();
    let crater_refit_ms = t.elapsed().as_secs_f64() * 1e3;

    // Frames of small edits along a path: tracks of radius 2..6 a few
    // texels apart, shallow, as vehicles leave them.
    let frames = 600;
    let mut frame_ms = Vec::with_capacity(frames);
    let mut track = EditSite::fostral();
    let (mut px, mut py) = (site.centre_x as f64, site.centre_y as f64);
    for _ in 0..frames {
        let mut dirty = Vec::new();
        for k in 0..args.edits {
            px += (rng.next() - 0.5) * 8.0;
            py += 3.0 + rng.next() * 2.0;
            track.centre_x = px as i64;
            track.centre_y = py as i64;
            track.radius = 2 + (k % 5) as u32;
            track.depth = 1.0 + rng.next() as f32 * 2.0;
            dirty.extend(strata_level::edit::crater(&mut level, &track));
        }
        let t = Instant::now();
        collider.apply_edit(&level, &dirty);
        frame_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    frame_ms.sort_by(f64::total_cmp);

    let n = args.rays as f64;
    let texels = f64::from(level.width()) * f64::from(level.height());
    let report = Report {
        world: world.name,
        width: level.width(),
        height: level.height(),
        build_seconds,
        threads,
        memory_bytes: stats.memory_bytes,
        memory_mib: stats.memory_bytes as f64 / f64::from(1 << 20),
        memory_bytes_per_texel: stats.memory_bytes as f64 / texels,
        crater_chunks,
        crater_refit_ms,
        edits_per_frame: args.edits,
        edit_frames: frames,
        edit_frame_refit_ms_median: frame_ms[frames / 2],
        edit_frame_refit_ms_p99: frame_ms[frames * 99 / 100],
        edit_frame_refit_ms_max: frame_ms[frames - 1],
        rays: args.rays,
        collider_rays_per_second: n / collider_seconds,
        reference_rays_per_second: n / reference_seconds,
        hits_both,
        agree_percent: agreeing as f64 * 100.0 / n,
        grazing_rays: grazing.len(),
        grazing_agree_percent: grazing_agreeing as f64 * 100.0 / grazing.len() as f64,
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).context("writing the report")?
        );
        return Ok(());
    }
    let r = &report;
    println!("{} ({}x{})", r.world, r.width, r.height);
    println!(
        "collider: built in {:.3} s on {} threads; {:.1} MiB ({:.2} B per texel)",
        r.build_seconds, r.threads, r.memory_mib, r.memory_bytes_per_texel
    );
    println!(
        "crater refit: {} chunks in {:.3} ms; {} small edits a frame: {:.3} ms median, {:.3} ms p99, {:.3} ms worst of {} frames",
        r.crater_chunks,
        r.crater_refit_ms,
        r.edits_per_frame,
        r.edit_frame_refit_ms_median,
        r.edit_frame_refit_ms_p99,
        r.edit_frame_refit_ms_max,
        r.edit_frames
    );
    println!(
        "ray casts, one thread: collider {:.0} rays/s, CPU reference {:.0} rays/s ({} rays, {} hit in both)",
        r.collider_rays_per_second, r.reference_rays_per_second, r.rays, r.hits_both
    );
    println!(
        "agreement with the reference: {:.3} % of those rays, {:.3} % of {} grazing rays",
        r.agree_percent, r.grazing_agree_percent, r.grazing_rays
    );
    Ok(())
}
