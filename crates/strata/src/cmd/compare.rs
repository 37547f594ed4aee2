//! `strata compare`: the one-command comparison. With no arguments it runs
//! the publication configuration: every method at its tuned setting, the
//! level's views, 1280x800, far 600, shadows on, per-method warm-up, 40 timed
//! frames, and the edit protocol. Every input is checked before GPU work.
//!
//! `--all-adapters` runs the protocol once per adapter the machine offers
//! (each into `<out>/<adapter>-<backend>/`), then writes one merged
//! `portability.md` + `portability.json` into `<out>`.

use crate::adapter_arg::AdapterArgs;
use crate::paged_arg::{PagedArgs, PagedWorld};
use crate::world_arg::WorldArgs;
use anyhow::Context;
use std::path::PathBuf;
use strata_bench::plan::{MethodChoice, every_method, parse_methods, parse_size, prepare_out_dir};
use strata_bench::portability::{self, Input, SkippedAdapter, adapter_dir_name};
use strata_bench::run::{EditMode, Options, Plan};
use strata_level::{ViewSpec, World};
use strata_render::adapter::list_adapters;
use strata_render::methods::METHODS;
use strata_render::{AdapterChoice, AdapterReport, Gpu};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// Output directory: `results-<adapter>.json`, report.md, grid.png, cells/.
    #[arg(long, value_name = "DIR", default_value = "out/compare")]
    pub out: PathBuf,
    /// The CPU-machine smoke: 320x200, 4 timed frames (explicit --size/--frames win).
    /// The default on a CPU rasteriser such as lavapipe.
    #[arg(long)]
    pub quick: bool,
    /// Comma-separated methods, each `name` or `name:setting`
    /// (`ray:64`, `voxel:4,8,2/100`, `scattered:4,4,4`, `sliced:512`, `sliced:512/refine`, `mesh:0.5`, `mesh:0.5o` outline-constrained, `mesh:0.5/2` LOD tolerance 2 px, `mesh:0.5/gradient` shaded with the height-field normal, a diagnostic, `mesh:0.5/fragment` coloured in the raster pass, `mesh:0.5/centres` samples at texel centres, `ray:128/nobeam` and `voxel:/nobeam` marching from the near plane as before the beam). Default: all.
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// `strata tune`'s settings.json: each method named without a setting takes its tuned one.
    #[arg(long, value_name = "FILE")]
    pub settings: Option<PathBuf>,
    /// Views file (`NAME X,Y:YAW:EYE[:under] PITCH` per line). Default: the level's own views.
    #[arg(long, value_name = "FILE")]
    pub views: Option<PathBuf>,
    /// Keep only these of the views (comma-separated names, e.g. `hangar,stash`): a shorter
    /// run of the same protocol (CI runs the README's command so).
    #[arg(long, value_name = "NAMES")]
    pub view_names: Option<String>,
    /// Turn the shared shadow map off (a method-only diagnostic run).
    #[arg(long)]
    pub no_shadows: bool,
    /// Require the edit protocol (an error when the level has no edit site).
    #[arg(long, conflicts_with = "no_edits")]
    pub edits: bool,
    /// Skip the edit protocol.
    #[arg(long)]
    pub no_edits: bool,
    /// Also fly a short path (the video's default, in 2 s at 10 fps, crater dug midway) with
    /// every method and report each one's depth flicker beyond the CPU reference's.
    #[arg(long)]
    pub temporal: bool,
    /// Also run the sustained edit workload (issue 35): K small edits a frame (default 64;
    /// tracks of radius 2-6 along the video's default path, a few craters, slabs carved and
    /// built, old edits undone) for 600 frames (24 with --quick), through every method's own
    /// update path; per method the edits' and the frame's CPU/GPU ms (p50/p99/max), checked
    /// against a fresh build every 100 frames (12 with --quick) and at the end; the terrain
    /// collider's refit per frame.
    #[arg(long, value_name = "K", num_args = 0..=1, default_missing_value = "64")]
    pub gameplay: Option<u32>,
    /// What grid.png shows: `pictures` (each method's picture) or `flip` (each cell's ꟻLIP
    /// error map against the CPU colour reference, which fills the reference column).
    #[arg(long, value_name = "MODE", default_value = "pictures")]
    pub grid: strata_bench::session::GridMode,
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
    /// Ms of untimed frames back to back before each cell (default 300; 0
    /// with --quick), so a GPU that lowers its clock when mostly idle times
    /// every method at its busy clock. 0 turns it off.
    #[arg(long, value_name = "MS")]
    pub hold_busy: Option<u32>,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// `--gpu-budget`: ray-exact and ray-exact-fragment draw through pages
    /// (converged at each view before timing; `paging` in each row); the
    /// other methods keep the whole-world path. Without it nothing changes.
    #[command(flatten)]
    pub paged: PagedArgs,
    /// Run the protocol on every adapter of --backend (default: every backend), each into
    /// `<out>/<adapter>-<backend>/`, then write the merged `portability.md` and
    /// `portability.json` into `<out>`. A CPU rasteriser runs the --quick form unless
    /// --size/--frames are given.
    #[arg(long, conflicts_with = "adapter")]
    pub all_adapters: bool,
    /// Reference cache directory (default: $STRATA_CACHE_DIR/reference or ~/.cache/strata/reference).
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Finish the interrupted run in DIR (its output directory): its finished cells are kept
    /// and only the rest are measured. Refused, naming what differs, unless the protocol,
    /// level, adapter and settings (give the same flags) are the same.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["out", "all_adapters"])]
    pub resume: Option<PathBuf>,
}

impl Args {
    /// Where the run writes: the `--resume` directory, else `--out`.
    fn out_dir(&self) -> PathBuf {
        self.resume.clone().unwrap_or_else(|| self.out.clone())
    }
}

/// Everything checked before any adapter is opened.
struct Prepared {
    methods: Vec<MethodChoice>,
    explicit_size: Option<(u32, u32)>,
    views: Vec<ViewSpec>,
    world: World,
    edits: EditMode,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(refusal) = past_the_limit(&args.world)? {
        return run_paged_store(&args, refusal);
    }
    let prepared = prepare(&args)?;
    if args.all_adapters {
        return run_all_adapters(&args, prepared);
    }
    let gpu = args.adapter.open()?;
    announce(&gpu.report);
    let options = options_for(&args, &prepared, &gpu.report, args.out_dir());
    let plan = Plan::new(prepared.world, options)?
        .with_paging(paging(&args))?
        .with_gameplay(gameplay(&args, &gpu.report))?;
    let (json, report) = plan.run(&gpu)?;
    println!("wrote {}", json.display());
    println!("wrote {}", report.display());
    Ok(())
}

/// `--gameplay [K]`'s workload: the 600 frames, or the quick form's
/// 24 where the run is quick (`--quick`, or a CPU rasteriser without
/// `--size`/`--frames`).
fn gameplay(args: &Args, adapter: &AdapterReport) -> Option<strata_bench::gameplay::GameplaySpec> {
    use strata_bench::gameplay::GameplaySpec;
    let k = args.gameplay?;
    Some(match is_quick(args, adapter) {
        true => GameplaySpec::quick(k),
        false => GameplaySpec::full(k),
    })
}

/// The paging of `--gpu-budget` (`None` without it: the paper's protocol).
fn paging(args: &Args) -> Option<strata_render::paged::PagedOptions> {
    args.paged
        .gpu_budget
        .map(|_| PagedWorld::options(&args.paged))
}

/// `Some(why)` when `--level` is a store past the whole-world limit (it
/// cannot be loaded whole here): why, naming the limit.
pub(crate) fn past_the_limit(
    world: &crate::world_arg::WorldArgs,
) -> anyhow::Result<Option<String>> {
    let Some(dir) = &world.level else {
        return Ok(None);
    };
    if !matches!(
        strata_store::fs::dir_kind(dir),
        Ok(strata_store::fs::DirKind::Store)
    ) {
        return Ok(None);
    }
    let store = strata_store::DirStore::open(dir)
        .with_context(|| format!("opening the store in {}", dir.display()))?;
    let (bytes, limit) = (
        store.store().map_bytes(),
        crate::world_arg::whole_world_limit(),
    );
    let size = |b: u64| match b {
        b if b >= 1 << 30 => format!("{:.2} GiB", b as f64 / f64::from(1u32 << 30)),
        b => format!("{:.1} MiB", b as f64 / f64::from(1u32 << 20)),
    };
    Ok((bytes > limit).then(|| {
        format!(
            "the store in {} is {}x{} texels ({} in memory), past the whole-world limit here ({}: half the available memory, at most 4 GiB; STRATA_WHOLE_WORLD_LIMIT_MIB sets it)",
            dir.display(),
            store.store().width(),
            store.store().height(),
            size(bytes),
            size(limit)
        )
    }))
}

/// A store that cannot be loaded whole: the paged methods are measured
/// through pages (at `--gpu-budget`, default 256 MiB), every other method
/// is a refusal in the results naming the limit and the paged methods.
fn run_paged_store(args: &Args, refusal: String) -> anyhow::Result<()> {
    if args.gameplay.is_some() {
        anyhow::bail!(
            "{refusal}: --gameplay edits the world in memory; run it on a world loaded whole"
        );
    }
    if args.all_adapters || args.resume.is_some() {
        anyhow::bail!(
            "{refusal}: --all-adapters and --resume need a world loaded whole; compare it on one adapter (the paged methods draw it)"
        );
    }
    let methods = choose_methods(args)?;
    let explicit_size = args.size.as_deref().map(parse_size).transpose()?;
    let mut paged_args = args.paged.clone();
    paged_args.gpu_budget = Some(
        paged_args
            .gpu_budget
            .unwrap_or(strata_render::paged::DEFAULT_GPU_BUDGET),
    );
    let pages = crate::paged_arg::open_paged(&args.world, &paged_args)?
        .context("a store past the whole-world limit is drawn paged")?;
    let opened = args.world.open()?;
    let mut views = match &args.views {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading views file {}", path.display()))?;
            strata_level::views::parse_views(&text)
                .with_context(|| format!("views file {}", path.display()))?
        }
        None => pages.views.clone(),
    };
    if let Some(names) = &args.view_names {
        views = keep_views(views, names)?;
    }
    prepare_out_dir(&args.out)?;
    eprintln!(
        "{refusal}: only {} are measured",
        strata_render::paged::PAGED_METHODS.join(", ")
    );
    let prepared = Prepared {
        methods,
        explicit_size,
        views,
        world: opened.world().clone(),
        edits: EditMode::Off,
    };
    let gpu = args.adapter.open()?;
    announce(&gpu.report);
    let options = options_for(args, &prepared, &gpu.report, args.out.clone());
    let input = strata_bench::paged_run::PagedInput {
        name: pages.name.clone(),
        size: pages.size,
        mid_rule: args.world.mid_rule(),
        colors: pages.colors.clone(),
        source: pages.source.clone(),
        columns: opened.source(),
        paging: PagedWorld::options(&paged_args),
        refusal,
    };
    let (json, report) = strata_bench::paged_run::run(&gpu, &input, &options)?;
    println!("wrote {}", json.display());
    println!("wrote {}", report.display());
    Ok(())
}

/// `--methods` (default: all), each without a setting taking `--settings`'.
fn choose_methods(args: &Args) -> anyhow::Result<Vec<MethodChoice>> {
    let mut methods = match &args.methods {
        Some(list) => parse_methods(list, METHODS)?,
        None => every_method(),
    };
    if let Some(path) = &args.settings {
        strata_bench::tune::output::TunedSettings::read(path)?.apply(&mut methods);
        // A tuned setting that does not parse fails here, naming the file.
        for m in &methods {
            strata_bench::methods::settings_for(m, true)
                .with_context(|| format!("settings file {}", path.display()))?;
        }
    }
    Ok(methods)
}

/// Cheap checks first, then the level; the GPU comes later.
fn prepare(args: &Args) -> anyhow::Result<Prepared> {
    let methods = choose_methods(args)?;
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
    if let Some(dir) = &args.resume
        && !dir.join("cells").is_dir()
    {
        anyhow::bail!(
            "--resume {}: not the output directory of a compare run (no cells/ inside)",
            dir.display()
        );
    }
    prepare_out_dir(&args.out_dir())?;
    if args.all_adapters {
        // The per-adapter subfolders hold the cells; the top level only the merged report.
        let _ = std::fs::remove_dir(args.out.join("cells"));
    }
    let world = args.world.load()?;
    let mut views = file_views.unwrap_or_else(|| world.views.clone());
    if let Some(names) = &args.view_names {
        views = keep_views(views, names)?;
    }
    let edits = if args.no_edits {
        EditMode::Off
    } else if args.edits {
        EditMode::Required
    } else {
        EditMode::Auto
    };
    Ok(Prepared {
        methods,
        explicit_size,
        views,
        world,
        edits,
    })
}

/// The views named in `names` (comma-separated), in the order given; an
/// unknown name is an error listing the views there are.
fn keep_views(views: Vec<ViewSpec>, names: &str) -> anyhow::Result<Vec<ViewSpec>> {
    names
        .split(',')
        .map(str::trim)
        .filter(|n| !n.is_empty())
        .map(|name| {
            views
                .iter()
                .find(|v| v.name == name)
                .cloned()
                .with_context(|| {
                    let known: Vec<&str> = views.iter().map(|v| v.name.as_str()).collect();
                    format!(
                        "--view-names: no view `{name}` (the views are {})",
                        known.join(", ")
                    )
                })
        })
        .collect()
}

fn announce(report: &AdapterReport) {
    eprintln!(
        "adapter: {} ({}, {}); timestamps {}",
        report.name,
        report.backend,
        report.driver,
        if report.timestamps {
            "on"
        } else {
            "off: CPU submit-and-wait"
        }
    );
}

/// `--quick`, or a CPU rasteriser without an explicit `--size`/`--frames`.
fn is_quick(args: &Args, adapter: &AdapterReport) -> bool {
    args.quick || (adapter.device_type == "Cpu" && args.size.is_none() && args.frames.is_none())
}

/// The run's options on one adapter: the publication configuration, or the
/// quick smoke on a CPU rasteriser (lavapipe/llvmpipe), where the full one
/// takes hours; an explicit --size or --frames still wins.
fn options_for(args: &Args, p: &Prepared, adapter: &AdapterReport, out: PathBuf) -> Options {
    let quick = is_quick(args, adapter);
    if quick && !args.quick {
        eprintln!(
            "note: {} is a CPU rasteriser: running the --quick smoke (320x200, 4 frames); \
             pass --size/--frames for the full configuration",
            adapter.name
        );
    }
    let (width, height) = p
        .explicit_size
        .unwrap_or(if quick { (320, 200) } else { (1280, 800) });
    Options {
        out,
        methods: p.methods.clone(),
        views: p.views.clone(),
        width,
        height,
        frames: args.frames.unwrap_or(if quick { 4 } else { 40 }),
        min_warmup: args.warmup.unwrap_or(if quick { 1 } else { 3 }),
        hold_busy_ms: args.hold_busy.unwrap_or(if quick { 0 } else { 300 }),
        shadows: !args.no_shadows,
        edits: p.edits,
        temporal: args.temporal,
        cache_dir: args
            .cache
            .clone()
            .unwrap_or_else(strata_reference::default_cache_dir),
        resume: args.resume.is_some(),
        grid: args.grid,
    }
}

/// `--all-adapters`: one run per adapter, then the merged portability report.
/// An adapter that cannot be opened or whose run stops is recorded and the
/// batch goes on; a method an adapter refuses is a failure in its run.
fn run_all_adapters(args: &Args, prepared: Prepared) -> anyhow::Result<()> {
    let backend = args.adapter.backend;
    let adapters = list_adapters(backend);
    if adapters.is_empty() {
        anyhow::bail!(
            "--all-adapters: no adapter found on backend `{backend}` (install mesa-vulkan-drivers \
             for lavapipe, libegl1 + libgl1-mesa-dri for llvmpipe's GL)"
        );
    }
    eprintln!(
        "{} adapter(s): {}",
        adapters.len(),
        adapters
            .iter()
            .map(|a| format!("[{}] {} ({})", a.index, a.name, a.backend))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut inputs: Vec<Input> = Vec::new();
    let mut skipped: Vec<SkippedAdapter> = Vec::new();
    let mut dirs: Vec<String> = Vec::new();
    for listing in &adapters {
        let mut dir_name = adapter_dir_name(&listing.name, &listing.backend);
        if dirs.contains(&dir_name) {
            dir_name = format!("{dir_name}-{}", listing.index);
        }
        dirs.push(dir_name.clone());
        let out = args.out.join(&dir_name);
        eprintln!(
            "\n== [{}] {} ({}) -> {}",
            listing.index,
            listing.name,
            listing.backend,
            out.display()
        );
        let choice = AdapterChoice {
            backend,
            index: Some(listing.index),
            name: None,
        };
        let skip = |error: String| SkippedAdapter {
            adapter: listing.name.clone(),
            backend: listing.backend.clone(),
            error,
        };
        let gpu = match Gpu::open(&choice) {
            Ok(mut gpu) => {
                gpu.options = crate::adapter_arg::render_options();
                gpu
            }
            Err(e) => {
                eprintln!("skipped: {e:#}");
                skipped.push(skip(format!("{e:#}")));
                continue;
            }
        };
        announce(&gpu.report);
        let options = options_for(args, &prepared, &gpu.report, out.clone());
        let result = Plan::new(prepared.world.clone(), options)
            .and_then(|plan| plan.with_paging(paging(args)))
            .and_then(|plan| plan.with_gameplay(gameplay(args, &gpu.report)))
            .and_then(|plan| plan.run(&gpu));
        drop(gpu);
        match result {
            Ok((json, report)) => {
                println!("wrote {}", json.display());
                println!("wrote {}", report.display());
                inputs.push(Input {
                    run: strata_bench::merge::read_run(&json)?,
                    path: json,
                });
            }
            Err(e) => {
                eprintln!("stopped: {e:#}");
                skipped.push(skip(format!("{e:#}")));
                // A run that stopped part-way keeps its finished cells: merge them.
                let partial = out.join(format!(
                    "results-{}.json",
                    strata_bench::results::slug(&listing.name)
                ));
                if let Ok(run) = strata_bench::merge::read_run(&partial) {
                    inputs.push(Input { path: partial, run });
                }
            }
        }
    }
    let (report, md, json) = portability::write(&inputs, skipped, &args.out)?;
    println!("wrote {}", md.display());
    println!("wrote {}", json.display());
    summarize(&report);
    Ok(())
}

/// The batch's findings in a few lines.
pub fn summarize(report: &portability::Portability) {
    for g in &report.groups {
        println!(
            "group {} ({}x{}, {} adapter(s)): {} of {} cells disagree, {} refusal(s) or failure(s)",
            g.id,
            g.protocol.width,
            g.protocol.height,
            g.adapters.len(),
            g.disagreeing_cells,
            g.cells.len(),
            g.failures.len()
        );
        if let Some(why) = &g.separate_because {
            println!("  not compared with group A: {why}");
        }
    }
    for s in &report.skipped {
        println!(
            "adapter {} ({}) did not finish: {}",
            s.adapter, s.backend, s.error
        );
    }
}
