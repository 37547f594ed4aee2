//! Shared by the bench's GPU tests: the adapter or a loud skip, and the
//! options of a small comparison.

#![allow(dead_code)] // each test file uses its part

use std::path::PathBuf;
use strata_bench::plan::MethodChoice;
use strata_bench::run::{EditMode, Options};
use strata_level::generate::{GenerateParams, generate};
use strata_level::{ViewSpec, World};
use strata_render::Gpu;

/// Say loudly that a GPU test is skipped (a failure under
/// `STRATA_REQUIRE_GPU=1`). Straight to stderr: libtest swallows
/// `eprintln!` of passing tests.
pub fn skip_loudly(why: &str) {
    use std::io::Write;
    if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_GPU=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU test: {why} ***\n");
}

/// The headless adapter, or `None` after [`skip_loudly`].
pub fn gpu_or_skip(test: &str) -> Option<Gpu> {
    match Gpu::headless() {
        Ok(g) => Some(g),
        Err(e) => {
            skip_loudly(&format!("{test}: no GPU adapter ({e:#})"));
            None
        }
    }
}

/// One adapter per backend found (lavapipe's Vulkan and llvmpipe's GL on a
/// CPU machine), every method held to the same check on each; none found:
/// a loud skip (as [`gpu_or_skip`]).
pub fn every_backend(test: &str) -> Vec<Gpu> {
    use strata_render::{AdapterChoice, BackendChoice};
    let mut found = Vec::new();
    for backend in [BackendChoice::Vulkan, BackendChoice::Gl] {
        let choice = AdapterChoice {
            backend,
            ..Default::default()
        };
        match Gpu::open(&choice) {
            Ok(g) => found.push(g),
            Err(e) => eprintln!("\n*** SKIPPED GPU backend {backend}: {test}: {e:#} ***\n"),
        }
    }
    if found.is_empty() {
        skip_loudly(&format!("{test}: no GPU adapter on Vulkan or GL"));
    }
    found
}

/// The methods of these names, default settings.
pub fn choices(names: &[&str]) -> Vec<MethodChoice> {
    names
        .iter()
        .map(|n| MethodChoice {
            method: strata_render::methods::entry(n).unwrap(),
            setting: None,
        })
        .collect()
}

/// A small comparison into `out`: 32x20 pixels, one timed frame, shadows
/// on, the edit protocol required.
pub fn options(out: PathBuf, methods: &[&str], views: Vec<ViewSpec>) -> Options {
    Options {
        cache_dir: out.join("cache"),
        out,
        methods: choices(methods),
        views,
        width: 32,
        height: 20,
        frames: 1,
        min_warmup: 1,
        hold_busy_ms: 0,
        shadows: true,
        edits: EditMode::Required,
        temporal: false,
        resume: false,
        grid: Default::default(),
    }
}

/// A small generated world (256 x 1024, seed 7) with its views and edit site.
pub fn world() -> World {
    generate(&GenerateParams {
        seed: 7,
        width: 256,
        height: 1024,
    })
    .expect("generate a small world")
}
