//! `strata compare` end to end: bad input is refused before any GPU work, and
//! a tiny run (2 views x 1 method, plus the edit protocol) writes results
//! with sane metrics. The GPU part skips loudly without an adapter.

use std::path::PathBuf;
use strata_bench::plan::MethodChoice;
use strata_bench::results::RunResults;
use strata_bench::run::{EditMode, Options, Plan};
use strata_level::World;
use strata_level::generate::{GenerateParams, generate};

fn world() -> World {
    generate(&GenerateParams {
        seed: 7,
        width: 256,
        height: 1024,
    })
    .expect("generate a small world")
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strata-bench-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn options(world: &World, out: PathBuf) -> Options {
    Options {
        out: out.clone(),
        methods: vec![MethodChoice {
            method: strata_render::methods::entry("ray").unwrap(),
            setting: None,
        }],
        views: world.views.iter().take(2).cloned().collect(),
        width: 64,
        height: 40,
        frames: 2,
        min_warmup: 1,
        hold_busy_ms: 0,
        shadows: true,
        edits: EditMode::Auto,
        temporal: false,
        cache_dir: out.join("cache"),
        resume: false,
        grid: Default::default(),
    }
}

#[test]
fn bad_input_is_refused_before_gpu_work() {
    let w = world();
    let base = temp("bad");
    std::fs::create_dir_all(&base).unwrap();
    let file = base.join("a-file");
    std::fs::write(&file, b"x").unwrap();

    let err = |o: Options| {
        Plan::new(w.clone(), o)
            .err()
            .map(|e| format!("{e:#}"))
            .unwrap_or_default()
    };
    let e = err(options(&w, file.join("out")));
    assert!(e.contains("output directory"), "{e}");

    let mut o = options(&w, base.join("o1"));
    o.views[1].name = o.views[0].name.clone();
    assert!(err(o).contains("appears twice"));

    let mut o = options(&w, base.join("o2"));
    o.frames = 0;
    assert!(err(o).contains("--frames"));

    let mut o = options(&w, base.join("o3"));
    o.methods[0].setting = Some("0".into());
    assert!(err(o).contains("positive"));

    let mut no_site = w.clone();
    no_site.edit = None;
    let mut o = options(&w, base.join("o4"));
    o.edits = EditMode::Required;
    let e = Plan::new(no_site, o)
        .err()
        .map(|e| format!("{e:#}"))
        .unwrap_or_default();
    assert!(e.contains("no edit site"), "{e}");
    std::fs::remove_dir_all(&base).unwrap();
}

/// The headless adapter, or `None` after a loud SKIPPED line (a failure
/// under `STRATA_REQUIRE_GPU=1`).
fn gpu_or_skip(test: &str) -> Option<strata_render::Gpu> {
    match strata_render::Gpu::headless() {
        Ok(g) => Some(g),
        Err(e) => {
            // Straight to stderr: libtest swallows eprintln! of passing tests.
            use std::io::Write;
            if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
                panic!("STRATA_REQUIRE_GPU=1 but no GPU adapter ({e:#})");
            }
            let _ = writeln!(
                std::io::stderr(),
                "\n*** SKIPPED {test}: no GPU adapter ({e:#}) ***\n"
            );
            None
        }
    }
}

#[test]
fn tiny_run_writes_sane_results() {
    let Some(gpu) = gpu_or_skip("tiny_run_writes_sane_results") else {
        return;
    };
    let w = world();
    let out = temp("tiny");
    let mut opts = options(&w, out.clone());
    opts.temporal = true;
    let plan = Plan::new(w.clone(), opts).expect("plan");
    let (json, report) = plan.run(&gpu).expect("run");
    let run = RunResults::from_json(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(
        run.complete && run.failures.is_empty(),
        "{:?}",
        run.failures
    );
    assert_eq!(run.rows.len(), 2);
    for r in &run.rows {
        for pct in [r.see_through, r.covers_sky, r.coherence] {
            assert!((0.0..=100.0).contains(&pct), "{r:?}");
        }
        // The 128-step march agrees with the exact reference on almost every pixel.
        assert!(
            r.see_through + r.covers_sky < 10.0,
            "{}: {} / {}",
            r.view,
            r.see_through,
            r.covers_sky
        );
        assert!(r.cpu_ms_mean > 0.0 && r.cpu_ms.samples.len() == 2);
        assert_eq!(r.gpu_ms_mean.is_some(), run.adapter.timestamps);
        assert!(r.prep_setup_ms > 0.0 && r.prep_warmup_ms >= r.prep_first_frame_ms);
        assert!(out.join(&r.image).is_file());
        // ꟻLIP against the CPU colour reference: the march shades the
        // surface the reference hits, so the error stays well below a wrong
        // palette's (seen: mean 0.15 on `river` at 64x40, where the march's
        // misses are a large share of so few pixels), and its map is written
        // beside the picture.
        let flip = r.flip.as_ref().expect("every native cell has ꟻLIP");
        assert!(
            flip.mean < 0.25 && flip.over_half < 10.0,
            "{}: {flip:?}",
            r.view
        );
        assert!(out.join(&flip.image).is_file());
    }
    // The ray march reads the edited texture directly: consistent on the first frame.
    assert_eq!(run.edit_rows.len(), 1);
    let e = &run.edit_rows[0];
    assert_eq!(e.first_frame_cpu_samples.len(), 5);
    assert_eq!(e.consistent_after_frames, Some(1), "{:?}", e.checks);
    let md = std::fs::read_to_string(report).unwrap();
    assert!(md.contains("![views down, methods across](grid.png)") && md.contains("| ray | "));
    assert!(md.contains("## Colour error by pitch"), "{md}");
    assert!(out.join("grid.png").is_file());
    // --temporal: the default path in 2 s at 10 fps, the crater dug on the
    // way. Played this fast, frames are far apart, and under the depot's roof
    // the march steps through its thin walls in some frames and not others:
    // flicker, but never most of the picture on average.
    assert_eq!(run.temporal.len(), 1);
    let t = &run.temporal[0];
    assert_eq!((t.frames, t.fps, t.dug), (21, 10, true));
    assert!(
        (0.5..40.0).contains(&t.flicker_mean) && t.flicker_max >= t.flicker_mean,
        "{t:?}"
    );
    assert!(md.contains("## Temporal flicker") && md.contains("| ray | "));
    // The figures, and the edit figure from the edit protocol's pictures.
    for f in ["frame-time-by-pitch", "preparation", "memory"] {
        assert!(md.contains(&format!("figures/{f}.png")), "{f}");
        assert!(out.join(format!("figures/{f}.png")).is_file(), "{f}");
        assert!(out.join(format!("figures/{f}.svg")).is_file(), "{f}");
    }
    assert_eq!(run.edit_images.len(), 1);
    assert!(out.join(&run.edit_images[0].before).is_file());
    assert!(md.contains("figures/edit.png") && out.join("figures/edit.png").is_file());
    std::fs::remove_dir_all(&out).unwrap();
}

/// The (view, method) cells of a results file.
fn cells(run: &RunResults) -> Vec<(String, String)> {
    let mut c: Vec<_> = run
        .rows
        .iter()
        .map(|r| (r.view.clone(), r.method.clone()))
        .collect();
    c.sort();
    c
}

#[test]
fn interrupted_run_resumes_to_the_full_cell_set() {
    let Some(gpu) = gpu_or_skip("interrupted_run_resumes_to_the_full_cell_set") else {
        return;
    };
    let w = world();
    let base = temp("resume");
    let two_methods = |out: PathBuf| {
        let mut o = options(&w, out);
        o.methods = ["ray", "ray-compute"]
            .map(|n| MethodChoice {
                method: strata_render::methods::entry(n).unwrap(),
                setting: None,
            })
            .to_vec();
        o.edits = EditMode::Off;
        // One reference cache for the three runs.
        o.cache_dir = base.join("cache");
        o
    };
    let read = |json: &std::path::Path| {
        RunResults::from_json(&std::fs::read_to_string(json).unwrap()).unwrap()
    };

    // Uninterrupted: 2 views x 2 methods.
    let (json, _) = Plan::new(w.clone(), two_methods(base.join("full")))
        .unwrap()
        .run(&gpu)
        .unwrap();
    let full = read(&json);
    assert!(
        full.complete && full.failures.is_empty(),
        "{:?}",
        full.failures
    );
    assert_eq!(cells(&full).len(), 4);

    // Interrupted after three cells: the results file holds those three.
    let dir = base.join("cut");
    let err = Plan::new(w.clone(), two_methods(dir.clone()))
        .unwrap()
        .run_until(&gpu, Some(3))
        .unwrap_err();
    assert!(err.to_string().contains("stopped after 3 cells"), "{err:#}");
    let json = dir.join(full.file_name());
    let cut = read(&json);
    assert!(!cut.complete);
    assert_eq!(cut.rows.len(), 3);

    // A resume with other settings is refused, naming them.
    let mut other = two_methods(dir.clone());
    other.frames = 3;
    other.resume = true;
    let err = Plan::new(w.clone(), other).unwrap().run(&gpu).unwrap_err();
    let msg = format!("{err:#}");
    assert!(msg.contains("frames (there 2, here 3)"), "{msg}");
    assert_eq!(
        read(&json),
        cut,
        "a refused resume must leave the file alone"
    );

    // Resumed: the three kept as measured, the fourth measured now.
    let mut resume = two_methods(dir.clone());
    resume.resume = true;
    Plan::new(w.clone(), resume).unwrap().run(&gpu).unwrap();
    let resumed = read(&json);
    assert!(
        resumed.complete && resumed.failures.is_empty(),
        "{:?}",
        resumed.failures
    );
    assert_eq!(cells(&resumed), cells(&full));
    assert_eq!(
        resumed.rows[..3],
        cut.rows[..],
        "kept cells were measured again"
    );
    // Rendering is deterministic (tests/determinism.rs in strata-render), so
    // the new cell's accuracy equals the uninterrupted run's.
    let (a, b) = (
        &resumed.rows[3],
        full.rows
            .iter()
            .find(|r| r.view == resumed.rows[3].view && r.method == resumed.rows[3].method)
            .unwrap(),
    );
    assert_eq!(
        (
            a.see_through,
            a.covers_sky,
            a.depth_p50,
            a.depth_p95,
            a.coherence
        ),
        (
            b.see_through,
            b.covers_sky,
            b.depth_p50,
            b.depth_p95,
            b.coherence
        )
    );
    assert!(dir.join(&a.image).is_file() && dir.join("grid.png").is_file());
    std::fs::remove_dir_all(&base).unwrap();
}
