//! Level-of-detail arrays: made with the store, equal to halving the map in
//! memory, kept equal by edit batches, and absent ones read as none.

use std::path::PathBuf;
use strata_level::generate::{GenerateParams, generate};
use strata_level::lod::halve;
use strata_level::{Level, MidRule};
use strata_store::crashtest::batch;
use strata_store::{DirStore, Layout};

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strata-lod-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The map's level `k` planes, halving in memory.
fn levels(level: &Level, k: u32) -> (Vec<u8>, Vec<u8>, usize, usize) {
    let (mut w, mut h) = (level.width() as usize, level.height() as usize);
    let (mut hs, mut ms) = (level.heights().to_vec(), level.metas().to_vec());
    for _ in 0..k {
        (hs, ms) = halve(&hs, &ms, w, h);
        w /= 2;
        h /= 2;
    }
    (hs, ms, w, h)
}

/// Every chunk of every level in the store equals the halved map.
fn check(store: &DirStore, level: &Level) {
    let s = store.store();
    assert_eq!(s.lod_levels(), 2, "4 chunks across: 2 levels");
    for k in 1..=s.lod_levels() {
        let (hs, ms, w, h) = levels(level, k);
        for cy in 0..(h / 256) as u64 {
            for cx in 0..(w / 256) as u64 {
                let c = s.read_lod_chunk(k, cy, cx).unwrap();
                for y in 0..256usize {
                    let row = (cy as usize * 256 + y) * w + cx as usize * 256;
                    assert_eq!(
                        &c.heights[y * 256..(y + 1) * 256],
                        &hs[row..row + 256],
                        "level {k} chunk ({cy}, {cx}) row {y}"
                    );
                    assert_eq!(&c.metas[y * 256..(y + 1) * 256], &ms[row..row + 256]);
                }
            }
        }
    }
}

#[test]
fn coarse_levels_equal_the_halved_map_and_follow_edits() {
    let root = temp("levels");
    let world = generate(&GenerateParams {
        seed: 33,
        width: 1024,
        height: 2048,
    })
    .unwrap();
    let dir = root.join("s");
    let store = DirStore::create(&dir, &world, &Layout::default()).unwrap();
    assert_eq!(store.store().lod_levels(), 0, "levels are built on demand");
    let store = DirStore::build_lods(&dir, &|_, _| {}).unwrap();
    assert_eq!(store.store().possible_lod_levels(), 2);
    check(&store, &world.level);
    // Edit batches rewrite the coarse chunks over them in the same batch.
    let mut level = world.level.clone();
    for i in 0..6 {
        let dirty = batch(&mut level, 700 + i);
        store.commit_rects(&level, &dirty).unwrap();
    }
    assert_ne!(level, world.level);
    let reopened = DirStore::open(&dir).unwrap();
    assert_eq!(
        reopened.store().read_level(MidRule::Original).unwrap(),
        level
    );
    check(&reopened, &level);
    // Outside the grid, or past the levels: an error, not a panic.
    assert!(reopened.store().read_lod_chunk(1, 0, 99).is_err());
    let err = reopened
        .store()
        .read_lod_chunk(3, 0, 0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("level of detail 3") && err.contains("has 2"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_store_whose_levels_never_completed_reads_as_having_none() {
    let root = temp("partial");
    let world = generate(&GenerateParams {
        seed: 3,
        width: 1024,
        height: 1024,
    })
    .unwrap();
    let dir = root.join("s");
    DirStore::create(&dir, &world, &Layout::default()).unwrap();
    DirStore::build_lods(&dir, &|_, _| {}).unwrap();
    // The group attribute is written last: without it, the levels do not count.
    let group = dir.join("lod").join("zarr.json");
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&group).unwrap()).unwrap();
    json["attributes"]
        .as_object_mut()
        .unwrap()
        .remove("strata_lod");
    std::fs::write(&group, serde_json::to_vec(&json).unwrap()).unwrap();
    let store = DirStore::open(&dir).unwrap();
    assert_eq!(store.store().lod_levels(), 0);
    // Rebuilt in place, they count again.
    let store = DirStore::build_lods(&dir, &|_, _| {}).unwrap();
    assert_eq!(store.store().lod_levels(), 2);
    check(&store, &world.level);
    let _ = std::fs::remove_dir_all(&root);
}
