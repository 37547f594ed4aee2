//! The reference read through a store's chunk cache (bounded memory, the
//! pyramid built per chunk from the chunk summaries down) is bit-identical
//! to the reference of the same world in memory: distance, class, terrain
//! and colour, over a generated 4096² world and views at every pitch, with
//! a cache budget small enough to evict all the time, and the cache never
//! holds more than its budget.

use std::sync::Arc;
use strata_camera::Camera;
use strata_level::generate::{GenerateParams, generate};
use strata_level::{MidRule, ViewSpec};
use strata_reference::{
    ReferenceSettings, TerrainRamps, Tracer, camera_for_view, render_color, render_color_checked,
};
use strata_store::{ChunkCache, DirStore, Layout};

#[test]
fn reference_over_a_store_equals_the_reference_in_memory() {
    let world = generate(&GenerateParams {
        seed: 1997,
        width: 4096,
        height: 4096,
    })
    .unwrap();
    let dir = std::env::temp_dir().join(format!("strata-ref-store-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let store = DirStore::create(&dir, &world, &Layout::default()).unwrap();
    // 24 chunks of 128 KiB: far fewer than a view crosses, so chunks are
    // evicted and read again while a picture is traced.
    let budget = 24 * 2 * 256 * 256;
    let cache = ChunkCache::new(Arc::clone(store.store()), budget, MidRule::Original);
    let memory = Tracer::new(&world.level);
    let tiled = Tracer::over(&cache).unwrap();
    assert!(tiled.level().is_none(), "a store is read through its tiles");
    let ramps = TerrainRamps::from_world(&world);
    let mut views: Vec<ViewSpec> = world.views.clone();
    // Across the map's wrapping corner, under a slab and straight down.
    for (spec, pitch) in [
        ("4090,4090:45:60", -20.0),
        ("10,4000:250:150", -90.0),
        ("2048,100:0:300", 0.0),
    ] {
        views.push(ViewSpec::parse("extra", spec, pitch).unwrap());
    }
    assert!(views.len() >= 6, "{} views", views.len());
    for (k, view) in views.iter().enumerate() {
        let cam = Camera::from_view(&world.level, view, 120, 75).unwrap();
        assert_eq!(camera_for_view(&cache, view, 120, 75).unwrap(), cam);
        let want = memory.render(&cam, &ReferenceSettings::default());
        let got = tiled
            .try_render(&cam, &ReferenceSettings::default())
            .unwrap();
        assert_eq!(got.class, want.class, "view {k} {}: class", view.name);
        assert_eq!(got.terrain, want.terrain, "view {k}: terrain");
        let bits = |d: &[f32]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&got.distance),
            bits(&want.distance),
            "view {k}: distance"
        );
        if k % 3 == 0 {
            let shadows = k % 2 == 0;
            let c_want = render_color(&memory, &ramps, &cam, shadows);
            let c_got = render_color_checked(&tiled, &ramps, &cam, shadows).unwrap();
            assert_eq!(c_got, c_want, "view {k}: colour");
        }
        let st = cache.stats();
        assert!(st.peak_bytes <= budget && st.bytes <= budget, "{st:?}");
    }
    let st = cache.stats();
    assert!(st.evictions > 0 && st.hits > st.misses, "{st:?}");
    // Unaccelerated over the store: the same pictures.
    let cam = Camera::from_view(&world.level, &views[0], 64, 40).unwrap();
    let bare = Tracer::over_unaccelerated(&cache).unwrap();
    assert_eq!(
        bare.render(&cam, &ReferenceSettings::default()),
        memory.render(&cam, &ReferenceSettings::default())
    );
    // A chunk that cannot be read is an error, not a picture with holes.
    let victim = dir.join("heights/c/0/0");
    let fresh = ChunkCache::new(Arc::clone(store.store()), budget, MidRule::Original);
    std::fs::write(&victim, b"not gzip").unwrap();
    let down = Camera::new(glam::Vec3::new(100.0, 100.0, 300.0), 0.0, -90.0, 32, 32).unwrap();
    let broken = Tracer::over(&fresh).unwrap();
    let err = broken
        .try_render(&down, &ReferenceSettings::default())
        .unwrap_err();
    assert!(err.to_string().contains("heights"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
