//! `mesh` over paged terrain (issue 33) on lavapipe / llvmpipe: a 2048²
//! world four times larger than the budget draws along a path of views with
//! no sky where the whole-world mesh shows terrain and never past its
//! budget (asserted every frame), converges to the whole-world `mesh` image
//! (its fragment path, `mesh_fragment`) bit for bit when still, evicts and
//! refits; an edit of its store equals a fresh open.

mod common;

use std::sync::Arc;
use strata_camera::Camera;
use strata_render::paged::{PageSource, PagedOptions};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const W: u32 = 160;
const H: u32 = 100;
/// The world's pages alone take 8.5 MiB of atlas and its mesh 20 MiB of
/// indices; this budget holds a quarter of either.
const BUDGET: u64 = 7 << 20;

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

use common::paged::{converge_paged as converge, level_pages, world};

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
    let source = level_pages(&w);
    for gpu in gpus {
        // The paged mesh colours in its fragments (its stand-in boxes share
        // the pass): the whole-world mesh's fragment path is its twin.
        let settings = MethodSettings {
            mesh_fragment: true,
            ..MethodSettings::default()
        };
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
    common::paged::check_edit_equals_fresh_open(
        "mesh-edit",
        "mesh",
        (W, H, 400),
        |gpu, source, colors| paged(gpu, source, colors, BUDGET).unwrap(),
    );
}
