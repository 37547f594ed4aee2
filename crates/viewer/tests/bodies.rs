//! The physics toy's bodies compose with the terrain by depth in every
//! method: after a method's frame the viewer's own body pipeline draws into
//! the renderer's colour and depth; a ball resting in the open shows, a
//! ball resting in the cave under a slab stays hidden by the slab.

use glam::Vec3;
use strata_camera::Camera;
use strata_level::edit::{EditRect, edit_columns};
use strata_level::{Column, Level};
use strata_physics::{BodyShape, PhysicsSettings, TerrainPhysics};
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors, methods};
use strata_viewer::bodies::BodyPainter;

const W: u32 = 160;
const H: u32 = 160;

/// Flat ground at 40 with a slab (cave 40..64, top 80) over x 100..160,
/// y 120..200.
fn level() -> Level {
    let mut level = Level::flat(256, 256, 40, 1).unwrap();
    let slab = EditRect {
        x: 100,
        y: 120,
        width: 60,
        height: 80,
    };
    edit_columns(&mut level, slab, |_, _, c| Column {
        mid: 70,
        high: 80,
        dual: true,
        upper_type: 5,
        ..c
    });
    level
}

fn pixel(color: &[u8], p: Vec3) -> [u8; 3] {
    let k = ((p.y as u32 * W + p.x as u32) * 4) as usize;
    [color[k], color[k + 1], color[k + 2]]
}

#[test]
fn bodies_show_in_the_open_and_hide_under_a_slab_in_every_method() {
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
    let level = level();
    let mut physics = TerrainPhysics::fit(&level, 0.5, PhysicsSettings::default());
    let ball = BodyShape::Sphere { radius: 5.0 };
    let open = physics.drop_body(ball, [130.5, 108.5, 60.0]).unwrap();
    let cave = physics.drop_body(ball, [130.5, 160.5, 52.0]).unwrap();
    for _ in 0..300 {
        physics.step();
    }
    let bodies: Vec<_> = physics.bodies().collect();
    let at = |id| Vec3::from(physics.body(id).unwrap().position);
    let (open_at, cave_at) = (at(open), at(cave));
    assert!((open_at.z - 45.0).abs() < 0.5 && (cave_at.z - 45.0).abs() < 0.5);

    let camera = Camera::new(Vec3::new(130.5, 20.0, 160.0), 0.0, -46.0, W, H).unwrap();
    let open_px = camera.project(open_at).unwrap();
    let cave_px = camera.project(cave_at).unwrap();
    for p in [open_px, cave_px] {
        let inside = p.x > 2.0 && p.x < W as f32 - 2.0 && p.y > 2.0 && p.y < H as f32 - 2.0;
        assert!(inside, "{p} outside the picture");
    }
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let colors = TerrainColors::test_ramps();
    let mut painter = BodyPainter::new(&gpu.device);
    let mut tested = 0;
    for name in methods::names() {
        let mut r = match Renderer::new(&gpu, &level, &colors, name, &settings, W, H) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name}: not on this adapter ({e:#})");
                continue;
            }
        };
        // The bodies draw over Strata's own depth target.
        r.set_depth_attachment(true);
        r.render_frame(&camera).unwrap();
        let terrain = r.read_color().unwrap();
        painter.draw(
            r.shared(),
            camera.view_proj(),
            camera.position,
            [256.0, 256.0],
            &bodies,
        );
        let drawn = r.read_color().unwrap();
        let (o, c) = (pixel(&drawn, open_px), pixel(&drawn, cave_px));
        println!(
            "{name}: open ball pixel {:?} -> {o:?}, cave ball pixel {:?} -> {c:?}",
            pixel(&terrain, open_px),
            pixel(&terrain, cave_px)
        );
        // The ball's orange, lit: red well above blue.
        assert!(
            o != pixel(&terrain, open_px) && o[0] > 100 && o[0] > o[2] + 60,
            "{name}: the ball in the open shows: {o:?}"
        );
        assert_eq!(
            c,
            pixel(&terrain, cave_px),
            "{name}: the ball under the slab stays hidden"
        );
        tested += 1;
    }
    assert!(tested >= 2, "{tested} methods ran");
}
