//! The browser build in a real headless Chromium (WebGPU on SwiftShader),
//! driven through chromedriver with fantoccini: every method at one view of
//! a generated world at 160x100 scored in the page against the CPU reference
//! (computed in the page too) within the native lavapipe tests' limits; a
//! crater dug through the page shows in the next frames and the edited
//! level's reference agrees; undo brings the picture back; the screenshot is
//! not blank; and `?backend=webgl2` draws `ray`, `painted` and `sliced`
//! within the same limits.
//!
//! Needs Debian's `chromium` and `chromium-driver` and the bundle
//! (`crates/web/build.sh`). Without them it prints a SKIPPED line;
//! `STRATA_REQUIRE_BROWSER=1` (set by `.ci/run`) makes that a failure.

mod browser_common;

use browser_common::*;
use fantoccini::Client;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// The page: a small generated world (the whole default one takes the
/// single-threaded page tens of seconds), a 160x100 canvas drawn 1:1, the
/// edit fixture's camera (it looks down at ground, so a dig lands).
const PAGE: &str = "?world=512x2048&size=160x100&scale=1&view=edit";

/// Per method: see-through, covers-sky, coherence limits (percent), the
/// native tests' (`crates/render/tests`, `voxel_tests.rs`).
const LIMITS: [(&str, f64, f64, f64); 10] = [
    ("ray", 1.0, 0.2, 1.0),
    ("ray-compute", 1.0, 0.2, 1.0),
    // Exact (issue 15): `ray_exact_tests.rs` holds them to 0.05 % and 0.05 %.
    ("ray-exact", 0.05, 0.05, 0.5),
    ("ray-exact-fragment", 0.05, 0.05, 0.5),
    ("voxel", 0.5, 0.2, 0.5),
    ("voxel-compute", 0.5, 0.2, 0.5),
    ("painted", 2.0, 0.2, 3.5),
    ("sliced", 2.0, 0.2, 3.5),
    ("scattered", 2.0, 1.5, 3.5),
    ("mesh", 1.5, 1.0, 0.5),
];

/// Score the drawn method; its metrics (see-through, covers-sky, coherence).
async fn score(client: &Client, before: &Value, method: &str) -> (f64, f64, f64) {
    let (see, sky, coh, _) = score_with_depth(client, before, method).await;
    (see, sky, coh)
}

/// [`score`] and the median depth error (world units).
async fn score_with_depth(client: &Client, before: &Value, method: &str) -> (f64, f64, f64, f64) {
    let scored = before["scored"].as_u64().unwrap_or(0);
    let s = run(client, "score", 600).await;
    assert!(
        s["scored"].as_u64().unwrap_or(0) > scored,
        "no new score: {s}"
    );
    let entry = s["scores"]
        .as_array()
        .and_then(|a| a.iter().find(|e| e["method"] == method))
        .unwrap_or_else(|| panic!("no score for {method}: {s}"));
    let m = &entry["metrics"];
    let get = |k: &str| m[k].as_f64().unwrap_or(f64::NAN);
    (
        get("see_through"),
        get("covers_sky"),
        get("coherence"),
        get("depth_p50"),
    )
}

fn check(method: &str, (see, sky, coh): (f64, f64, f64), failures: &mut Vec<String>) {
    let &(_, max_see, max_sky, max_coh) = LIMITS
        .iter()
        .find(|l| l.0 == method)
        .expect("a method with limits");
    eprintln!("{method:14} see-through {see:.3} %, covers-sky {sky:.3} %, coherence {coh:.3} %");
    if !(see <= max_see && sky <= max_sky && coh <= max_coh) {
        failures.push(format!(
            "{method}: see-through {see:.3} (<= {max_see}), covers-sky {sky:.3} (<= {max_sky}), \
             coherence {coh:.3} (<= {max_coh})"
        ));
    }
}

#[test]
fn every_method_in_headless_chromium() {
    let Some((chromium, driver, bundle)) = tools() else {
        return;
    };
    let fixture = CompareFixture::new();
    let (_server, url) = serve(&bundle, &fixture.world);
    let (_driver, driver_url) = chromedriver(&driver);
    with_browser(&driver_url, &chromium, |client| drive(client, url, fixture));
}

async fn drive(client: Client, url: String, fixture: CompareFixture) {
    // WebGPU: every method.
    let (s, load_s) = open(&client, &format!("{url}/{PAGE}")).await;
    eprintln!(
        "WebGPU page: first frames after {load_s:.1} s (page load to first frame {:.0} ms) on {}",
        s["page_to_first_frame_ms"], s["adapter"]
    );
    assert_eq!(s["adapter"]["backend"], "browserwebgpu", "{s}");
    run(&client, "overlay off\nframes 2", 60).await;
    let mut failures = Vec::new();
    for (method, ..) in LIMITS {
        run(&client, &format!("method {method}"), 300).await;
        let start = Instant::now();
        let s = run(&client, "frames 2", 600).await;
        let frame_ms = start.elapsed().as_secs_f64() * 1e3 / 2.0;
        check(method, score(&client, &s, method).await, &mut failures);
        eprintln!("{method:14} {frame_ms:.0} ms per frame (2 frames, wall clock)");
    }
    assert!(
        failures.is_empty(),
        "over the limits:\n{}",
        failures.join("\n")
    );

    // A crater: the picture changes, the edited level's reference agrees,
    // undo brings the picture back.
    run(&client, "method ray\nframes 2", 60).await;
    let before = canvas_pixels(&client).await;
    assert_not_blank(&before, "WebGPU ray");
    let s = run(&client, "dig 0.5 0.6\nframes 2", 60).await;
    assert_eq!(s["undo_depth"], 1, "the dig did not land: {}", s["log"]);
    let dug = canvas_pixels(&client).await;
    let changed = differing(&before, &dug);
    eprintln!("the crater changed {changed} pixels");
    assert!(
        changed > 200,
        "a crater changed only {changed} pixels of the picture"
    );
    let mut failures = Vec::new();
    check("ray", score(&client, &s, "ray").await, &mut failures);
    assert!(failures.is_empty(), "after the dig: {failures:?}");
    run(&client, "undo\nframes 2", 60).await;
    let undone = canvas_pixels(&client).await;
    let left = differing(&before, &undone);
    assert!(left < 20, "undo left {left} pixels different");
    // The mouse: a click on the canvas digs (through winit's pointer events).
    client
        .find(fantoccini::Locator::Id("strata-canvas"))
        .await
        .expect("the canvas")
        .click()
        .await
        .expect("clicking the canvas");
    let s = wait_for(&client, "a dig by a click", 60, |s| s["undo_depth"] == 1).await;
    eprintln!("a click dug: {}", s["log"]);
    let s = run(&client, "undo\nframes 2", 60).await;
    assert_eq!(s["undo_depth"], 0, "{s}");

    // The folder picker: a world folder replaces the generated world (the
    // same readers as natively); a folder without world.ini is a clear error
    // in the page, and the viewer goes on.
    let picker = client
        .find(fantoccini::Locator::Id("strata-open"))
        .await
        .expect("the folder picker");
    picker
        .send_keys(&fixture.world.to_string_lossy())
        .await
        .expect("picking the world folder");
    let s = wait_for(&client, "the picked world", 120, |s| {
        s["level_size"] == serde_json::json!([256, 1024]) && s["frames"].as_u64() >= Some(3)
    })
    .await;
    eprintln!("picked the world folder: {}", s["log"]);
    let empty = fixture.dir.join("not-a-world");
    std::fs::create_dir_all(&empty).expect("a folder");
    std::fs::write(empty.join("readme.txt"), "no world here").expect("a file");
    // ChromeDriver adds to a `multiple` input's files: empty it first.
    client
        .execute("document.getElementById('strata-open').value = '';", vec![])
        .await
        .expect("emptying the picker");
    picker
        .send_keys(&empty.to_string_lossy())
        .await
        .expect("picking a folder without a world");
    let message = error_text(&client, 30).await;
    eprintln!("a folder without a world: {message}");
    assert!(message.contains("world.ini"), "{message}");

    // WebGL2: ray.
    let (s, _) = open(&client, &format!("{url}/{PAGE}&backend=webgl2")).await;
    eprintln!("WebGL2 page on {}", s["adapter"]);
    assert_eq!(s["adapter"]["backend"], "gl", "{s}");
    let s = run(&client, "overlay off\nframes 2", 60).await;
    let unavailable = s["unavailable"].as_array().cloned().unwrap_or_default();
    for u in &unavailable {
        eprintln!("WebGL2 unavailable: {}", u["reason"]);
        assert!(
            u["reason"].as_str().is_some_and(|r| r.contains("needs")),
            "an unavailable method without the capability named: {u}"
        );
    }
    assert!(
        !unavailable.iter().any(|u| u["method"] == "ray"),
        "ray must run on WebGL2"
    );
    let gl = canvas_pixels(&client).await;
    assert_not_blank(&gl, "WebGL2 ray");
    // The same view, the same WGSL: WebGL2 draws what WebGPU drew.
    let apart = differing(&before, &gl);
    eprintln!(
        "WebGL2 ray differs from WebGPU ray in {apart} of {} pixels",
        gl.pixels().len()
    );
    assert!(
        apart * 50 < gl.pixels().len(),
        "WebGL2 ray differs from WebGPU ray in {apart} pixels"
    );
    // Scored like WebGPU's: the depth comes back through the RGBA8 pass.
    let mut failures = Vec::new();
    let (see, sky, coh, depth) = score_with_depth(&client, &s, "ray").await;
    eprintln!("WebGL2 ray: depth p50 {depth:.3}");
    check("ray", (see, sky, coh), &mut failures);
    // Depth itself (a read-back of zeros once passed the coverage limits
    // vacuously: every pixel a hit at the near plane).
    assert!(
        depth <= 0.5,
        "WebGL2 ray: depth p50 {depth} world units off"
    );
    // The object-order methods WebGL2 has: their vertex shaders read the
    // terrain through GLSL ES 3.00. Each is scored against the reference
    // from the page's own read-back of its picture (a blank or shifted
    // picture fails the coverage limits).
    //
    // Only `painted` is also screenshotted: a WebDriver screenshot waits
    // for the compositor, which waits behind the frames the page keeps
    // drawing, and a WebGL2 `sliced` frame on SwiftShader is seconds long
    // (with Chromium 156.0.8078.108 its screenshot missed chromedriver's
    // 10 s renderer timeout four times in a row, in CI and on a 2-core
    // machine; 156.0.8078.129 takes it). That the canvas shows what WebGL2
    // draws is checked by `ray` and `painted`.
    for (method, screenshot) in [("painted", true), ("sliced", false)] {
        assert!(
            !unavailable.iter().any(|u| u["method"] == method),
            "{method} must run on WebGL2"
        );
        run(&client, &format!("method {method}"), 300).await;
        let start = Instant::now();
        let s = run(&client, "frames 2", 300).await;
        eprintln!(
            "WebGL2 {method}: {:.0} ms per frame (2 frames, wall clock)",
            start.elapsed().as_secs_f64() * 1e3 / 2.0
        );
        if screenshot {
            assert_not_blank(&canvas_pixels(&client).await, &format!("WebGL2 {method}"));
        }
        let scores = score(&client, &s, method).await;
        eprintln!("WebGL2 {method}: {scores:?}");
        check(method, scores, &mut failures);
    }
    assert!(failures.is_empty(), "WebGL2: {failures:?}");

    // `?compare`: the quick protocol in the page; `strata merge` takes its
    // results file next to lavapipe's, and the accuracy agrees.
    compare_in_the_page(&client, &url, &fixture).await;

    // WebGPU's default limits only: voxel (2,4,1) on the default world needs
    // more than 128 MiB of storage binding and is refused, the limit named.
    voxel_grid_over_the_limit(&client, &url).await;
}

/// `?compare`'s world and views: a small generated world served at
/// `/level/`, two of its views (a pitch-0 cave mouth and a -30 one), so the
/// page's protocol (SwiftShader draws `painted` slowly) stays short.
struct CompareFixture {
    dir: PathBuf,
    world: PathBuf,
    views: Vec<String>,
    /// One method of each kind that agrees exactly across rasterisers: a
    /// fragment march, a compute build and march, the fitted mesh (built in
    /// steps in the page). Every method at 320x200 takes SwiftShader ~6 minutes
    /// (painted and sliced are seconds a frame), too long for CI; and `sliced`
    /// at the horizon differs per rasteriser (bench/portability/README.md).
    /// `ray:64` is a method with a setting: the page must check its support
    /// by the method, not by the label (issue 30).
    methods: &'static str,
}

impl CompareFixture {
    fn new() -> Self {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("browser-compare");
        let _ = std::fs::remove_dir_all(&dir);
        let world = dir.join("world");
        let status = Command::new(env!("CARGO_BIN_EXE_strata"))
            .args(["generate", "--size", "256x1024", "--out"])
            .arg(&world)
            .stdout(Stdio::null())
            .status()
            .expect("running strata generate");
        assert!(status.success(), "strata generate failed");
        let views = vec!["hangar".to_string(), "portal".to_string()];
        let text = std::fs::read_to_string(world.join("views.txt")).expect("views.txt");
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| views.iter().any(|v| l.split_whitespace().next() == Some(v)))
            .collect();
        assert_eq!(
            lines.len(),
            views.len(),
            "the generated world's views: {text}"
        );
        std::fs::write(dir.join("views.txt"), lines.join("\n") + "\n").expect("writing views");
        CompareFixture {
            dir,
            world,
            views,
            methods: "ray:64,voxel-compute,mesh",
        }
    }
}

async fn compare_in_the_page(client: &Client, url: &str, fixture: &CompareFixture) {
    let start = Instant::now();
    let page = format!(
        "{url}/?level=/level/&compare&views={}&methods={}",
        fixture.views.join(","),
        fixture.methods
    );
    client.goto(&page).await.expect("opening the compare page");
    let s = wait_for(client, "the protocol in the page", 900, |s| {
        s["phase"] == "compared"
    })
    .await;
    eprintln!(
        "?compare: {} rows, {} failures in {:.0} s (references {:.0} ms, protocol {:.0} ms)",
        s["rows"],
        s["failures"],
        start.elapsed().as_secs_f64(),
        s["reference_ms"].as_f64().unwrap_or(f64::NAN),
        s["total_ms"].as_f64().unwrap_or(f64::NAN)
    );
    let json = client
        .execute("return window.strata.strataResults()", vec![])
        .await
        .expect("reading the results");
    let json = json.as_str().expect("a results file");
    let name = s["results_name"].as_str().expect("its name");
    assert!(
        name.starts_with("results-") && name.ends_with(".json"),
        "{name}"
    );
    let browser_file = fixture.dir.join(name);
    std::fs::write(&browser_file, json).expect("writing the page's results");
    let link = client
        .find(fantoccini::Locator::Id("strata-download"))
        .await
        .expect("a download link in the page");
    assert_eq!(
        link.attr("download").await.expect("its name").as_deref(),
        Some(name)
    );

    // The same protocol natively on lavapipe.
    let native = fixture.dir.join("native");
    let output = Command::new(env!("CARGO_BIN_EXE_strata"))
        .args([
            "compare",
            "--quick",
            "--no-edits",
            "--backend",
            "vulkan",
            "--level",
        ])
        .arg(&fixture.world)
        .arg("--views")
        .arg(fixture.dir.join("views.txt"))
        .args(["--methods", fixture.methods])
        .arg("--out")
        .arg(&native)
        .arg("--cache")
        .arg(fixture.dir.join("cache"))
        .output()
        .expect("running strata compare");
    assert!(
        output.status.success(),
        "strata compare: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let native_file = std::fs::read_dir(&native)
        .expect("the native run's directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("results-") && n.ends_with(".json"))
        })
        .expect("the native results file");

    let output = Command::new(env!("CARGO_BIN_EXE_strata"))
        .arg("merge")
        .arg(&native_file)
        .arg(&browser_file)
        .arg("--out")
        .arg(fixture.dir.join("merged"))
        .output()
        .expect("running strata merge");
    let stdout = String::from_utf8_lossy(&output.stdout);
    eprintln!("strata merge: {stdout}");
    assert!(
        output.status.success(),
        "strata merge refused the page's results: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    // Every chosen method has its cells; accuracy as lavapipe's.
    let run: strata_bench::results::RunResults =
        serde_json::from_str(json).expect("the page's results parse");
    assert!(run.complete, "the page's run is incomplete");
    assert_eq!(
        run.rows.len(),
        fixture.methods.split(',').count() * fixture.views.len(),
        "{:?}",
        run.failures
    );
    assert!(
        stdout.contains("accuracy agrees"),
        "the page's accuracy differs from lavapipe's: {stdout}"
    );
}

async fn voxel_grid_over_the_limit(client: &Client, url: &str) {
    let page = format!("{url}/?method=voxel&voxel=2,4,1&size=160x100&scale=1");
    let (s, load_s) = open(client, &page).await;
    eprintln!(
        "the default world in the page: first frames after {load_s:.1} s (generated in {:.0} ms)",
        s["generate_ms"].as_f64().unwrap_or(f64::NAN)
    );
    let failed = |s: &Value| -> Option<String> {
        s["log"].as_array()?.iter().find_map(|l| {
            l.as_str()
                .filter(|l| l.contains("building voxel failed"))
                .map(str::to_string)
        })
    };
    let s = wait_for(client, "the voxel (2,4,1) refusal", 300, |s| {
        failed(s).is_some()
    })
    .await;
    let line = failed(&s).unwrap_or_default();
    eprintln!("{line}");
    assert!(
        line.contains("storage buffer") && line.contains("128.0 MiB"),
        "the refusal does not name the limit: {line}"
    );
    assert_eq!(
        s["active"], "ray",
        "the viewer goes on with its first method: {s}"
    );
}
