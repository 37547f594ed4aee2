//! `strata view`: the interactive viewer (crate `strata-viewer`). Fly over the
//! level, switch methods live, dig craters; `--script` or `--frames N
//! --screenshot PATH` run it without a person.

use crate::adapter_arg::AdapterArgs;
use crate::cmd::render::{MethodArgs, parse_size};
use crate::paged_arg::{PagedArgs, PagedWorld, open_paged};
use crate::world_arg::WorldArgs;
use anyhow::Context;
use std::path::PathBuf;
use std::sync::Arc;
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
    #[command(flatten)]
    pub paged: PagedArgs,
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
    // A store past the whole-world limit, or any world with --gpu-budget:
    // paged terrain, the map read as the view needs it.
    let (world, paged) = match viewer_pages(&args.world, &args.paged)? {
        Some((world, pages)) => {
            let options = PagedWorld::options(&args.paged);
            let (w, h) = pages.size();
            eprintln!(
                "strata view: {} ({w}x{h}) opened paged in {:.2} s (GPU budget {} B)",
                world.name,
                start.elapsed().as_secs_f64(),
                options.gpu_budget
            );
            (
                world,
                Some(strata_viewer::paged::PagedWorld { pages, options }),
            )
        }
        None => {
            let world = args.world.load()?;
            eprintln!(
                "strata view: {} loaded in {:.2} s",
                world.name,
                start.elapsed().as_secs_f64()
            );
            (world, None)
        }
    };
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
        paged,
    })
}

/// The world's files besides its map (the map a stand-in) and its pages
/// with the viewer's edit layer over them; `None`: draw the world whole.
#[allow(clippy::type_complexity)]
fn viewer_pages(
    world: &WorldArgs,
    paged: &PagedArgs,
) -> anyhow::Result<Option<(strata_level::World, Arc<strata_viewer::paged::EditedPages>)>> {
    use strata_viewer::paged::{Base, EditedPages};
    let mid_rule = world.mid_rule();
    let is_store = world.level.as_deref().is_some_and(|d| {
        matches!(
            strata_store::fs::dir_kind(d),
            Ok(strata_store::fs::DirKind::Store)
        )
    });
    if !is_store {
        if paged.gpu_budget.is_none() {
            return Ok(None);
        }
        // A world in memory with --gpu-budget: loaded once, paged.
        let mut shell = world.load()?;
        let level = std::mem::replace(&mut shell.level, strata_level::Level::flat(2, 1, 0, 0)?);
        let base = Base::Level(Arc::new(level));
        return Ok(Some((shell, Arc::new(EditedPages::new(base, mid_rule)?))));
    }
    let Some(p) = open_paged(world, paged)? else {
        return Ok(None);
    };
    let (Some(cache), Some(dir)) = (p.cache(), &p.dir) else {
        anyhow::bail!("a store opened paged has a chunk cache");
    };
    let shell = cache
        .store()
        .world_shell()
        .with_context(|| format!("reading the world in {}", dir.display()))?;
    let base = Base::Store {
        cache: cache.clone(),
        dir: dir.clone(),
    };
    Ok(Some((shell, Arc::new(EditedPages::new(base, mid_rule)?))))
}
