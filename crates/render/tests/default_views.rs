//! Issue 4's numbers on the built-in generated world: `ray` and `ray-compute`
//! at 320x200 over its twelve default views against the CPU reference:
//! see-through <= 1 %, covers-sky <= 0.2 %, coherence <= 1 %.
//! (Shadows off: they change colour only, and cost ~1 s a frame on lavapipe.)

mod common;

use strata_camera::Camera;
use strata_reference::{metrics, render_reference};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 320;
const H: u32 = 200;

#[test]
fn twelve_default_views_match_the_reference() {
    for gpu in common::gpus() {
        let world = strata_level::generate::generate(&Default::default()).unwrap();
        assert_eq!(world.views.len(), 12, "the default world has twelve views");
        let cameras: Vec<Camera> = world
            .views
            .iter()
            .map(|v| Camera::from_view(&world.level, v, W, H).unwrap())
            .collect();
        let references: Vec<_> = cameras
            .iter()
            .map(|c| render_reference(&world.level, c))
            .collect();
        let settings = MethodSettings {
            shadows: false,
            ray_steps: common::ray_steps(),
            ..Default::default()
        };
        let colors = TerrainColors::from_world(&world);
        let mut failures = Vec::new();
        for method in ["ray", "ray-compute"] {
            let mut r =
                Renderer::new(&gpu, &world.level, &colors, method, &settings, W, H).unwrap();
            for ((view, camera), reference) in world.views.iter().zip(&cameras).zip(&references) {
                r.render_frame(camera).unwrap();
                let distance = metrics::distance_from_depth(camera, &r.read_depth().unwrap());
                common::save_png(&r, &format!("{method}-{}", view.name), (W, H));
                let m = metrics::compare(reference, &distance);
                eprintln!(
                    "{method:12} {:11} pitch {:4}: {} sky {:.1} %",
                    view.name,
                    view.pitch,
                    common::metrics_line(&m),
                    reference.sky_fraction()
                );
                if m.see_through > 1.0 || m.covers_sky > 0.2 || m.coherence > 1.0 {
                    failures.push(format!("{method} {}: {m:?}", view.name));
                }
            }
        }
        assert!(
            failures.is_empty(),
            "over the limits:\n{}",
            failures.join("\n")
        );
    }
}
