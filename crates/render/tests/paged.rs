//! Paged rendering (issue 33) on lavapipe / llvmpipe: a world four times the
//! budget draws with no sky through pages that are not resident, converges
//! to the whole-world image bit for bit, evicts and reloads along a path of
//! views, shows an edit of its store on the next frame, and refuses a budget
//! too small with the smallest that works.

mod common;

use std::sync::Arc;
use strata_camera::Camera;
use strata_level::{MidRule, World};
use strata_render::paged::{LevelPages, PageSource, PagedOptions, StorePages};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;
/// 2 MiB for a 2048x2048 world: its texels alone are 8 MiB.
const BUDGET: u64 = 2 << 20;

fn world() -> World {
    strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 6,
        width: 2048,
        height: 2048,
    })
    .expect("generated world")
}

/// `w` written as a store in a fresh temporary directory named for `what`.
fn temp_store(w: &World, what: &str) -> (std::path::PathBuf, strata_store::DirStore) {
    let dir = std::env::temp_dir().join(format!("strata-paged-{what}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let store = strata_store::DirStore::create(&dir, w, &strata_store::Layout::default()).unwrap();
    (dir, store)
}

/// Pages of `store` through a fresh 64 MiB chunk cache (returned too, to
/// invalidate after an edit).
fn store_pages(
    store: &strata_store::DirStore,
) -> (Arc<strata_store::ChunkCache>, Arc<dyn PageSource>) {
    let cache = Arc::new(strata_store::ChunkCache::new(
        store.store().clone(),
        64 << 20,
        MidRule::Original,
    ));
    let source: Arc<dyn PageSource> =
        Arc::new(StorePages::new(cache.clone(), MidRule::Original).unwrap());
    (cache, source)
}

fn paged(
    gpu: &strata_render::Gpu,
    source: Arc<dyn PageSource>,
    colors: &TerrainColors,
    method: &str,
    budget: u64,
) -> anyhow::Result<Renderer> {
    Renderer::new_paged(
        gpu,
        source,
        colors,
        method,
        &MethodSettings::default(),
        W,
        H,
        PagedOptions {
            gpu_budget: budget,
            upload_pages: 4,
            ..Default::default()
        },
    )
}

/// Frames until no pixel is pending (at most `most`); asserts every frame
/// that no pixel shows sky where the whole world has terrain, and that the
/// paged terrain stays within its budget.
fn converge(r: &mut Renderer, camera: &Camera, whole_depth: &[f32], most: u32) -> u32 {
    for frame in 1..=most {
        r.render_frame(camera).unwrap();
        let depth = r.read_depth().unwrap();
        let see_through = depth
            .iter()
            .zip(whole_depth)
            .filter(|(p, w)| **p >= 1.0 && **w < 1.0)
            .count();
        assert_eq!(see_through, 0, "frame {frame}: sky through missing pages");
        let stats = r.paged_terrain().unwrap().stats();
        assert!(stats.gpu_bytes <= stats.gpu_budget, "{stats:?}");
        if stats.converged() && frame > 1 {
            return frame;
        }
        if frame + 3 > most {
            eprintln!("frame {frame}: {stats:?}");
        }
        if stats.in_flight > 0 {
            // Let the page readers run (the test threads share the cores).
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }
    panic!("still pending after {most} frames");
}

#[test]
fn a_world_four_times_the_budget_converges_to_the_whole_world_image() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(Arc::new(w.level.clone())).unwrap());
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
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let (dir, store) = temp_store(&w, "edit");
    let open = || store_pages(&store);
    let site = w.edit.clone().expect("an edit site");
    let camera = Camera::from_view(&w.level, &site.camera, W, H).unwrap();
    let settings = MethodSettings::default();
    let mut level = w.level.clone();
    let rects = strata_level::edit::crater(&mut level, &site);
    for gpu in gpus {
        let (cache, source) = open();
        let mut r = paged(&gpu, source, &colors, "ray-exact", 16 << 20).unwrap();
        let mut whole =
            Renderer::new(&gpu, &w.level, &colors, "ray-exact", &settings, W, H).unwrap();
        whole.render_frame(&camera).unwrap();
        converge(&mut r, &camera, &whole.read_depth().unwrap(), 40);
        let d0 = r.read_depth().unwrap();
        let w0 = whole.read_depth().unwrap();
        eprintln!(
            "before the edit: {} pixels differ; camera {:?}",
            d0.iter().zip(&w0).filter(|(a, b)| a != b).count(),
            camera.position
        );
        // Save the batch into the store, then refresh the touched pages.
        let cells = store.commit_rects(&level, &rects).unwrap();
        cache.invalidate(&cells);
        let across = w.level.width() / 256;
        let chunks: Vec<u32> = cells
            .iter()
            .map(|&(cy, cx)| cy as u32 * across + cx as u32)
            .collect();
        r.refresh_pages(&chunks).unwrap();
        r.render_frame(&camera).unwrap();
        whole.apply_edit(&level, &rects).unwrap();
        whole.render_frame(&camera).unwrap();
        let (depth, color) = (r.read_depth().unwrap(), r.read_color().unwrap());
        let whole_depth = whole.read_depth().unwrap();
        let differ = depth
            .iter()
            .zip(&whole_depth)
            .filter(|(a, b)| a != b)
            .count();
        let stats = r.paged_terrain().unwrap().stats();
        let cnt = |a: &[f32], b: &[f32]| a.iter().zip(b).filter(|(x, y)| x != y).count();
        eprintln!(
            "paged vs before {}, whole vs before {}, sky paged {} whole {}",
            cnt(&depth, &d0),
            cnt(&whole_depth, &w0),
            depth.iter().filter(|d| **d >= 1.0).count(),
            whole_depth.iter().filter(|d| **d >= 1.0).count()
        );
        eprintln!("edit: chunks {chunks:?} rects {rects:?}: {differ} pixels differ; {stats:?}");
        assert!(depth == whole_depth, "depth after the edit");
        assert!(
            color == whole.read_color().unwrap(),
            "colour after the edit"
        );
        // And a fresh open of the edited store draws the same.
        let (_, source) = open();
        let mut fresh = paged(&gpu, source, &colors, "ray-exact", 16 << 20).unwrap();
        converge(&mut fresh, &camera, &depth, 40);
        assert!(fresh.read_depth().unwrap() == depth);
        assert!(fresh.read_color().unwrap() == color);
        // Put the store back for the next adapter.
        let cells = store.commit_rects(&w.level, &rects).unwrap();
        cache.invalidate(&cells);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_budget_too_small_is_refused_with_the_smallest_that_works() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(Arc::new(w.level.clone())).unwrap());
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
