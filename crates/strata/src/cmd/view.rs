//! `strata view`: the interactive viewer (crate `strata-viewer`). Fly over the
//! level, switch methods live, dig craters; `--script` or `--frames N
//! --screenshot PATH` run it without a person.

use crate::adapter_arg::AdapterArgs;
use crate::cmd::render::{MethodArgs, parse_size};
use crate::world_arg::WorldArgs;
use std::path::PathBuf;
use strata_level::save::SavePolicy;
use strata_viewer::save::SaveOptions;
use strata_viewer::{Options, Script};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// The method to draw first (1-8 switch later); built in the background while `ray` shows.
    #[arg(long, default_value = "ray")]
    pub method: String,
    /// One of the level's named views to start at (default: its first).
    #[arg(long, value_name = "NAME")]
    pub view: Option<String>,
    /// Window size at start.
    #[arg(long, default_value = "1280x800", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Picture size as a fraction of the window's (it follows resizes) [default: 1, or 0.5 on a CPU adapter].
    #[arg(long, value_name = "F")]
    pub render_scale: Option<f32>,
    /// Run the commands of FILE (see `strata_viewer::script`), then quit.
    #[arg(long, value_name = "FILE", conflicts_with = "frames")]
    pub script: Option<PathBuf>,
    /// Draw N frames, then quit (with --screenshot: save the last).
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// With --frames: save the last frame here as PNG.
    #[arg(long, value_name = "PATH", requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// Present without waiting for the display's refresh (frame rate unbounded).
    #[arg(long)]
    pub no_vsync: bool,
    #[command(flatten)]
    pub method_args: MethodArgs,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// Where screenshots (key P) go.
    #[arg(long, default_value = "out/view")]
    pub out: PathBuf,
    /// Where Ctrl+S saves the edited world (default: `OUT/<world>-edited`, or the loaded world's directory with --overwrite).
    #[arg(long, value_name = "DIR")]
    pub save_to: Option<PathBuf>,
    /// Let a save (Ctrl+S, script `save`) write over the loaded world's own directory.
    #[arg(long)]
    pub overwrite: bool,
    /// Start with the physics toy on (key O toggles it): clicks drop balls and boxes (rapier3d) onto the terrain collider.
    #[arg(long)]
    pub physics: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    // Check what can be checked before loading the world.
    let script = match (&args.script, args.frames) {
        (Some(path), _) => Some(Script::load(path)?),
        (None, Some(0)) => anyhow::bail!("--frames must be at least 1"),
        (None, Some(n)) => Some(Script::frames_then_screenshot(n, args.screenshot.clone())),
        (None, None) => None,
    };
    strata_render::methods::entry(&args.method)?;
    let settings = args.method_args.settings();
    let start = std::time::Instant::now();
    let world = args.world.load()?;
    eprintln!(
        "strata view: {} loaded in {:.2} s",
        world.name,
        start.elapsed().as_secs_f64()
    );
    strata_viewer::run(Options {
        world,
        method: args.method,
        settings,
        size: args.size,
        render_scale: args.render_scale,
        view: args.view,
        script,
        vsync: !args.no_vsync,
        adapter: args.adapter.choice(),
        render: crate::adapter_arg::render_options(),
        out: args.out,
        save: SaveOptions {
            policy: SavePolicy {
                source: args.world.source_dir(),
                overwrite: args.overwrite,
            },
            dir: args.save_to,
        },
        physics: args.physics,
    })
}
