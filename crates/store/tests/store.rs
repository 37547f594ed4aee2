//! Stores end to end: Vangers <-> store round trips, the chunk cache,
//! summaries, edits on a store equal to edits in memory, and bad input.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use strata_level::generate::{GenerateParams, generate};
use strata_level::stats::LevelStats;
use strata_level::{MidRule, World, io};
use strata_store::crashtest::{Rng, batch};
use strata_store::fs::{to_store, to_vangers};
use strata_store::{ChunkCache, DirStore, Layout, StoreError, load_any};

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strata-store-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn world(w: u32, h: u32, seed: u64) -> World {
    generate(&GenerateParams {
        seed,
        width: w,
        height: h,
    })
    .unwrap()
}

fn small_layout() -> Layout {
    Layout {
        chunk_height: 64,
        chunk_width: 128,
        gzip_level: 6,
    }
}

/// Every file under `dir`, by relative path.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let key = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.insert(key, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

#[test]
fn vangers_store_vangers_is_byte_identical() {
    let root = temp("roundtrip");
    let (a, s, b) = (root.join("a"), root.join("s"), root.join("b"));
    io::write_world(&a, &world(256, 512, 5)).unwrap();
    to_store(&a, &s, &small_layout()).unwrap();
    assert!(s.join("zarr.json").is_file());
    to_vangers(&s, &b).unwrap();
    let (fa, fb) = (files(&a), files(&b));
    assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>());
    for (name, bytes) in &fa {
        assert!(
            bytes == &fb[name],
            "{name} differs after Vangers -> store -> Vangers"
        );
    }
    let from_a = io::load_world(&a, MidRule::Original).unwrap();
    for dir in [&s, &b] {
        let w = load_any(dir, MidRule::Original).unwrap();
        assert_eq!(w.level, from_a.level);
        assert_eq!(w.views, from_a.views);
        assert_eq!(w.edit, from_a.edit);
        assert_eq!(w.water, from_a.water);
        assert_eq!(w.palette, from_a.palette);
        assert_eq!(w.config, from_a.config);
    }
    // The other mid rule is a load-time choice, as for a Vangers world.
    let vr = load_any(&s, MidRule::VangeRs).unwrap();
    assert_eq!(
        vr.level,
        io::load_world(&a, MidRule::VangeRs).unwrap().level
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn summaries_match_the_level_and_the_cache_keeps_its_budget() {
    let root = temp("cache");
    let w = world(512, 256, 9);
    let store = DirStore::create(&root.join("s"), &w, &small_layout()).unwrap();
    let s = store.store();
    assert_eq!(s.grid(), (4, 4));
    let sums = s.summaries().unwrap();
    let stats = LevelStats::compute(&w.level);
    let dual: u64 = sums.iter().map(|c| u64::from(c.dual_texels)).sum();
    assert_eq!(dual, w.level.dual_texel_count());
    assert!((100.0 * dual as f64 / (512.0 * 256.0) - stats.dual_percent).abs() < 1e-9);
    assert_eq!(sums.iter().map(|c| c.low_min).min(), Some(stats.height_min));
    assert_eq!(sums.iter().map(|c| c.top_max).max(), Some(stats.height_max));
    // Each chunk's summary is the chunk's.
    for (i, sum) in sums.iter().enumerate() {
        let (cy, cx) = (i as u64 / 4, i as u64 % 4);
        let c = s.chunk_of_level(&w.level, cy, cx);
        let want = strata_store::ChunkSummary::of(
            &c.heights,
            &c.metas,
            c.cols as usize,
            MidRule::Original,
        );
        assert_eq!(*sum, want, "chunk {cy},{cx}");
    }
    // Three chunks' worth of budget: columns equal the level's, wrapping.
    let chunk_bytes = 2 * 64 * 128;
    let cache = ChunkCache::new(Arc::clone(s), 3 * chunk_bytes, MidRule::Original);
    let mut rng = Rng(3);
    for _ in 0..2000 {
        let (x, y) = (rng.below(2000) as i64 - 1000, rng.below(2000) as i64 - 1000);
        assert_eq!(
            cache.column(x, y).unwrap(),
            w.level.column(x, y),
            "({x},{y})"
        );
        assert!(cache.stats().bytes <= 3 * chunk_bytes);
    }
    let st = cache.stats();
    assert!(st.evictions > 0 && st.hits > 0 && st.chunks <= 3, "{st:?}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn random_edits_on_a_store_equal_the_same_edits_in_memory() {
    let root = temp("edits");
    let w = world(256, 256, 21);
    let dir = root.join("s");
    let store = DirStore::create(&dir, &w, &small_layout()).unwrap();
    let mut level = w.level.clone();
    for i in 0..25 {
        let dirty = batch(&mut level, 1000 + i);
        store.commit_rects(&level, &dirty).unwrap();
        if i % 6 == 0 {
            let reopened = DirStore::open(&dir).unwrap();
            assert_eq!(
                reopened.store().read_level(MidRule::Original).unwrap(),
                level
            );
        }
    }
    let reopened = DirStore::open(&dir).unwrap();
    assert_eq!(
        reopened.store().read_level(MidRule::Original).unwrap(),
        level
    );
    assert_ne!(level, w.level, "the edits changed nothing");
    // Summaries were kept up to date by the edits.
    let stats = LevelStats::compute(&level);
    let sums = reopened.store().summaries().unwrap();
    assert_eq!(sums.iter().map(|c| c.low_min).min(), Some(stats.height_min));
    assert_eq!(sums.iter().map(|c| c.top_max).max(), Some(stats.height_max));
    assert!(!dir.join(strata_store::fs::JOURNAL).exists());
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn an_uncommitted_journal_is_discarded_and_a_committed_one_replayed() {
    let root = temp("journal");
    let w = world(256, 256, 2);
    let dir = root.join("s");
    let store = DirStore::create(&dir, &w, &small_layout()).unwrap();
    let mut level = w.level.clone();
    let dirty = batch(&mut level, 1);
    store.commit_rects(&level, &dirty).unwrap();
    drop(store);
    let after = files(&dir);
    // A journal whose manifest never got renamed: junk is dropped on open.
    let j = dir.join(strata_store::fs::JOURNAL);
    std::fs::create_dir_all(j.join("heights/c/0")).unwrap();
    std::fs::write(j.join("heights/c/0/0"), b"garbage").unwrap();
    std::fs::write(j.join("manifest.tmp"), b"[\"heights/c/0/0\"]").unwrap();
    let store = DirStore::open(&dir).unwrap();
    assert!(!j.exists());
    assert_eq!(files(&dir), after);
    assert_eq!(store.store().read_level(MidRule::Original).unwrap(), level);
    let _ = std::fs::remove_dir_all(&root);
}

/// Open and read everything; the error, as text.
fn open_error(dir: &Path) -> String {
    match DirStore::open(dir) {
        Err(e) => e.to_string(),
        Ok(s) => match s.store().read_level(MidRule::Original) {
            Err(e) => e.to_string(),
            Ok(_) => match s.store().summaries() {
                Err(e) => e.to_string(),
                Ok(_) => panic!("{}: read without an error", dir.display()),
            },
        },
    }
}

/// A fresh store of a small world, for one bad-input case.
fn fresh(root: &Path, name: &str) -> PathBuf {
    let dir = root.join(name);
    DirStore::create(&dir, &world(256, 256, 4), &small_layout()).unwrap();
    dir
}

/// Damage a store with `damage`, then check that opening and reading it
/// fails with an error containing every one of `wants` and changes no file.
fn check_bad(root: &Path, name: &str, damage: impl Fn(&Path), wants: &[&str]) {
    let dir = fresh(root, name);
    damage(&dir);
    let before = files(&dir);
    let err = open_error(&dir);
    for want in wants {
        assert!(
            err.contains(want),
            "{name}: `{err}` does not contain `{want}`"
        );
    }
    assert_eq!(
        files(&dir),
        before,
        "{name}: the failed open changed the store"
    );
}

fn edit_json(path: &Path, edit: impl Fn(&mut serde_json::Value)) {
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(path, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
}

#[test]
fn bad_input_is_a_clear_error_and_touches_nothing() {
    let root = temp("bad");
    check_bad(
        &root,
        "truncated",
        |d| {
            let p = d.join("metas/c/1/1");
            let bytes = std::fs::read(&p).unwrap();
            std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
        },
        &["array `metas`", "chunk [1, 1]"],
    );
    check_bad(
        &root,
        "checksum",
        |d| {
            let p = d.join("heights/c/2/0");
            let mut bytes = std::fs::read(&p).unwrap();
            let mid = bytes.len() / 2;
            bytes[mid] ^= 0x10;
            std::fs::write(&p, bytes).unwrap();
        },
        &["array `heights`", "chunk [2, 0]"],
    );
    check_bad(
        &root,
        "missing-chunk",
        |d| std::fs::remove_file(d.join("heights/c/3/1")).unwrap(),
        &["array `heights`", "chunk [3, 1]", "missing"],
    );
    check_bad(
        &root,
        "summary",
        |d| {
            let p = d.join("summary/c/0/0/0");
            let mut bytes = std::fs::read(&p).unwrap();
            bytes[3] ^= 0xff;
            std::fs::write(&p, bytes).unwrap();
        },
        &["array `summary`", "chunk [0, 0, 0]"],
    );
    check_bad(
        &root,
        "newer",
        |d| {
            edit_json(&d.join("zarr.json"), |v| {
                v["attributes"]["strata"]["format_version"] = 99.into()
            })
        },
        &["format version 99", "update Strata"],
    );
    check_bad(
        &root,
        "shape",
        |d| {
            edit_json(&d.join("metas/zarr.json"), |v| {
                v["shape"] = serde_json::json!([256, 512])
            })
        },
        &["array `metas`", "shape [256, 512], expected [256, 256]"],
    );
    check_bad(
        &root,
        "type",
        |d| {
            edit_json(&d.join("heights/zarr.json"), |v| {
                v["data_type"] = "int16".into()
            })
        },
        &["array `heights`", "data type int16, expected uint8"],
    );
    check_bad(
        &root,
        "no-array",
        |d| std::fs::remove_file(d.join("summary/zarr.json")).unwrap(),
        &["array `summary`"],
    );
    check_bad(
        &root,
        "foreign",
        |d| {
            edit_json(&d.join("zarr.json"), |v| {
                v["attributes"] = serde_json::json!({"title": "ocean temperature"})
            })
        },
        &["not a Strata world"],
    );
    // No zarr.json (and no world.ini): neither kind of world.
    let dir = fresh(&root, "no-zarr-json");
    std::fs::remove_file(dir.join("zarr.json")).unwrap();
    let before = files(&dir);
    let err = load_any(&dir, MidRule::Original).unwrap_err();
    assert!(matches!(err, StoreError::NotAStore { .. }), "{err}");
    assert!(err.to_string().contains("no zarr.json"), "{err}");
    assert_eq!(files(&dir), before);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn create_refuses_a_non_empty_directory() {
    let root = temp("refuse");
    std::fs::write(root.join("cat.jpg"), b"meow").unwrap();
    let err = DirStore::create(&root, &world(256, 256, 1), &small_layout()).unwrap_err();
    assert!(err.to_string().contains("not an empty directory"), "{err}");
    assert_eq!(files(&root).len(), 1);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn edit_batches_report_every_texel_they_change() {
    let w = strata_store::crashtest::start_world();
    let mut level = w.level.clone();
    for i in 0..300 {
        let before = level.clone();
        let dirty = batch(&mut level, i);
        let (bh, bm) = (before.heights(), before.metas());
        let (ah, am) = (level.heights(), level.metas());
        let width = level.width() as usize;
        for t in 0..ah.len() {
            if bh[t] != ah[t] || bm[t] != am[t] {
                let (x, y) = ((t % width) as u32, (t / width) as u32);
                assert!(
                    dirty.iter().any(|r| r.contains(x, y)),
                    "batch {i}: texel ({x},{y}) changed outside its dirty rects {dirty:?}"
                );
            }
        }
    }
}
