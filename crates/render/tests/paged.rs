//! Paged rendering (issue 33) on lavapipe / llvmpipe: a world four times the
//! budget draws with no sky through pages that are not resident, converges
//! to the whole-world image bit for bit, evicts and reloads along a path of
//! views, shows an edit of its store on the next frame, and refuses a budget
//! too small with the smallest that works.

mod common;

use std::sync::Arc;
use strata_camera::Camera;
use strata_render::paged::{LevelPages, PageSource, PagedOptions};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;
/// 2 MiB for a 2048x2048 world: its texels alone are 8 MiB.
const BUDGET: u64 = 2 << 20;

fn paged(
    gpu: &strata_render::Gpu,
    source: Arc<dyn PageSource>,
    colors: &TerrainColors,
    method: &str,
    budget: u64,
) -> anyhow::Result<Renderer> {
    paged_with(
        gpu,
        source,
        colors,
        method,
        PagedOptions {
            gpu_budget: budget,
            upload_pages: 4,
            ..Default::default()
        },
    )
}

/// A paged renderer of `source` at the test size with `options`.
fn paged_with(
    gpu: &strata_render::Gpu,
    source: Arc<dyn PageSource>,
    colors: &TerrainColors,
    method: &str,
    options: PagedOptions,
) -> anyhow::Result<Renderer> {
    Renderer::new_paged(
        gpu,
        source,
        colors,
        method,
        &MethodSettings::default(),
        W,
        H,
        options,
    )
}

use common::paged::{converge_paged as converge, level_pages, store_pages, temp_store, world};

#[test]
fn a_world_four_times_the_budget_converges_to_the_whole_world_image() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let source = level_pages(&w);
    for gpu in gpus {
        for method in ["ray-exact", "ray-exact-fragment"] {
            let mut whole = Renderer::new(
                &gpu,
                &w.level,
                &colors,
                method,
                &MethodSettings::default(),
                W,
                H,
            )
            .unwrap();
            let mut r = paged(&gpu, source.clone(), &colors, method, BUDGET).unwrap();
            let plan = *r.paged_terrain().unwrap().plan();
            eprintln!(
                "{method}: budget {BUDGET} B -> {} slots of {} chunks, {} B on the GPU",
                plan.slots,
                plan.chunks,
                plan.total()
            );
            assert!(plan.slots * 4 <= plan.chunks, "{plan:?}");
            // The path: every view, then the first again (evicted meanwhile).
            let mut path: Vec<_> = w.views.iter().collect();
            path.push(&w.views[0]);
            for view in path {
                let camera = Camera::from_view(&w.level, view, W, H).unwrap();
                whole.render_frame(&camera).unwrap();
                let whole_depth = whole.read_depth().unwrap();
                let frames = converge(&mut r, &camera, &whole_depth, 40);
                let depth = r.read_depth().unwrap();
                let color = r.read_color().unwrap();
                let stats = r.paged_terrain().unwrap().stats();
                eprintln!(
                    "{method} {:12}: converged in {frames} frames, {} resident, {} uploads, {} evictions",
                    view.name, stats.resident_pages, stats.total_uploads, stats.total_evictions
                );
                assert!(
                    depth == whole_depth,
                    "{method} {}: depth differs",
                    view.name
                );
                assert!(
                    color == whole.read_color().unwrap(),
                    "{method} {}: colour differs",
                    view.name
                );
            }
            let stats = r.paged_terrain().unwrap().stats();
            assert!(
                stats.total_evictions > 0,
                "the path never evicted: {stats:?}"
            );
        }
    }
}

#[test]
fn an_edit_of_the_store_shows_on_the_next_frame() {
    common::paged::check_edit_equals_fresh_open(
        "edit",
        "ray-exact",
        (W, H, 40),
        |gpu, source, colors| paged(gpu, source, colors, "ray-exact", 16 << 20).unwrap(),
    );
}

#[test]
fn a_budget_too_small_is_refused_with_the_smallest_that_works() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let source = level_pages(&w);
    for gpu in gpus {
        let err = paged(&gpu, source.clone(), &colors, "ray-exact", 100_000)
            .err()
            .expect("refused");
        let text = format!("{err:#}");
        assert!(text.contains("smallest budget that works"), "{text}");
        let err = paged(&gpu, source.clone(), &colors, "voxel", BUDGET)
            .err()
            .expect("refused");
        assert!(format!("{err:#}").contains("ray-exact"), "{err:#}");
    }
}

#[test]
fn a_chunk_that_fails_to_read_stays_pending_and_is_reported_once() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let (dir, store) = temp_store(&w, "bad");
    let site = w.edit.clone().expect("an edit site");
    let camera = Camera::from_view(&w.level, &site.camera, W, H).unwrap();
    // Truncate the chunk under the crater: its checksum no longer holds.
    let (cx, cy) = (site.centre_x / 256, site.centre_y / 256);
    let chunk_file = dir.join(format!("heights/c/{cy}/{cx}"));
    let bytes = std::fs::read(&chunk_file).unwrap();
    std::fs::write(&chunk_file, &bytes[..bytes.len() / 2]).unwrap();
    for gpu in gpus {
        let (_, source) = store_pages(&store);
        let mut r = paged(&gpu, source, &colors, "ray-exact", 16 << 20).unwrap();
        let err = r.converge(&camera, 60).expect_err("never converges");
        let text = format!("{err:#}");
        eprintln!("{text}");
        assert!(text.contains(&format!("chunk ({cx}, {cy})")), "{text}");
        // The renderer keeps drawing, the failed chunk's pixels pending,
        // and the error counted once.
        let t = r.render_frame(&camera);
        assert!(t.is_ok(), "{t:?}");
        let stats = r.paged_terrain().unwrap().stats();
        assert!(stats.pending_pixels > 0, "{stats:?}");
        assert_eq!(stats.read_errors, 1, "{stats:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A paged renderer of `source` at a 16 MiB budget drawing far columns from
/// coarse pages at `lod_pixels` (0: none).
fn lod_renderer(
    gpu: &strata_render::Gpu,
    source: Arc<dyn PageSource>,
    colors: &TerrainColors,
    method: &str,
    lod_pixels: f32,
) -> Renderer {
    paged_with(
        gpu,
        source,
        colors,
        method,
        PagedOptions {
            gpu_budget: 16 << 20,
            upload_pages: 16,
            lod_pixels,
            ..Default::default()
        },
    )
    .unwrap()
}

/// Coarse (level-of-detail) pages resident in `r`'s atlas.
fn coarse_resident(r: &mut Renderer) -> u32 {
    let paged = r.paged_terrain().unwrap();
    let chunks = paged.ids().chunks() as usize;
    paged.residency().table()[chunks..]
        .iter()
        .filter(|&&e| e != 0)
        .count() as u32
}

/// Converge `camera` and score it against the CPU reference; also the
/// coarse pages resident.
fn horizon_run(
    gpu: &strata_render::Gpu,
    source: Arc<dyn PageSource>,
    colors: &TerrainColors,
    method: &str,
    camera: &Camera,
    reference: &strata_reference::Reference,
    lod_pixels: f32,
) -> (strata_reference::Metrics, u32) {
    let mut r = lod_renderer(gpu, source, colors, method, lod_pixels);
    r.converge(camera, 200).unwrap();
    common::save_png(
        &r,
        &format!("horizon-{method}-{lod_pixels}-{}", camera.yaw_deg as i32),
        (W, H),
    );
    let depth = r.read_depth().unwrap();
    let distance = strata_reference::metrics::distance_from_depth(camera, &depth);
    let m = strata_reference::metrics::compare(reference, &distance);
    (m, coarse_resident(&mut r))
}

#[test]
fn horizon_views_take_coarse_pages_far_away_and_stay_close_to_the_reference() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let level = Arc::new(w.level.clone());
    let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(level.clone()).unwrap());
    assert_eq!(source.lod_levels(), 3);
    // Two horizon views: the far plane 6000 texels out (the world wraps),
    // where a pixel covers up to 12 texels.
    let cameras: Vec<Camera> = w.views[..2]
        .iter()
        .map(|v| {
            let mut c = Camera::from_view(&w.level, v, W, H).unwrap();
            c.pitch_deg = -4.0;
            c.position.z = 240.0;
            c.far = 6000.0;
            c
        })
        .collect();
    let tracer = strata_reference::Tracer::new(&level);
    for gpu in gpus {
        for method in ["ray-exact", "ray-exact-fragment"] {
            for camera in &cameras {
                let reference =
                    tracer.render(camera, &strata_reference::ReferenceSettings::default());
                let (exact, coarse0) = horizon_run(
                    &gpu,
                    source.clone(),
                    &colors,
                    method,
                    camera,
                    &reference,
                    0.0,
                );
                let (lod, coarse) = horizon_run(
                    &gpu,
                    source.clone(),
                    &colors,
                    method,
                    camera,
                    &reference,
                    1.0,
                );
                eprintln!(
                    "{method}: exact {} | lod {} ({coarse} coarse pages resident)",
                    common::metrics_line(&exact),
                    common::metrics_line(&lod)
                );
                assert_eq!(coarse0, 0);
                assert_eq!(exact.see_through, 0.0, "{exact:?}");
                assert!(coarse > 0, "no coarse page was drawn");
                assert!(lod.see_through <= 0.5, "{lod:?}");
                assert!(lod.coherence <= 1.0, "{lod:?}");
            }
        }
    }
}

/// On a flat world every coarse copy is the map itself: drawing far columns
/// from them (down to 2 % of a pixel, so nearly every ray does) changes
/// nothing against the reference.
#[test]
fn coarse_pages_of_a_flat_world_draw_it_exactly() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let level = Arc::new(strata_level::Level::flat(2048, 2048, 100, 2).unwrap());
    let colors = TerrainColors::test_ramps();
    let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(level.clone()).unwrap());
    let mut camera =
        Camera::new(glam::Vec3::new(1000.0, 1000.0, 140.0), 30.0, -10.0, W, H).unwrap();
    camera.far = 1500.0;
    let tracer = strata_reference::Tracer::new(&level);
    let reference = tracer.render(&camera, &strata_reference::ReferenceSettings::default());
    for gpu in gpus {
        for method in ["ray-exact-fragment", "ray-exact"] {
            let (m, coarse) = horizon_run(
                &gpu,
                source.clone(),
                &colors,
                method,
                &camera,
                &reference,
                0.02,
            );
            eprintln!(
                "flat {method}: {} coarse {coarse}",
                common::metrics_line(&m)
            );
            assert!(coarse > 0, "no coarse page was drawn");
            assert_eq!(
                (m.see_through, m.covers_sky, m.coherence),
                (0.0, 0.0, 0.0),
                "{m:?}"
            );
        }
    }
}

/// An edit of a store with levels of detail: its coarse pages change in the
/// same batch, and a far view that draws the crater from them shows it on
/// the next frame, equal to a fresh open of the edited store.
#[test]
fn an_edit_reaches_the_coarse_pages_of_a_far_view() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let (dir, _) = temp_store(&w, "edit-lod");
    let store = strata_store::DirStore::build_lods(&dir, &|_, _| {}).unwrap();
    assert_eq!(store.store().lod_levels(), 3);
    let mut site = w.edit.clone().expect("an edit site");
    site.radius = 40;
    site.depth = 60.0;
    let mut level = w.level.clone();
    let rects = strata_level::edit::crater(&mut level, &site);
    // 1200 texels south of the crater, looking north at it from above:
    // a pixel there spans 2.3 texels, drawn from level 1 at a half-pixel
    // tolerance.
    let (sx, sy) = (site.centre_x as f32, site.centre_y as f32);
    let ground = w.level.column_at(sx, sy).top() as f32;
    let eye = glam::Vec3::new(sx, sy - 1200.0, ground + 150.0);
    let pitch = -(150.0f32 / 1200.0).atan().to_degrees();
    let mut camera = Camera::new(eye, 0.0, pitch, W, H).unwrap();
    camera.far = 2000.0;
    for gpu in gpus {
        let (cache, source) = store_pages(&store);
        let mut r = lod_renderer(&gpu, source, &colors, "ray-exact", 0.5);
        r.converge(&camera, 100).unwrap();
        let before = r.read_depth().unwrap();
        let cells = store.commit_rects(&level, &rects).unwrap();
        cache.invalidate(&cells);
        let across = w.level.width() / 256;
        let chunks: Vec<u32> = cells
            .iter()
            .map(|&(cy, cx)| cy as u32 * across + cx as u32)
            .collect();
        r.refresh_pages(&chunks).unwrap();
        r.render_frame(&camera).unwrap();
        let after = r.read_depth().unwrap();
        let changed = after.iter().zip(&before).filter(|(a, b)| a != b).count();
        let (_, source) = store_pages(&store);
        let mut fresh = lod_renderer(&gpu, source, &colors, "ray-exact", 0.5);
        fresh.converge(&camera, 100).unwrap();
        let coarse = coarse_resident(&mut fresh);
        eprintln!("far edit: {changed} pixels changed, {coarse} coarse pages resident");
        assert!(changed > 0, "the edit changed nothing in the far view");
        assert!(coarse > 0, "the far view drew no coarse page");
        assert!(
            fresh.read_depth().unwrap() == after,
            "depth differs from a fresh open"
        );
        assert!(
            fresh.read_color().unwrap() == r.read_color().unwrap(),
            "colour differs from a fresh open"
        );
        let cells = store.commit_rects(&w.level, &rects).unwrap();
        cache.invalidate(&cells);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
