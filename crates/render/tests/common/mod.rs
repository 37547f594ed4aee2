//! Shared by the GPU tests: the adapter (or a loud skip), a hand-built level,
//! the small generated world, and the metric and crater comparisons.
#![allow(dead_code)]

use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT};
use strata_level::{Level, MidRule, ViewSpec};
use strata_reference::metrics::Metrics;
use strata_render::Gpu;

/// The GPU, or `None` after printing a loud skip notice.
pub fn gpu() -> Option<Gpu> {
    match Gpu::headless() {
        Ok(gpu) => {
            eprintln!(
                "adapter: {} ({}, {})",
                gpu.report.name, gpu.report.backend, gpu.report.driver
            );
            Some(gpu)
        }
        Err(e) => {
            skip_loudly(&format!("no GPU adapter ({e:#})"));
            None
        }
    }
}

/// The adapters the reference-comparing tests run on: one per backend
/// found, Vulkan (lavapipe on a CPU machine) and GL (llvmpipe through EGL),
/// so each method is held to the same limits on both, plus Metal or DX12
/// where they exist. `STRATA_TEST_BACKENDS=vulkan` (a comma list) narrows
/// it. A missing Vulkan or GL adapter is skipped loudly;
/// `STRATA_REQUIRE_GPU=1` (CI) makes a missing Vulkan adapter a failure,
/// `STRATA_REQUIRE_GL=1` (CI) a missing GL one.
pub fn gpus() -> Vec<Gpu> {
    use strata_render::{AdapterChoice, BackendChoice};
    let wanted = std::env::var("STRATA_TEST_BACKENDS").ok();
    let mut found = Vec::new();
    for (backend, required_by) in [
        (BackendChoice::Vulkan, Some("STRATA_REQUIRE_GPU")),
        (BackendChoice::Gl, Some("STRATA_REQUIRE_GL")),
        (BackendChoice::Metal, None),
        (BackendChoice::Dx12, None),
    ] {
        if wanted
            .as_deref()
            .is_some_and(|w| !w.split(',').any(|b| b.trim() == backend.to_string()))
        {
            continue;
        }
        match Gpu::open(&AdapterChoice {
            backend,
            index: None,
            name: std::env::var("WGPU_ADAPTER_NAME").ok(),
        }) {
            Ok(gpu) => {
                eprintln!(
                    "adapter: {} ({}, {})",
                    gpu.report.name, gpu.report.backend, gpu.report.driver
                );
                found.push(gpu);
            }
            Err(e) => {
                if let Some(var) = required_by {
                    skip_backend_loudly(var, &format!("no {backend} adapter ({e:#})"));
                }
            }
        }
    }
    if found.is_empty() {
        skip_loudly("no GPU adapter on any backend");
    }
    found
}

fn skip_backend_loudly(var: &str, why: &str) {
    use std::io::Write;
    if std::env::var_os(var).is_some_and(|v| v == "1") {
        panic!("{var}=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU backend: {why} ***\n");
}

/// Report a skipped GPU test where the harness cannot swallow it: libtest
/// captures `eprintln!` of passing tests, so this writes to the process's
/// stderr directly. With `STRATA_REQUIRE_GPU=1` (CI, which installs lavapipe)
/// a missing adapter fails the test instead.
pub fn skip_loudly(why: &str) {
    use std::io::Write;
    if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_GPU=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU test: {why} ***\n");
}

/// 256x256: terraces with cliffs, a water basin, a bridge slab and a cave.
pub fn synthetic_level() -> Level {
    let (w, h) = (256usize, 256usize);
    let mut heights = vec![0u8; w * h];
    let mut metas = vec![0u8; w * h];
    let tau = std::f32::consts::TAU;
    let base = |x: usize, y: usize| -> (u8, u8) {
        let (xf, yf) = (x as f32, y as f32);
        let f = 70.0
            + 45.0 * (tau * xf / 128.0).sin() * (tau * yf / 128.0).cos()
            + 20.0 * (tau * (xf + yf) / 64.0).sin();
        if f < 45.0 {
            return (8, 0); // water
        }
        // Terraces of 20 with a gentle slope on each.
        let h = 20.0 * (f / 20.0).floor() + 0.3 * (f % 20.0);
        let t = 1 + ((h / 40.0) as u8).min(6);
        (h.clamp(0.0, 220.0) as u8, t)
    };
    for y in 0..h {
        for x in 0..w {
            let (hh, t) = base(x, y);
            heights[y * w + x] = hh;
            metas[y * w + x] = t << META_TERRAIN_SHIFT;
        }
    }
    // Dual regions: (x range, y range, gap code, slab top above the floor, slab type).
    let regions = [
        ((96, 160), (120, 136), 3u8, 60u32, 7u8),
        ((20, 80), (170, 230), 7u8, 84u32, 5u8),
    ];
    for ((x0, x1), (y0, y1), code, above, slab_type) in regions {
        for y in y0..y1 {
            for x in (x0..x1).step_by(2) {
                let i = y * w + x;
                let low = heights[i].min(heights[i + 1]);
                heights[i] = low;
                heights[i + 1] = (u32::from(low) + above).min(255) as u8;
                let lower_type = metas[i] >> META_TERRAIN_SHIFT;
                metas[i] =
                    META_DOUBLE_LEVEL | (lower_type << META_TERRAIN_SHIFT) | ((code >> 2) & 3);
                metas[i + 1] = META_DOUBLE_LEVEL | (slab_type << META_TERRAIN_SHIFT) | (code & 3);
            }
        }
    }
    Level::from_planes(w as u32, h as u32, heights, metas, MidRule::Original).unwrap()
}

/// Views over the synthetic level at 0, -30, -60 and -90 degrees.
pub fn synthetic_views() -> Vec<ViewSpec> {
    [
        ("horizon", "128,40:0:30", 0.0),
        ("horizon-b", "200,200:135:15", 0.0),
        ("cave", "50,200:90:10:under", 0.0),
        ("high", "200,60:300:70", 0.0),
        ("down30", "128,100:10:60", -30.0),
        ("bridge30", "128,175:180:40", -30.0),
        ("down60", "60,60:45:80", -60.0),
        ("bridge60", "128,160:200:70", -60.0),
        ("down90", "128,128:0:100", -90.0),
        ("cave90", "50,200:0:60", -90.0),
    ]
    .into_iter()
    .map(|(n, s, p)| ViewSpec::parse(n, s, p).unwrap())
    .collect()
}

/// The small generated world the method tests share (seed 6, 512x1024).
pub fn generated_world() -> strata_level::World {
    generated_world_of_seed(6)
}

/// A generated world of `seed` at the method tests' size (512x1024): other
/// seeds than 6 are worlds no setting was tuned on.
pub fn generated_world_of_seed(seed: u64) -> strata_level::World {
    strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed,
        width: 512,
        height: 1024,
    })
    .expect("generated world")
}

/// `RAY_STEPS` from the environment (to try other budgets by hand), else
/// the paper's 128.
pub fn ray_steps() -> u32 {
    std::env::var("RAY_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(128)
}

/// Pictures for a human: with `STRATA_TEST_OUT=/tmp/x cargo test ...`, the
/// renderer's colour image goes to `/tmp/x/{name}.png`.
/// `$STRATA_TEST_OUT`: where tests may leave pictures to look at.
pub fn test_out_dir() -> Option<std::path::PathBuf> {
    std::env::var_os("STRATA_TEST_OUT").map(std::path::PathBuf::from)
}

/// `WxH` from environment variable `var`, else `default`.
pub fn env_size(var: &str, default: (u32, u32)) -> (u32, u32) {
    std::env::var(var)
        .ok()
        .and_then(|s| {
            let (a, b) = s.split_once('x')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .unwrap_or(default)
}

pub fn save_png(r: &strata_render::Renderer, name: &str, (w, h): (u32, u32)) {
    if let Ok(dir) = std::env::var("STRATA_TEST_OUT") {
        let path = std::path::Path::new(&dir).join(format!("{name}.png"));
        std::fs::create_dir_all(&dir).unwrap();
        strata_render::report::write_png(&path, w, h, &r.read_color().unwrap()).unwrap();
    }
}

/// One view's metrics for the test log.
pub fn metrics_line(m: &Metrics) -> String {
    format!(
        "see-through {:.3} % covers-sky {:.3} % coherence {:.3} % p50 {:.3} p95 {:.3}",
        m.see_through, m.covers_sky, m.coherence, m.depth_p50, m.depth_p95
    )
}

/// Render each of `views` with `r` at `(w, h)`, compare it with the CPU
/// reference, log the view's metrics and GPU time under `label`, and return
/// the worst of each metric. `each` sees every view's renderer, reference and
/// distances (for pictures and debug maps).
pub fn worst_over_views(
    r: &mut strata_render::Renderer,
    level: &Level,
    views: &[ViewSpec],
    (w, h): (u32, u32),
    label: &str,
    mut each: impl FnMut(&strata_render::Renderer, &ViewSpec, &strata_reference::Reference, &[f32]),
) -> Metrics {
    use strata_reference::metrics;
    let mut worst = Metrics::default();
    for view in views {
        let camera = strata_camera::Camera::from_view(level, view, w, h).unwrap();
        let t = r.render_frame(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        let reference = strata_reference::render_reference(level, &camera);
        let distance = metrics::distance_from_depth(&camera, &depth);
        each(r, view, &reference, &distance);
        let m = metrics::compare(&reference, &distance);
        eprintln!(
            "{label:8} {:12} pitch {:4}: {} gpu {:?} ms",
            view.name,
            view.pitch,
            metrics_line(&m),
            t.gpu_ms.map(|g| (g * 10.0).round() / 10.0),
        );
        fold_worst(&mut worst, &m);
    }
    worst
}

/// Where the environment variable `var` names `view`, print its hit/miss
/// map against the reference: `#` both hit, `R` only the reference (the
/// method sees through), `M` only the method, `.` both see sky.
pub fn debug_hit_map(
    var: &str,
    view: &ViewSpec,
    reference: &strata_reference::Reference,
    distance: &[f32],
    (w, h): (u32, u32),
) {
    if std::env::var(var).as_deref() != Ok(view.name.as_str()) {
        return;
    }
    for j in 0..h as usize {
        let row: String = (0..w as usize)
            .map(|i| {
                let k = j * w as usize + i;
                match (reference.distance[k].is_finite(), distance[k].is_finite()) {
                    (true, true) => '#',
                    (true, false) => 'R',
                    (false, true) => 'M',
                    _ => '.',
                }
            })
            .collect();
        eprintln!("{row}");
    }
}

/// Raise `worst` to at least `m`, field by field.
pub fn fold_worst(worst: &mut Metrics, m: &Metrics) {
    worst.see_through = worst.see_through.max(m.see_through);
    worst.covers_sky = worst.covers_sky.max(m.covers_sky);
    worst.coherence = worst.coherence.max(m.coherence);
    worst.depth_p50 = worst.depth_p50.max(m.depth_p50);
    worst.depth_p95 = worst.depth_p95.max(m.depth_p95);
}

/// Two frames' distances compared: the % of pixels where one hits and the
/// other sees sky, and the p95 of |a - b| where both hit.
pub fn distance_mismatch(a: &[f32], b: &[f32]) -> (f64, f32) {
    let mismatch = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() != y.is_finite())
        .count();
    let mut d: Vec<f32> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (x - y).abs())
        .collect();
    d.sort_by(f32::total_cmp);
    let p95 = d.get(d.len() * 95 / 100).copied().unwrap_or(0.0);
    (100.0 * mismatch as f64 / a.len() as f64, p95)
}

/// The generated world's crater, dug after the first frame: the next frame's
/// distances against a renderer built fresh from the edited level (class
/// mismatch %, p95, and how many pixels the crater changed).
pub fn crater_against_fresh(gpu: &Gpu, method: &str) -> (f64, f32, usize) {
    use strata_reference::metrics;
    use strata_render::{MethodSettings, Renderer, TerrainColors};
    // The fixture's camera stands 158 back and 40 up at pitch -30: the crater
    // is about 14 degrees down, in frame only in a tall image.
    let (w_px, h_px) = (160, 400);
    let w = generated_world();
    let colors = TerrainColors::from_world(&w);
    let settings = MethodSettings::default();
    let site = w.edit.clone().expect("generated worlds carry an edit site");
    let mut level = w.level.clone();
    let camera = strata_camera::Camera::from_view(&level, &site.camera, w_px, h_px).unwrap();
    let mut r = Renderer::new(gpu, &level, &colors, method, &settings, w_px, h_px).unwrap();
    r.render_frame(&camera).unwrap();
    let before = r.read_depth().unwrap();
    let rects = strata_level::edit::crater(&mut level, &site);
    r.apply_edit(&level, &rects).unwrap();
    // `mesh` refits off the frame: compare the settled state.
    r.settle_edits().unwrap();
    r.render_frame(&camera).unwrap();
    let after = metrics::distance_from_depth(&camera, &r.read_depth().unwrap());
    let mut fresh = Renderer::new(gpu, &level, &colors, method, &settings, w_px, h_px).unwrap();
    fresh.render_frame(&camera).unwrap();
    let want = metrics::distance_from_depth(&camera, &fresh.read_depth().unwrap());
    let changed = metrics::distance_from_depth(&camera, &before)
        .iter()
        .zip(&after)
        .filter(|(a, b)| a.is_finite() != b.is_finite() || (*a - *b).abs() > 1e-3)
        .count();
    let (pct, p95) = distance_mismatch(&after, &want);
    eprintln!(
        "{method}: crater changed {changed} pixels; vs fresh: class mismatch {pct:.4} %, p95 {p95:.4}"
    );
    (pct, p95, changed)
}

pub mod paged;

/// Where two word buffers (a GPU read-back and its CPU twin) differ: how
/// many words, of how many, and the first.
pub fn word_diff(a: &[u32], b: &[u32]) -> String {
    let bad: Vec<usize> = (0..a.len().min(b.len()))
        .filter(|&i| a[i] != b[i])
        .collect();
    format!(
        "{} of {} words differ, first at {:?}",
        bad.len(),
        a.len(),
        bad.first()
    )
}
