//! The temporal metric on the GPU: a still camera does not flicker at all
//! (each method draws the same frame, the reference traces the same
//! picture); a slow pan flickers little. Skips loudly without an adapter.

mod common;

use common::world;
use indicatif::ProgressBar;
use strata_bench::video::path::CameraPath;
use strata_bench::video::{VideoOptions, record};
use strata_level::World;

fn flicker(
    gpu: &strata_render::Gpu,
    w: &World,
    path: &str,
    method: &str,
    overlap: bool,
) -> (f64, f64) {
    let path = CameraPath::parse(path).unwrap();
    let opts = VideoOptions {
        methods: common::choices(&[method]),
        tile: (64, 40),
        frame: None,
        fps: 4,
        shadows: true,
        temporal: true,
        overlap: Some(overlap),
        paging: None,
    };
    let r = record(gpu, w, &path, &opts, None, &ProgressBar::hidden()).unwrap();
    assert_eq!(r.frames, 9);
    let f = r.methods[0].flicker.clone().unwrap();
    assert_eq!(f.pairs, 8);
    (f.mean_percent, f.max_percent)
}

#[test]
fn still_camera_does_not_flicker_and_a_slow_pan_little() {
    let Some(gpu) = common::gpu_or_skip("still_camera_does_not_flicker") else {
        return;
    };
    let w = world();
    let v = &w.views[3];
    let at = |yaw: f32| format!("{},{}:{yaw}:{}", v.x, v.y, v.eye);
    let still = format!("{} {} 0\n{} {} 2\n", at(v.yaw), v.pitch, at(v.yaw), v.pitch);
    for method in ["ray", "mesh"] {
        assert_eq!(
            flicker(&gpu, &w, &still, method, false),
            (0.0, 0.0),
            "{method}"
        );
    }
    // Two degrees over two seconds: a quarter degree per frame.
    let pan = format!(
        "{} {} 0\n{} {} 2\n",
        at(v.yaw),
        v.pitch,
        at(v.yaw + 2.0),
        v.pitch
    );
    let (mean, worst) = flicker(&gpu, &w, &pan, "ray", false);
    assert!(
        mean < 5.0 && worst < 10.0,
        "ray on a slow pan: {mean} / {worst}"
    );
    // Tracing the reference while the GPU renders measures the same.
    assert_eq!(flicker(&gpu, &w, &pan, "ray", true), (mean, worst));
}
