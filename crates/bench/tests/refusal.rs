//! A method the adapter cannot run is refused by `Plan::run` before any GPU
//! work: one failure naming the missing capability, no cells and no edit
//! row for it, while the other methods run. The adapter's capabilities are
//! narrowed by hand (no compute), so this runs on any adapter.

use strata_bench::plan::MethodChoice;
use strata_bench::run::{EditMode, Options, Plan};
use strata_level::ViewSpec;
use strata_level::generate::{GenerateParams, generate};
use strata_render::Gpu;

fn skip_loudly(why: &str) {
    use std::io::Write;
    if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_GPU=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU test: {why} ***\n");
}

#[test]
fn a_method_the_adapter_cannot_run_is_one_failure_and_no_edit_row() {
    let mut gpu = match Gpu::headless() {
        Ok(gpu) => gpu,
        Err(e) => return skip_loudly(&format!("no GPU adapter ({e:#})")),
    };
    // As on WebGL2: no compute. `ray` draws with a fragment pass; `ray-compute` cannot.
    gpu.caps.compute = false;
    gpu.caps.storage_textures = false;
    let world = generate(&GenerateParams {
        seed: 4,
        width: 256,
        height: 512,
    })
    .unwrap();
    assert!(world.edit.is_some(), "generated worlds carry an edit site");
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("refusal");
    let _ = std::fs::remove_dir_all(&out);
    let methods = ["ray", "ray-compute"]
        .iter()
        .map(|n| MethodChoice {
            method: strata_render::methods::entry(n).unwrap(),
            setting: None,
        })
        .collect();
    let opts = Options {
        out: out.clone(),
        methods,
        views: vec![ViewSpec::parse("low", "100,100:0:30", 0.0).unwrap()],
        width: 32,
        height: 20,
        frames: 1,
        min_warmup: 1,
        hold_busy_ms: 0,
        shadows: true,
        edits: EditMode::Required,
        temporal: false,
        cache_dir: out.join("cache"),
        resume: false,
        grid: Default::default(),
    };
    let (json, _) = Plan::new(world, opts).unwrap().run(&gpu).unwrap();
    let run = strata_bench::merge::read_run(&json).unwrap();
    assert_eq!(run.rows.len(), 1, "{:?}", run.rows);
    assert_eq!(run.rows[0].method, "ray");
    assert_eq!(run.failures.len(), 1, "{:?}", run.failures);
    let f = &run.failures[0];
    assert_eq!((f.view.as_str(), f.method.as_str()), ("*", "ray-compute"));
    assert!(
        f.error.contains("ray-compute: needs compute shaders"),
        "{}",
        f.error
    );
    let edits: Vec<&str> = run.edit_rows.iter().map(|e| e.method.as_str()).collect();
    assert_eq!(edits, vec!["ray"]);
    assert_eq!(run.reference_images.len(), 1);
    assert!(out.join(&run.reference_images[0].image).is_file());
    assert!(run.complete);
}
