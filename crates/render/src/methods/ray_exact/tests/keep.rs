//! Frames that keep the shadow blocks earlier frames cast, walking
//! (`keep::ShadowKeep`) and still (`cover.rs`), against methods built
//! fresh for each frame.

use super::*;

/// Shadow blocks kept from earlier frames draw what casting them again
/// draws: a camera walking and turning over the generated world, an edit on
/// the way, and another writer of the shadow map between two frames. Each
/// frame, bit for bit, against a method built fresh for it (which casts every
/// block it reads) on a shared frame of its own; and the kept frames cast
/// fewer blocks, and leave fewer pixel tiles to the shading pass (their
/// pixels are shaded in the march), than the fresh ones.
#[test]
fn kept_shadow_blocks_draw_what_casting_every_block_draws() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let mut level = w.level.clone();
        let site = w.edit.clone().expect("an edit site");
        let sized = |level: &Level| shared_sized(&gpu, level, (W, H));
        let kept_shared = sized(&level);
        let mut kept = build(&kept_shared, &level, ExactOptions::DEFAULT).unwrap();
        assert!(kept.defers());
        let timer = crate::timing::PassTimer::new(&gpu.device, &gpu.queue, false);
        let read = |shared: &Shared, m: &RayExact| {
            let color = crate::gpu::read_texture(
                &shared.device,
                &shared.queue,
                &gpu.errors,
                &shared.color,
                wgpu::TextureAspect::All,
            )
            .unwrap();
            let depth = crate::gpu::read_texture(
                &shared.device,
                &shared.queue,
                &gpu.errors,
                m.depth_image().unwrap(),
                wgpu::TextureAspect::All,
            )
            .unwrap();
            (color, depth)
        };
        let start = Camera::from_view(&level, &site.camera, W, H).unwrap();
        let (mut kept_total, mut fresh_total) = (0u64, 0u64);
        let mut tiles_total = (0u64, 0u64);
        for step in 0..10u32 {
            // A walk of a few units a frame, turning a degree.
            let mut camera = start;
            let forward = camera.basis().forward;
            camera.position += Vec3::new(forward.x, forward.y, 0.0) * (3.0 * step as f32);
            camera.yaw_deg += step as f32;
            if step == 5 {
                let rects = dig(&w, &mut level);
                kept_shared
                    .terrain
                    .upload(&gpu.queue, &level, &rects)
                    .unwrap();
                kept.apply_edit(&kept_shared, &level, &rects).unwrap();
            }
            if step == 7 {
                // Another writer: the map is no longer what `kept` left.
                kept_shared.shadow_map_written();
            }
            let shadow = crate::shadow::ShadowFrame::fit(&camera, true);
            let globals =
                crate::frame::Globals::new(&camera, &crate::frame::LevelShape::of(&level), &shadow);
            record_frame(
                &kept_shared,
                &mut kept,
                &camera,
                &globals,
                &timer,
                step as usize,
            );
            let kept_picture = read(&kept_shared, &kept);
            let (kept_cast, kept_tiles) = kept.deferred_work().unwrap();

            let fresh_shared = sized(&level);
            let mut fresh = build(&fresh_shared, &level, ExactOptions::DEFAULT).unwrap();
            record_frame(&fresh_shared, &mut fresh, &camera, &globals, &timer, 0);
            let fresh_picture = read(&fresh_shared, &fresh);
            let (fresh_cast, fresh_tiles) = fresh.deferred_work().unwrap();
            eprintln!(
                "frame {step}: blocks cast {kept_cast} kept against {fresh_cast} fresh, tiles left to the shading {kept_tiles} against {fresh_tiles}"
            );
            assert!(
                kept_picture.0 == fresh_picture.0,
                "frame {step}: colour differs"
            );
            assert!(
                kept_picture.1 == fresh_picture.1,
                "frame {step}: depth differs"
            );
            assert!(kept_cast <= fresh_cast && fresh_cast > 0, "frame {step}");
            // A fresh method keeps nothing: every tile is left to the
            // shading; a kept frame shades most of its pixels in the march.
            assert!(kept_tiles <= fresh_tiles && fresh_tiles > 0, "frame {step}");
            if matches!(step, 0 | 7) {
                // The first frame and the other writer keep nothing.
                assert_eq!(
                    kept_cast, fresh_cast,
                    "frame {step} kept blocks it must not"
                );
            } else if step != 5 {
                // (The edit's frame keeps what its rays cannot reach, but
                // the walk changes the texel size there too.)
                kept_total += u64::from(kept_cast);
                fresh_total += u64::from(fresh_cast);
                tiles_total.0 += u64::from(kept_tiles);
                tiles_total.1 += u64::from(fresh_tiles);
            }
        }
        assert!(
            kept_total * 2 < fresh_total,
            "walking frames kept too little: {kept_total} cast against {fresh_total}"
        );
        assert!(
            tiles_total.0 * 2 < tiles_total.1,
            "walking frames shaded too little in the march: {tiles_total:?} tiles left to the shading"
        );
        gpu.errors.check().unwrap();
    }
}

/// A still view's frames once its whole cover is cast (`cover.rs`): the
/// march shades in one pass with no stamps, and every frame equals, bit for
/// bit, a method built fresh for it. The cover is cast ahead once the view
/// has been still for two frames, in budgets; an edit recasts the blocks it
/// spoils, and another writer of the map starts it over.
#[test]
fn a_still_view_with_its_cover_cast_draws_what_a_fresh_method_draws() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let mut level = w.level.clone();
        let site = w.edit.clone().expect("an edit site");
        let sized = |level: &Level| shared_sized(&gpu, level, (W, H));
        let timer = crate::timing::PassTimer::new(&gpu.device, &gpu.queue, false);
        let read = |shared: &Shared, m: &RayExact| {
            let texture = |t: &wgpu::Texture| {
                crate::gpu::read_texture(
                    &shared.device,
                    &shared.queue,
                    &gpu.errors,
                    t,
                    wgpu::TextureAspect::All,
                )
                .unwrap()
            };
            (texture(&shared.color), texture(m.depth_image().unwrap()))
        };
        let camera = Camera::from_view(&level, &site.camera, W, H).unwrap();
        // A budget that casts the cover in a few frames, so that some
        // deferred marches keep blocks cast ahead of them.
        let blocks = {
            let shadow = crate::shadow::ShadowFrame::fit(&camera, true);
            (0..128 * 128)
                .filter(|b| super::cover::block_in_cover(&shadow.cover, b % 128, b / 128))
                .count() as u32
        };
        let options = ExactOptions {
            cover_budget: blocks.div_ceil(3),
            ..ExactOptions::DEFAULT
        };
        let still_shared = sized(&level);
        let mut still = build(&still_shared, &level, options).unwrap();
        let mut covered = Vec::new();
        for step in 0..16u32 {
            if step == 6 {
                let rects = dig(&w, &mut level);
                still_shared
                    .terrain
                    .upload(&gpu.queue, &level, &rects)
                    .unwrap();
                still.apply_edit(&still_shared, &level, &rects).unwrap();
            }
            if step == 11 {
                still_shared.shadow_map_written();
            }
            let shadow = crate::shadow::ShadowFrame::fit(&camera, true);
            let globals =
                crate::frame::Globals::new(&camera, &crate::frame::LevelShape::of(&level), &shadow);
            record_frame(
                &still_shared,
                &mut still,
                &camera,
                &globals,
                &timer,
                step as usize,
            );
            let picture = read(&still_shared, &still);
            covered.push(still.covered());
            let fresh_shared = sized(&level);
            let mut fresh = build(&fresh_shared, &level, ExactOptions::DEFAULT).unwrap();
            record_frame(&fresh_shared, &mut fresh, &camera, &globals, &timer, 0);
            assert!(!fresh.covered(), "a fresh method's first frame defers");
            let fresh_picture = read(&fresh_shared, &fresh);
            assert!(picture.0 == fresh_picture.0, "frame {step}: colour differs");
            assert!(picture.1 == fresh_picture.1, "frame {step}: depth differs");
        }
        eprintln!("{blocks} cover blocks; covered frames {covered:?}");
        // Frames 0-1: the view is new; 2-4 cast a third of the cover each,
        // the third finishing it. The edit (6) spoils only the blocks whose
        // rays cross the crater (`keep.rs`), fewer than a budget: cast ahead
        // in its own frame, which stays covered. The other writer (11)
        // starts over.
        let (f, t) = (false, true);
        let expect = [f, f, f, f, t, t, t, t, t, t, t, f, f, f, f, t];
        assert_eq!(covered, expect);
        gpu.errors.check().unwrap();
    }
}
