//! `strata exact-counts`: `ray-exact`'s frame on paper (issue 36, item 1).
//! A CPU replay of the GPU traversal, step for step
//! (`strata_render::methods::ray_exact::replay`), over every view: per pass
//! (the camera march, the shadow casts of the blocks the hits sample, the
//! shading) the traversal iterations, pyramid words and terrain texels read
//! per ray (mean, 99th percentile, most), and the bytes the frame reads and
//! writes, all requests and the distinct bytes of terrain and pyramid. Set
//! against a GPU's texture and memory rates, they bound each pass's time.

use anyhow::{Context, bail};
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;
use strata_level::{ViewSpec, views::parse_views};
use strata_render::frame::{Globals, LevelShape};
use strata_render::methods::ray_exact::replay::{
    BeamSearch, FrameCount, PassCount, Replay, Traversal, beam_disagreements, compute_pyramid,
    replay_frame,
};
use strata_render::options::TexelWalk;

fn parse_search(s: &str) -> Result<BeamSearch, String> {
    match s {
        "serial" => Ok(BeamSearch::Serial),
        "wide" => Ok(BeamSearch::Wide),
        "wide-pass" => Ok(BeamSearch::WidePass),
        _ => Err(format!(
            "`{s}`: the beam search is `serial`, `wide` or `wide-pass`"
        )),
    }
}

fn parse_texel_walk(s: &str) -> Result<TexelWalk, String> {
    match s {
        "off" => Ok(TexelWalk::Terrain),
        "plane" => Ok(TexelWalk::Plane),
        "beside" => Ok(TexelWalk::PlaneBeside),
        _ => Err(format!(
            "`{s}`: the texel walk is `off`, `plane` or `beside`"
        )),
    }
}

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    world: crate::world_arg::WorldArgs,
    /// Every view of a views file (`NAME X,Y:YAW:EYE[:under] PITCH` per
    /// line); without it the world's own views (the protocol's twelve).
    #[arg(long, value_name = "FILE")]
    views: Option<PathBuf>,
    /// Image size in pixels.
    #[arg(long, default_value = "1280x800", value_parser = super::reference::parse_image_size)]
    size: (u32, u32),
    /// Shadows off: no shadow pass, no shadow taps.
    #[arg(long)]
    no_shadows: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Try another traversal on paper: most levels climbed per step
    /// (`EXACT_CLIMB`; the GPU's: 1).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=8))]
    climb: u32,
    /// Try another traversal on paper: the visited level rays start at (0
    /// texels, 1 .. 4 tiles of 4, 16, 64, 256 texels; the GPU's: 3).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=4))]
    start_level: Option<u32>,
    /// Try another traversal on paper: no beam pre-pass (camera rays start
    /// at the near plane, as `ray-exact` with `STRATA_EXACT_BEAM=off`).
    #[arg(long)]
    no_beam: bool,
    /// How the beams are searched: `serial` (a pre-pass, one invocation per
    /// tile) or `wide` (the tile's 64 invocations at once, in the march;
    /// `wide-pass`: the same in a pre-pass, the same counts);
    /// the GPU's default is `wide` (`STRATA_EXACT_BEAM` picks it there).
    #[arg(long, value_parser = parse_search)]
    search: Option<BeamSearch>,
    /// Most rounds of the shadow blocks' wide search (1 to 8; the GPU's
    /// default 8, `STRATA_EXACT_SHADOW_ROUNDS` there).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=8))]
    shadow_rounds: Option<u32>,
    /// Try another traversal on paper: a descent into the texels tests the
    /// texel in its own iteration (as `STRATA_EXACT_FUSED_DESCENT=on`; the
    /// GPU's default walks the descent as an iteration of its own, which the
    /// H100 runs faster).
    #[arg(long)]
    fused_descent: bool,
    /// Try another traversal on paper: no tile skipped between its floors
    /// and slabs (as `STRATA_EXACT_CAVE_SKIP=off`; the GPU's default skips
    /// them by the cave pyramid).
    #[arg(long)]
    no_cave_skip: bool,
    /// Try another beam on paper: its finest test on the pyramid's 4-texel
    /// tiles (as `STRATA_EXACT_BEAM_TEXELS=off`; the GPU's default tests a
    /// box no wider than a texel against the texels that hold it).
    #[arg(long)]
    no_beam_texels: bool,
    /// Try another traversal on paper: a 4x4 tile's texels walked from the
    /// texel plane, its words loaded on the way down (`plane`) or beside
    /// the tile's maximum (`beside`), as `STRATA_EXACT_TEXEL_BLOCKS`: only
    /// columns with a slab wait on a terrain fetch ("waits" counts the
    /// fetches each ray's steps wait on). Default `off`: a terrain fetch per
    /// texel.
    #[arg(long, value_parser = parse_texel_walk, default_value = "off")]
    texel_walk: TexelWalk,
    /// Try another traversal on paper: the visited level camera rays start
    /// at from their tile's beam (the GPU's: 1, tiles of 4 texels).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=4))]
    beam_level: Option<u32>,
    /// Also check the beam on every pixel: its ray marched from the near
    /// plane and from its tile's beam finds the same hit (t to the bit and
    /// the column), never before the beam; fails otherwise.
    #[arg(long)]
    verify_beam: bool,
}

#[derive(Serialize)]
struct ViewCount {
    view: String,
    pitch: f32,
    #[serde(flatten)]
    frame: FrameCount,
    bytes: u64,
}

#[derive(Serialize)]
struct Report {
    world: String,
    size: [u32; 2],
    shadows: bool,
    views: Vec<ViewCount>,
    /// Means over the views.
    mean_bytes: f64,
    mean_march_iterations: f64,
    /// The beams' iterations over the pixels: a serial beam's iterations
    /// are shared by its tile's 64 pixels, the wide search's rounds are each
    /// one interval test for every pixel of the tile.
    mean_beam_iterations_per_pixel: f64,
    /// The beams' iterations (serial) or rounds (wide) a tile.
    mean_beam_iterations_per_tile: f64,
    mean_march_warp_iterations: f64,
    mean_shadow_iterations: f64,
    mean_shadow_warp_iterations: f64,
    /// The most waits (fetches a ray's steps wait on) of a warp's lanes,
    /// camera and shadow rays.
    mean_march_warp_waits: f64,
    mean_shadow_warp_waits: f64,
    /// The shadow blocks' beams' iterations over the shadow rays.
    mean_shadow_beam_iterations_per_ray: f64,
    /// The shadow blocks' beams' rounds a block (each round one interval
    /// test for every ray of the block).
    mean_shadow_beam_rounds_per_block: f64,
    mean_shadow_rays: f64,
}

fn pass_line(name: &str, p: &PassCount) -> String {
    format!(
        "  {name:7} {:>9} rays  iter {:6.1} (p99 {:4}, max {:4}; warp {:6.1}, SIMD {:3.0} %; down {:5.1}, up {:5.1})  pyramid {:6.1} (p99 {:4})  \
         terrain {:5.1} (p99 {:3})  waits {:5.1} (warp {:5.1})  shadow taps {:>8}  read {:8.2} MB  written {:6.2} MB",
        p.rays,
        p.iterations.mean,
        p.iterations.p99,
        p.iterations.max,
        p.warp_iterations,
        100.0 * p.simd_efficiency,
        p.descents,
        p.climbs,
        p.pyramid_reads.mean,
        p.pyramid_reads.p99,
        p.terrain_reads.mean,
        p.terrain_reads.p99,
        p.waits.mean,
        p.warp_waits,
        p.shadow_reads,
        p.bytes_read as f64 / 1e6,
        p.bytes_written as f64 / 1e6,
    )
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let world = args.world.load()?;
    let views: Vec<ViewSpec> = match &args.views {
        Some(file) => {
            let text = std::fs::read_to_string(file)
                .with_context(|| format!("reading views file {}", file.display()))?;
            parse_views(&text).with_context(|| format!("views file {}", file.display()))?
        }
        None => world.views.clone(),
    };
    if views.is_empty() {
        bail!("no views: give --views FILE (the world has none of its own)");
    }
    let (w, h) = args.size;
    let cameras = views
        .iter()
        .map(|v| {
            strata_camera::Camera::from_view(&world.level, v, w, h)
                .with_context(|| format!("view {}", v.name))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let pyramid = compute_pyramid(&world.level);
    let mut replay = Replay::new(&world.level, &pyramid);
    replay.traversal = Traversal {
        climb: args.climb,
        start: args.start_level.or(Traversal::GPU.start),
        beam: !args.no_beam,
        search: args.search.unwrap_or(Traversal::GPU.search),
        shadow_rounds: args.shadow_rounds.unwrap_or(Traversal::GPU.shadow_rounds),
        beam_level: args.beam_level.unwrap_or(Traversal::GPU.beam_level),
        fused_descent: args.fused_descent,
        cave_skip: !args.no_cave_skip,
        beam_texels: !args.no_beam_texels,
        texel_walk: args.texel_walk,
    };
    let shape = LevelShape::of(&world.level);
    let mut out = std::io::stdout().lock();
    let mut counts = Vec::new();
    for (view, camera) in views.iter().zip(&cameras) {
        let shadow = strata_render::shadow::ShadowFrame::fit(camera, !args.no_shadows);
        let globals = Globals::new(camera, &shape, &shadow);
        let frame = replay_frame(&mut replay, &globals);
        if args.verify_beam {
            let (differ, early) = beam_disagreements(&mut replay, &globals);
            eprintln!(
                "{}: beam check: {differ} rays' hits differ, {early} hits before their beam (camera rays and shadow rays)",
                view.name
            );
            if differ + early > 0 {
                bail!(
                    "{}: the beam changed {differ} hits ({early} before their tile's start)",
                    view.name
                );
            }
        }
        if !args.json {
            writeln!(
                out,
                "{} (pitch {}): {} of {} pixels hit, {} shadow blocks; {:.2} MB a frame \
                 (distinct: terrain {:.2} MB, pyramid {:.2} MB)",
                view.name,
                view.pitch,
                frame.hits,
                u64::from(w) * u64::from(h),
                frame.shadow_blocks,
                frame.bytes() as f64 / 1e6,
                frame.terrain_bytes_touched as f64 / 1e6,
                frame.pyramid_bytes_touched as f64 / 1e6,
            )?;
            for (name, pass) in [
                ("beam", &frame.beam),
                ("march", &frame.march),
                ("shadow", &frame.shadow),
                ("shade", &frame.shade),
            ] {
                writeln!(out, "{}", pass_line(name, pass))?;
            }
        }
        counts.push(ViewCount {
            view: view.name.clone(),
            pitch: view.pitch,
            bytes: frame.bytes(),
            frame,
        });
    }
    let n = counts.len() as f64;
    let mean = |f: &dyn Fn(&ViewCount) -> f64| counts.iter().map(f).sum::<f64>() / n;
    let report = Report {
        world: world.name.clone(),
        size: [w, h],
        shadows: !args.no_shadows,
        mean_bytes: mean(&|c| c.bytes as f64),
        mean_march_iterations: mean(&|c| c.frame.march.iterations.mean),
        mean_beam_iterations_per_pixel: mean(&|c| {
            (c.frame.beam.iterations.total * u64::from(c.frame.beam_lanes)) as f64
                / c.frame.march.rays.max(1) as f64
        }),
        mean_beam_iterations_per_tile: mean(&|c| c.frame.beam.iterations.mean),
        mean_march_warp_iterations: mean(&|c| c.frame.march.warp_iterations),
        mean_shadow_iterations: mean(&|c| c.frame.shadow.iterations.mean),
        mean_shadow_warp_iterations: mean(&|c| c.frame.shadow.warp_iterations),
        mean_march_warp_waits: mean(&|c| c.frame.march.warp_waits),
        mean_shadow_warp_waits: mean(&|c| c.frame.shadow.warp_waits),
        mean_shadow_beam_iterations_per_ray: mean(&|c| {
            c.frame.shadow_beam_iterations as f64 / c.frame.shadow.rays.max(1) as f64
        }),
        mean_shadow_beam_rounds_per_block: mean(&|c| {
            c.frame.shadow_beam_iterations as f64 / c.frame.shadow_blocks.max(1) as f64
        }),
        mean_shadow_rays: mean(&|c| c.frame.shadow.rays as f64),
        views: counts,
    };
    if args.json {
        serde_json::to_writer_pretty(&mut out, &report)?;
        writeln!(out)?;
    } else {
        writeln!(
            out,
            "mean over {} views: {:.2} MB a frame, {:.2} march iterations a pixel ({:.2} a warp) \
             + {:.3} beam iterations a pixel ({:.2} a tile), {:.0} shadow rays of {:.2} iterations ({:.2} a warp) \
             + {:.2} beam rounds a block; waits a warp: march {:.2}, shadow {:.2}",
            report.views.len(),
            report.mean_bytes / 1e6,
            report.mean_march_iterations,
            report.mean_march_warp_iterations,
            report.mean_beam_iterations_per_pixel,
            report.mean_beam_iterations_per_tile,
            report.mean_shadow_rays,
            report.mean_shadow_iterations,
            report.mean_shadow_warp_iterations,
            report.mean_shadow_beam_rounds_per_block,
            report.mean_march_warp_waits,
            report.mean_shadow_warp_waits,
        )?;
    }
    Ok(())
}
