//! The GPU pyramid, cave bounds and texel plane against their CPU twins
//! (`strata_maxmip`), built and after edits.

use super::*;

/// Record and submit the pyramid's queued updates.
fn run_pending(p: &mut GpuMaxMip, shared: &Shared) {
    p.prepare(shared);
    let mut encoder = shared.device.create_command_encoder(&Default::default());
    p.record(&mut encoder, None);
    shared.queue.submit([encoder.finish()]);
}

/// The GPU's words read back equal the CPU twin's.
fn same_words(got: anyhow::Result<Vec<u32>>, want: Vec<u32>, what: &str) {
    let got = got.unwrap();
    assert!(got == want, "{what}: {}", common::word_diff(&got, &want));
}

/// `twin` updated by `update` equals `fresh` (a fresh build) and differs
/// from `twin` (the edit changed something).
fn updated_twin<T: Clone + PartialEq>(twin: &T, fresh: &T, update: impl Fn(&mut T), what: &str) {
    let mut t = twin.clone();
    update(&mut t);
    assert!(
        t == *fresh,
        "{what}: the CPU update differs from a fresh build"
    );
    assert!(t != *twin, "{what}: the edit changed nothing");
}

#[test]
fn gpu_pyramid_equals_its_twin_before_and_after_an_edit() {
    for gpu in common::gpus() {
        // A square map, a tall one (the default world's shape) and one
        // narrower than a word at its coarsest level.
        // Every level, and every other one (what the default traversal reads).
        for (w, h, step) in [
            (512, 512, 1),
            (256, 1024, 1),
            (8, 16, 1),
            (512, 512, 2),
            (256, 1024, 2),
            (8, 16, 2),
        ] {
            let world = if w >= 256 { world(w, h, 6) } else { tiny(w, h) };
            let mut level = world.level.clone();
            let shared = shared_for(&gpu, &level);
            let mut gp = GpuMaxMip::with_texels(&shared, &level, step, true, true).unwrap();
            let cpu = strata_maxmip::Pyramid::with_step(&level, step);
            let caves = strata_maxmip::CavePyramid::with_step(&level, step);
            let texels = strata_maxmip::TexelTops::new(&level);
            let what = |plane: &str| format!("{w}x{h}: {plane}");
            same_words(gp.read_back(&shared), cpu.words(), &what("maxima"));
            same_words(gp.read_back_caves(&shared), caves.words(), &what("caves"));
            same_words(
                gp.read_back_texels(&shared),
                texels.words(),
                &what("texel plane"),
            );
            let rects = if w >= 256 {
                dig(&world, &mut level)
            } else {
                let r = DirtyRect {
                    x: 2,
                    y: 5,
                    width: 3,
                    height: 4,
                };
                for y in r.y..r.y + r.height {
                    for x in r.x..r.x + r.width {
                        level.planes_mut().0[(y * w + x) as usize] = 250 - (x + y) as u8;
                    }
                }
                vec![r]
            };
            shared
                .terrain
                .upload(&shared.queue, &level, &rects)
                .unwrap();
            gp.enqueue(&rects);
            run_pending(&mut gp, &shared);
            // The CPU twins updated over the rectangles equal fresh builds
            // and changed; the GPU's updated planes equal them.
            let fresh = strata_maxmip::Pyramid::with_step(&level, step);
            updated_twin(
                &cpu,
                &fresh,
                |t| rects.iter().for_each(|r| t.update(&level, r)),
                &what("maxima"),
            );
            same_words(
                gp.read_back(&shared),
                fresh.words(),
                &what("maxima after the edit"),
            );
            let fresh = strata_maxmip::CavePyramid::with_step(&level, step);
            updated_twin(
                &caves,
                &fresh,
                |t| rects.iter().for_each(|r| t.update(&level, r)),
                &what("caves"),
            );
            same_words(
                gp.read_back_caves(&shared),
                fresh.words(),
                &what("caves after the edit"),
            );
            let fresh = strata_maxmip::TexelTops::new(&level);
            updated_twin(
                &texels,
                &fresh,
                |t| rects.iter().for_each(|r| t.update(&level, r)),
                &what("texel plane"),
            );
            same_words(
                gp.read_back_texels(&shared),
                fresh.words(),
                &what("texel plane after the edit"),
            );
            eprintln!(
                "{w}x{h}: GPU pyramid, caves and texel plane == CPU twins before and after the crater ({rects:?})"
            );
            gpu.errors.check().unwrap();
        }
    }
}

/// Issue 35: a game's frame of edits (here 200 small rectangles, more than
/// the update's slots) is merged into fewer rectangles, and the GPU
/// pyramid still equals a fresh one.
#[test]
fn many_small_edits_in_one_frame_update_the_pyramid_exactly() {
    for gpu in common::gpus() {
        let world = world(256, 1024, 6);
        let mut level = world.level.clone();
        let shared = shared_for(&gpu, &level);
        let mut gp = GpuMaxMip::new(&shared, &level, 2, true).unwrap();
        let mut rects = Vec::new();
        for k in 0..200u32 {
            // Tracks lower, ridges raise: a stale tile either way shows.
            let (x, y) = ((k * 37) % 250, (k * 101) % 1020);
            let rect = strata_level::edit::EditRect {
                x: i64::from(x),
                y: i64::from(y),
                width: 3,
                height: 3,
            };
            let height = if k % 2 == 0 { 0 } else { 250 };
            rects.extend(strata_level::edit::fill_single(&mut level, rect, height, 1));
        }
        assert!(rects.len() >= 150, "{} rects", rects.len());
        shared
            .terrain
            .upload(&shared.queue, &level, &rects)
            .unwrap();
        gp.enqueue(&rects);
        run_pending(&mut gp, &shared);
        let fresh = strata_maxmip::Pyramid::with_step(&level, 2);
        let got = gp.read_back(&shared).unwrap();
        assert!(
            got == fresh.words(),
            "after {} rects: {}",
            rects.len(),
            common::word_diff(&got, &fresh.words())
        );
        let caves = strata_maxmip::CavePyramid::with_step(&level, 2);
        let got = gp.read_back_caves(&shared).unwrap();
        assert!(
            got == caves.words(),
            "caves after {} rects: {}",
            rects.len(),
            common::word_diff(&got, &caves.words())
        );
        gpu.errors.check().unwrap();
    }
}
