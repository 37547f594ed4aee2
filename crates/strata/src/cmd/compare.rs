//! `strata compare`: the one-command comparison. With no arguments it runs
//! the publication configuration: every method at its tuned setting, the
//! level's views, 1280x800, far 600, shadows on, per-method warm-up, 40 timed
//! frames, and the edit protocol. Every input is checked before GPU work.

use crate::adapter_arg::AdapterArgs;
use crate::world_arg::WorldArgs;
use anyhow::Context;
use std::path::PathBuf;
use strata_bench::plan::{MethodChoice, parse_methods, parse_size, prepare_out_dir};
use strata_bench::run::{EditMode, Options, Plan};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// Output directory: results-<adapter>.json, report.md, grid.png, cells/.
    #[arg(long, value_name = "DIR", default_value = "out/compare")]
    pub out: PathBuf,
    /// The CPU-machine smoke: 320x200, 4 timed frames (explicit --size/--frames win).
    /// The default on a CPU rasteriser such as lavapipe.
    #[arg(long)]
    pub quick: bool,
    /// Comma-separated methods, each `name` or `name:setting`
    /// (`ray:64`, `voxel:4,8,2/100`, `scattered:4,4,4`, `sliced:512`, `mesh:0.5`). Default: all.
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// Views file (`NAME X,Y:YAW:EYE[:under] PITCH` per line). Default: the level's own views.
    #[arg(long, value_name = "FILE")]
    pub views: Option<PathBuf>,
    /// Turn the shared shadow map off (a method-only diagnostic run).
    #[arg(long)]
    pub no_shadows: bool,
    /// Require the edit protocol (an error when the level has no edit site).
    #[arg(long, conflicts_with = "no_edits")]
    pub edits: bool,
    /// Skip the edit protocol.
    #[arg(long)]
    pub no_edits: bool,
    /// Image size WxH (default 1280x800; 320x200 with --quick).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Timed frames per cell (default 40; 4 with --quick).
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// Pre-timing frames at every view (default 3; 1 with --quick). A
    /// renderer's first view goes on while an incremental build is in flight.
    #[arg(long, value_name = "N")]
    pub warmup: Option<u32>,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// Reference cache directory (default: $STRATA_CACHE_DIR/reference or ~/.cache/strata/reference).
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    // Cheap checks first, then the level, then the plan; the GPU last.
    let known = strata_render::methods::names();
    let methods = match &args.methods {
        Some(list) => parse_methods(list, &known)?,
        None => known
            .iter()
            .map(|n| MethodChoice {
                name: (*n).to_string(),
                setting: None,
            })
            .collect(),
    };
    // Parse an explicit size now, so a bad one fails before any GPU work.
    let explicit_size = args.size.as_deref().map(parse_size).transpose()?;
    let file_views = match &args.views {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading views file {}", path.display()))?;
            let views = strata_level::views::parse_views(&text)
                .with_context(|| format!("views file {}", path.display()))?;
            Some(views)
        }
        None => None,
    };
    prepare_out_dir(&args.out)?;
    let world = args.world.load()?;
    let views = file_views.unwrap_or_else(|| world.views.clone());
    let edits = if args.no_edits {
        EditMode::Off
    } else if args.edits {
        EditMode::Required
    } else {
        EditMode::Auto
    };
    let gpu = strata_render::Gpu::open(&args.adapter.choice())?;
    eprintln!(
        "adapter: {} ({}, {}); timestamps {}",
        gpu.report.name,
        gpu.report.backend,
        gpu.report.driver,
        if gpu.report.timestamps {
            "on"
        } else {
            "off: CPU submit-and-wait"
        }
    );
    // The publication configuration takes hours on a CPU rasteriser
    // (lavapipe/llvmpipe), so there the default is the quick smoke; an
    // explicit --size or --frames still wins.
    let quick = args.quick
        || (gpu.report.device_type == "Cpu" && args.size.is_none() && args.frames.is_none());
    if quick && !args.quick {
        eprintln!(
            "note: {} is a CPU rasteriser: running the --quick smoke (320x200, 4 frames); \
             pass --size/--frames for the full configuration",
            gpu.report.name
        );
    }
    let (width, height) = explicit_size.unwrap_or(if quick { (320, 200) } else { (1280, 800) });
    let frames = args.frames.unwrap_or(if quick { 4 } else { 40 });
    let options = Options {
        out: args.out.clone(),
        methods,
        views,
        width,
        height,
        frames,
        min_warmup: args.warmup.unwrap_or(if quick { 1 } else { 3 }),
        shadows: !args.no_shadows,
        edits,
        cache_dir: args
            .cache
            .clone()
            .unwrap_or_else(strata_reference::default_cache_dir),
    };
    let plan = Plan::new(world, options)?;
    let (json, report) = plan.run(&gpu)?;
    println!("wrote {}", json.display());
    println!("wrote {}", report.display());
    Ok(())
}
