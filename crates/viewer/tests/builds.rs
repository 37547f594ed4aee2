//! Background builds: a method built off the render thread while the level
//! is dug shows the dig once kept, exactly as a method built after it would.

use std::sync::Arc;
use std::time::{Duration, Instant};
use strata_camera::Camera;
use strata_level::edit::crater;
use strata_level::generate::{GenerateParams, generate};
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};
use strata_viewer::builds::{Builds, Finished};

#[test]
fn a_dig_during_a_background_build_reaches_the_built_method() {
    let gpu = match Gpu::headless() {
        Ok(gpu) => gpu,
        Err(e) => {
            use std::io::Write;
            if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
                panic!("STRATA_REQUIRE_GPU=1 but no GPU adapter: {e:#}");
            }
            let _ = writeln!(
                std::io::stderr(),
                "\n*** SKIPPED GPU test: no GPU adapter ({e:#}) ***\n"
            );
            return;
        }
    };
    let world = generate(&GenerateParams {
        seed: 5,
        width: 256,
        height: 512,
    })
    .unwrap();
    let site = world
        .edit
        .clone()
        .expect("generated worlds carry an edit site");
    let colors = TerrainColors::from_world(&world);
    let settings = MethodSettings::default();
    let (w, h) = (160, 100);
    let undug = world.level.clone();
    let mut level = Arc::new(world.level);
    let camera = Camera::from_view(&level, &site.camera, w, h).unwrap();
    let mut renderer = Renderer::new(&gpu, &level, &colors, "ray", &settings, w, h).unwrap();

    let mut builds = Builds::default();
    builds.start(&renderer, &level, "mesh", &settings).unwrap();
    // Dig while the mesh is fitted from the copy of the level it took.
    let dirty = crater(Arc::make_mut(&mut level), &site);
    assert!(!dirty.is_empty());
    builds.record_edit(&dirty);
    renderer.apply_edit(&level, &dirty).unwrap();

    let start = Instant::now();
    let kept = loop {
        let done = builds.collect(&mut renderer, &level);
        if let Some(f) = done.into_iter().next() {
            break f;
        }
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "the build never ended"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    match kept {
        Finished::Kept { name, .. } => assert_eq!(name, "mesh"),
        Finished::Failed { error, .. } => panic!("{error:#}"),
    }
    renderer.activate("mesh").unwrap();
    // The build's recorded edit is refitted off the frame: settle it first.
    renderer.settle_edits().unwrap();
    renderer.render_frame(&camera).unwrap();
    let got = renderer.read_depth().unwrap();

    let mut fresh = Renderer::new(&gpu, &level, &colors, "mesh", &settings, w, h).unwrap();
    fresh.render_frame(&camera).unwrap();
    let want = fresh.read_depth().unwrap();
    let differ = got
        .iter()
        .zip(&want)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(
        differ, 0,
        "{differ} depth values differ from a mesh built after the dig"
    );

    // And the dig is in the picture: the level before it draws differently.
    let mut before = Renderer::new(&gpu, &undug, &colors, "mesh", &settings, w, h).unwrap();
    before.render_frame(&camera).unwrap();
    assert!(
        before.read_depth().unwrap() != want,
        "the crater changed nothing on screen"
    );
}
