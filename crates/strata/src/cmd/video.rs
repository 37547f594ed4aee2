//! `strata video`: fly a camera path with one method or several side by
//! side, encode to H.264 MP4 through `ffmpeg` (or write numbered PNGs with
//! `--frames-dir`), and write the JSON sidecar with each method's frame
//! times and temporal flicker.

use crate::adapter_arg::AdapterArgs;
use crate::paged_arg::{PagedArgs, PagedWorld};
use crate::world_arg::WorldArgs;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;
use strata_bench::plan::{MethodChoice, every_method, parse_methods, parse_size};
use strata_bench::video::encode::{self, Ffmpeg, FrameSink, PngDir};
use strata_bench::video::path::{CameraPath, default_path};
use strata_bench::video::{self, VideoOptions, tiles};

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

    let tile = tiles::tile_size(methods.len(), width, height);
    let opts = VideoOptions {
        methods,
        tile,
        frame: Some((width, height)),
        fps: args.fps,
        shadows: !args.no_shadows,
        temporal: !args.no_temporal,
        overlap: None,
        paging: paging(&args),
    };
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
    let recorded = video::record(&gpu, &world, &path, &opts, Some(sink.as_mut()), &bar);
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
