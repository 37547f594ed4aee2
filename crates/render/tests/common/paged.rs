//! Shared by the paged-terrain tests: the 2048² world four times a small
//! budget, that world as a temporary store and its pages, an edit committed
//! to it, and the frames until a paged view converges.

use std::sync::Arc;
use strata_level::{DirtyRect, Level, MidRule, World};
use strata_render::paged::{PageSource, StorePages};

/// The generated 2048x2048 world the paged tests draw.
pub fn world() -> World {
    strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 6,
        width: 2048,
        height: 2048,
    })
    .expect("generated world")
}

/// Pages cut from `w`'s level in memory.
pub fn level_pages(w: &World) -> std::sync::Arc<dyn strata_render::paged::PageSource> {
    std::sync::Arc::new(
        strata_render::paged::LevelPages::new(std::sync::Arc::new(w.level.clone()))
            .expect("a paged world"),
    )
}

/// `w` written as a store in a fresh temporary directory named for `what`.
pub fn temp_store(w: &World, what: &str) -> (std::path::PathBuf, strata_store::DirStore) {
    let dir = std::env::temp_dir().join(format!("strata-paged-{what}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let store = strata_store::DirStore::create(&dir, w, &strata_store::Layout::default()).unwrap();
    (dir, store)
}

/// Pages of `store` through a fresh 64 MiB chunk cache (returned too, to
/// invalidate after an edit).
pub fn store_pages(
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

/// The paged edit tests' case: the world as a store, its edit site's
/// camera, and the world with the site's crater dug (`rects` changed).
pub struct EditCase {
    pub world: World,
    pub colors: strata_render::TerrainColors,
    pub dir: std::path::PathBuf,
    pub store: strata_store::DirStore,
    pub camera: strata_camera::Camera,
    pub edited: Level,
    pub rects: Vec<DirtyRect>,
}

/// [`EditCase`] in a temporary store named for `what`, the camera at
/// `width` x `height`.
pub fn edit_case(what: &str, width: u32, height: u32) -> EditCase {
    let world = world();
    let colors = strata_render::TerrainColors::from_world(&world);
    let (dir, store) = temp_store(&world, what);
    let site = world.edit.clone().expect("an edit site");
    let camera = strata_camera::Camera::from_view(&world.level, &site.camera, width, height)
        .expect("the site's camera");
    let mut edited = world.level.clone();
    let rects = strata_level::edit::crater(&mut edited, &site);
    EditCase {
        world,
        colors,
        dir,
        store,
        camera,
        edited,
        rects,
    }
}

/// Save `rects` of `level` into `store` as one batch and tell `cache`; the
/// pages (chunk ids) it touched, for `Renderer::refresh_pages`.
pub fn commit_edit(
    store: &strata_store::DirStore,
    cache: &strata_store::ChunkCache,
    level: &Level,
    rects: &[DirtyRect],
) -> Vec<u32> {
    let cells = store.commit_rects(level, rects).unwrap();
    cache.invalidate(&cells);
    let across = level.width() / 256;
    cells
        .iter()
        .map(|&(cy, cx)| cy as u32 * across + cx as u32)
        .collect()
}

/// Frames of `camera` on paged renderer `r` until nothing is pending (at
/// most `most`); asserts every frame that no pixel shows sky where the
/// whole world (`whole_depth`) has terrain, and that the paged path stays
/// within its budget. Panics when it does not converge.
pub fn converge_paged(
    r: &mut strata_render::Renderer,
    camera: &strata_camera::Camera,
    whole_depth: &[f32],
    most: u32,
) -> u32 {
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
        if frame + 3 > most {
            eprintln!("frame {frame}: {stats:?}");
        }
        if stats.in_flight > 0 {
            // Let the page readers and fitters run (the test threads share the cores).
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }
    panic!("still pending after {most} frames");
}

/// An edit of a paged world's store (`Renderer::refresh_pages`) shows on
/// the next frame, equal to the whole world's `apply_edit` with `method`,
/// and a fresh open of the edited store converges to the same image; on
/// every adapter. `paged` opens the paged renderer over a source;
/// `converge_frames` bounds each convergence.
pub fn check_edit_equals_fresh_open(
    what: &str,
    method: &str,
    (width, height, converge_frames): (u32, u32, u32),
    paged: impl Fn(
        &strata_render::Gpu,
        Arc<dyn PageSource>,
        &strata_render::TerrainColors,
    ) -> strata_render::Renderer,
) {
    let gpus = super::gpus();
    if gpus.is_empty() {
        return;
    }
    let case = edit_case(what, width, height);
    let (w, camera) = (&case.world, &case.camera);
    let settings = strata_render::MethodSettings::default();
    let differing = |a: &[f32], b: &[f32]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    for gpu in gpus {
        let (cache, source) = store_pages(&case.store);
        let mut r = paged(&gpu, source, &case.colors);
        let mut whole = strata_render::Renderer::new(
            &gpu,
            &w.level,
            &case.colors,
            method,
            &settings,
            width,
            height,
        )
        .unwrap();
        whole.render_frame(camera).unwrap();
        let before = whole.read_depth().unwrap();
        converge_paged(&mut r, camera, &before, converge_frames);
        assert_eq!(
            differing(&r.read_depth().unwrap(), &before),
            0,
            "before the edit"
        );
        // Save the batch into the store, then refresh the touched pages.
        let chunks = commit_edit(&case.store, &cache, &case.edited, &case.rects);
        r.refresh_pages(&chunks).unwrap();
        r.render_frame(camera).unwrap();
        whole.apply_edit(&case.edited, &case.rects).unwrap();
        // `mesh` refits off the frame: compare the settled state.
        whole.settle_edits().unwrap();
        whole.render_frame(camera).unwrap();
        let (depth, color) = (r.read_depth().unwrap(), r.read_color().unwrap());
        let whole_depth = whole.read_depth().unwrap();
        let stats = r.paged_terrain().unwrap().stats();
        eprintln!(
            "{method} on {}: edit of pages {chunks:?} ({} pixels changed): {} pixels differ from the whole world; {stats:?}",
            gpu.report.backend,
            differing(&whole_depth, &before),
            differing(&depth, &whole_depth)
        );
        assert!(
            differing(&whole_depth, &before) > 0,
            "the crater is not in view"
        );
        assert_eq!(differing(&depth, &whole_depth), 0, "depth after the edit");
        assert!(
            color == whole.read_color().unwrap(),
            "colour after the edit"
        );
        // And a fresh open of the edited store draws the same.
        let (_, source) = store_pages(&case.store);
        let mut fresh = paged(&gpu, source, &case.colors);
        converge_paged(&mut fresh, camera, &depth, converge_frames);
        assert_eq!(differing(&fresh.read_depth().unwrap(), &depth), 0);
        assert!(fresh.read_color().unwrap() == color);
        // Put the store back for the next adapter.
        commit_edit(&case.store, &cache, &w.level, &case.rects);
    }
    let _ = std::fs::remove_dir_all(&case.dir);
}
