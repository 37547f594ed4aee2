//! What `strata render` writes, as typed structs (serialised with serde), and
//! the files: `color.png`, `depth.f32`, `render.json`. The harness may reuse them.

use crate::gpu::AdapterReport;
use crate::methods::MethodSettings;
use crate::renderer::Renderer;
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
    /// Paged terrain (`--gpu-budget`): the budget, the bytes it keeps (in
    /// `gpu_bytes` too), pages resident and uploaded, pending pixels of the
    /// last frame. `null` for a whole world.
    pub paging: Option<crate::paged::PagingStats>,
    /// Frames drawn before the timed ones until no pixel was pending (paged
    /// terrain only).
    pub converge_frames: Option<u32>,
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

/// Measure one view: a first frame, `warmup` untimed frames, `frames` timed
/// ones; then the report (adapter, timings, prep, memory) and the last
/// frame's colour and depth.
pub fn measure_view(
    renderer: &mut Renderer,
    world: &str,
    view: &ViewSpec,
    camera: &Camera,
    warmup: u32,
    frames: u32,
) -> anyhow::Result<(RenderReport, Vec<u8>, Vec<f32>)> {
    let adapter = renderer.adapter().clone();
    if frames == 0 {
        anyhow::bail!("at least one timed frame is needed");
    }
    let m = renderer.measure(camera, warmup, frames)?;
    let gpu_ms: Vec<f64> = m.timings.iter().filter_map(|t| t.gpu_ms).collect();
    let cpu_ms: Vec<f64> = m.timings.iter().map(|t| t.cpu_ms).collect();
    let n = m.timings.len() as f64;
    let mut passes: Vec<(String, f64)> = Vec::new();
    for t in &m.timings {
        for (label, ms) in &t.passes {
            match passes.iter_mut().find(|(l, _)| l == label) {
                Some(p) => p.1 += ms / n,
                None => passes.push((label.clone(), ms / n)),
            }
        }
    }
    let timestamps = gpu_ms.len() == m.timings.len();
    let settings = renderer.settings().clone();
    let retained = renderer.retained_bytes();
    let report = RenderReport {
        adapter: adapter.name.clone(),
        backend: adapter.backend.clone(),
        driver: adapter.driver.clone(),
        adapter_info: adapter.clone(),
        world: world.to_string(),
        method: renderer.method_name().to_string(),
        view: view.clone(),
        camera: *camera,
        size: [camera.width, camera.height],
        shadows: settings.shadows,
        settings,
        frames,
        timing_source: if timestamps {
            "gpu-timestamps-per-pass"
        } else {
            "cpu-submit-and-wait"
        },
        gpu_ms: if timestamps { Stats::of(&gpu_ms) } else { None },
        cpu_ms: Stats::of(&cpu_ms).unwrap_or_default(),
        passes,
        prep: Prep {
            setup_ms: renderer.setup_ms(),
            first_frame_ms: m.first_frame_ms,
            warmup_ms: m.warmup_ms,
            warmup_frames: warmup,
        },
        gpu_bytes: retained.gpu,
        cpu_bytes: retained.cpu,
        shared_gpu_bytes: renderer.shared_gpu_bytes(),
        paging: renderer.paged_terrain().map(|p| p.stats()),
        converge_frames: None,
    };
    let color = renderer.read_color()?;
    let depth = renderer.read_depth()?;
    Ok((report, color, depth))
}
