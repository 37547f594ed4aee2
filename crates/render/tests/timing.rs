//! Per-pass timestamps: one interval per pass, summed; none without support.

mod common;

use strata_camera::Camera;
use strata_render::{MethodSettings, Renderer, TerrainColors};

#[test]
fn every_pass_is_timed() {
    let Some(gpu) = common::gpu() else { return };
    let level = common::synthetic_level();
    let view = strata_level::ViewSpec::parse("v", "128,100:10:60", -30.0).unwrap();
    let camera = Camera::from_view(&level, &view, 160, 100).unwrap();
    for (method, shadows, depth_attachment, want) in [
        // `ray`'s beam pre-pass (its tiles' starts) goes before its march.
        ("ray", true, false, vec![vec!["shadow", "ray beam", "ray"]]),
        ("ray", false, false, vec![vec!["ray beam", "ray"]]),
        // The compute march copies its depth image into the shared depth
        // target only when asked.
        (
            "ray-compute",
            true,
            false,
            vec![vec!["shadow", "ray-compute march"]],
        ),
        (
            "ray-compute",
            true,
            true,
            vec![vec![
                "shadow",
                "ray-compute march",
                "ray-compute depth copy",
            ]],
        ),
        // The exact march casts the shadow blocks its hits read between
        // marching and shading; its beam is searched in the march (the
        // default `BeamSearch::Wide`: no pass of its own). From its second
        // frame at a view it casts the view's cover ahead (a build), and
        // once that is whole it marches and shades in one pass.
        (
            "ray-exact",
            true,
            false,
            vec![
                vec!["ray-exact march", "shadow", "ray-exact shade"],
                vec![
                    "shadow cover build",
                    "ray-exact march",
                    "shadow",
                    "ray-exact shade",
                ],
                vec!["shadow cover build", "ray-exact march"],
                vec!["ray-exact march"],
            ],
        ),
        ("ray-exact", false, false, vec![vec!["ray-exact march"]]),
    ] {
        let settings = MethodSettings {
            shadows,
            ..Default::default()
        };
        let mut r = Renderer::new(
            &gpu,
            &level,
            &TerrainColors::test_ramps(),
            method,
            &settings,
            160,
            100,
        )
        .unwrap();
        r.set_depth_attachment(depth_attachment);
        let m = r.measure(&camera, 1, 3).unwrap();
        for t in &m.timings {
            eprintln!("{method} shadows={shadows}: {t:?}");
            assert!(t.cpu_ms > 0.0);
            if gpu.report.timestamps {
                let labels: Vec<&str> = t.passes.iter().map(|p| p.0.as_str()).collect();
                assert!(want.contains(&labels), "{method}: passes {labels:?}");
                let sum: f64 = t.passes.iter().map(|p| p.1).sum();
                assert_eq!(t.gpu_ms, Some(sum));
                assert!(t.passes.iter().all(|p| p.1 >= 0.0));
            } else {
                eprintln!("NOTE: adapter has no timestamps; gpu_ms must be None");
                assert_eq!(t.gpu_ms, None);
            }
        }
    }
}
