//! The reference and its cache files are bit-identical across runs and rayon
//! thread counts (issue 20): the cache is shared between machines and runs,
//! so a reference that depended on scheduling would make results drift.

mod common;

use strata_camera::Camera;
use strata_level::ViewSpec;
use strata_reference::ReferenceCache;

/// Every cache file in `dir`, by name, with its bytes.
fn cache_files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    files.sort();
    files
}

#[test]
fn reference_cache_is_identical_across_runs_and_thread_counts() {
    let level = common::rough_level(20);
    // Level, steep down and up-under-slab views: every code path of the march.
    let cameras: Vec<Camera> = [
        "60,20:30:40 0",
        "128,128:200:90 -60",
        "200,50:300:4:under 20",
    ]
    .iter()
    .map(|line| {
        let (spec, pitch) = line.split_once(' ').unwrap();
        let view = ViewSpec::parse("v", spec, pitch.parse().unwrap()).unwrap();
        Camera::from_view(&level, &view, 96, 60).unwrap()
    })
    .collect();
    let base = std::env::temp_dir().join(format!("strata-ref-determinism-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    let mut runs = Vec::new();
    for (run, threads) in [1usize, 2, 2].into_iter().enumerate() {
        let dir = base.join(format!("run{run}-threads{threads}"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let cache = ReferenceCache::new(&dir);
        pool.install(|| {
            for camera in &cameras {
                cache.get_or_compute(&level, camera).unwrap();
            }
        });
        runs.push(cache_files(&dir));
    }
    assert_eq!(runs[0].len(), cameras.len());
    // Not an empty picture: each view sees terrain and sky differs by view.
    for (name, bytes) in &runs[0] {
        assert!(bytes.len() > 96 * 60 * 4, "{name}: {} bytes", bytes.len());
    }
    for (i, run) in runs.iter().enumerate().skip(1) {
        assert_eq!(run.len(), runs[0].len());
        for ((name_a, a), (name_b, b)) in runs[0].iter().zip(run) {
            assert_eq!(name_a, name_b);
            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
            assert!(
                a == b,
                "run {i}: {name_a} differs from the one-thread run in {differ} bytes"
            );
        }
    }
    std::fs::remove_dir_all(&base).unwrap();
}
