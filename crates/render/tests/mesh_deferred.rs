//! `mesh`'s deferred frame (issue 36 item 3): the raster pass writes depth
//! and two words a pixel, one compute pass colours every pixel. Against the
//! fragment path (`mesh_fragment`, the same colour step per fragment) it draws
//! the same depth everywhere and the same colours (ꟻLIP between the two), and
//! against the CPU colour reference its ꟻLIP is within 2x `ray`'s (128 steps)
//! on the same views; and on the held-out views of an unseen world at
//! 320x200 it shows at most 1 % see-through at every view.

mod common;

use strata_camera::Camera;
use strata_reference::{TerrainRamps, Tracer, render_color};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;

fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Mean ꟻLIP of `test` (RGBA8) against `reference` (RGB8), W x H.
fn mean_flip(reference: &[u8], test_rgba: &[u8]) -> f32 {
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(W, H, reference),
        nv_flip::FlipImageRgb8::with_data(W, H, &rgb(test_rgba)),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec();
    map.iter().sum::<f32>() / map.len() as f32
}

#[test]
fn the_deferred_frame_draws_what_the_fragment_path_draws() {
    for gpu in common::gpus() {
        if !(gpu.caps.compute && gpu.caps.storage_textures) {
            common::skip_loudly("the deferred mesh needs compute and storage textures");
            continue;
        }
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let ramps = TerrainRamps {
            palette: colors.palette,
            begin: colors.begin,
            end: colors.end,
        };
        let tracer = Tracer::new(&world.level);
        let deferred_settings = MethodSettings::default();
        let fragment_settings = MethodSettings {
            mesh_fragment: true,
            ..MethodSettings::default()
        };
        let new = |method: &str, settings: &MethodSettings| {
            Renderer::new(&gpu, &world.level, &colors, method, settings, W, H).unwrap()
        };
        let mut deferred = new("mesh", &deferred_settings);
        let mut fragment = new("mesh", &fragment_settings);
        let mut ray = new("ray", &MethodSettings::default());
        // The deferred frame keeps its two words a pixel; the fragment path
        // nothing beyond the mesh.
        let extra = deferred.retained_bytes().gpu - fragment.retained_bytes().gpu;
        assert_eq!(extra, u64::from(W * H) * 8, "no G-buffer: not deferred");
        let (mut sum_deferred, mut sum_fragment, mut sum_ray) = (0.0, 0.0, 0.0);
        for view in &world.views {
            let camera = Camera::from_view(&world.level, view, W, H).unwrap();
            deferred.render_frame(&camera).unwrap();
            fragment.render_frame(&camera).unwrap();
            ray.render_frame(&camera).unwrap();
            let depth = deferred.read_depth().unwrap();
            let want = fragment.read_depth().unwrap();
            let differ = depth.iter().zip(&want).filter(|(a, b)| a != b).count();
            assert_eq!(differ, 0, "{}: {differ} depth pixels differ", view.name);
            let colour = deferred.read_color().unwrap();
            let fragment_colour = fragment.read_color().unwrap();
            let between = mean_flip(&rgb(&fragment_colour), &colour);
            let reference = render_color(&tracer, &ramps, &camera, true);
            let (d, f, r) = (
                mean_flip(&reference.rgb, &colour),
                mean_flip(&reference.rgb, &fragment_colour),
                mean_flip(&reference.rgb, &ray.read_color().unwrap()),
            );
            eprintln!(
                "{} ({}°): ꟻLIP deferred vs fragment {between:.5}; vs the CPU reference: deferred {d:.4}, fragment {f:.4}, ray {r:.4}",
                view.name, view.pitch
            );
            assert!(between <= 0.002, "{}: ꟻLIP {between}", view.name);
            (sum_deferred, sum_fragment, sum_ray) =
                (sum_deferred + d, sum_fragment + f, sum_ray + r);
        }
        let n = world.views.len() as f32;
        let (d, f, r) = (sum_deferred / n, sum_fragment / n, sum_ray / n);
        eprintln!(
            "{}: mean ꟻLIP vs the CPU reference: mesh deferred {d:.4}, fragment {f:.4}, ray:128 {r:.4}",
            gpu.report.backend
        );
        assert!(d <= f + 0.001, "deferred {d} vs fragment {f}");
        assert!(d <= 2.0 * r, "mesh {d} vs ray {r}: over 2x");
        gpu.errors.check().unwrap();
    }
}

/// An adapter without compute (or storage textures) keeps the fragment path:
/// no G-buffer, and the picture the deferred frame draws.
#[test]
fn without_compute_the_mesh_colours_in_its_fragments() {
    // An adapter that cannot stand in for one without compute is passed
    // over (llvmpipe's GL: no deferred frame to compare, or no R32Float
    // targets for the shadow map without compute); at least one must run.
    let mut compared = 0;
    for mut gpu in common::gpus() {
        if !(gpu.caps.compute && gpu.caps.storage_textures) {
            eprintln!(
                "{}: no deferred mesh here (needs compute and storage textures)",
                gpu.report.backend
            );
            continue;
        }
        if !gpu.caps.float32_targets {
            // Without compute the shared shadow map needs R32Float targets.
            eprintln!(
                "{}: cannot pretend to lack compute (no R32Float targets)",
                gpu.report.backend
            );
            continue;
        }
        compared += 1;
        let world = common::generated_world();
        let colors = TerrainColors::from_world(&world);
        let settings = MethodSettings {
            shadows: false,
            ..MethodSettings::default()
        };
        let camera = Camera::from_view(&world.level, &world.views[0], W, H).unwrap();
        let mut deferred =
            Renderer::new(&gpu, &world.level, &colors, "mesh", &settings, W, H).unwrap();
        deferred.render_frame(&camera).unwrap();
        let want = deferred.read_color().unwrap();
        let bytes = deferred.retained_bytes().gpu;
        drop(deferred);
        gpu.caps.compute = false;
        gpu.caps.storage_textures = false;
        let mut r = Renderer::new(&gpu, &world.level, &colors, "mesh", &settings, W, H).unwrap();
        assert_eq!(bytes - r.retained_bytes().gpu, u64::from(W * H) * 8);
        r.render_frame(&camera).unwrap();
        let got = r.read_color().unwrap();
        let differ = got
            .chunks(4)
            .zip(want.chunks(4))
            .filter(|(a, b)| a != b)
            .count();
        eprintln!("{}: {differ} pixels differ", gpu.report.backend);
        assert_eq!(differ, 0, "the fragment path draws another picture");
        gpu.errors.check().unwrap();
    }
    if compared == 0 {
        common::skip_loudly("no adapter here can stand in for one without compute");
    }
}

/// Issue 36 item 3: held-out views of a world no setting was tuned on
/// (`strata generate --seed 5 --size 512x1024`; the views in
/// `bench/issue36-mesh/held-out-seed5.txt`: 250 above the top at -30°, as
/// issue 17's held-out views, and 60 above at 0°) at 320x200: see-through at
/// most 1 % at every view. With every sample at its texel's centre
/// (`mesh_texel_centres`, the geometry before) the worst view showed 1.08 %:
/// walls ramped from centre to centre, their tops half a texel inside the
/// silhouette. `MESH_DEBUG=NAME` prints that view's hit/miss map (`R`: the
/// reference hits, the mesh sees sky).
#[test]
fn held_out_views_of_an_unseen_world_show_at_most_one_percent_see_through() {
    let Some(gpu) = common::gpu() else { return };
    let w = common::generated_world_of_seed(5);
    let views = strata_level::views::parse_views(include_str!(
        "../../../bench/issue36-mesh/held-out-seed5.txt"
    ))
    .unwrap();
    assert_eq!(views.len(), 12);
    let colors = TerrainColors::from_world(&w);
    let (width, height) = (320, 200);
    let worst = |settings: &MethodSettings, label: &str| {
        let mut r =
            Renderer::new(&gpu, &w.level, &colors, "mesh", settings, width, height).unwrap();
        common::worst_over_views(
            &mut r,
            &w.level,
            &views,
            (width, height),
            label,
            |_, view, reference, distance| {
                common::debug_hit_map("MESH_DEBUG", view, reference, distance, (width, height));
            },
        )
    };
    let m = worst(&MethodSettings::default(), "mesh");
    let centres = MethodSettings {
        mesh_texel_centres: true,
        ..MethodSettings::default()
    };
    let before = worst(&centres, "centres");
    eprintln!(
        "mesh worst (seed 5, held-out, 320x200): {m:?}; samples at texel centres: {before:?}"
    );
    assert!(m.see_through <= 1.0, "{m:?}");
    assert!(m.covers_sky <= 0.5 && m.coherence <= 1.0, "{m:?}");
    assert!(
        before.see_through > m.see_through && before.coherence > m.coherence,
        "moving samples to walls no longer helps: {before:?} vs {m:?}"
    );
    gpu.errors.check().unwrap();
}
