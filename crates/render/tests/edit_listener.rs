//! Issue 18: a terrain collider follows the renderer's edits in the same
//! `apply_edit` call that updates the GPU data (mesh method).

mod common;

use std::sync::{Arc, Mutex};
use strata_collide::TerrainCollider;
use strata_render::{MethodSettings, Renderer, TerrainColors};

#[test]
fn collider_follows_the_renderers_edit() {
    let Some(gpu) = common::gpu() else {
        return;
    };
    let mut level = common::synthetic_level();
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let colors = TerrainColors::test_ramps();
    let mut renderer = Renderer::new(&gpu, &level, &colors, "mesh", &settings, 64, 48).unwrap();
    let tol = strata_mesh::tolerance_for_quality(f64::from(settings.mesh_quality)).unwrap();
    let collider = Arc::new(Mutex::new(TerrainCollider::fit(&level, tol)));
    let calls = Arc::new(Mutex::new(Vec::new()));
    let (c, k) = (collider.clone(), calls.clone());
    renderer.set_edit_listener(Some(Box::new(move |level, rects| {
        let rebuilt = c.lock().unwrap().apply_edit(level, rects);
        k.lock().unwrap().extend(rebuilt);
    })));
    let (cx, cy) = (i64::from(level.width() / 2), i64::from(level.height() / 2));
    let probe = |c: &TerrainCollider| {
        let o = [cx as f64 + 0.5, cy as f64 + 0.5, 400.0];
        c.cast_ray(o, [0.0, 0.0, -1.0], 1000.0).unwrap().point[2]
    };
    let before = probe(&collider.lock().unwrap());
    let mut site = strata_level::EditSite::fostral();
    (site.centre_x, site.centre_y, site.radius, site.depth) = (cx, cy, 12, 40.0);
    let dirty = strata_level::edit::crater(&mut level, &site);
    renderer.apply_edit(&level, &dirty).unwrap();
    let after = probe(&collider.lock().unwrap());
    let floor = f64::from(level.column(cx, cy).low);
    println!("crater centre: collider z {before:.1} -> {after:.1}, level floor {floor}");
    assert!(
        !calls.lock().unwrap().is_empty(),
        "the listener rebuilt chunks"
    );
    assert!((after - floor).abs() <= tol + 1e-3, "{after} vs {floor}");
    assert!(before - after > 10.0, "{before} -> {after}");
}
