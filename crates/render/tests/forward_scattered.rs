//! `scattered` against the CPU reference (the hand-built level at 160x100 and
//! a small generated world's twelve views at 320x200, pitches 0, -30, -60,
//! -90), the first frame after a crater against a fresh renderer, memory, and
//! bad settings.

mod common;

use strata_camera::Camera;
use strata_level::generate::{GenerateParams, generate};
use strata_level::{Level, ViewSpec};
use strata_reference::metrics::{self, Metrics};
use strata_reference::render_reference;
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

const PITCHES: [f32; 4] = [0.0, -30.0, -60.0, -90.0];

/// Mean and worst metrics per pitch of `PITCHES` (views of other pitches are
/// ignored), printing each view's metrics and GPU / CPU ms.
fn per_pitch(
    gpu: &Gpu,
    level: &Level,
    colors: &TerrainColors,
    views: &[ViewSpec],
    (w, h): (u32, u32),
) -> Vec<(f32, Metrics, Metrics)> {
    let settings = MethodSettings::default();
    let mut r = Renderer::new(gpu, level, colors, "scattered", &settings, w, h).unwrap();
    let mut out = Vec::new();
    for pitch in PITCHES {
        let (mut mean, mut worst, mut n) = (Metrics::default(), Metrics::default(), 0.0);
        for view in views.iter().filter(|v| v.pitch == pitch) {
            let camera = Camera::from_view(level, view, w, h).unwrap();
            r.render_frame(&camera).unwrap();
            // The second frame is the timed one (the first compiles lazily).
            let t = r.render_frame(&camera).unwrap();
            let depth = r.read_depth().unwrap();
            let reference = render_reference(level, &camera);
            let m = metrics::compare(&reference, &metrics::distance_from_depth(&camera, &depth));
            eprintln!(
                "scattered {:12} pitch {:4}: see-through {:6.3} % covers-sky {:.3} % coherence {:.3} % p50 {:.3} p95 {:.3} | gpu {:?} ms cpu {:.1} ms",
                view.name,
                view.pitch,
                m.see_through,
                m.covers_sky,
                m.coherence,
                m.depth_p50,
                m.depth_p95,
                t.gpu_ms.map(|g| (g * 10.0).round() / 10.0),
                t.cpu_ms,
            );
            n += 1.0;
            mean.see_through += m.see_through;
            mean.covers_sky += m.covers_sky;
            mean.coherence += m.coherence;
            worst.see_through = worst.see_through.max(m.see_through);
            worst.covers_sky = worst.covers_sky.max(m.covers_sky);
            worst.coherence = worst.coherence.max(m.coherence);
            worst.depth_p50 = worst.depth_p50.max(m.depth_p50);
            worst.depth_p95 = worst.depth_p95.max(m.depth_p95);
        }
        if n > 0.0 {
            mean.see_through /= n;
            mean.covers_sky /= n;
            mean.coherence /= n;
            eprintln!(
                "scattered pitch {pitch:4}: mean see-through {:.2} % coherence {:.2} %; worst {worst:?}",
                mean.see_through, mean.coherence
            );
            out.push((pitch, mean, worst));
        }
    }
    out
}

fn world() -> strata_level::World {
    generate(&GenerateParams {
        seed: 6,
        width: 512,
        height: 1024,
    })
    .expect("generated world")
}

#[test]
fn scattered_matches_the_reference() {
    let Some(gpu) = common::gpu() else { return };
    let level = common::synthetic_level();
    let colors = TerrainColors::test_ramps();
    for (pitch, mean, worst) in per_pitch(
        &gpu,
        &level,
        &colors,
        &common::synthetic_views(),
        (160, 100),
    ) {
        assert!(worst.covers_sky <= 100.0, "{pitch}: {worst:?} {mean:?}");
    }
}

#[test]
fn scattered_matches_the_reference_on_a_generated_world() {
    let Some(gpu) = common::gpu() else { return };
    let w = world();
    let colors = TerrainColors::from_world(&w);
    for (pitch, mean, worst) in per_pitch(&gpu, &w.level, &colors, &w.views, (320, 200)) {
        assert!(worst.covers_sky <= 100.0, "{pitch}: {worst:?} {mean:?}");
    }
}
