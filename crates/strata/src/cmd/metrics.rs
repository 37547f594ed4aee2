//! `strata metrics`: score a rendered image against a reference view written
//! by `strata reference`.
//!
//! `--reference DIR` is one view directory (`reference.json`, `distance.f32`,
//! ...). The rendered image is either `--depth FILE.f32` (the raw depth
//! buffer, 0 near .. 1 far, `>= 1` = nothing drawn, as `strata render` writes
//! `depth.f32`) or `--distance FILE.f32` (distances along each pixel's ray,
//! non-finite = nothing drawn). Both are width*height f32 little-endian,
//! row-major. Depth is linearised with the reference's camera; `--camera
//! FILE.json` (a Camera, or any JSON object with a `camera` field, like the
//! render's metadata) checks that the image was rendered with that camera.
//! `--render DIR` is shorthand for `--depth DIR/depth.f32 --camera
//! DIR/render.json`, i.e. a view directory written by `strata render`.
//!
//! `strata metrics --reference ref/river --render render-out/river --json`

use anyhow::{Context, bail};
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;
use strata_camera::Camera;
use strata_reference::metrics::try_compare;
use strata_reference::output::{read_f32, read_view};
use strata_reference::{Metrics, distance_from_depth};

#[derive(clap::Args)]
pub struct Args {
    /// A view directory written by `strata reference` (`OUT/<view name>`).
    #[arg(long, value_name = "DIR")]
    pub reference: PathBuf,
    /// A view directory written by `strata render` (`depth.f32` + `render.json`).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["depth", "distance", "camera"])]
    pub render: Option<PathBuf>,
    /// Raw depth buffer (f32 LE, 0 near .. 1 far; >= 1 = nothing drawn).
    #[arg(long, value_name = "FILE.f32", conflicts_with = "distance")]
    pub depth: Option<PathBuf>,
    /// Distances along the pixel rays (f32 LE; inf/NaN = nothing drawn).
    #[arg(long, value_name = "FILE.f32")]
    pub distance: Option<PathBuf>,
    /// JSON holding the camera the image was rendered with; must match the reference's.
    #[arg(long, value_name = "FILE.json")]
    pub camera: Option<PathBuf>,
    /// Print one JSON line instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct Report {
    reference: String,
    rendered: String,
    /// `depth` or `distance`: how the rendered file was read.
    input: &'static str,
    #[serde(flatten)]
    metrics: Metrics,
}

fn read_camera(path: &PathBuf) -> anyhow::Result<Camera> {
    let text = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let value: serde_json::Value =
        serde_json::from_slice(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let inner = value.get("camera").cloned().unwrap_or(value);
    serde_json::from_value(inner).with_context(|| {
        format!(
            "{}: no camera (a Camera object or a `camera` field)",
            path.display()
        )
    })
}

pub fn run(mut args: Args) -> anyhow::Result<()> {
    // Written, not println!ed: a closed pipe (`| head`) is an error, not a panic.
    let mut out = std::io::stdout().lock();
    if let Some(dir) = args.render.take() {
        args.depth = Some(dir.join("depth.f32"));
        args.camera = Some(dir.join("render.json"));
    }
    let (header, reference) = read_view(&args.reference)
        .with_context(|| format!("reading reference view {}", args.reference.display()))?;
    let camera = header.camera;
    if let Some(path) = &args.camera {
        let rendered = read_camera(path)?;
        if rendered != camera {
            bail!(
                "the image was rendered with a different camera than the reference:\n  rendered  {rendered:?}\n  reference {camera:?}"
            );
        }
    }
    let n = reference.pixel_count();
    let (input, path, distance) = match (&args.depth, &args.distance) {
        (Some(p), _) => {
            let depth = read_f32(p, n).context("--depth (must match the reference's size)")?;
            ("depth", p, distance_from_depth(&camera, &depth))
        }
        (None, Some(p)) => (
            "distance",
            p,
            read_f32(p, n).context("--distance (must match the reference's size)")?,
        ),
        (None, None) => bail!("give --render DIR, --depth FILE.f32 or --distance FILE.f32"),
    };
    let metrics = try_compare(&reference, &distance)?;
    let report = Report {
        reference: args.reference.display().to_string(),
        rendered: path.display().to_string(),
        input,
        metrics,
    };
    if args.json {
        writeln!(out, "{}", serde_json::to_string(&report)?)?;
    } else {
        writeln!(
            out,
            "reference   {} ({}x{})",
            report.reference, reference.width, reference.height
        )?;
        writeln!(out, "rendered    {} (read as {input})", report.rendered)?;
        writeln!(out, "see-through {:.3} %", metrics.see_through)?;
        writeln!(out, "covers-sky  {:.3} %", metrics.covers_sky)?;
        writeln!(out, "depth p50   {:.4}", metrics.depth_p50)?;
        writeln!(out, "depth p95   {:.4}", metrics.depth_p95)?;
        writeln!(out, "coherence   {:.3} %", metrics.coherence)?;
        writeln!(out, "both solid  {:.3} %", metrics.both_solid)?;
    }
    Ok(())
}
