//! `scattered` against the CPU reference (the hand-built level at 160x100 and
//! a small generated world's twelve views at 320x200, pitches 0, -30, -60,
//! -90), the first frame after a crater against a fresh renderer, memory, and
//! bad settings.

mod common;

use strata_camera::Camera;
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
            common::save_png(&r, &format!("scattered-{}", view.name), (w, h));
            let reference = render_reference(level, &camera);
            let m = metrics::compare(&reference, &metrics::distance_from_depth(&camera, &depth));
            eprintln!(
                "scattered {:12} pitch {:4}: {} | gpu {:?} ms cpu {:.1} ms",
                view.name,
                view.pitch,
                common::metrics_line(&m),
                t.gpu_ms.map(|g| (g * 10.0).round() / 10.0),
                t.cpu_ms,
            );
            n += 1.0;
            mean.see_through += m.see_through;
            mean.covers_sky += m.covers_sky;
            mean.coherence += m.coherence;
            common::fold_worst(&mut worst, &m);
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

#[test]
fn scattered_matches_the_reference() {
    for gpu in common::gpus() {
        let level = common::synthetic_level();
        let colors = TerrainColors::test_ramps();
        for (pitch, mean, worst) in per_pitch(
            &gpu,
            &level,
            &colors,
            &common::synthetic_views(),
            (160, 100),
        ) {
            // Measured (screen-space density, floor walk culled behind the
            // neighbours): see-through 0.14 % at `high` (pitch 0), 0 % elsewhere;
            // covers-sky 0.83 % at `high`; p50 <= 0.28. With one sample per pixel
            // across instead of 1.25 the horizon views had 0.8-1.3 %.
            // Coherence (speckle) <= 2.0 % (cave; near walls walked at one point
            // per pixel had rows of holes: 13 %).
            let limit = if pitch == 0.0 { 1.0 } else { 0.5 };
            assert!(worst.coherence <= 3.0, "{pitch}: {worst:?}");
            assert!(worst.see_through <= limit, "{pitch}: {worst:?} {mean:?}");
            assert!(worst.covers_sky <= 1.5, "{pitch}: {worst:?}");
            assert!(worst.depth_p50 <= 2.5, "{pitch}: {worst:?}");
        }
    }
}

#[test]
fn scattered_matches_the_reference_on_a_generated_world() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let colors = TerrainColors::from_world(&w);
        let pitches = per_pitch(&gpu, &w.level, &colors, &w.views, (160, 100));
        assert_eq!(pitches.len(), 4, "three views per pitch expected");
        for (pitch, mean, worst) in pitches {
            // Measured at 160x100: see-through and covers-sky 0 % in all twelve
            // views (the paper's 40 % at the horizon is not reproduced); p50 <=
            // 0.11, p95 <= 0.85 (river), <= 0.4 looking down. Horizon: mean 1 %,
            // worst 2 % allowed; 0.5 % in any view elsewhere. Coherence <= 2.4 %.
            assert!(worst.coherence <= 3.5, "{pitch}: {worst:?}");
            if pitch == 0.0 {
                assert!(
                    mean.see_through <= 1.0 && worst.see_through <= 2.0,
                    "{pitch}: {worst:?} {mean:?}"
                );
            } else {
                assert!(worst.see_through <= 0.5, "{pitch}: {worst:?} {mean:?}");
            }
            assert!(worst.covers_sky <= 0.5, "{pitch}: {worst:?}");
            assert!(worst.depth_p50 <= 1.6, "{pitch}: {worst:?}");
            if pitch <= -60.0 {
                assert!(
                    mean.see_through <= 0.2 && worst.depth_p95 <= 2.0,
                    "{pitch}: {worst:?}"
                );
            }
        }
    }
}

#[test]
fn scattered_shows_a_crater_in_the_next_frame() {
    for gpu in common::gpus() {
        let (pct, p95, changed) = common::crater_against_fresh(&gpu, "scattered");
        assert!(
            changed > 100,
            "the crater left (almost) no trace: {changed}"
        );
        // The grid depends only on the camera, so this holds exactly.
        assert!(pct == 0.0 && p95 == 0.0, "mismatch {pct} %, p95 {p95}");
    }
}

#[test]
fn memory_and_bad_settings() {
    for gpu in common::gpus() {
        let level = Level::flat(64, 64, 10, 1).unwrap();
        let colors = TerrainColors::test_ramps();
        for density in [[0.0, 4.0, 4.0], [4.0, -1.0, 4.0], [4.0, 4.0, f32::NAN]] {
            let settings = MethodSettings {
                scatter_density: density,
                ..Default::default()
            };
            let err = Renderer::new(&gpu, &level, &colors, "scattered", &settings, 8, 8)
                .err()
                .expect("should fail");
            assert!(format!("{err:#}").contains("scatter density"), "{err:#}");
        }
        let (w, h) = (64, 40);
        let mut r = Renderer::new(
            &gpu,
            &level,
            &colors,
            "scattered",
            &MethodSettings::default(),
            w,
            h,
        )
        .unwrap();
        // The screen buffer (4 bytes per pixel) plus the 192-byte grid uniform.
        let bytes = r.retained_bytes();
        assert_eq!(bytes.gpu, u64::from(w * h) * 4 + 192, "{bytes:?}");
        assert_eq!(bytes.cpu, 0);
        // Looking level over flat ground: ground below the horizon, sky above.
        let camera = Camera::new(glam::Vec3::new(5.0, 5.0, 30.0), 45.0, 0.0, w, h).unwrap();
        r.render_frame(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        let (w, h) = (w as usize, h as usize);
        assert!(depth[..w].iter().all(|&d| d == 1.0), "sky at the top");
        assert!(
            depth[(h - 1) * w..].iter().all(|&d| d < 1.0),
            "ground at the bottom"
        );
        // Above the terrain looking up: nothing in view, all sky.
        let up = Camera::new(
            glam::Vec3::new(5.0, 5.0, 300.0),
            0.0,
            30.0,
            w as u32,
            h as u32,
        )
        .unwrap();
        r.render_frame(&up).unwrap();
        assert!(r.read_depth().unwrap().iter().all(|&d| d == 1.0));
    }
}

/// Work per frame, counted by the CPU twin of the scatter
/// (`scattered::count_points`) at 160x100 over the world's twelve views.
/// Measured at 320x200: 0.64 M (depot, -90) to 5.4 M (hangar, 0) points,
/// 30 M over the twelve views; the grid per texel with 4 points per unit of
/// altitude it replaced scattered 38 M (canyon; now 3.9 M) to 578 M (ramp;
/// now 3.7 M), 2.7 G in all.
#[test]
fn points_per_frame_stay_within_budget() {
    let w = common::generated_world();
    let (px, py) = (160u32, 100u32);
    let mut total = 0;
    for view in &w.views {
        let camera = Camera::from_view(&w.level, view, px, py).unwrap();
        let (_, points) =
            strata_render::methods::scattered::count_points(&w.level, &camera, [4.0; 3]);
        eprintln!(
            "points {px}x{py} {:12} pitch {:4}: {points}",
            view.name, view.pitch
        );
        total += points;
        // At most ~400 points per pixel in any view (hangar is ~330 at 320x200).
        assert!(
            points <= 400 * u64::from(px * py),
            "{}: {points}",
            view.name
        );
    }
    eprintln!("points {px}x{py} total {total}");
    // Measured: 11.7 M over the twelve views.
    assert!(total <= 16_000_000, "{total}");
}
