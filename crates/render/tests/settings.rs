//! `Renderer::update_settings` (the viewer's sliders): a method that takes
//! new settings in place draws exactly what one built with them draws; one
//! that cannot says so; an invalid value is refused and changes nothing.

mod common;

use strata_camera::Camera;
use strata_render::{MethodSettings, Renderer, TerrainColors};

fn changed(f: impl Fn(&mut MethodSettings)) -> MethodSettings {
    let mut s = MethodSettings::default();
    f(&mut s);
    s
}

#[test]
fn settings_taken_in_place_draw_what_a_fresh_build_draws() {
    let Some(gpu) = common::gpu() else { return };
    let level = common::synthetic_level();
    let view = strata_level::ViewSpec::parse("slope", "128,60:0:40", -25.0).unwrap();
    let (w, h) = (128, 80);
    let camera = Camera::from_view(&level, &view, w, h).unwrap();
    let colors = TerrainColors::test_ramps();
    let cases = [
        ("ray", changed(|s| s.ray_steps = 24)),
        ("ray-compute", changed(|s| s.ray_steps = 24)),
        ("voxel", changed(|s| s.voxel_steps = 12)),
        ("voxel-compute", changed(|s| s.voxel_steps = 12)),
        ("sliced", changed(|s| s.slices = 40)),
        ("scattered", changed(|s| s.scatter_density = [1.0; 3])),
    ];
    for (method, new) in cases {
        let mut r = Renderer::new(
            &gpu,
            &level,
            &colors,
            method,
            &MethodSettings::default(),
            w,
            h,
        )
        .unwrap();
        r.render_frame(&camera).unwrap();
        let old_depth = r.read_depth().unwrap();
        assert!(
            r.update_settings(method, &new).unwrap(),
            "{method} wants a rebuild"
        );
        assert_eq!(r.settings_of(method), Some(&new));
        r.render_frame(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        let mut fresh = Renderer::new(&gpu, &level, &colors, method, &new, w, h).unwrap();
        fresh.render_frame(&camera).unwrap();
        assert!(
            depth == fresh.read_depth().unwrap(),
            "{method}: depth differs from a fresh build"
        );
        assert!(
            r.read_color().unwrap() == fresh.read_color().unwrap(),
            "{method}: colours differ"
        );
        assert!(
            depth != old_depth,
            "{method}: the new setting changed nothing on screen"
        );
    }
}

#[test]
fn a_new_fit_or_grid_needs_a_rebuild_and_bad_values_change_nothing() {
    let Some(gpu) = common::gpu() else { return };
    let level = common::synthetic_level();
    let colors = TerrainColors::test_ramps();
    let default = MethodSettings::default();
    let mut mesh = Renderer::new(&gpu, &level, &colors, "mesh", &default, 64, 40).unwrap();
    assert!(
        !mesh
            .update_settings("mesh", &changed(|s| s.mesh_quality = 0.75))
            .unwrap()
    );
    assert!(
        mesh.update_settings("mesh", &changed(|s| s.ray_steps = 3))
            .unwrap()
    );
    let mut voxel = Renderer::new(&gpu, &level, &colors, "voxel", &default, 64, 40).unwrap();
    assert!(
        !voxel
            .update_settings("voxel", &changed(|s| s.voxel_size = [2, 4, 1]))
            .unwrap()
    );
    let mut ray = Renderer::new(&gpu, &level, &colors, "ray", &default, 64, 40).unwrap();
    assert!(
        ray.update_settings("ray", &changed(|s| s.ray_steps = 0))
            .is_err()
    );
    assert_eq!(ray.settings_of("ray"), Some(&default));
    assert!(
        !ray.update_settings("mesh", &default).unwrap(),
        "mesh is not kept here"
    );
}
