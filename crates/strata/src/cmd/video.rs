//! `strata video`: fly a camera path with one method or several side by
//! side, encode to H.264 MP4 through `ffmpeg` (or write numbered PNGs with
//! `--frames-dir`), and write the JSON sidecar with each method's frame
//! times and temporal flicker.

use crate::adapter_arg::AdapterArgs;
use crate::paged_arg::{PagedArgs, PagedWorld};
use crate::world_arg::WorldArgs;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use strata_bench::plan::{MethodChoice, every_method, parse_methods, parse_size};
use strata_bench::video::encode::{self, Ffmpeg, FrameSink, PngDir};
use strata_bench::video::path::{CameraPath, default_path, default_path_over};
use strata_bench::video::{self, PagedTerrain, VideoOptions, tiles};
use strata_level::EditSite;
use strata_level::source::{ColumnSource, SourceError, SourceTile};
use strata_render::paged::PageData;
use strata_store::ChunkCache;
use strata_viewer::paged::{Base, EditedPages, Planes};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// Comma-separated methods, each `name` or `name:setting` (as `compare`). Default: all.
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// Camera path file: `X,Y:YAW:EYE[:under] PITCH TIME` per line, and optionally `dig TIME`.
    /// Default: the fly-through around the level's edit site (see --print-path).
    #[arg(long, value_name = "FILE")]
    pub path: Option<PathBuf>,
    /// Play the path in this many seconds (its keyframe times scaled).
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f32>,
    /// Output frame size WxH (the methods share it as a tile grid).
    #[arg(long, value_name = "WxH", default_value = "1280x720")]
    pub size: String,
    /// Frames per second of the video.
    #[arg(long, value_name = "N", default_value_t = 30)]
    pub fps: u32,
    /// The MP4 to write (needs `ffmpeg` on the PATH); its sidecar is `<name>.json`.
    #[arg(long, value_name = "FILE", required_unless_present_any = ["frames_dir", "print_path"])]
    pub out: Option<PathBuf>,
    /// Write numbered PNGs (and `video.json`) into DIR instead of encoding.
    #[arg(long, value_name = "DIR", conflicts_with = "out")]
    pub frames_dir: Option<PathBuf>,
    /// Skip the temporal metric (no CPU reference traced per frame).
    #[arg(long)]
    pub no_temporal: bool,
    /// Turn the shared shadow map off.
    #[arg(long)]
    pub no_shadows: bool,
    /// Print the path (the default one unless --path) in the path-file format and exit.
    #[arg(long)]
    pub print_path: bool,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// `--gpu-budget`: ray-exact and ray-exact-fragment draw through pages
    /// streamed as the camera flies; the other methods draw the world whole.
    #[command(flatten)]
    pub paged: PagedArgs,
}

/// The paging of `--gpu-budget` (`None` without it).
fn paging(args: &Args) -> Option<strata_render::paged::PagedOptions> {
    args.paged
        .gpu_budget
        .map(|_| PagedWorld::options(&args.paged))
}

pub fn run(args: Args) -> anyhow::Result<()> {
    // Everything that can be wrong with the input, before the level and the GPU.
    let methods = choose_methods(args.methods.as_deref())?;
    let (width, height) = parse_size(&args.size)?;
    if args.fps == 0 {
        anyhow::bail!("--fps must be at least 1");
    }
    if let Some(d) = args.duration
        && !(d.is_finite() && d > 0.0)
    {
        anyhow::bail!("--duration must be a positive number of seconds (got {d})");
    }
    let file_path = match &args.path {
        Some(p) => Some(read_path(p)?),
        None => None,
    };
    if args.out.is_some() && !args.print_path {
        if !width.is_multiple_of(2) || !height.is_multiple_of(2) {
            anyhow::bail!(
                "--size {width}x{height}: H.264 needs even sides (or use --frames-dir for PNGs)"
            );
        }
        encode::check_ffmpeg()?;
    }
    // A store past the whole-world limit is never loaded whole: its
    // ground is read through the store's chunk cache and drawn through pages.
    if let Some(refusal) = past_the_limit(&args.world)? {
        let methods = paged_methods(args.methods.is_some(), methods, &refusal)?;
        return run_paged_store(&args, methods, (width, height), file_path);
    }
    let world = args.world.load()?;
    let mut path = file_path.unwrap_or_else(|| default_path(&world));
    if let Some(d) = args.duration {
        path = path.retimed(d);
    }
    if args.print_path {
        print!("{}", path.to_text());
        return Ok(());
    }
    // Fail on a keyframe inside terrain now, not after the GPU is up.
    path.resolve(&world.level).context("the camera path")?;

    let opts = options(&args, methods, (width, height), paging(&args));
    let recorded = |gpu: &strata_render::Gpu, sink: &mut dyn FrameSink, bar: &ProgressBar| {
        video::record(gpu, &world, &path, &opts, Some(sink), bar)
    };
    film(&args, &opts, &path, (width, height), recorded)
}

/// The video's options from the flags.
fn options(
    args: &Args,
    methods: Vec<MethodChoice>,
    (width, height): (u32, u32),
    paging: Option<strata_render::paged::PagedOptions>,
) -> VideoOptions {
    VideoOptions {
        tile: tiles::tile_size(methods.len(), width, height),
        methods,
        frame: Some((width, height)),
        fps: args.fps,
        shadows: !args.no_shadows,
        temporal: !args.no_temporal,
        overlap: None,
        paging,
    }
}

/// Open the GPU and the sink, record the frames (`record`), and write the
/// sidecar and the summary.
fn film(
    args: &Args,
    opts: &VideoOptions,
    path: &CameraPath,
    (width, height): (u32, u32),
    record: impl FnOnce(
        &strata_render::Gpu,
        &mut dyn FrameSink,
        &ProgressBar,
    ) -> anyhow::Result<video::Recording>,
) -> anyhow::Result<()> {
    let tile = opts.tile;
    let gpu = args.adapter.open()?;
    eprintln!(
        "adapter: {} ({}); {} method(s) in {}x{} tiles, {} frames at {} fps",
        gpu.report.name,
        gpu.report.backend,
        opts.methods.len(),
        tile.0,
        tile.1,
        video::frame_count(path.end() - path.start(), args.fps),
        args.fps
    );

    let (mut sink, sidecar): (Box<dyn FrameSink>, PathBuf) = match (&args.out, &args.frames_dir) {
        (_, Some(dir)) => (Box::new(PngDir::create(dir)?), dir.join("video.json")),
        (Some(out), None) => (
            Box::new(Ffmpeg::start(out, width, height, args.fps)?),
            out.with_extension("json"),
        ),
        (None, None) => anyhow::bail!("give --out FILE.mp4 or --frames-dir DIR"),
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:30} {pos}/{len} frames  {msg}  [{elapsed_precise}, {eta_precise} left]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let start = Instant::now();
    let recorded = record(&gpu, sink.as_mut(), &bar);
    bar.finish_and_clear();
    let mut recording = recorded?;
    let written = sink.finish()?;
    let total = start.elapsed().as_secs_f64();
    recording.output = written.clone();
    // The encoder's tail (flushing the last frames) counts towards output fps.
    recording.wall_seconds = total;
    recording.output_fps = f64::from(recording.frames) / total.max(1e-9);
    write_sidecar(&sidecar, &recording)?;
    println!("{written}");
    println!("wrote {}", sidecar.display());
    summarize(&recording);
    Ok(())
}

/// Why a whole world cannot be loaded from `--level`, when it is a store
/// past the whole-world limit (the memory a whole world may take here, as
/// `compare` says, or the texels one texture holds).
fn past_the_limit(world: &WorldArgs) -> anyhow::Result<Option<String>> {
    if let Some(refusal) = crate::cmd::compare::past_the_limit(world)? {
        return Ok(Some(refusal));
    }
    let Some(dir) = world.level.as_ref().filter(|d| {
        matches!(
            strata_store::fs::dir_kind(d),
            Ok(strata_store::fs::DirKind::Store)
        )
    }) else {
        return Ok(None);
    };
    let store = strata_store::DirStore::open(dir)
        .with_context(|| format!("opening the store in {}", dir.display()))?;
    let (w, h) = (store.store().width(), store.store().height());
    Ok((u64::from(w) * u64::from(h) > strata_level::generate::MAX_TEXELS).then(|| {
        format!(
            "the store in {} is {w}x{h} texels, past the whole-world limit of {} texels (one GPU texture)",
            dir.display(),
            strata_level::generate::MAX_TEXELS
        )
    }))
}

/// The methods that can draw a store past the limit: those asked for, each
/// of them paged (another is refused, naming the limit and the paged
/// methods), or every paged method when none was asked for.
fn paged_methods(
    asked: bool,
    methods: Vec<MethodChoice>,
    refusal: &str,
) -> anyhow::Result<Vec<MethodChoice>> {
    use strata_render::paged::PAGED_METHODS;
    let paged = |m: &MethodChoice| PAGED_METHODS.contains(&m.method.name);
    if asked {
        if let Some(m) = methods.iter().find(|m| !paged(m)) {
            anyhow::bail!(
                "{refusal}: `{}` draws whole worlds only; the methods that draw it through pages are {}",
                m.method.name,
                PAGED_METHODS.join(", ")
            );
        }
        return Ok(methods);
    }
    eprintln!(
        "note: {refusal}; filming the methods that draw it through pages: {}",
        PAGED_METHODS.join(", ")
    );
    Ok(methods.into_iter().filter(paged).collect())
}

/// Film a store past the whole-world limit: its ground (eye heights, the
/// dig site) read through the store's chunk cache, every method drawing
/// pages, and the crater dug into an edit layer over the pages (the
/// viewer's), never into the store on disk.
fn run_paged_store(
    args: &Args,
    methods: Vec<MethodChoice>,
    size: (u32, u32),
    file_path: Option<CameraPath>,
) -> anyhow::Result<()> {
    let Some(paged) = crate::paged_arg::open_paged(&args.world, &args.paged)? else {
        anyhow::bail!("the store could not be opened for paged drawing");
    };
    let (Some(cache), Some(dir)) = (paged.cache().cloned(), paged.dir.clone()) else {
        anyhow::bail!("the world past the limit is not a store");
    };
    let shell = strata_store::DirStore::open(&dir)
        .with_context(|| format!("opening the store in {}", dir.display()))?
        .store()
        .world_shell()
        .with_context(|| format!("reading the world in {}", dir.display()))?;
    let terrain = store_terrain(cache, dir, args.world.mid_rule())?;
    let mut path = match file_path {
        Some(p) => p,
        None => default_path_over(&shell, &*terrain.columns).context("the default path")?,
    };
    if let Some(d) = args.duration {
        path = path.retimed(d);
    }
    if args.print_path {
        print!("{}", path.to_text());
        return Ok(());
    }
    // Fail on a keyframe inside terrain now, not after the GPU is up.
    path.resolve(&*terrain.columns).context("the camera path")?;
    let opts = options(args, methods, size, Some(PagedWorld::options(&args.paged)));
    let recorded = |gpu: &strata_render::Gpu, sink: &mut dyn FrameSink, bar: &ProgressBar| {
        video::record_paged(gpu, &shell, &terrain, &path, &opts, Some(sink), bar)
    };
    film(args, &opts, &path, size, recorded)
}

/// A store's pages with an edit layer over them (the viewer's), read by
/// the renderers, the camera path and the CPU reference alike.
fn store_terrain(
    cache: Arc<ChunkCache>,
    dir: PathBuf,
    mid_rule: strata_level::MidRule,
) -> anyhow::Result<PagedTerrain> {
    let page = strata_render::paged::PAGE;
    if cache.tile_shape() != (page, page) {
        anyhow::bail!(
            "the store's chunks are {:?} texels; paged drawing needs {page}x{page}",
            cache.tile_shape()
        );
    }
    let pages = Arc::new(EditedPages::new(
        Base::Store {
            cache: cache.clone(),
            dir,
        },
        mid_rule,
    )?);
    let columns = Arc::new(DugColumns {
        pages: pages.clone(),
        cache,
        dug: Mutex::new(HashSet::new()),
    });
    let dig = {
        let (pages, columns) = (pages.clone(), columns.clone());
        move |site: &EditSite| -> anyhow::Result<Vec<u32>> {
            let dug = pages.dig(site)?;
            columns
                .dug
                .lock()
                .expect("dug lock")
                .extend(dug.chunks.iter().copied());
            Ok(dug.chunks)
        }
    };
    Ok(PagedTerrain {
        pages,
        columns,
        dig: Box::new(dig),
    })
}

/// A store's columns with the chunks dug into its edit layer read from
/// the layer (the others straight from the chunk cache, its summaries
/// and per-chunk pyramids kept).
struct DugColumns {
    pages: Arc<EditedPages>,
    cache: Arc<ChunkCache>,
    /// Chunks dug (grid row-major).
    dug: Mutex<HashSet<u32>>,
}

/// A dug chunk's planes as a tile.
struct DugTile(Arc<Planes>);

impl SourceTile for DugTile {
    fn planes(&self) -> (&[u8], &[u8]) {
        (&self.0.heights, &self.0.metas)
    }
}

impl DugColumns {
    fn is_dug(&self, ty: u64, tx: u64) -> Option<u32> {
        let gx = u64::from(self.pages.grid().0);
        let index = u32::try_from(ty * gx + tx).ok()?;
        self.dug
            .lock()
            .expect("dug lock")
            .contains(&index)
            .then_some(index)
    }
}

impl ColumnSource for DugColumns {
    fn size(&self) -> (u32, u32) {
        self.cache.size()
    }
    fn mid_rule(&self) -> strata_level::MidRule {
        ColumnSource::mid_rule(&*self.cache)
    }
    fn tile_shape(&self) -> (u32, u32) {
        self.cache.tile_shape()
    }
    fn tile(&self, ty: u64, tx: u64) -> Result<Arc<dyn SourceTile + '_>, SourceError> {
        if self.is_dug(ty, tx).is_none() {
            return self.cache.tile(ty, tx);
        }
        let planes = self
            .pages
            .planes(tx as u32, ty as u32)
            .map_err(SourceError)?;
        Ok(Arc::new(DugTile(planes)))
    }
    fn tile_tops(&self) -> Result<Option<Vec<u8>>, SourceError> {
        let dug: Vec<u32> = self.dug.lock().expect("dug lock").iter().copied().collect();
        let Some(mut tops) = self.cache.tile_tops()? else {
            return Ok(None);
        };
        for index in dug {
            let gx = self.pages.grid().0;
            let p = self
                .pages
                .planes(index % gx, index / gx)
                .map_err(SourceError)?;
            tops[index as usize] = PageData::from_planes(&p.heights, &p.metas, self.mid_rule(), 1)
                .map_err(SourceError)?
                .top(1);
        }
        Ok(Some(tops))
    }
}

fn choose_methods(list: Option<&str>) -> anyhow::Result<Vec<MethodChoice>> {
    match list {
        Some(list) => parse_methods(list, strata_render::methods::METHODS),
        None => Ok(every_method()),
    }
}

fn read_path(file: &Path) -> anyhow::Result<CameraPath> {
    let text = std::fs::read_to_string(file)
        .with_context(|| format!("reading the camera path {}", file.display()))?;
    CameraPath::parse(&text).with_context(|| format!("camera path {}", file.display()))
}

fn write_sidecar(path: &Path, recording: &video::Recording) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(recording)?;
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// One line per method: frame time, flicker, edit response.
fn summarize(r: &video::Recording) {
    println!(
        "{} frames in {:.1} s: {:.2} output frames per second",
        r.frames, r.wall_seconds, r.output_fps
    );
    for m in &r.methods {
        if let Some(e) = &m.error {
            println!("  {:<14} left out: {e}", m.method);
            continue;
        }
        let flicker = m.flicker.as_ref().map_or("-".to_string(), |f| {
            format!("{:.2} % (worst {:.2} %)", f.mean_percent, f.max_percent)
        });
        let edit = m
            .first_post_edit_ms
            .map_or("-".to_string(), |e| format!("{e:.1} ms"));
        println!(
            "  {:<14} frame {:>7.2} ms  flicker {flicker}  edit+frame {edit}",
            m.method, m.frame_ms_mean
        );
    }
}
