//! Hand-made results for the report and merge tests.

use crate::stats::summarize;
use crate::*;
use strata_level::ViewSpec;

pub fn view(name: &str, pitch: f32) -> ViewSpec {
    ViewSpec {
        name: name.into(),
        x: 1.0,
        y: 2.0,
        yaw: 0.0,
        eye: 10.0,
        under: false,
        pitch,
    }
}

/// A row with see-through `see`, coherence `coh` and GPU frames `gpu`.
pub fn row(view: &str, pitch: f32, method: &str, see: f64, coh: f64, gpu: &[f64]) -> Row {
    // CPU time is GPU + 1 ms; without GPU samples, a constant 5 ms.
    let cpu: Vec<f64> = if gpu.is_empty() {
        vec![5.0; 3]
    } else {
        gpu.iter().map(|g| g + 1.0).collect()
    };
    let gpu_t = summarize(gpu);
    let cpu_t = summarize(&cpu).expect("cpu samples");
    Row {
        view: view.into(),
        pitch,
        method: method.into(),
        see_through: see,
        covers_sky: 0.1,
        depth_p50: 0.2,
        depth_p95: 1.5,
        coherence: coh,
        gpu_ms_mean: gpu_t.as_ref().map(|t| t.mean),
        cpu_ms_mean: cpu_t.mean,
        timing_source: TimingSource::of(gpu_t.as_ref()),
        gpu_ms: gpu_t,
        cpu_ms: cpu_t,
        prep_setup_ms: 10.0,
        prep_first_frame_ms: 20.0,
        prep_warmup_ms: 30.0,
        gpu_bytes: 3 * 1024 * 1024,
        cpu_bytes: 0,
        passes: Vec::new(),
        image: format!("cells/{view}-{method}.png"),
        flip: None,
        paging: None,
    }
}

/// Two views (0° and -90°) x two methods on adapter `adapter`.
pub fn run(adapter: &str) -> RunResults {
    let views = vec![view("river", 0.0), view("spiral", -90.0)];
    RunResults {
        temporal: Vec::new(),
        edit_images: Vec::new(),
        gameplay: None,
        protocol_version: PROTOCOL_VERSION,
        level: LevelInfo {
            name: "test".into(),
            hash: "abcdef0123456789".into(),
            width: 64,
            height: 64,
        },
        adapter: AdapterInfo {
            name: adapter.into(),
            backend: "Vulkan".into(),
            driver: "1.0".into(),
            timestamps: true,
        },
        settings: Settings {
            width: 32,
            height: 20,
            far: 600.0,
            frames: 4,
            shadows: true,
            methods: vec!["ray".into(), "mesh".into()],
            method_settings: vec!["ray steps=128".into(), "mesh q=0.5".into()],
            warmup_first_view: 4,
            warmup_frames: 3,
            hold_busy_ms: 0,
            views,
            edits: true,
            mid_rule: "original".into(),
        },
        source_revision: "abc123".into(),
        complete: true,
        rows: vec![
            row("river", 0.0, "ray", 0.6, 0.4, &[4.0, 5.0, 6.0]),
            row("river", 0.0, "mesh", 0.3, 0.1, &[2.0, 2.0, 2.0]),
            row("spiral", -90.0, "ray", 0.1, 0.5, &[6.0, 7.0, 8.0]),
            row("spiral", -90.0, "mesh", 0.0, 0.1, &[3.0, 3.0, 3.0]),
        ],
        edit_rows: vec![EditRow {
            method: "ray".into(),
            first_frame_cpu_ms: 8.70,
            first_frame_gpu_ms: Some(7.45),
            first_frame_cpu_samples: vec![8.7; 5],
            first_frame_gpu_samples: vec![7.45; 5],
            steady_cpu_ms: 6.51,
            steady_gpu_ms: Some(5.59),
            consistent_after_frames: Some(1),
            checks: vec![EditCheck {
                frames: 1,
                class_mismatch: 0.0,
                depth_p95: 0.0,
                consistent: true,
            }],
        }],
        failures: Vec::new(),
        edit_skipped: None,
        reference_images: Vec::new(),
    }
}
