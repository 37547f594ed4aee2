//! Paged `mesh` in the page (issue 34): a 512x16384 store (past WebGPU's
//! 8192-texel texture side) served by `strata serve`, opened with
//! `?level=...&method=mesh` in headless Chromium (WebGPU on SwiftShader).
//! The page has no threads: the mesh's chunk fits run between frames
//! within a few milliseconds each (`methods/mesh/fitter.rs`, `Fitter::poll`),
//! their results handed back as the worker threads' are natively. Once
//! nothing is pending or in flight, the canvas must equal the native paged
//! `mesh` (`strata render --gpu-budget`, itself the whole-world mesh bit for
//! bit, `crates/render/tests/paged_mesh.rs`) up to the two rasterisers'
//! edges, and that image must meet mesh's limits against the CPU reference
//! (`strata metrics`; the page tests' limits, `browser.rs`). No frame may
//! come near chromedriver's 10 s renderer timeout.
//!
//! Same tools and skipping as `browser.rs` (`STRATA_REQUIRE_BROWSER=1`
//! makes a missing one a failure).

mod browser_common;

use browser_common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// The canvas: 160x100 drawn 1:1, overlay off.
const SIZE: (u32, u32) = (160, 100);

/// The GPU budget of the native render (the page's default, 64 MiB).
const BUDGET: u64 = 64 << 20;

/// Canvas pixels allowed to differ from the native paged mesh by more than
/// 8 in a channel: the same triangles and shading, rasterised by
/// SwiftShader in the page and lavapipe natively (edge pixels, f32 vertex
/// transforms, the canvas's presentation).
const MAX_DIFFERING: f64 = 0.02;

/// Mesh's limits against the CPU reference (percent): see-through,
/// covers-sky, coherence (`browser.rs`'s `LIMITS`, the native tests').
const MESH_LIMITS: (f64, f64, f64) = (1.5, 1.0, 0.5);

/// The slowest frame allowed while the page fits chunks (ms): well inside
/// chromedriver's 10 s renderer timeout.
const MAX_FRAME_MS: f64 = 5_000.0;

fn strata(args: &[&str], what: &str) -> std::process::Output {
    let output = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .output()
        .unwrap_or_else(|e| panic!("running strata {what}: {e}"));
    assert!(
        output.status.success(),
        "strata {what}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// The store, its view (a -30° one: fewer chunks to fit on the page's one
/// thread than a view along the world) and its `views.txt`.
fn fixture(dir: &Path) -> (PathBuf, String, PathBuf) {
    let store = dir.join("store");
    let s = store.to_string_lossy().to_string();
    strata(
        &[
            "generate",
            "--to",
            "store",
            "--size",
            "512x16384",
            "--out",
            &s,
        ],
        "generate --to store",
    );
    let line = store_view_line(&store, "-30");
    let view = line.split_whitespace().next().expect("a name").to_string();
    let file = dir.join("views.txt");
    std::fs::write(&file, format!("{line}\n")).expect("views.txt");
    (store, view, file)
}

#[test]
fn paged_mesh_streams_into_the_page_and_matches_the_native_mesh() {
    let Some((chromium, driver, bundle)) = tools() else {
        return;
    };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("browser-stream-mesh");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the fixture directory");
    let (store, view, views) = fixture(&dir);
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let (reference, native) = (dir.join("reference"), dir.join("native"));
    // `strata COMMAND FLAGS` over the store's view at the canvas's size into `out`.
    let over_view = |command: &[&str], out: &Path| {
        let mut args: Vec<String> = command.iter().map(|a| a.to_string()).collect();
        for (flag, value) in [
            ("--size", size.clone()),
            ("--level", store.to_string_lossy().into()),
            ("--views", views.to_string_lossy().into()),
            ("--out", out.to_string_lossy().into()),
        ] {
            args.extend([flag.to_string(), value]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        strata(&args, command[0]);
    };
    over_view(&["reference", "--no-cache"], &reference);
    let budget = BUDGET.to_string();
    over_view(
        &["render", "--method", "mesh", "--gpu-budget", &budget],
        &native,
    );
    let metrics = strata(
        &[
            "metrics",
            "--json",
            "--reference",
            &reference.join(&view).to_string_lossy(),
            "--render",
            &native.to_string_lossy(),
        ],
        "metrics",
    );
    let m: Value = serde_json::from_slice(&metrics.stdout).expect("metrics JSON");
    let get = |k: &str| m[k].as_f64().unwrap_or(f64::NAN);
    let (see, sky, coh) = (get("see_through"), get("covers_sky"), get("coherence"));
    eprintln!(
        "native paged mesh against the CPU reference: see-through {see:.3} %, covers-sky {sky:.3} %, coherence {coh:.3} %"
    );
    let (max_see, max_sky, max_coh) = MESH_LIMITS;
    assert!(
        see <= max_see && sky <= max_sky && coh <= max_coh,
        "the native paged mesh is outside mesh's limits: {m}"
    );
    let native_color = image::open(native.join("color.png"))
        .expect("the native render's color.png")
        .to_rgba8();

    let (_server, url) = serve(&bundle, &store);
    let (_driver, driver_url) = chromedriver(&driver);
    with_browser(&driver_url, &chromium, move |client| async move {
        let page = format!("{url}/?level=/level/&method=mesh&size={size}&scale=1&view={view}");
        let (s, load_s) = open(&client, &page).await;
        eprintln!(
            "paged mesh in the page: first frame {:.0} ms after navigation (10 frames after {load_s:.1} s)",
            s["page_to_first_frame_ms"].as_f64().unwrap_or(f64::NAN)
        );
        assert_eq!(s["adapter"]["backend"], "browserwebgpu", "{s}");
        assert_eq!(s["active"], "mesh", "the page refused paged mesh: {s}");
        run(&client, "overlay off\nframes 2", 60).await;
        let start = Instant::now();
        let (s, frames, slowest) = converge(&client, 600).await;
        eprintln!(
            "paged mesh converged in {:.1} s, {frames} frames, the slowest {slowest:.0} ms (wall, with the script round trip); paging {}",
            start.elapsed().as_secs_f64(),
            s["paging"]["stats"]
        );
        assert!(
            slowest <= MAX_FRAME_MS,
            "a frame took {slowest:.0} ms (chromedriver gives the renderer 10 s)"
        );
        let canvas = canvas_pixels(&client).await;
        assert_not_blank(&canvas, "streamed mesh");
        assert_eq!(canvas.dimensions(), native_color.dimensions());
        let apart = differing(&canvas, &native_color);
        let n = canvas.pixels().len();
        eprintln!(
            "paged mesh in the page differs from the native paged mesh in {apart} of {n} pixels ({:.2} %)",
            100.0 * apart as f64 / n as f64
        );
        assert!(
            (apart as f64) <= MAX_DIFFERING * n as f64,
            "{apart} of {n} pixels differ from the native paged mesh"
        );
    });
}
