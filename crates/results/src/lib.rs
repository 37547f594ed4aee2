//! The results file (`results-<adapter>.json`): typed, serialised with serde.
//! Other tools read `rows` and `edit_rows`; the field names are a contract.
//!
//! With what reads it and needs no GPU: [`merge`] (the checks `strata
//! merge` makes before it combines runs), [`stats`] and [`report`]
//! (`report.md`). `strata-bench` measures and writes these files and
//! re-exports this crate as `strata_bench::results`; `strata-fuzz` fuzzes
//! the reader without building a GPU stack.

pub mod gameplay;
pub mod merge;
pub mod report;
pub mod stats;

#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;

use serde::{Deserialize, Serialize};
use strata_level::ViewSpec;

/// Bumped whenever the meaning of a field or of the protocol changes; `merge`
/// refuses to combine runs of different versions.
pub const PROTOCOL_VERSION: u32 = 1;

/// Where the frame time in the report's timing table comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimingSource {
    /// Per-pass GPU timestamps, summed.
    GpuTimestamps,
    /// CPU submit-and-wait (the adapter has no timestamps).
    CpuSubmitWait,
}

impl TimingSource {
    /// GPU timestamps where every frame carried them (`gpu`), else CPU
    /// submit-and-wait.
    pub fn of(gpu: Option<&Timing>) -> Self {
        if gpu.is_some() {
            TimingSource::GpuTimestamps
        } else {
            TimingSource::CpuSubmitWait
        }
    }
}

/// One run of `strata compare` on one adapter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunResults {
    pub protocol_version: u32,
    pub level: LevelInfo,
    pub adapter: AdapterInfo,
    pub settings: Settings,
    /// The revision the binary was built from (`git describe`, `-dirty` when
    /// its sources differed from the commit), baked in at build time; "unknown"
    /// when built outside git.
    pub source_revision: String,
    /// False while the run is in progress or when it was interrupted.
    pub complete: bool,
    pub rows: Vec<Row>,
    pub edit_rows: Vec<EditRow>,
    /// Cells or methods that failed (the run goes on without them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<Failure>,
    /// Why the edit protocol did not run, when it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edit_skipped: Option<String>,
    /// Each view's reference picture, relative to the directory holding
    /// this results file (absent in files written before it was recorded).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reference_images: Vec<ViewImage>,
    /// `compare --temporal`: each method's flicker along a short path.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub temporal: Vec<TemporalRow>,
    /// Before/after pictures of the edit camera for the edit figure.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub edit_images: Vec<EditImages>,
    /// `compare --gameplay`: the sustained edit workload (issue 35).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gameplay: Option<gameplay::GameplayResults>,
}

/// One method's temporal flicker along `compare --temporal`'s short path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TemporalRow {
    pub method: String,
    /// Percent of pixels flickering beyond the reference, mean over frame pairs.
    pub flicker_mean: f64,
    pub flicker_max: f64,
    pub frames: u32,
    pub fps: u32,
    /// The crater was dug part-way along the path.
    pub dug: bool,
    pub frame_ms_mean: f64,
}

/// The edit camera before the crater and on the first post-edit frame.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct EditImages {
    pub method: String,
    /// Relative to the directory holding the results file.
    pub before: String,
    pub after: String,
}

/// A picture of one view (the CPU reference's distance picture).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ViewImage {
    pub view: String,
    /// Relative to the directory holding the results file.
    pub image: String,
}

/// A method that could not be measured at a view (or anywhere: view "*").
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Failure {
    pub view: String,
    pub method: String,
    pub error: String,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelInfo {
    pub name: String,
    /// `Level::content_hash`: size, mid rule and both planes.
    pub hash: String,
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AdapterInfo {
    pub name: String,
    pub backend: String,
    pub driver: String,
    pub timestamps: bool,
}

/// Everything that must agree for two runs to be comparable.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    pub far: f32,
    /// Timed frames per cell.
    pub frames: u32,
    pub shadows: bool,
    /// Method labels in report order (`name` or `name:setting`).
    pub methods: Vec<String>,
    /// Each method's effective knob, same order (`voxel grid=(4,8,2) steps=100`).
    pub method_settings: Vec<String>,
    pub views: Vec<ViewSpec>,
    /// Pre-timing frames at a renderer's first view: the minimum plus enough
    /// for the largest incremental build budget to cover the level.
    pub warmup_first_view: u32,
    /// Pre-timing frames at every later view.
    pub warmup_frames: u32,
    /// Ms of back-to-back untimed frames before each cell's warm-up (0: none;
    /// absent in results written before it existed).
    #[serde(default)]
    pub hold_busy_ms: u32,
    pub edits: bool,
    /// The cave-ceiling convention (`original` or `vange-rs`).
    pub mid_rule: String,
}

/// Mean / median / min / max of a set of frame times, and the samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    pub mean: f64,
    pub median: f64,
    pub min: f64,
    pub max: f64,
    pub samples: Vec<f64>,
}

/// One (view, method) cell. Percent fields are percent of all pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    pub view: String,
    pub pitch: f32,
    pub method: String,
    pub see_through: f64,
    pub covers_sky: f64,
    /// World units.
    pub depth_p50: f64,
    pub depth_p95: f64,
    pub coherence: f64,
    /// Null without timestamp support.
    pub gpu_ms_mean: Option<f64>,
    pub cpu_ms_mean: f64,
    pub gpu_ms: Option<Timing>,
    pub cpu_ms: Timing,
    pub timing_source: TimingSource,
    pub prep_setup_ms: f64,
    pub prep_first_frame_ms: f64,
    pub prep_warmup_ms: f64,
    /// Persistent method-specific bytes (shared resources excluded).
    pub gpu_bytes: u64,
    pub cpu_bytes: u64,
    /// Mean GPU ms of each timed pass (label order of the first frame); empty without timestamps.
    #[serde(default)]
    pub passes: Vec<PassTime>,
    /// The cell picture, relative to the output directory, which is the
    /// directory holding the results file (`merge --portability` finds the
    /// pictures there).
    pub image: String,
    /// ꟻLIP against the CPU colour reference (absent in older results files
    /// and in the browser's runs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flip: Option<FlipScore>,
    /// Paged terrain's numbers where the method drew through pages
    /// (`compare --gpu-budget`); absent for the whole-world path.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paging: Option<CellPaging>,
}

/// What a paged cell kept on the GPU and how it converged (issue 33).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellPaging {
    /// The budget, bytes.
    pub gpu_budget: u64,
    /// Bytes the paged terrain keeps on the GPU (at most the budget).
    pub gpu_bytes: u64,
    /// Slots of the atlas, and pages resident when the cell was timed.
    pub slots: u32,
    pub resident_pages: u32,
    pub resident_bytes: u64,
    /// Frames drawn at the view until nothing was pending, before timing.
    pub converge_frames: u32,
    /// Pixels drawn from a missing page in the last timed frame (0 once
    /// converged).
    pub pending_pixels: u32,
    /// Chunks that failed to read.
    pub read_errors: u32,
}

/// A cell's perceptual colour error: ꟻLIP between its picture and the CPU
/// colour reference (`strata_reference::shading`), per pixel in [0, 1].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlipScore {
    /// Mean ꟻLIP over the image.
    pub mean: f64,
    /// Percent of pixels with ꟻLIP above 0.5 (clearly visible errors).
    pub over_half: f64,
    /// The error map (magma colours), relative to the output directory.
    pub image: String,
}

impl Row {
    /// The frame time the report ranks by: GPU when timed, else CPU.
    pub fn frame_ms(&self) -> f64 {
        self.gpu_ms_mean.unwrap_or(self.cpu_ms_mean)
    }

    /// The samples behind [`Row::frame_ms`].
    pub fn frame_samples(&self) -> &[f64] {
        match &self.gpu_ms {
            Some(t) => &t.samples,
            None => &self.cpu_ms.samples,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassTime {
    pub label: String,
    pub mean_ms: f64,
}

/// The disagreement between an edited renderer and a fresh build of the
/// edited level after some number of post-edit frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EditCheck {
    pub frames: u32,
    /// Percent of pixels where one image has terrain and the other sky.
    pub class_mismatch: f64,
    /// 95th percentile of |distance difference| where both hit, world units.
    pub depth_p95: f64,
    pub consistent: bool,
}

/// One method under the edit protocol.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EditRow {
    pub method: String,
    /// Median of independent first post-edit frames (each from a fresh renderer).
    pub first_frame_cpu_ms: f64,
    pub first_frame_gpu_ms: Option<f64>,
    pub first_frame_cpu_samples: Vec<f64>,
    pub first_frame_gpu_samples: Vec<f64>,
    /// Median of frames of a renderer built fresh from the edited level.
    pub steady_cpu_ms: f64,
    pub steady_gpu_ms: Option<f64>,
    /// First of 1, 2, 4, 8, 16 post-edit frames after which the edited
    /// renderer matches the fresh one; null if never within 16.
    pub consistent_after_frames: Option<u32>,
    pub checks: Vec<EditCheck>,
}

/// One accuracy field of one cell on which an adapter differs from the baseline.
/// Found by [`merge::disagreements`], listed in `report.md`.
#[derive(Clone, Debug, PartialEq)]
pub struct Disagreement {
    pub adapter: String,
    pub view: String,
    pub method: String,
    pub field: &'static str,
    pub baseline: Option<f64>,
    pub other: Option<f64>,
}

/// The frame counts at which consistency is checked.
pub const EDIT_CHECK_FRAMES: [u32; 5] = [1, 2, 4, 8, 16];
/// Consistency thresholds (paper §Dynamic-edit protocol).
pub const EDIT_MAX_CLASS_MISMATCH: f64 = 0.01;
pub const EDIT_MAX_DEPTH_P95: f64 = 0.1;

/// A file-name-safe form of an adapter name: lower-case ASCII letters,
/// digits and single dashes ("NVIDIA H100 80GB HBM3" -> "nvidia-h100-80gb-hbm3").
pub fn slug(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('-') {
            out.push('-');
        }
    }
    while out.ends_with('-') {
        out.pop();
    }
    if out.is_empty() {
        "unknown".into()
    } else {
        out
    }
}

impl RunResults {
    pub fn file_name(&self) -> String {
        format!("results-{}.json", slug(&self.adapter.name))
    }

    pub fn from_json(text: &str) -> anyhow::Result<Self> {
        Ok(serde_json::from_str(text)?)
    }

    pub fn to_json(&self) -> anyhow::Result<String> {
        Ok(serde_json::to_string_pretty(self)?)
    }

    /// Write atomically (temporary file + rename), so an interrupted run
    /// never leaves a half-written file in place of the last good one.
    pub fn write(&self, dir: &std::path::Path) -> anyhow::Result<std::path::PathBuf> {
        use anyhow::Context;
        let path = dir.join(self.file_name());
        let tmp = dir.join(format!(".{}.tmp", self.file_name()));
        std::fs::write(&tmp, self.to_json()?)
            .with_context(|| format!("writing {}", tmp.display()))?;
        std::fs::rename(&tmp, &path).with_context(|| format!("renaming to {}", path.display()))?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slugs_are_file_safe() {
        assert_eq!(slug("NVIDIA H100 80GB HBM3"), "nvidia-h100-80gb-hbm3");
        assert_eq!(
            slug("llvmpipe (LLVM 15.0.7, 256 bits)"),
            "llvmpipe-llvm-15-0-7-256-bits"
        );
        assert_eq!(slug("  /../ "), "unknown");
    }
}
