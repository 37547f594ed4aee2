//! A method whose build the GPU refuses (here: forced to ask for a buffer
//! over the device's `max_buffer_size`, as a build too large for the GPU
//! would) is one failure naming the method and the sizes, in the results
//! JSON and the report, and the run goes on with the next method, whose
//! cells and edit row are all there. Runs on any adapter.

mod common;

use common::skip_loudly;
use strata_bench::run::Plan;
use strata_level::ViewSpec;
use strata_level::generate::{GenerateParams, generate};
use strata_render::Gpu;

#[test]
fn a_build_the_gpu_refuses_is_recorded_and_the_next_method_runs() {
    let mut gpu = match Gpu::headless() {
        Ok(gpu) => gpu,
        Err(e) => return skip_loudly(&format!("no GPU adapter ({e:#})")),
    };
    // The test hook (`STRATA_TEST_OVERSIZE_BUILD=ray` for the binary).
    gpu.options.oversize_build = Some("ray".into());
    let world = generate(&GenerateParams {
        seed: 4,
        width: 256,
        height: 512,
    })
    .unwrap();
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("build_failure");
    let _ = std::fs::remove_dir_all(&out);
    let views = vec![
        ViewSpec::parse("low", "100,100:0:30", 0.0).unwrap(),
        ViewSpec::parse("down", "120,300:90:80", -60.0).unwrap(),
    ];
    let opts = common::options(out.clone(), &["ray", "painted"], views);
    let (json, report) = Plan::new(world, opts).unwrap().run(&gpu).unwrap();
    let run = strata_bench::merge::read_run(&json).unwrap();
    // The other method: every view and its edit row.
    let drawn: Vec<(&str, &str)> = run
        .rows
        .iter()
        .map(|r| (r.method.as_str(), r.view.as_str()))
        .collect();
    assert_eq!(drawn, vec![("painted", "low"), ("painted", "down")]);
    let edits: Vec<&str> = run.edit_rows.iter().map(|e| e.method.as_str()).collect();
    assert_eq!(edits, vec!["painted"]);
    // The refused build: its column and its edit row, each naming the method
    // and the sizes.
    let failed: Vec<(&str, &str)> = run
        .failures
        .iter()
        .map(|f| (f.view.as_str(), f.method.as_str()))
        .collect();
    assert_eq!(
        failed,
        vec![("*", "ray"), ("edit", "ray")],
        "{:?}",
        run.failures
    );
    for f in &run.failures {
        for needle in [
            "building `ray`",
            "32x20 picture",
            "256x512 level",
            "refused",
        ] {
            assert!(f.error.contains(needle), "`{needle}` not in: {}", f.error);
        }
    }
    assert!(run.complete);
    let report = std::fs::read_to_string(report).unwrap();
    assert!(report.contains("building `ray`"), "{report}");
    // The device is still good: the failure left nothing in its error sink.
    gpu.wait().unwrap();
}
