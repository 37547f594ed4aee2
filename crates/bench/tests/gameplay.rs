//! Issue 35: the sustained edit workload (`compare --gameplay`) at small K
//! on every backend's adapter (lavapipe's Vulkan and llvmpipe's GL here):
//! every method the adapter runs follows 20 frames of 4 track stamps (plus
//! craters, slabs and undos) through its own update path and must match a
//! renderer built fresh from the edited level at frame 10 and at the end.
//! A renderer that is not told of the edits must fail the same check.

mod common;

use strata_bench::edits::{self, FreshBuild};
use strata_bench::gameplay::{GameplayInput, GameplaySpec, Replay, Workload, method_row};
use strata_render::{MethodSettings, Renderer, TerrainColors};

const SIZE: (u32, u32) = (64, 40);

/// Fresh builds on `gpu` at `camera`, warmed up past any incremental build.
fn fresh<'a>(
    gpu: &'a strata_render::Gpu,
    colors: &'a TerrainColors,
    camera: &'a strata_camera::Camera,
    level: &strata_level::Level,
) -> FreshBuild<'a> {
    FreshBuild {
        gpu,
        colors,
        camera,
        warmup_cap: strata_bench::warm::build_frames(level) + 1,
        hold_busy_ms: 0,
        timestamps: gpu.report.timestamps,
    }
}

/// The workload's input at the tests' size.
fn input<'a>(world: &'a strata_level::World, fresh: FreshBuild<'a>) -> GameplayInput<'a> {
    GameplayInput {
        world,
        fresh,
        width: SIZE.0,
        height: SIZE.1,
    }
}

/// No shared shadow map: 1024² cast on a CPU rasteriser per frame.
fn no_shadows() -> MethodSettings {
    MethodSettings {
        shadows: false,
        ..Default::default()
    }
}

fn spec() -> GameplaySpec {
    GameplaySpec {
        edits_per_frame: 4,
        frames: 20,
        check_every: 10,
        seed: 35,
    }
}

#[test]
fn every_method_follows_the_gameplay_workload_on_every_backend() {
    let world = common::world();
    let colors = TerrainColors::from_world(&world);
    let workload = Workload::new(&world, spec(), SIZE.0, SIZE.1).unwrap();
    for gpu in common::every_backend("gameplay workload") {
        let camera = workload.camera(&world.level, 0, SIZE.0, SIZE.1).unwrap();
        let input = input(&world, fresh(&gpu, &colors, &camera, &world.level));
        let settings = no_shadows();
        let mut ran = 0;
        for entry in strata_render::methods::METHODS {
            if strata_render::methods::check_support(entry, &gpu.caps).is_err() {
                eprintln!("{}: {} not supported here", gpu.report.name, entry.name);
                continue;
            }
            let row = method_row(&input, &workload, entry.name, entry.name, &settings)
                .unwrap_or_else(|e| panic!("{} on {}: {e:#}", entry.name, gpu.report.name));
            eprintln!(
                "{} ({}) {:20} edits {:.2}/{:.2} ms, edits+frame {:.2}/{:.2} ms, alone {:.2}/{:.2} ms (p50/p99 CPU); checks {:?}",
                gpu.report.name,
                gpu.report.backend,
                row.method,
                row.edit_cpu_ms.p50,
                row.edit_cpu_ms.p99,
                row.with_edits_cpu_ms.p50,
                row.with_edits_cpu_ms.p99,
                row.alone_cpu_ms.p50,
                row.alone_cpu_ms.p99,
                row.checks
                    .iter()
                    .map(|c| (c.frame, c.consistent_after_frames, c.differing_pixels))
                    .collect::<Vec<_>>()
            );
            assert_eq!(
                row.checks.iter().map(|c| c.frame).collect::<Vec<_>>(),
                [9, 19],
                "{}",
                row.method
            );
            assert!(
                row.consistent,
                "{} on {} ({}) differs from a fresh build: {:?}",
                row.method, gpu.report.name, gpu.report.backend, row.checks
            );
            assert_eq!(row.edit_cpu_samples.len(), 20);
            // Every method but `mesh` (refits off the frame) draws a
            // frame's edits in the next frame.
            let lag = row.edit_lag_frames.expect("the edits' lag");
            eprintln!("{}: edits drawn after {lag:?} frames", row.method);
            if row.method != "mesh" {
                assert_eq!(lag.max, 0.0, "{}", row.method);
            }
            assert!(row.with_edits_cpu_ms.max >= row.edit_cpu_ms.max);
            ran += 1;
        }
        assert!(ran >= 3, "{}: only {ran} methods ran", gpu.report.name);
    }
}

/// The check can fail: a renderer that never saw the edits differs from a
/// fresh build of the edited level.
#[test]
fn a_renderer_not_told_of_the_edits_fails_the_check() {
    let world = common::world();
    let colors = TerrainColors::from_world(&world);
    let workload = Workload::new(&world, spec(), SIZE.0, SIZE.1).unwrap();
    let Some(gpu) = common::gpu_or_skip("gameplay negative control") else {
        return;
    };
    let mut replay = Replay::new(world.level.clone());
    for f in 0..spec().frames {
        replay.apply(f, &workload.edits(f));
    }
    // The last frame's camera looks at the tracks being laid.
    let camera = workload
        .camera(replay.level(), spec().frames - 1, SIZE.0, SIZE.1)
        .unwrap();
    let fresh = fresh(&gpu, &colors, &camera, &world.level);
    let settings = no_shadows();
    let target = edits::distance(
        &edits::build(&fresh, replay.level(), "ray-exact", &settings).unwrap(),
        &camera,
    )
    .unwrap();
    let mut stale: Renderer = edits::build(&fresh, &world.level, "ray-exact", &settings).unwrap();
    let differing = edits::differing_pixels(&edits::distance(&stale, &camera).unwrap(), &target);
    eprintln!("stale renderer: {differing:.3} % of pixels differ");
    assert!(differing > 1.0, "the edits are not in view: {differing} %");
    let checks = edits::checks_until(&mut stale, &camera, &target, 1, |seen| {
        edits::differing_pixels(seen, &target) <= strata_bench::gameplay::MAX_DIFFERING_PIXELS
    })
    .unwrap();
    assert_eq!(edits::consistent_after(&checks), None, "{checks:?}");
}

/// `compare --gameplay` end to end: the plan runs the workload after the
/// protocol; the results file holds a row per method and the collider's
/// refit, the report its section.
#[test]
fn the_protocol_writes_the_gameplay_rows_and_section() {
    let Some(gpu) = common::gpu_or_skip("gameplay protocol") else {
        return;
    };
    let out = std::env::temp_dir().join(format!("strata-gameplay-plan-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let world = common::world();
    let views = world.views[..1].to_vec();
    let mut opts = common::options(out.clone(), &["ray-exact", "mesh"], views);
    opts.shadows = false;
    let plan = strata_bench::run::Plan::new(world, opts)
        .unwrap()
        .with_gameplay(Some(GameplaySpec {
            frames: 6,
            check_every: 3,
            ..spec()
        }))
        .unwrap();
    let (json, report) = plan.run(&gpu).unwrap();
    let run =
        strata_bench::results::RunResults::from_json(&std::fs::read_to_string(&json).unwrap())
            .unwrap();
    let g = run.gameplay.expect("gameplay results");
    assert_eq!((g.frames, g.edits_per_frame), (6, 4));
    assert_eq!(
        g.rows.iter().map(|r| r.method.as_str()).collect::<Vec<_>>(),
        ["ray-exact", "mesh"]
    );
    assert!(g.rows.iter().all(|r| r.consistent && r.checks.len() == 2));
    let collider = g.collider.expect("the collider's refit");
    assert!(collider.consistent && collider.refit_ms.max >= collider.refit_ms.p50);
    let md = std::fs::read_to_string(report).unwrap();
    assert!(
        md.contains("## Gameplay edits") && md.contains("| mesh |"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// K = 64: a frame's rectangles outnumber the exact pyramid's update slots,
/// which then merges them (not the whole map); the result still matches a
/// fresh build at every check.
#[test]
fn the_exact_march_follows_sixty_four_edits_a_frame() {
    let Some(gpu) = common::gpu_or_skip("gameplay K = 64") else {
        return;
    };
    let world = common::world();
    let colors = TerrainColors::from_world(&world);
    let spec = GameplaySpec {
        edits_per_frame: 64,
        frames: 6,
        check_every: 3,
        ..spec()
    };
    let workload = Workload::new(&world, spec, SIZE.0, SIZE.1).unwrap();
    let camera = workload.camera(&world.level, 0, SIZE.0, SIZE.1).unwrap();
    let input = input(&world, fresh(&gpu, &colors, &camera, &world.level));
    let settings = no_shadows();
    for name in ["ray-exact", "ray-exact-fragment"] {
        let row = method_row(&input, &workload, name, name, &settings).unwrap();
        eprintln!(
            "{name}: edits {:?}, checks {:?}",
            row.edit_cpu_ms, row.checks
        );
        assert!(row.consistent, "{name}: {:?}", row.checks);
        assert_eq!(row.checks.len(), 2);
    }
}
