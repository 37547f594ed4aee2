//! `Renderer::resize` (the viewer following its window): after a resize
//! every method draws exactly what a renderer built at the new size draws,
//! and the methods kept across it are reused, not rebuilt.

mod common;

use strata_camera::Camera;
use strata_render::{MethodSettings, Renderer, TerrainColors, methods};

#[test]
fn every_method_draws_after_a_resize_what_a_fresh_renderer_draws() {
    let Some(gpu) = common::gpu() else { return };
    let level = common::synthetic_level();
    let view = strata_level::ViewSpec::parse("slope", "128,60:0:40", -25.0).unwrap();
    let colors = TerrainColors::test_ramps();
    let settings = MethodSettings::default();
    let (small, large) = ((96, 60), (176, 110));
    let names = methods::names();
    // One renderer keeping every method, first drawn small.
    let mut resized =
        Renderer::new(&gpu, &level, &colors, names[0], &settings, small.0, small.1).unwrap();
    for name in &names[1..] {
        resized.build_method(&level, name, &settings).unwrap();
    }
    let small_camera = Camera::from_view(&level, &view, small.0, small.1).unwrap();
    for name in &names {
        resized.activate(name).unwrap();
        resized.render_frame(&small_camera).unwrap();
    }
    resized.resize(large.0, large.1).unwrap();
    assert_eq!(resized.shared().width, large.0);
    let camera = Camera::from_view(&level, &view, large.0, large.1).unwrap();
    for name in &names {
        resized.activate(name).unwrap();
        resized.render_frame(&camera).unwrap();
        let (color, depth) = (resized.read_color().unwrap(), resized.read_depth().unwrap());
        let mut fresh =
            Renderer::new(&gpu, &level, &colors, name, &settings, large.0, large.1).unwrap();
        fresh.render_frame(&camera).unwrap();
        let want_depth = fresh.read_depth().unwrap();
        assert_eq!(depth.len(), want_depth.len());
        let differ = depth
            .iter()
            .zip(&want_depth)
            .filter(|(a, b)| a.to_bits() != b.to_bits())
            .count();
        assert_eq!(
            differ, 0,
            "{name}: {differ} depth values differ after the resize"
        );
        assert!(
            color == fresh.read_color().unwrap(),
            "{name}: colours differ"
        );
        assert!(
            depth.iter().any(|&d| d < 1.0),
            "{name}: the view shows no terrain"
        );
    }
    // A size the adapter cannot hold is refused, and the renderer still works.
    assert!(resized.resize(0, 10).is_err());
    assert_eq!(resized.shared().width, large.0);
    resized.render_frame(&camera).unwrap();
}
