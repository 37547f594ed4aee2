//! Random edit sequences (issue 20): on a small generated world, random
//! craters, raises, slab removals and undos at the wrap edges, across chunk
//! corners and inside caves. After every step every method the adapter runs
//! must pass the edit protocol's check against a renderer built fresh from
//! the edited level (its depth within `EDIT_MAX_CLASS_MISMATCH` /
//! `EDIT_MAX_DEPTH_P95` of the fresh one within `EDIT_CHECK_FRAMES`
//! frames), looking at the step's site, and the mesh's local refit must
//! equal a fresh fit.
//!
//! `cargo test` runs a few short sequences (bounded to well under a minute
//! on lavapipe); `STRATA_EDIT_SEQ_CASES=N STRATA_EDIT_SEQ_STEPS=M` runs
//! longer ones and prints the steps checked. Failing sequences are shrunk
//! and their seeds kept in `edit_sequences.proptest-regressions`, rerun
//! first every time.

use proptest::prelude::*;
use proptest::test_runner::{
    Config, FileFailurePersistence, RngAlgorithm, TestCaseError, TestRng, TestRunner,
};
use strata_bench::edits::disagreement;
use strata_bench::results::{EDIT_CHECK_FRAMES, EDIT_MAX_CLASS_MISMATCH, EDIT_MAX_DEPTH_P95};
use strata_camera::Camera;
use strata_level::edit::{EditRect, Snapshot, crater, crater_rect, edit_columns};
use strata_level::generate::{GenerateParams, generate};
use strata_level::{Column, DirtyRect, EditSite, Level, ViewSpec};
use strata_mesh::{CHUNK, LevelMesh, tolerance_for_quality};
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors, methods};

const SIZE: (u32, u32) = (64, 40);
const WORLD: u32 = 256;

fn skip_loudly(why: &str) {
    use std::io::Write;
    if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_GPU=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU test: {why} ***\n");
}

fn env_count(name: &str, default: u32) -> u32 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Where a step edits.
#[derive(Clone, Debug)]
enum Site {
    /// Near a corner of the map, where every edit wraps.
    WrapCorner { dx: i64, dy: i64 },
    /// Near a corner of four mesh chunks.
    ChunkCorner { cx: u32, cy: u32, dx: i64, dy: i64 },
    /// At the k-th dual (cave) texel of the level, modulo their count.
    Cave(usize),
}

#[derive(Clone, Debug)]
enum Step {
    Crater { site: Site, radius: u32, depth: u8 },
    Raise { site: Site, half: u32, by: u8 },
    RemoveSlab { site: Site, half: u32 },
    Undo,
}

fn site() -> impl Strategy<Value = Site> {
    prop_oneof![
        (-6i64..6, -6i64..6).prop_map(|(dx, dy)| Site::WrapCorner { dx, dy }),
        (0..WORLD / CHUNK, 0..WORLD / CHUNK, -4i64..4, -4i64..4)
            .prop_map(|(cx, cy, dx, dy)| Site::ChunkCorner { cx, cy, dx, dy }),
        any::<usize>().prop_map(Site::Cave),
    ]
}

fn step() -> impl Strategy<Value = Step> {
    prop_oneof![
        3 => (site(), 2u32..12, 2u8..24)
            .prop_map(|(site, radius, depth)| Step::Crater { site, radius, depth }),
        2 => (site(), 1u32..6, 1u8..30).prop_map(|(site, half, by)| Step::Raise { site, half, by }),
        2 => (site(), 1u32..8).prop_map(|(site, half)| Step::RemoveSlab { site, half }),
        2 => Just(Step::Undo),
    ]
}

/// Unwrapped texel coordinates of a site on `level` (`caves`: its dual texels).
fn locate(site: &Site, caves: &[(u32, u32)]) -> (i64, i64) {
    match *site {
        Site::WrapCorner { dx, dy } => (dx, dy),
        Site::ChunkCorner { cx, cy, dx, dy } => {
            (i64::from(cx * CHUNK) + dx, i64::from(cy * CHUNK) + dy)
        }
        Site::Cave(k) => {
            let (x, y) = caves[k % caves.len()];
            (i64::from(x), i64::from(y))
        }
    }
}

fn square(x: i64, y: i64, half: u32) -> EditRect {
    EditRect {
        x: x - i64::from(half),
        y: y - i64::from(half),
        width: 2 * half + 1,
        height: 2 * half + 1,
    }
}

/// Apply one step; returns the dirty rectangles and where to look.
fn apply(
    level: &mut Level,
    step: &Step,
    caves: &[(u32, u32)],
    undo: &mut Vec<(Snapshot, (i64, i64))>,
) -> (Vec<DirtyRect>, Option<(i64, i64)>) {
    let mut edit = |rect: EditRect, at: (i64, i64), level: &mut Level| {
        undo.push((Snapshot::take(level, rect), at));
        rect
    };
    match step {
        Step::Crater {
            site,
            radius,
            depth,
        } => {
            let at = locate(site, caves);
            let site = EditSite {
                centre_x: at.0,
                centre_y: at.1,
                radius: *radius,
                depth: f32::from(*depth),
                ..EditSite::fostral()
            };
            edit(crater_rect(&site), at, level);
            (crater(level, &site), Some(at))
        }
        Step::Raise { site, half, by } => {
            let at = locate(site, caves);
            let rect = edit(square(at.0, at.1, *half), at, level);
            let by = *by;
            let dirty = edit_columns(level, rect, |_, _, c| Column {
                low: c.low.saturating_add(by),
                mid: c.mid.saturating_add(by),
                high: c.high.saturating_add(by),
                ..c
            });
            (dirty, Some(at))
        }
        Step::RemoveSlab { site, half } => {
            let at = locate(site, caves);
            let rect = edit(square(at.0, at.1, *half), at, level);
            let dirty = edit_columns(level, rect, |_, _, c| Column {
                mid: c.low,
                high: c.low,
                dual: false,
                upper_type: c.lower_type,
                ..c
            });
            (dirty, Some(at))
        }
        Step::Undo => match undo.pop() {
            Some((snapshot, at)) => (snapshot.restore(level), Some(at)),
            None => (Vec::new(), None),
        },
    }
}

/// A camera looking down at 60° onto texel `at` from 40 units behind it.
fn camera_at(level: &Level, at: (i64, i64)) -> Camera {
    let (w, h) = (i64::from(level.width()), i64::from(level.height()));
    let view = ViewSpec {
        name: "step".into(),
        x: at.0.rem_euclid(w) as f32,
        y: (at.1 - 40).rem_euclid(h) as f32,
        yaw: 0.0,
        eye: 70.0,
        under: false,
        pitch: -60.0,
    };
    Camera::from_view(level, &view, SIZE.0, SIZE.1).expect("a valid step camera")
}

fn distances(r: &Renderer, camera: &Camera) -> anyhow::Result<Vec<f32>> {
    Ok(strata_reference::distance_from_depth(
        camera,
        &r.read_depth()?,
    ))
}

struct Fixture {
    gpu: Gpu,
    level: Level,
    colors: TerrainColors,
    caves: Vec<(u32, u32)>,
    methods: Vec<&'static str>,
    tolerance: f64,
    mesh: LevelMesh,
}

fn fail(msg: String) -> TestCaseError {
    TestCaseError::fail(msg)
}

/// Run one sequence: every method built on the original level follows each
/// step and must agree with a fresh build; returns the steps checked and
/// how many of them changed what the camera saw.
fn run_sequence(fx: &Fixture, steps: &[Step]) -> Result<(u32, u32), TestCaseError> {
    let err = |e: anyhow::Error| fail(format!("{e:#}"));
    let settings = MethodSettings::default();
    let mut level = fx.level.clone();
    let mut mesh = fx.mesh.clone();
    let start_camera = camera_at(&level, (128, 128));
    let mut renderers = Vec::new();
    for &m in &fx.methods {
        let r = Renderer::new(&fx.gpu, &level, &fx.colors, m, &settings, SIZE.0, SIZE.1)
            .map_err(err)?;
        renderers.push(r);
    }
    for r in &mut renderers {
        r.render_frame(&start_camera).map_err(err)?;
    }
    let mut undo = Vec::new();
    let (mut checked, mut visible) = (0, 0);
    for (i, step) in steps.iter().enumerate() {
        let (dirty, at) = apply(&mut level, step, &fx.caves, &mut undo);
        let Some(at) = at else { continue };
        mesh.refit(&level, &dirty);
        if mesh != LevelMesh::fit(&level, fx.tolerance) {
            return Err(fail(format!(
                "step {i} {step:?}: the refit mesh differs from a fresh fit"
            )));
        }
        let camera = camera_at(&level, at);
        // The first method's picture before it learns of the edit: did the
        // step change what the camera sees (else the check proves little)?
        renderers[0].render_frame(&camera).map_err(err)?;
        let before = distances(&renderers[0], &camera).map_err(err)?;
        for (r, &m) in renderers.iter_mut().zip(&fx.methods) {
            r.apply_edit(&level, &dirty).map_err(err)?;
            // `mesh` refits off the frame: compare the settled state.
            r.settle_edits().map_err(err)?;
            let mut fresh =
                Renderer::new(&fx.gpu, &level, &fx.colors, m, &settings, SIZE.0, SIZE.1)
                    .map_err(err)?;
            fresh.render_frame(&camera).map_err(err)?;
            let want = distances(&fresh, &camera).map_err(err)?;
            drop(fresh);
            let (mut done, mut last) = (0, (0.0, 0.0));
            let mut agreed = false;
            for frames in EDIT_CHECK_FRAMES {
                while done < frames {
                    r.render_frame(&camera).map_err(err)?;
                    done += 1;
                }
                last = disagreement(&distances(r, &camera).map_err(err)?, &want);
                if last.0 <= EDIT_MAX_CLASS_MISMATCH && last.1 <= EDIT_MAX_DEPTH_P95 {
                    agreed = true;
                    break;
                }
            }
            if m == fx.methods[0] && disagreement(&before, &want) != (0.0, 0.0) {
                visible += 1;
            }
            if !agreed {
                return Err(fail(format!(
                    "step {i} {step:?}: {m} still differs from a fresh build after {done} \
                     frames: {:.3} % class mismatch, depth p95 {:.3}",
                    last.0, last.1
                )));
            }
        }
        checked += 1;
    }
    Ok((checked, visible))
}

#[test]
fn random_edit_sequences_match_a_fresh_build() {
    let gpu = match Gpu::headless() {
        Ok(gpu) => gpu,
        Err(e) => return skip_loudly(&format!("no GPU adapter ({e:#})")),
    };
    let world = generate(&GenerateParams {
        seed: 11,
        width: WORLD,
        height: WORLD,
    })
    .unwrap();
    let level = world.level.clone();
    let caves: Vec<(u32, u32)> = (0..level.height())
        .flat_map(|y| (0..level.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| level.column(i64::from(x), i64::from(y)).dual)
        .step_by(7)
        .collect();
    assert!(
        !caves.is_empty(),
        "the generated world has no caves to edit in"
    );
    let tolerance = tolerance_for_quality(0.5).unwrap();
    let methods: Vec<&'static str> = methods::names()
        .into_iter()
        .filter(|m| methods::check_support(m, &gpu.caps).is_ok())
        .collect();
    let fx = Fixture {
        mesh: LevelMesh::fit(&level, tolerance),
        colors: TerrainColors::from_world(&world),
        gpu,
        level,
        caves,
        methods,
        tolerance,
    };
    let cases = env_count("STRATA_EDIT_SEQ_CASES", 2);
    let steps = env_count("STRATA_EDIT_SEQ_STEPS", 3) as usize;
    let mut config = Config::with_cases(cases);
    config.failure_persistence = Some(Box::new(FileFailurePersistence::Direct(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/edit_sequences.proptest-regressions"
    ))));
    // A shrunk GPU failure costs a fresh build per method per try: few tries.
    config.max_shrink_iters = 64;
    // In `cargo test` the sequences are the same every run (a test that
    // sometimes draws only off-camera steps would fail at random: CI saw
    // 0 of 4 steps visible once); STRATA_EDIT_SEQ_RANDOM=1 draws new ones.
    let mut runner = if std::env::var_os("STRATA_EDIT_SEQ_RANDOM").is_some() {
        TestRunner::new(config)
    } else {
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
    };
    let (checked, visible) = (std::cell::Cell::new(0u32), std::cell::Cell::new(0u32));
    let start = std::time::Instant::now();
    let result = runner.run(&proptest::collection::vec(step(), 1..=steps), |seq| {
        let (c, v) = run_sequence(&fx, &seq)?;
        checked.set(checked.get() + c);
        visible.set(visible.get() + v);
        Ok(())
    });
    eprintln!(
        "edit sequences: {} steps checked, {} of them visible in the step's camera ({cases} \
         sequences of up to {steps}, {} methods + the mesh fit) in {:.1} s",
        checked.get(),
        visible.get(),
        fx.methods.len(),
        start.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    assert!(checked.get() > 0, "no step was checked");
    assert!(visible.get() > 0, "no step changed what its camera saw");
}
