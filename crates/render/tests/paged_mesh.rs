//! `mesh` over paged terrain (issue 33) on lavapipe / llvmpipe: a 2048²
//! world four times larger than the budget draws along a path of views with
//! no sky where the whole-world mesh shows terrain and never past its
//! budget (asserted every frame), converges to the whole-world `mesh` image
//! bit for bit when still, evicts and refits; an edit of its store equals a
//! fresh open.

mod common;

use std::sync::Arc;
use strata_camera::Camera;
use strata_level::{MidRule, World};
use strata_render::paged::{LevelPages, PageSource, PagedOptions, StorePages};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;
/// The world's pages alone take 8.5 MiB of atlas and its mesh 20 MiB of
/// indices; this budget holds a quarter of either.
const BUDGET: u64 = 7 << 20;

fn world() -> World {
    strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 6,
        width: 2048,
        height: 2048,
    })
    .expect("generated world")
}

fn paged(
    gpu: &strata_render::Gpu,
    source: Arc<dyn PageSource>,
    colors: &TerrainColors,
    budget: u64,
) -> anyhow::Result<Renderer> {
    Renderer::new_paged(
        gpu,
        source,
        colors,
        "mesh",
        &MethodSettings::default(),
        W,
        H,
        PagedOptions {
            gpu_budget: budget,
            upload_pages: 8,
            threads: 2,
            ..Default::default()
        },
    )
}

/// Frames until nothing is pending (at most `most`); asserts every frame
/// that no pixel shows sky where the whole world has terrain and that the
/// paged mesh stays within its budget.
fn converge(r: &mut Renderer, camera: &Camera, whole_depth: &[f32], most: u32) -> u32 {
    for frame in 1..=most {
        r.render_frame(camera).unwrap();
        let depth = r.read_depth().unwrap();
        let see_through = depth
            .iter()
            .zip(whole_depth)
            .filter(|(p, w)| **p >= 1.0 && **w < 1.0)
            .count();
        assert_eq!(see_through, 0, "frame {frame}: sky through what is missing");
        let stats = r.paged_terrain().unwrap().stats();
        assert!(stats.gpu_bytes <= stats.gpu_budget, "{stats:?}");
        if stats.converged() && stats.method_in_flight == 0 && frame > 1 {
            return frame;
        }
        if frame + 2 > most {
            eprintln!("frame {frame}: {stats:?}");
        }
        if stats.in_flight > 0 {
            // Let the readers and fitters run (the test threads share the cores).
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }
    panic!("still pending after {most} frames");
}

fn differing(a: &[f32], b: &[f32]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

#[test]
fn a_world_four_times_the_budget_converges_to_the_whole_world_mesh() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let source: Arc<dyn PageSource> = Arc::new(LevelPages::new(Arc::new(w.level.clone())).unwrap());
    for gpu in gpus {
        let settings = MethodSettings::default();
        let mut whole = Renderer::new(&gpu, &w.level, &colors, "mesh", &settings, W, H).unwrap();
        let whole_bytes =
            whole.retained_bytes().gpu + 2 * (w.level.width() * w.level.height()) as u64;
        let mut r = paged(&gpu, source.clone(), &colors, BUDGET).unwrap();
        let stats = r.paged_terrain().unwrap().stats();
        eprintln!(
            "{}: budget {BUDGET} B; whole-world mesh and texels {whole_bytes} B; {} slots, pool {} B",
            gpu.report.backend, stats.slots, stats.method_gpu_bytes
        );
        assert!(BUDGET * 4 <= whole_bytes, "the budget is not 4x too small");
        // The path: every view, a flight at altitude across the world
        // (more chunks a view), then the first view again (evicted meanwhile).
        let mut path: Vec<(String, Camera)> = w
            .views
            .iter()
            .map(|v| {
                (
                    v.name.clone(),
                    Camera::from_view(&w.level, v, W, H).unwrap(),
                )
            })
            .collect();
        for k in 0..4 {
            let at = glam::Vec3::new(200.0 + 500.0 * k as f32, 300.0 + 400.0 * k as f32, 330.0);
            let camera = Camera::new(at, 30.0 + 60.0 * k as f32, -40.0, W, H).unwrap();
            path.push((format!("flight-{k}"), camera));
        }
        path.push(path[0].clone());
        for (name, camera) in path {
            whole.render_frame(&camera).unwrap();
            let whole_depth = whole.read_depth().unwrap();
            let frames = converge(&mut r, &camera, &whole_depth, 400);
            let depth = r.read_depth().unwrap();
            let color = r.read_color().unwrap();
            let stats = r.paged_terrain().unwrap().stats();
            eprintln!(
                "{:12}: converged in {frames} frames, {} pages resident, {} uploads, {} evictions, {} chunk evictions; {} B of {} B",
                name,
                stats.resident_pages,
                stats.total_uploads,
                stats.total_evictions,
                stats.method_evictions,
                stats.gpu_bytes,
                stats.gpu_budget
            );
            assert_eq!(differing(&depth, &whole_depth), 0, "{name}: depth differs");
            assert!(
                color == whole.read_color().unwrap(),
                "{name}: colour differs"
            );
        }
        let stats = r.paged_terrain().unwrap().stats();
        assert!(stats.total_evictions > 0, "no page evicted: {stats:?}");
        assert!(
            stats.method_evictions > 0,
            "no mesh chunk evicted: {stats:?}"
        );
    }
}

#[test]
fn an_edit_of_the_store_equals_a_fresh_open() {
    let gpus = common::gpus();
    if gpus.is_empty() {
        return;
    }
    let w = world();
    let colors = TerrainColors::from_world(&w);
    let dir = std::env::temp_dir().join(format!("strata-paged-mesh-edit-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let store = strata_store::DirStore::create(&dir, &w, &strata_store::Layout::default()).unwrap();
    let open = || {
        let cache = Arc::new(strata_store::ChunkCache::new(
            store.store().clone(),
            64 << 20,
            MidRule::Original,
        ));
        let source: Arc<dyn PageSource> =
            Arc::new(StorePages::new(cache.clone(), MidRule::Original).unwrap());
        (cache, source)
    };
    let site = w.edit.clone().expect("an edit site");
    let camera = Camera::from_view(&w.level, &site.camera, W, H).unwrap();
    let settings = MethodSettings::default();
    let mut level = w.level.clone();
    let rects = strata_level::edit::crater(&mut level, &site);
    for gpu in gpus {
        let (cache, source) = open();
        let mut r = paged(&gpu, source, &colors, BUDGET).unwrap();
        let mut whole = Renderer::new(&gpu, &w.level, &colors, "mesh", &settings, W, H).unwrap();
        whole.render_frame(&camera).unwrap();
        let before = whole.read_depth().unwrap();
        converge(&mut r, &camera, &before, 400);
        assert_eq!(differing(&r.read_depth().unwrap(), &before), 0);
        // Save the batch into the store, then refresh the touched pages.
        let cells = store.commit_rects(&level, &rects).unwrap();
        cache.invalidate(&cells);
        let across = w.level.width() / 256;
        let chunks: Vec<u32> = cells
            .iter()
            .map(|&(cy, cx)| cy as u32 * across + cx as u32)
            .collect();
        r.refresh_pages(&chunks).unwrap();
        whole.apply_edit(&level, &rects).unwrap();
        whole.render_frame(&camera).unwrap();
        let whole_depth = whole.read_depth().unwrap();
        assert!(
            differing(&whole_depth, &before) > 0,
            "the crater is not in view"
        );
        // The next frame shows it, equal to the whole world's refit.
        r.render_frame(&camera).unwrap();
        let (depth, color) = (r.read_depth().unwrap(), r.read_color().unwrap());
        let stats = r.paged_terrain().unwrap().stats();
        eprintln!(
            "{}: edit of pages {chunks:?}: {} pixels differ from the whole world; {stats:?}",
            gpu.report.backend,
            differing(&depth, &whole_depth)
        );
        assert!(stats.converged(), "{stats:?}");
        assert_eq!(differing(&depth, &whole_depth), 0, "depth after the edit");
        assert!(
            color == whole.read_color().unwrap(),
            "colour after the edit"
        );
        // And a fresh open of the edited store draws the same.
        let (_, source) = open();
        let mut fresh = paged(&gpu, source, &colors, BUDGET).unwrap();
        converge(&mut fresh, &camera, &depth, 400);
        assert_eq!(differing(&fresh.read_depth().unwrap(), &depth), 0);
        assert!(fresh.read_color().unwrap() == color);
        // Put the store back for the next adapter.
        let cells = store.commit_rects(&w.level, &rects).unwrap();
        cache.invalidate(&cells);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
