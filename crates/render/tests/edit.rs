//! Edits reach the next frame, and bad input fails clearly.

mod common;

use strata_camera::Camera;
use strata_level::{DirtyRect, Level};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;

fn renderer(gpu: &strata_render::Gpu, level: &Level, method: &str) -> Renderer {
    Renderer::new(
        gpu,
        level,
        &TerrainColors::test_ramps(),
        method,
        &MethodSettings::default(),
        W,
        H,
    )
    .unwrap()
}

/// Dig a square pit (also removing any slab) inside `rect`.
fn dig(level: &mut Level, rect: DirtyRect) {
    let w = level.width() as usize;
    let (heights, metas) = level.planes_mut();
    for y in rect.y..rect.y + rect.height {
        for x in rect.x..rect.x + rect.width {
            let i = y as usize * w + x as usize;
            heights[i] = 2;
            metas[i] &= !strata_level::model::META_DOUBLE_LEVEL;
        }
    }
}

#[test]
fn an_edit_shows_in_the_next_frame() {
    for gpu in common::gpus() {
        let level = common::synthetic_level();
        let view = strata_level::ViewSpec::parse("pit", "128,100:0:80", -60.0).unwrap();
        let camera = Camera::from_view(&level, &view, W, H).unwrap();
        // A pit where the centre pixel looks, starting at an odd x so the upload
        // must widen to whole pairs.
        let d = camera.pixel_ray(W / 2, H / 2);
        let t = (0..4000).map(|i| i as f32 * 0.25).find(|&t| {
            let p = camera.position + d * t;
            level.is_solid(p.x, p.y, p.z)
        });
        let hit = camera.position + d * t.expect("the centre pixel sees terrain");
        let rect = DirtyRect {
            x: (hit.x as u32 - 12) | 1,
            y: hit.y as u32 - 10,
            width: 23,
            height: 20,
        };
        for method in ["ray", "ray-compute"] {
            let mut r = renderer(&gpu, &level, method);
            r.render_frame(&camera).unwrap();
            let before = r.read_depth().unwrap();
            let mut edited = level.clone();
            dig(&mut edited, rect);
            r.apply_edit(&edited, &[rect]).unwrap();
            // `mesh` refits off the frame: compare the settled state.
            r.settle_edits().unwrap();
            r.render_frame(&camera).unwrap();
            let after = r.read_depth().unwrap();
            let mut fresh = renderer(&gpu, &edited, method);
            fresh.render_frame(&camera).unwrap();
            let want = fresh.read_depth().unwrap();
            let changed = before.iter().zip(&after).filter(|(a, b)| a != b).count();
            let differ = after.iter().zip(&want).filter(|(a, b)| a != b).count();
            eprintln!(
                "{method}: {changed} pixels changed by the edit, {differ} differ from a fresh renderer"
            );
            assert!(
                changed > 200,
                "{method}: the pit should change many pixels, changed {changed}"
            );
            assert_eq!(
                differ, 0,
                "{method}: edited renderer differs from a fresh one"
            );
        }
    }
}

#[test]
fn bad_input_fails_clearly() {
    for gpu in common::gpus() {
        let level = Level::flat(64, 64, 10, 1).unwrap();
        let colors = TerrainColors::test_ramps();
        let err = |r: anyhow::Result<Renderer>| format!("{:#}", r.err().expect("should fail"));
        let unknown = err(Renderer::new(
            &gpu,
            &level,
            &colors,
            "raytrace",
            &MethodSettings::default(),
            8,
            8,
        ));
        assert!(
            unknown.contains("unknown method `raytrace`") && unknown.contains("ray-compute"),
            "{unknown}"
        );
        for method in ["ray", "ray-compute"] {
            let zero = MethodSettings {
                ray_steps: 0,
                ..Default::default()
            };
            let steps = err(Renderer::new(&gpu, &level, &colors, method, &zero, 8, 8));
            assert!(steps.contains("ray steps"), "{steps}");
        }
        let max = gpu.device.limits().max_texture_dimension_2d;
        let big = err(Renderer::new(
            &gpu,
            &level,
            &colors,
            "ray",
            &MethodSettings::default(),
            max + 1,
            8,
        ));
        assert!(big.contains("render size"), "{big}");
        let mut r = renderer(&gpu, &level, "ray");
        let wrong = Camera::new(glam::Vec3::new(1.0, 1.0, 50.0), 0.0, 0.0, 16, 8).unwrap();
        assert!(r.render_frame(&wrong).is_err());
        let outside = DirtyRect {
            x: 60,
            y: 0,
            width: 8,
            height: 1,
        };
        assert!(r.apply_edit(&level, &[outside]).is_err());
    }
}
