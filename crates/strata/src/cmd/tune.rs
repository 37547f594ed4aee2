//! `strata tune`: sweep each method's knob over a horizon fixture, pick the
//! cheapest setting within one percentage point of its best combined error,
//! and write `tuning.md`, `tuning.json`, plots and `settings.json` (which
//! `strata compare --settings FILE` takes).

use crate::adapter_arg::AdapterArgs;
use crate::world_arg::WorldArgs;
use anyhow::Context;
use std::path::PathBuf;
use strata_bench::plan::parse_size;
use strata_bench::tune::{self, TuneOptions, output};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// Output directory: tuning.md, tuning.json, settings.json, tune-*.png/svg.
    #[arg(long, value_name = "DIR", default_value = "out/tune")]
    pub out: PathBuf,
    /// Fewer points per sweep at 200x130 and no 1280x800 mesh pass (the CPU-machine form).
    #[arg(long)]
    pub quick: bool,
    /// Views file for the fixture. Default: the level's first three 0° views.
    #[arg(long, value_name = "FILE")]
    pub views: Option<PathBuf>,
    /// Sweep size WxH (default 400x260; 200x130 with --quick).
    #[arg(long, value_name = "WxH")]
    pub size: Option<String>,
    /// Only these methods (comma list of ray, voxel, sliced, scattered, mesh, painted, ray-exact).
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// Timed frames per point and view (default 5; 1 with --quick).
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// Ms of untimed frames back to back before each point's timed frames
    /// at each view (default 100; 0 with --quick), so every point is timed
    /// at the GPU's busy clock (see `compare --hold-busy`).
    #[arg(long, value_name = "MS")]
    pub hold_busy: Option<u32>,
    /// Turn the shared shadow map off.
    #[arg(long)]
    pub no_shadows: bool,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// Reference cache directory (default: $STRATA_CACHE_DIR/reference or ~/.cache/strata/reference).
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let size = match &args.size {
        Some(s) => parse_size(s)?,
        None if args.quick => (200, 130),
        None => (400, 260),
    };
    let file_views = match &args.views {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading views file {}", path.display()))?;
            Some(
                strata_level::views::parse_views(&text)
                    .with_context(|| format!("views file {}", path.display()))?,
            )
        }
        None => None,
    };
    if args.frames == Some(0) {
        anyhow::bail!("--frames must be at least 1");
    }
    let world = args.world.load()?;
    let views = file_views.unwrap_or_else(|| tune::horizon_fixture(&world));
    let opts = TuneOptions {
        out: args.out.clone(),
        views,
        size,
        mesh_size: (!args.quick).then_some((1280, 800)),
        quick: args.quick,
        frames: args.frames.unwrap_or(if args.quick { 1 } else { 5 }),
        min_warmup: if args.quick { 1 } else { 3 },
        hold_busy_ms: args.hold_busy.unwrap_or(if args.quick { 0 } else { 100 }),
        shadows: !args.no_shadows,
        cache_dir: args
            .cache
            .clone()
            .unwrap_or_else(strata_reference::default_cache_dir),
        methods: args
            .methods
            .as_ref()
            .map(|l| l.split(',').map(|m| m.trim().to_string()).collect()),
    };
    let gpu = args.adapter.open()?;
    eprintln!(
        "adapter: {} ({}); tuning {} view(s) at {}x{}",
        gpu.report.name,
        gpu.report.backend,
        opts.views.len(),
        size.0,
        size.1
    );
    let tuning = tune::run(&world, &gpu, &opts)?;
    let (md, settings) = output::write(&tuning, &args.out)?;
    for m in &tuning.methods {
        let chosen = m.chosen.map(|i| &m.points[i]);
        println!(
            "{:<10} {:>9}  chosen {:<32} combined {:>6} %  {:>8} ms  (paper: {})",
            m.method,
            format!("{}x{}", m.size[0], m.size[1]),
            chosen.map_or("—".into(), |p| p.label.clone()),
            chosen.map_or("—".into(), |p| format!("{:.2}", p.combined)),
            chosen.map_or("—".into(), |p| format!("{:.3}", p.cost_ms)),
            m.paper_setting.as_deref().unwrap_or("no knob")
        );
    }
    println!("{:.0} s", tuning.seconds);
    println!("wrote {}", md.display());
    println!("wrote {}", settings.display());
    Ok(())
}
