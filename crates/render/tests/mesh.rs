//! `mesh` (issue 7 items 4, 5): against the CPU reference on the hand-built
//! level and a small generated world, the first frame after a crater equal
//! to a fresh renderer's exactly (with the refit + upload CPU time), retained
//! memory, and bad settings.

mod common;

use strata_camera::Camera;
use strata_level::generate::generate;
use strata_level::{Level, ViewSpec};
use strata_reference::metrics::Metrics;
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

fn settings() -> MethodSettings {
    // Shadows change colour only, and cost time on lavapipe.
    MethodSettings {
        shadows: false,
        ..Default::default()
    }
}

/// [`settings`] with the outline-constrained fit (`mesh:0.5o`).
fn outline_settings() -> MethodSettings {
    MethodSettings {
        mesh_outline: true,
        ..settings()
    }
}

/// Worst metrics over `views` at `size`, printing each view's.
fn worst_over(
    gpu: &Gpu,
    level: &Level,
    colors: &TerrainColors,
    views: &[ViewSpec],
    (w, h): (u32, u32),
    settings: &MethodSettings,
) -> Metrics {
    let mut r = Renderer::new(gpu, level, colors, "mesh", settings, w, h).unwrap();
    eprintln!(
        "mesh setup (fit + upload + pipelines): {:.1} ms",
        r.setup_ms()
    );
    common::worst_over_views(
        &mut r,
        level,
        views,
        (w, h),
        "mesh",
        |r, view, reference, distance| {
            common::save_png(r, &format!("mesh-{}", view.name), (w, h));
            common::debug_hit_map("MESH_DEBUG", view, reference, distance, (w, h));
        },
    )
}

#[test]
fn mesh_matches_the_reference() {
    for gpu in common::gpus() {
        let level = common::synthetic_level();
        let m = worst_over(
            &gpu,
            &level,
            &TerrainColors::test_ramps(),
            &common::synthetic_views(),
            (160, 100),
            &settings(),
        );
        eprintln!("mesh worst (synthetic, 160x100): {m:?}");
        // Measured: 0 % see-through at every view but `high` (pitch 0, 1.04 %
        // before issue 36's wall shift, 0.74 % after): samples stand at texel
        // centres, so the level's 20-unit terrace cliffs became ramps whose top
        // edge sat half a texel inside the block silhouette; a sample beside
        // a wall now moves to the texel boundary (`wall_shift` in mesh.wgsl).
        // Covers-sky 0.06 % before, 0.19 % after.
        assert!(m.see_through <= 1.5 && m.coherence <= 0.5, "{m:?}");
        assert!(m.covers_sky <= 1.0, "{m:?}");
    }
}

#[test]
fn mesh_matches_the_reference_on_a_generated_world() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let m = worst_over(
            &gpu,
            &w.level,
            &TerrainColors::from_world(&w),
            &w.views,
            (320, 200),
            &settings(),
        );
        eprintln!("mesh worst (generated, 320x200): {m:?}");
        // Measured: see-through 0 %, covers-sky 0 %, coherence <= 0.16 % before
        // issue 36's wall shift, <= 0.21 % after.
        assert!(m.see_through <= 0.5 && m.coherence <= 0.5, "{m:?}");
        assert!(m.covers_sky <= 0.5, "{m:?}");
    }
}

#[test]
fn outline_mesh_matches_the_reference_on_a_generated_world() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let m = worst_over(
            &gpu,
            &w.level,
            &TerrainColors::from_world(&w),
            &w.views,
            (320, 200),
            &outline_settings(),
        );
        eprintln!("outline mesh worst (generated, 320x200): {m:?}");
        assert!(m.see_through <= 0.5 && m.coherence <= 0.5, "{m:?}");
        assert!(m.covers_sky <= 0.5, "{m:?}");
    }
}

/// CPU ms of refitting the chunks `rects` dirty, one after another on this
/// thread (the renderer splits them over threads that exit before a
/// per-thread CPU reading could see them; the machine is shared, so wall
/// time overstates; the reading only advances at scheduler ticks, so the
/// refit is repeated and averaged), and the chunk count.
fn sequential_refit_cpu_ms(
    level: &Level,
    rects: &[strata_level::DirtyRect],
) -> (Option<f64>, usize) {
    let layout = strata_mesh::ChunkLayout::of(level);
    let ids = strata_mesh::dirty_chunks(&layout, level.width(), level.height(), rects);
    let mut fitter = strata_mesh::ChunkFitter::default();
    const REPEAT: u32 = 20;
    let cpu0 = strata_mesh::cpu_time::process_cpu_seconds();
    for _ in 0..REPEAT {
        for &i in &ids {
            let (cx, cy) = layout.coords(i);
            std::hint::black_box(fitter.fit(level, &layout, cx, cy, 4.0));
        }
    }
    let cpu = strata_mesh::cpu_time::process_cpu_seconds()
        .zip(cpu0)
        .map(|(b, a)| (b - a) * 1e3 / f64::from(REPEAT));
    (cpu, ids.len())
}

#[test]
fn a_settled_crater_equals_a_fresh_fit_in_the_next_frame() {
    for gpu in common::gpus() {
        for settings in [settings(), outline_settings()] {
            // The fixture's camera: the crater is ~14 degrees down, in frame only in
            // a tall image.
            let (w_px, h_px) = (160, 400);
            let w = common::generated_world();
            let colors = TerrainColors::from_world(&w);
            let site = w.edit.clone().expect("generated worlds carry an edit site");
            let mut level = w.level.clone();
            let camera = Camera::from_view(&level, &site.camera, w_px, h_px).unwrap();
            let mut r =
                Renderer::new(&gpu, &level, &colors, "mesh", &settings, w_px, h_px).unwrap();
            r.render_frame(&camera).unwrap();
            let before = r.read_depth().unwrap();
            let retained = r.retained_bytes();
            let rects = strata_level::edit::crater(&mut level, &site);
            let (cpu_ms, chunks) = sequential_refit_cpu_ms(&level, &rects);
            let t0 = std::time::Instant::now();
            r.apply_edit(&level, &rects).unwrap();
            let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
            // The refit runs off the frame: handed over, not yet drawn.
            assert_eq!(
                r.pending_edits(),
                1,
                "the crater's refit was not left in flight"
            );
            r.settle_edits().unwrap();
            assert_eq!(r.pending_edits(), 0);
            eprintln!(
                "mesh crater (outline {}): {chunks} dirty chunks",
                settings.mesh_outline
            );
            r.render_frame(&camera).unwrap();
            let after = r.read_depth().unwrap();
            let mut fresh =
                Renderer::new(&gpu, &level, &colors, "mesh", &settings, w_px, h_px).unwrap();
            fresh.render_frame(&camera).unwrap();
            let want = fresh.read_depth().unwrap();
            let changed = before.iter().zip(&after).filter(|(a, b)| a != b).count();
            let class = after
                .iter()
                .zip(&want)
                .filter(|(a, b)| (**a >= 1.0) != (**b >= 1.0))
                .count();
            let max_diff = after
                .iter()
                .zip(&want)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f32, f32::max);
            eprintln!(
                "mesh crater: {} rects, apply_edit (texture upload + the dirty chunks' samples copied and queued) wall {wall_ms:.2} ms, CPU {cpu_ms:?} ms; \
         {changed} pixels changed; vs fresh: class mismatch {class}, max depth difference {max_diff}; \
         retained before {retained:?}, after {:?}",
                rects.len(),
                r.retained_bytes()
            );
            assert!(
                changed > 100,
                "the crater left (almost) no trace: {changed}"
            );
            assert_eq!(class, 0, "hit/miss differs from a fresh renderer");
            assert_eq!(max_diff, 0.0, "depth differs from a fresh renderer");
            // The slot table does not grow with an edit; the pool is not reallocated
            // for a crater (its tail has room).
            assert_eq!(r.retained_bytes(), retained);
        }
    }
}

/// The browser's build (the fit a chunk or so per step, then the upload)
/// draws exactly what the whole build draws.
#[test]
fn a_build_in_steps_draws_what_the_whole_build_draws() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let colors = TerrainColors::from_world(&w);
        let (w_px, h_px) = (160, 100);
        let camera = Camera::from_view(&w.level, &w.views[0], w_px, h_px).unwrap();
        let mut whole =
            Renderer::new(&gpu, &w.level, &colors, "mesh", &settings(), w_px, h_px).unwrap();
        whole.render_frame(&camera).unwrap();
        let want = whole.read_depth().unwrap();

        let mut r = Renderer::new(&gpu, &w.level, &colors, "ray", &settings(), w_px, h_px).unwrap();
        let shared = r.shared_handle();
        let mut build =
            strata_render::methods::create_in_steps("mesh", &shared.caps, &settings()).unwrap();
        let mut steps = 0;
        let method = loop {
            steps += 1;
            // A zero budget: one chunk per step.
            if let Some(m) = build.step(&shared, &w.level, 0.0).unwrap() {
                break m;
            }
        };
        let chunks = strata_mesh::ChunkLayout::of(&w.level).count();
        assert_eq!(steps, chunks, "one chunk per step, then the upload");
        r.insert_method(method, settings());
        r.activate("mesh").unwrap();
        r.render_frame(&camera).unwrap();
        let got = r.read_depth().unwrap();
        let differ = got.iter().zip(&want).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{differ} pixels differ from the whole build");
        assert!(want.iter().any(|d| *d < 1.0), "the view shows terrain");
    }
}

#[test]
fn retained_bytes_cover_all_lods() {
    for gpu in common::gpus() {
        let level = common::synthetic_level();
        let r = Renderer::new(
            &gpu,
            &level,
            &TerrainColors::test_ramps(),
            "mesh",
            &settings(),
            64,
            40,
        )
        .unwrap();
        let mesh = strata_mesh::LevelMesh::fit(&level, 4.0);
        let stats = mesh.stats();
        let b = r.retained_bytes();
        let finest = stats.lods[0].emitted;
        eprintln!(
            "mesh retained {b:?}; fit: {} indices ({} bytes) for all LODs, {finest} finest-LOD triangles",
            stats.gpu_indices, stats.gpu_bytes
        );
        // All three LODs' indices, plus the tail kept for refits.
        assert!(b.gpu >= stats.gpu_bytes, "{b:?} vs {stats:?}");
        // The CPU keeps a slot table per chunk, not the triangulation.
        assert!(b.cpu > 0 && b.cpu < 64 * 1024, "{b:?}");
    }
}

#[test]
fn bad_quality_fails_clearly() {
    for gpu in common::gpus() {
        let level = Level::flat(64, 64, 10, 1).unwrap();
        for q in [-0.1, 1.5, f32::NAN] {
            let s = MethodSettings {
                mesh_quality: q,
                ..Default::default()
            };
            let err = Renderer::new(&gpu, &level, &TerrainColors::test_ramps(), "mesh", &s, 8, 8)
                .err()
                .map(|e| format!("{e:#}"))
                .expect("quality outside [0, 1] must fail");
            assert!(err.contains("mesh quality"), "{err}");
        }
    }
}

/// Issue 7's numbers on the built-in generated world (Fostral's size):
/// the twelve default views at 320x200 (see-through, coherence <= 0.5 %),
/// setup (the fit of all chunks), retained bytes, and the crater fixture
/// (refit + upload CPU time, first frame == a fresh renderer). Minutes on
/// lavapipe (the fit alone took 19-45 s wall on the shared 2-core machine):
/// `cargo test -p strata-render --test mesh -- --ignored`.
#[test]
#[ignore]
fn default_world_views_memory_and_crater() {
    for gpu in common::gpus() {
        let (w_px, h_px) = (320, 200);
        let world = generate(&Default::default()).unwrap();
        let colors = TerrainColors::from_world(&world);
        if std::env::var("MESH_SKIP_VIEWS").is_err() {
            let m = worst_over(
                &gpu,
                &world.level,
                &colors,
                &world.views,
                (w_px, h_px),
                &settings(),
            );
            eprintln!("mesh worst (default world, 320x200): {m:?}");
            assert!(m.see_through <= 0.5 && m.coherence <= 0.5, "{m:?}");
        }
        let site = world
            .edit
            .clone()
            .expect("the default world has an edit site");
        let mut level = world.level.clone();
        let camera = Camera::from_view(&level, &site.camera, w_px, h_px).unwrap();
        let mut r = Renderer::new(&gpu, &level, &colors, "mesh", &settings(), w_px, h_px).unwrap();
        let t = std::time::Instant::now();
        let fitted = strata_mesh::LevelMesh::fit(&level, 4.0);
        eprintln!(
            "mesh default world: LevelMesh::fit alone {:.0} ms",
            t.elapsed().as_secs_f64() * 1e3
        );
        let fit = fitted.stats();
        drop(fitted);
        let b = r.retained_bytes();
        let tris = fit.lods[0].emitted as f64;
        eprintln!(
            "mesh default world: setup {:.0} ms; retained {b:?} = GPU {:.2} B, CPU {:.3} B per finest-LOD triangle ({} emitted)",
            r.setup_ms(),
            b.gpu as f64 / tris,
            b.cpu as f64 / tris,
            fit.lods[0].emitted
        );
        assert!(
            (b.gpu as f64) < 16.0 * tris && (b.cpu as f64) < 4.0 * tris,
            "{b:?}"
        );
        r.render_frame(&camera).unwrap();
        let rects = strata_level::edit::crater(&mut level, &site);
        let (refit_cpu_ms, chunks) = sequential_refit_cpu_ms(&level, &rects);
        let t0 = std::time::Instant::now();
        r.apply_edit(&level, &rects).unwrap();
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        r.settle_edits().unwrap();
        r.render_frame(&camera).unwrap();
        let after = r.read_depth().unwrap();
        let mut fresh =
            Renderer::new(&gpu, &level, &colors, "mesh", &settings(), w_px, h_px).unwrap();
        fresh.render_frame(&camera).unwrap();
        let want = fresh.read_depth().unwrap();
        let cpu_ms = refit_cpu_ms;
        eprintln!(
            "mesh default-world crater: {chunks} dirty chunks, their refit on one thread: CPU {cpu_ms:?} ms"
        );
        let differ = after.iter().zip(&want).filter(|(a, b)| a != b).count();
        eprintln!(
            "mesh default-world crater: apply_edit wall {wall_ms:.2} ms; {differ} depth pixels differ from a fresh renderer"
        );
        assert_eq!(differ, 0);
        assert!(cpu_ms.is_none_or(|ms| ms < 20.0), "{cpu_ms:?}");
        // The paper's fixture spot, (1024, 8192) r 48, sits on a chunk corner:
        // four chunks to refit. Measured 31.7 ms CPU (2-core machine, load ~8):
        // over issue 7's 20 ms — the cost is the fitter's per chunk (~8 ms for
        // these four, ~2 ms for the world's own site); bound it against regression.
        let corner = strata_level::DirtyRect {
            x: 976,
            y: 8144,
            width: 97,
            height: 97,
        };
        let (corner_ms, corner_chunks) = sequential_refit_cpu_ms(&level, &[corner]);
        eprintln!(
            "mesh default-world refit of the paper's crater rect: {corner_chunks} chunks, CPU {corner_ms:?} ms"
        );
        assert!(corner_ms.is_none_or(|ms| ms < 50.0), "{corner_ms:?}");
    }
}
