//! `painted` and `sliced` against the CPU reference (the hand-built level and
//! a small generated world, pitches 0, -30, -60, -90), the first frame after a
//! crater against a fresh renderer, and bad settings.

mod common;

use strata_camera::Camera;
use strata_level::{Level, ViewSpec};
use strata_reference::metrics::Metrics;
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;

/// Worst metrics of `method` over `views` at `size`, printing each view's.
fn worst_over(
    gpu: &Gpu,
    level: &Level,
    colors: &TerrainColors,
    views: &[ViewSpec],
    method: &str,
    (w, h): (u32, u32),
) -> Metrics {
    let mut r =
        Renderer::new(gpu, level, colors, method, &MethodSettings::default(), w, h).unwrap();
    common::worst_over_views(&mut r, level, views, (w, h), method, |_, _, _, _| {})
}

#[test]
fn painted_matches_the_reference() {
    for gpu in common::gpus() {
        let level = common::synthetic_level();
        let m = worst_over(
            &gpu,
            &level,
            &TerrainColors::test_ramps(),
            &common::synthetic_views(),
            "painted",
            (W, H),
        );
        eprintln!("painted worst (synthetic): {m:?}");
        // Measured: 0 % see-through and covers-sky, p95 <= 0.033 at every pitch
        // (the issue asks <= 1 %): bars are the exact solid.
        assert!(m.see_through <= 0.1 && m.covers_sky <= 0.1, "{m:?}");
        assert!(m.depth_p95 <= 0.1, "{m:?}");
    }
}

#[test]
fn painted_matches_the_reference_on_a_generated_world() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let m = worst_over(
            &gpu,
            &w.level,
            &TerrainColors::from_world(&w),
            &w.views,
            "painted",
            (W, H),
        );
        eprintln!("painted worst (generated): {m:?}");
        assert!(m.see_through <= 0.1 && m.covers_sky <= 0.1, "{m:?}");
        assert!(m.depth_p95 <= 0.1, "{m:?}");
    }
}

/// The crater's first frame equals a fresh renderer's, and shows.
fn assert_crater_like_fresh(method: &str) {
    for gpu in common::gpus() {
        let (pct, p95, changed) = common::crater_against_fresh(&gpu, method);
        assert!(
            changed > 100,
            "the crater left (almost) no trace: {changed}"
        );
        assert!(pct <= 0.01 && p95 <= 0.1, "mismatch {pct} %, p95 {p95}");
    }
}

#[test]
fn painted_shows_a_crater_in_the_next_frame() {
    assert_crater_like_fresh("painted");
}

#[test]
fn sliced_matches_the_reference() {
    for gpu in common::gpus() {
        let level = common::synthetic_level();
        let colors = TerrainColors::test_ramps();
        let (level_views, pitched): (Vec<_>, Vec<_>) = common::synthetic_views()
            .into_iter()
            .partition(|v| v.pitch == 0.0);
        // Looking down, slices 0.5 apart leave nothing uncovered.
        let m = worst_over(&gpu, &level, &colors, &pitched, "sliced", (W, H));
        eprintln!("sliced worst (synthetic, pitched): {m:?}");
        assert!(m.see_through <= 0.1 && m.covers_sky <= 0.2, "{m:?}");
        assert!(m.depth_p95 <= 1.5, "{m:?}");
        // At the horizon a 100 px image is all grazing rays (11 degrees of
        // view): they cross slices 0.5/slope apart, and the gap pass walks
        // each such pixel's ray to its first solid point, the exact
        // crossing. Measured: 0 % see-through, depth p95 0.03 (13.1 % at
        // horizon-b before any gap walk; 0.39 % with each fragment walking
        // its own gap, `/fragwalk`).
        let m = worst_over(&gpu, &level, &colors, &level_views, "sliced", (W, H));
        eprintln!("sliced worst (synthetic, level): {m:?}");
        assert!(m.see_through <= 0.1 && m.covers_sky <= 0.1, "{m:?}");
        assert!(m.depth_p95 <= 0.1, "{m:?}");
    }
}

#[test]
fn sliced_matches_the_reference_on_a_generated_world() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let m = worst_over(
            &gpu,
            &w.level,
            &TerrainColors::from_world(&w),
            &w.views,
            "sliced",
            (320, 200),
        );
        eprintln!("sliced worst (generated, 320x200): {m:?}");
        // Measured: 0 % at every view (0.94 % at hangar, pitch 0, before the
        // gap walks); issue 36 asks <= 1.5 %.
        assert!(m.see_through <= 0.1, "{m:?}");
        assert!(m.covers_sky <= 0.2, "{m:?}");
    }
}

#[test]
fn sliced_shows_a_crater_in_the_next_frame() {
    assert_crater_like_fresh("sliced");
}

#[test]
fn bad_settings_fail_clearly() {
    for gpu in common::gpus() {
        let level = Level::flat(64, 64, 10, 1).unwrap();
        let colors = TerrainColors::test_ramps();
        for slices in [0, 1 << 20] {
            let settings = MethodSettings {
                slices,
                ..Default::default()
            };
            let err = Renderer::new(&gpu, &level, &colors, "sliced", &settings, 8, 8)
                .err()
                .expect("should fail");
            assert!(format!("{err:#}").contains("slices"), "{err:#}");
        }
        // A far plane far beyond the map at a grazing view: painted clamps its
        // footprint (a warning) and still draws; sliced draws its quads.
        for method in ["painted", "sliced"] {
            let mut r = Renderer::new(
                &gpu,
                &level,
                &colors,
                method,
                &MethodSettings::default(),
                16,
                8,
            )
            .unwrap();
            let mut camera =
                Camera::new(glam::Vec3::new(5.0, 5.0, 30.0), 45.0, -10.0, 16, 8).unwrap();
            camera.far = 200_000.0;
            r.render_frame(&camera).unwrap();
            let depth = r.read_depth().unwrap();
            assert!(depth.iter().any(|&d| d < 1.0), "{method}: nothing drawn");
        }
    }
}

/// Means over `views` of `sliced`'s see-through and coherence (%), and its
/// worst depth p95, refined or not. Not refined means `sliced:N/fragwalk`,
/// the slicer whose fragments walk their own gaps: plain `sliced`'s gap pass
/// draws every pixel of a grazing row at its exact crossing, so at 0° views
/// it shows no bands to compare with.
fn sliced_means(
    gpu: &Gpu,
    level: &Level,
    colors: &TerrainColors,
    views: &[ViewSpec],
    refine: bool,
    (w, h): (u32, u32),
) -> (f64, f64, f32) {
    let settings = MethodSettings {
        sliced_refine: refine,
        sliced_fragment_walk: !refine,
        ..MethodSettings::default()
    };
    let mut r = Renderer::new(gpu, level, colors, "sliced", &settings, w, h).unwrap();
    let (mut see, mut coh, mut p95) = (0.0, 0.0, 0.0f32);
    let label = if refine { "refined" } else { "fragwalk" };
    common::worst_over_views(&mut r, level, views, (w, h), label, |_, _, reference, d| {
        let m = strata_reference::metrics::compare(reference, d);
        see += m.see_through;
        coh += m.coherence;
        p95 = p95.max(m.depth_p95);
    });
    gpu.errors.check().unwrap();
    let n = views.len() as f64;
    (see / n, coh / n, p95)
}

/// `sliced_refine` against the fragment-walking slicer on the synthetic level's 0°
/// views: the exact crossing behind each kept slice writes depth, so the
/// bands go, and the see-through can only drop (rays the slices do not
/// sample are searched whole). Measured at 160x100: plain see-through
/// 0.10 %, coherence 3.08 %, depth p95 97.6 (4.73 %, 6.25 %, 164.8 before the
/// slices walked their gaps); refined 0.00 %, 0.00 %, 0.03.
#[test]
fn refined_slices_are_more_coherent_than_plain_ones() {
    let Some(gpu) = common::gpu() else { return };
    let level = common::synthetic_level();
    let colors = TerrainColors::test_ramps();
    let views: Vec<ViewSpec> = common::synthetic_views()
        .into_iter()
        .filter(|v| v.pitch == 0.0)
        .collect();
    let (plain_see, plain_coh, plain_p95) =
        sliced_means(&gpu, &level, &colors, &views, false, (W, H));
    let (see, coh, p95) = sliced_means(&gpu, &level, &colors, &views, true, (W, H));
    eprintln!(
        "sliced 0° (synthetic): plain see-through {plain_see:.2} % coherence {plain_coh:.2} % p95 {plain_p95:.2}, \
         refined {see:.2} % / {coh:.2} % / {p95:.2}"
    );
    assert!(
        coh <= 1.0 && coh < 0.5 * plain_coh,
        "refined {coh} vs plain {plain_coh}"
    );
    assert!(see <= plain_see, "refined see-through {see} vs {plain_see}");
    assert!(p95 <= 0.05, "refined depth p95 {p95}");
}

/// Issue 16's target on the generated world's 0° views at 320x200: the
/// refined slicer's coherence mean at most 1 %, its see-through no worse
/// than the fragment-walking slicer's (`/fragwalk`), its depth the exact
/// surface's. Measured: `/fragwalk`
/// see-through 0.00 %, coherence 10.93 %, depth p95 27.4 (0.61 %, 14.31 %,
/// 73.3 before the slices walked their gaps; it fails the coherence and
/// depth bounds); refined 0.00 %, 0.00 %, 0.00.
#[test]
fn refined_slices_meet_the_coherence_target_on_a_generated_world() {
    let Some(gpu) = common::gpu() else { return };
    let w = common::generated_world();
    let colors = TerrainColors::from_world(&w);
    let views: Vec<ViewSpec> = w.views.iter().filter(|v| v.pitch == 0.0).cloned().collect();
    assert!(!views.is_empty(), "the generated world has no 0° view");
    let size = (320, 200);
    let (plain_see, plain_coh, plain_p95) =
        sliced_means(&gpu, &w.level, &colors, &views, false, size);
    let (see, coh, p95) = sliced_means(&gpu, &w.level, &colors, &views, true, size);
    eprintln!(
        "sliced 0° (generated, 320x200): plain see-through {plain_see:.2} % coherence {plain_coh:.2} % p95 {plain_p95:.2}, \
         refined {see:.2} % / {coh:.2} % / {p95:.2}"
    );
    assert!(
        plain_coh > 1.0,
        "the fragment-walking slicer no longer shows bands: {plain_coh}"
    );
    assert!(coh <= 1.0, "refined coherence {coh} %");
    assert!(
        see <= plain_see && see <= 0.1,
        "refined see-through {see} vs {plain_see}"
    );
    assert!(p95 <= 0.05, "refined depth p95 {p95}");
}

/// Issue 36, item 4: grazing views of a world no setting was tuned on (seed
/// 5, 512x1024; its 0° views) at 320x200, plain and refined: see-through at
/// most 1.5 % on every view. Plain `sliced` walks the rays that cross the
/// slices more than two texels apart once per pixel after the slices
/// (`sliced_gaps.wgsl`); the refined slicer's marks walk each fragment's gap
/// (`sliced.wgsl::slice_hit`) and its refine pass searches whole the rays
/// whose gaps were too long to walk. Measured before any walk: plain 2.58 %
/// and refined 1.09 % at `hangar` (the eye at a thin wall 44 texels off, rays
/// at the horizon crossing no slice before it); since: 0 % and 0 %.
#[test]
fn slices_cover_grazing_views_of_an_unseen_world() {
    let Some(gpu) = common::gpu() else { return };
    let w = strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 5,
        width: 512,
        height: 1024,
    })
    .expect("generated world");
    let colors = TerrainColors::from_world(&w);
    let views: Vec<ViewSpec> = w.views.iter().filter(|v| v.pitch == 0.0).cloned().collect();
    assert!(views.iter().any(|v| v.name == "hangar"), "no hangar view");
    for refine in [false, true] {
        let settings = MethodSettings {
            sliced_refine: refine,
            ..MethodSettings::default()
        };
        let mut r = Renderer::new(&gpu, &w.level, &colors, "sliced", &settings, 320, 200).unwrap();
        let label = if refine { "refined" } else { "sliced" };
        let m =
            common::worst_over_views(&mut r, &w.level, &views, (320, 200), label, |_, _, _, _| {});
        eprintln!("{label} worst (seed 5, 0°, 320x200): {m:?}");
        assert!(m.see_through <= 1.5, "{label}: {m:?}");
        assert!(m.covers_sky <= 0.2, "{label}: {m:?}");
    }
    gpu.errors.check().unwrap();
}
