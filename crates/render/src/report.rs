//! What `strata render` writes, as typed structs (serialised with serde), and
//! the files: `color.png`, `depth.f32`, `render.json`. The harness may reuse them.

use crate::gpu::AdapterReport;
use crate::methods::MethodSettings;
use crate::timing::Stats;
use anyhow::Context;
use serde::Serialize;
use std::path::Path;
use strata_camera::Camera;
use strata_level::ViewSpec;

/// One-time costs, ms: building the renderer (terrain upload, pipelines,
/// method data), the first frame, and the warm-up frames together.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Prep {
    pub setup_ms: f64,
    pub first_frame_ms: f64,
    pub warmup_ms: f64,
    pub warmup_frames: u32,
}

/// One view rendered by one method: the `--json` line and `render.json`.
#[derive(Clone, Debug, Serialize)]
pub struct RenderReport {
    pub adapter: String,
    pub backend: String,
    pub driver: String,
    pub adapter_info: AdapterReport,
    pub world: String,
    pub method: String,
    pub view: ViewSpec,
    pub camera: Camera,
    pub size: [u32; 2],
    pub settings: MethodSettings,
    pub shadows: bool,
    pub frames: u32,
    /// `gpu-timestamps-per-pass` or `cpu-submit-and-wait` (no timestamps).
    pub timing_source: &'static str,
    /// Summed per-pass GPU time per frame; null without timestamp support.
    pub gpu_ms: Option<Stats>,
    /// CPU submit-and-wait per frame.
    pub cpu_ms: Stats,
    /// Mean GPU ms per pass label over the timed frames.
    pub passes: Vec<(String, f64)>,
    pub prep: Prep,
    /// Bytes the method retains beyond the shared resources.
    pub gpu_bytes: u64,
    pub cpu_bytes: u64,
    /// Bytes of the shared resources (terrain, uniforms, shadow map, targets).
    pub shared_gpu_bytes: u64,
}

/// Write `rgba` (row-major RGBA8) as a PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> anyhow::Result<()> {
    let img = image::RgbaImage::from_raw(width, height, rgba.to_vec())
        .context("colour buffer does not match the image size")?;
    img.save(path)
        .with_context(|| format!("writing {}", path.display()))
}

/// Write depth-buffer values as little-endian f32, row-major.
pub fn write_depth(path: &Path, depth: &[f32]) -> anyhow::Result<()> {
    let bytes: Vec<u8> = depth.iter().flat_map(|d| d.to_le_bytes()).collect();
    std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
}

/// Write `color.png`, `depth.f32` and `render.json` into `dir` (created).
pub fn write_outputs(
    dir: &Path,
    report: &RenderReport,
    color: &[u8],
    depth: &[f32],
) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let [w, h] = report.size;
    write_png(&dir.join("color.png"), w, h, color)?;
    write_depth(&dir.join("depth.f32"), depth)?;
    let json = serde_json::to_string_pretty(report)?;
    let path = dir.join("render.json");
    std::fs::write(&path, json + "\n").with_context(|| format!("writing {}", path.display()))
}
