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

use common::paged::{converge_paged as converge, store_pages, temp_store, world};

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
