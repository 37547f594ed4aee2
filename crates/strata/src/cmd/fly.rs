//! `strata fly`: a fly-through over paged terrain (issue 33). Per frame the
//! GPU and CPU ms, pending pixels, bytes uploaded and bytes resident; a
//! summary (mean, p99, max). `--scale` flies the same path over stores of
//! 2048x16384, 16384², 32768² and 65536² (generated once, reused) and
//! writes the scaling table: frame time and memory against world size.

use crate::adapter_arg::AdapterArgs;
use crate::paged_arg::{PagedArgs, PagedWorld, open_paged};
use crate::world_arg::WorldArgs;
use anyhow::{Context, bail};
use serde::Serialize;
use std::path::{Path, PathBuf};
use strata_camera::Camera;
use strata_level::ViewSpec;
use strata_markdown::Table;
use strata_render::{MethodSettings, Renderer};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub world: WorldArgs,
    /// A paged method: ray-exact, ray-exact-fragment or mesh.
    #[arg(long, default_value = "ray-exact")]
    pub method: String,
    /// Camera path file (`X,Y:YAW:EYE[:under] PITCH TIME` per line, as `strata
    /// video` reads). Default: the world's views in order, flown at --speed.
    #[arg(long, value_name = "FILE")]
    pub path: Option<PathBuf>,
    /// Default path: ground speed, texels per second.
    #[arg(long, default_value_t = 240.0)]
    pub speed: f32,
    /// Frames to fly (at --fps along the path).
    #[arg(long, default_value_t = 600)]
    pub frames: u32,
    /// Path seconds per frame is 1 / fps.
    #[arg(long, default_value_t = 60.0)]
    pub fps: f32,
    /// Image size.
    #[arg(long, default_value = "1280x800", value_parser = super::render::parse_size)]
    pub size: (u32, u32),
    /// Far plane, world units (default: the camera's, 600, as the paper).
    #[arg(long, value_name = "TEXELS", value_parser = super::render::parse_far)]
    pub far: Option<f32>,
    /// Fly at this altitude (texels above 0; terrain reaches 255) instead of
    /// the views' eye heights, where higher: the horizon path.
    #[arg(long, value_name = "Z")]
    pub altitude: Option<f32>,
    /// Pitch every pose by this many degrees (negative looks down) instead
    /// of the views' own.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub pitch: Option<f32>,
    #[arg(long)]
    pub no_shadows: bool,
    #[command(flatten)]
    pub paged: PagedArgs,
    #[command(flatten)]
    pub adapter: AdapterArgs,
    /// Fly stores of 2048x16384, 16384², 32768² and 65536² (made under
    /// --scale-dir by `strata generate --to store` when absent) and write
    /// the scaling table; --level is ignored.
    #[arg(long)]
    pub scale: bool,
    /// Where --scale keeps its stores.
    #[arg(long, value_name = "DIR", default_value = "fly-stores")]
    pub scale_dir: PathBuf,
    /// --scale: the sizes to fly, comma-separated `WxH`.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "2048x16384,16384x16384,32768x32768,65536x65536"
    )]
    pub scale_sizes: Vec<String>,
    /// Output directory: fly.json, frames.csv (per size with --scale).
    #[arg(long, default_value = "fly-out")]
    pub out: PathBuf,
}

/// One frame of the flight.
#[derive(Clone, Debug, Serialize)]
pub struct FlyFrame {
    pub frame: u32,
    pub gpu_ms: Option<f64>,
    pub cpu_ms: f64,
    /// Percent of the frame's pixels drawn from a missing page.
    pub pending_pct: f64,
    pub uploaded_bytes: u64,
    pub resident_bytes: u64,
    /// Everything the paged path keeps on the GPU within the budget (the
    /// atlas's plan, and the mesh's index pool and draw records).
    pub gpu_bytes: u64,
}

/// Mean, 99th percentile, largest.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Summary {
    pub mean: f64,
    pub p99: f64,
    pub max: f64,
}

impl Summary {
    fn of(values: &[f64]) -> Summary {
        if values.is_empty() {
            return Summary::default();
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let p99 = v[((v.len() as f64 * 0.99).ceil() as usize).clamp(1, v.len()) - 1];
        Summary {
            mean: v.iter().sum::<f64>() / v.len() as f64,
            p99,
            max: v[v.len() - 1],
        }
    }
}

/// What one flight measured.
#[derive(Clone, Debug, Serialize)]
pub struct FlyReport {
    pub world: String,
    pub world_size: [u32; 2],
    pub method: String,
    pub adapter: String,
    pub backend: String,
    pub size: [u32; 2],
    pub far: f32,
    pub shadows: bool,
    pub gpu_budget: u64,
    /// Most bytes the paged path kept on the GPU in a frame (≤ the budget;
    /// the mesh's index pool included).
    pub paged_gpu_bytes: u64,
    /// The renderer's own targets, uniforms and shadow map (every world
    /// alike; the atlas is in `paged_gpu_bytes`).
    pub frame_gpu_bytes: u64,
    pub setup_ms: f64,
    /// Frames and wall ms at the start pose until nothing was pending
    /// (before the flight; `null`: it did not converge in 600 frames).
    pub start_frames: Option<u32>,
    pub start_ms: f64,
    pub frames: u32,
    pub gpu_ms: Option<Summary>,
    pub cpu_ms: Summary,
    pub pending_pct: Summary,
    pub uploaded_bytes_total: u64,
    pub resident_bytes_max: u64,
    /// Peak resident set of the process after the flight, bytes (Linux).
    pub process_rss_peak: Option<u64>,
    pub revision: &'static str,
    pub per_frame: Vec<FlyFrame>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    if args.frames == 0 || args.fps <= 0.0 || args.speed <= 0.0 {
        bail!("--frames, --fps and --speed must be positive");
    }
    if args.scale {
        return run_scale(&args);
    }
    let report = fly_one(&args, &args.world, &args.out)?;
    print_summary(&report);
    Ok(())
}

fn fly_one(args: &Args, world_args: &WorldArgs, out: &Path) -> anyhow::Result<FlyReport> {
    let mut paged_args = args.paged.clone();
    paged_args.gpu_budget = Some(
        paged_args
            .gpu_budget
            .unwrap_or(strata_render::paged::DEFAULT_GPU_BUDGET),
    );
    let world = open_paged(world_args, &paged_args)?.context("fly draws paged terrain")?;
    let (w, h) = args.size;
    let cameras = path_cameras(args, &world)?;
    let gpu = args.adapter.open()?;
    let settings = MethodSettings {
        shadows: !args.no_shadows,
        ..MethodSettings::default()
    };
    let mut renderer = Renderer::new_paged(
        &gpu,
        world.source.clone(),
        &world.colors,
        &args.method,
        &settings,
        w,
        h,
        PagedWorld::options(&paged_args),
    )?;
    let plan = *renderer.paged_terrain().expect("paged").plan();
    let budget = renderer.paged_terrain().expect("paged").stats().gpu_budget;
    // The start pose first, until nothing is pending (a loading screen):
    // the flight then measures streaming as the camera moves, not the
    // empty atlas of the first frame.
    let start = std::time::Instant::now();
    let start_frames = match renderer.converge(&cameras[0], 600) {
        Ok(n) => Some(n),
        Err(e) => {
            eprintln!("fly: the start pose did not converge: {e:#}");
            None
        }
    };
    let start_ms = start.elapsed().as_secs_f64() * 1e3;
    let mut frames = Vec::with_capacity(cameras.len());
    let pixels = f64::from(w) * f64::from(h);
    let mut reported_error: Option<String> = None;
    for (i, camera) in cameras.iter().enumerate() {
        let t = renderer.render_frame(camera)?;
        let stats = renderer.paged_terrain().expect("paged").stats();
        frames.push(FlyFrame {
            frame: i as u32,
            gpu_ms: t.gpu_ms,
            cpu_ms: t.cpu_ms + t.record_ms,
            pending_pct: 100.0 * f64::from(stats.pending_pixels) / pixels,
            uploaded_bytes: stats.uploaded_bytes,
            resident_bytes: stats.resident_bytes,
            gpu_bytes: stats.gpu_bytes,
        });
        if let (Some(e), true) = (&stats.first_error, reported_error.is_none()) {
            eprintln!("fly: frame {i}: {e}");
            reported_error = Some(e.clone());
        }
    }
    let gpu_ms: Vec<f64> = frames.iter().filter_map(|f| f.gpu_ms).collect();
    let cpu_ms: Vec<f64> = frames.iter().map(|f| f.cpu_ms).collect();
    let pending: Vec<f64> = frames.iter().map(|f| f.pending_pct).collect();
    let report = FlyReport {
        world: world.name.clone(),
        world_size: [world.size.0, world.size.1],
        method: args.method.clone(),
        adapter: gpu.report.name.clone(),
        backend: gpu.report.backend.clone(),
        size: [w, h],
        far: cameras.first().map_or(0.0, |c| c.far),
        shadows: settings.shadows,
        // With the mesh's index pool: the plan has the atlas's part.
        gpu_budget: budget,
        paged_gpu_bytes: frames.iter().map(|f| f.gpu_bytes).max().unwrap_or(0),
        // The shared frame counts the atlas as its terrain texture.
        frame_gpu_bytes: renderer.shared_gpu_bytes() - plan.atlas_bytes,
        setup_ms: renderer.setup_ms(),
        start_frames,
        start_ms,
        frames: frames.len() as u32,
        gpu_ms: (gpu_ms.len() == frames.len()).then(|| Summary::of(&gpu_ms)),
        cpu_ms: Summary::of(&cpu_ms),
        pending_pct: Summary::of(&pending),
        uploaded_bytes_total: frames.iter().map(|f| f.uploaded_bytes).sum(),
        resident_bytes_max: frames.iter().map(|f| f.resident_bytes).max().unwrap_or(0),
        process_rss_peak: peak_rss(),
        revision: strata_bench::plan::SOURCE_REVISION,
        per_frame: frames,
    };
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let json = serde_json::to_string_pretty(&report)?;
    std::fs::write(out.join("fly.json"), json + "\n")
        .with_context(|| format!("writing {}", out.join("fly.json").display()))?;
    let mut csv =
        String::from("frame,gpu_ms,cpu_ms,pending_pct,uploaded_bytes,resident_bytes,gpu_bytes\n");
    for f in &report.per_frame {
        csv.push_str(&format!(
            "{},{},{:.4},{:.4},{},{},{}\n",
            f.frame,
            f.gpu_ms.map(|g| format!("{g:.4}")).unwrap_or_default(),
            f.cpu_ms,
            f.pending_pct,
            f.uploaded_bytes,
            f.resident_bytes,
            f.gpu_bytes
        ));
    }
    std::fs::write(out.join("frames.csv"), csv)
        .with_context(|| format!("writing {}", out.join("frames.csv").display()))?;
    Ok(report)
}

/// The flight's cameras, one per frame: `--path`, else the world's views
/// in order at `--speed`.
fn path_cameras(args: &Args, world: &PagedWorld) -> anyhow::Result<Vec<Camera>> {
    let (w, h) = args.size;
    let keys: Vec<(ViewSpec, f32)> = match &args.path {
        Some(file) => {
            let text = std::fs::read_to_string(file)
                .with_context(|| format!("reading the camera path {}", file.display()))?;
            let path = strata_bench::video::path::CameraPath::parse(&text)
                .with_context(|| format!("camera path {}", file.display()))?;
            path.keys.iter().map(|k| (k.view.clone(), k.time)).collect()
        }
        None => {
            if world.views.len() < 2 {
                bail!("the world has fewer than two views: give --path FILE");
            }
            let mut t = 0.0;
            let mut keys = vec![(world.views[0].clone(), 0.0)];
            for pair in world.views.windows(2) {
                let (a, b) = (&pair[0], &pair[1]);
                t += (b.x - a.x).hypot(b.y - a.y).max(1.0) / args.speed;
                keys.push((b.clone(), t));
            }
            keys
        }
    };
    // Each keyframe's eye altitude from the ground under it (one chunk read).
    let mut poses = Vec::with_capacity(keys.len());
    for (view, time) in &keys {
        let mut c = world.camera(view, w, h)?;
        if let Some(z) = args.altitude {
            c.position.z = c.position.z.max(z);
        }
        poses.push((
            c.position,
            view.yaw,
            args.pitch.unwrap_or(view.pitch),
            *time,
        ));
    }
    let mut cameras = Vec::with_capacity(args.frames as usize);
    for i in 0..args.frames {
        let t = i as f32 / args.fps;
        let k = poses
            .windows(2)
            .position(|p| t < p[1].3)
            .unwrap_or(poses.len().saturating_sub(2));
        let (a, b) = (poses[k], poses[(k + 1).min(poses.len() - 1)]);
        let s = if b.3 > a.3 {
            ((t - a.3) / (b.3 - a.3)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        // Smoothstep between keys; yaw the short way round.
        let s = s * s * (3.0 - 2.0 * s);
        let yaw = a.1 + ((b.1 - a.1 + 180.0).rem_euclid(360.0) - 180.0) * s;
        let mut c = Camera::new(
            a.0.lerp(b.0, s),
            yaw.rem_euclid(360.0),
            a.2 + (b.2 - a.2) * s,
            w,
            h,
        )?;
        if let Some(far) = args.far {
            c.far = far;
        }
        cameras.push(c);
    }
    Ok(cameras)
}

fn run_scale(args: &Args) -> anyhow::Result<()> {
    let exe = std::env::current_exe().context("locating the strata binary")?;
    std::fs::create_dir_all(&args.scale_dir)
        .with_context(|| format!("creating {}", args.scale_dir.display()))?;
    let mut reports = Vec::new();
    for size in &args.scale_sizes {
        let (w, h) = super::render::parse_size(size).map_err(anyhow::Error::msg)?;
        let dir = args.scale_dir.join(format!("world-{w}x{h}"));
        if !dir.join("zarr.json").exists() {
            eprintln!("fly --scale: generating {w}x{h} into {}", dir.display());
            let status = std::process::Command::new(&exe)
                .args(["generate", "--size", size, "--to", "store", "--out"])
                .arg(&dir)
                .status()
                .context("running strata generate")?;
            if !status.success() {
                bail!("strata generate --size {size} --to store failed ({status})");
            }
        }
        let world_args = WorldArgs {
            level: Some(dir),
            ..args.world.clone()
        };
        let report = fly_one(args, &world_args, &args.out.join(format!("{w}x{h}")))?;
        print_summary(&report);
        reports.push(report);
    }
    let mut table = Table::new()
        .left("world")
        .right("texels")
        .right("gpu ms mean")
        .right("gpu ms p99")
        .right("cpu ms mean")
        .right("pending % mean")
        .right("pending % max")
        .right("paged GPU MiB")
        .right("uploaded MiB")
        .right("RSS MiB");
    for r in &reports {
        let g = r.gpu_ms.unwrap_or_default();
        table.row([
            format!("{}x{}", r.world_size[0], r.world_size[1]),
            format!(
                "{:.2e}",
                f64::from(r.world_size[0]) * f64::from(r.world_size[1])
            ),
            format!("{:.3}", g.mean),
            format!("{:.3}", g.p99),
            format!("{:.3}", r.cpu_ms.mean),
            format!("{:.3}", r.pending_pct.mean),
            format!("{:.2}", r.pending_pct.max),
            format!("{:.1}", r.paged_gpu_bytes as f64 / 1048576.0),
            format!("{:.1}", r.uploaded_bytes_total as f64 / 1048576.0),
            r.process_rss_peak
                .map(|b| format!("{:.0}", b as f64 / 1048576.0))
                .unwrap_or_default(),
        ]);
    }
    let first = reports.first().context("no sizes flown")?;
    let text = format!(
        "# fly --scale\n\nRevision: {}\nMachine: {} ({})\n\n{} at {}x{}, far {}, shadows {}, budget {} B, {} frames at {} fps, {} texels/s.\n\n{}",
        first.revision,
        first.adapter,
        first.backend,
        first.method,
        first.size[0],
        first.size[1],
        first.far,
        first.shadows,
        first.gpu_budget,
        first.frames,
        args.fps,
        args.speed,
        table
    );
    let texels = |r: &FlyReport| f64::from(r.world_size[0]) * f64::from(r.world_size[1]);
    let line = |f: &dyn Fn(&FlyReport) -> f64| reports.iter().map(|r| (texels(r), f(r))).collect();
    let figures = args.out.join("figures");
    let time = strata_bench::figures::by_world_size(
        &figures,
        "scaling-time",
        "frame time along the path (ms)",
        "ms",
        &[
            (
                "GPU mean".into(),
                line(&|r| r.gpu_ms.unwrap_or_default().mean),
            ),
            (
                "GPU p99".into(),
                line(&|r| r.gpu_ms.unwrap_or_default().p99),
            ),
            ("CPU mean".into(), line(&|r| r.cpu_ms.mean)),
        ],
    )?;
    let memory = strata_bench::figures::by_world_size(
        &figures,
        "scaling-memory",
        "memory (MiB): paged terrain on the GPU, process peak RSS",
        "MiB",
        &[
            (
                "paged GPU".into(),
                line(&|r| r.paged_gpu_bytes as f64 / 1048576.0),
            ),
            (
                "RSS peak".into(),
                line(&|r| r.process_rss_peak.unwrap_or(0) as f64 / 1048576.0),
            ),
        ],
    )?;
    let text = format!(
        "{text}\n![{}]({})\n\n![{}]({})\n",
        time.title, time.png, memory.title, memory.png
    );
    std::fs::create_dir_all(&args.out)?;
    std::fs::write(args.out.join("scaling.md"), &text)?;
    std::fs::write(
        args.out.join("scaling.json"),
        serde_json::to_string_pretty(
            &reports
                .iter()
                .map(|r| {
                    let mut r = r.clone();
                    r.per_frame.clear();
                    r
                })
                .collect::<Vec<_>>(),
        )? + "\n",
    )?;
    println!("{text}");
    Ok(())
}

fn print_summary(r: &FlyReport) {
    let g = r
        .gpu_ms
        .map(|g| format!("{:.3} / {:.3} / {:.3}", g.mean, g.p99, g.max))
        .unwrap_or_else(|| "n/a".into());
    println!(
        "{}x{} {} on {} ({}): start converged in {} frames ({:.0} ms); {} frames; GPU ms mean/p99/max {g}; CPU ms mean/p99/max {:.3} / {:.3} / {:.3}; pending % mean {:.3} max {:.2}; paged GPU {} B of {} B; uploaded {:.1} MiB; RSS peak {}",
        r.world_size[0],
        r.world_size[1],
        r.method,
        r.adapter,
        r.backend,
        r.start_frames
            .map(|n| n.to_string())
            .unwrap_or_else(|| "(not)".into()),
        r.start_ms,
        r.frames,
        r.cpu_ms.mean,
        r.cpu_ms.p99,
        r.cpu_ms.max,
        r.pending_pct.mean,
        r.pending_pct.max,
        r.paged_gpu_bytes,
        r.gpu_budget,
        r.uploaded_bytes_total as f64 / 1048576.0,
        r.process_rss_peak
            .map(|b| format!("{:.0} MiB", b as f64 / 1048576.0))
            .unwrap_or_else(|| "n/a".into())
    );
}

/// The process's peak resident set (VmHWM), Linux only.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
