//! A store streamed into the page (issue 34), in headless Chromium (WebGPU
//! on SwiftShader): a 512x16384 store (past WebGPU's 8192-texel texture
//! side) served by `strata serve` as it lies on disk, opened with
//! `?level=`, drawn by `ray-exact` through paged terrain; once nothing is
//! pending the canvas equals the CPU reference (`strata reference` over the
//! same store, view and size), the first frame came within a bound, and
//! only part of the store was fetched. Bad input: a URL with no world
//! there is a clear message in the page; a store whose chunks are corrupt
//! or truncated keeps drawing its resident pages, retries each failing
//! chunk a bounded number of times and reports it.
//!
//! Same tools and skipping as `browser.rs` (`STRATA_REQUIRE_BROWSER=1`
//! makes a missing one a failure).

mod browser_common;

use browser_common::*;
use fantoccini::Client;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The canvas: 160x100 drawn 1:1 (the reference's size), overlay off.
const SIZE: (u32, u32) = (160, 100);

/// Page load to the first frame, at most (ms). Measured on this 2-core
/// machine with other builds running beside it (load average about 8):
/// 0.73-1.18 s for this store, 0.95-1.75 s for the built-in world (README,
/// browser section). The first frame needs the .wasm compiled, the store's
/// metadata and one chunk fetched, the device and the `ray-exact` pipelines
/// made (SwiftShader compiles shaders on the CPU): the bound is about eight
/// times the slowest seen, room for a CI machine of two cores.
const FIRST_FRAME_BOUND_MS: f64 = 15_000.0;

/// Pixels of the converged canvas allowed to differ from the CPU reference
/// by more than 8 in a channel: the paged march equals the whole-world
/// `ray-exact`, whose ꟻLIP against the CPU colours is 0 natively
/// (`crates/render/tests/color_reference.rs`); what is left is the GPU's f32
/// hit points and the presentation through the canvas, a few pixels.
const MAX_DIFFERING: f64 = 0.01;

struct Fixture {
    dir: PathBuf,
    store: PathBuf,
    /// The view the page opens at, and its `views.txt` line.
    view: String,
    reference: PathBuf,
    /// The world's width and height, texels.
    size: (u64, u64),
    chunks: u64,
}

/// A store's width and height from its `heights` array's shape (rows, columns).
fn store_size(store: &Path) -> (u64, u64) {
    let meta: Value = serde_json::from_slice(
        &std::fs::read(store.join("heights").join("zarr.json")).expect("heights/zarr.json"),
    )
    .expect("JSON");
    let shape = &meta["shape"];
    (
        shape[1].as_u64().expect("columns"),
        shape[0].as_u64().expect("rows"),
    )
}

impl Fixture {
    fn new() -> Self {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("browser-stream");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("the fixture directory");
        let store = dir.join("store");
        let start = Instant::now();
        let status = Command::new(env!("CARGO_BIN_EXE_strata"))
            .args(["generate", "--to", "store", "--size", "512x16384", "--out"])
            .arg(&store)
            .stdout(Stdio::null())
            .status()
            .expect("running strata generate");
        assert!(status.success(), "strata generate --to store failed");
        eprintln!(
            "512x16384 store generated in {:.1} s",
            start.elapsed().as_secs_f64()
        );
        Self::over(dir, store, "0")
    }

    /// The fixture over an existing `store` (its first view at `pitch`
    /// degrees, the CPU reference of it in `dir`).
    fn over(dir: PathBuf, store: PathBuf, pitch: &str) -> Self {
        // A view that looks along the world, not down: many chunks to stream.
        let line = store_view_line(&store, pitch);
        let view = line.split_whitespace().next().expect("a name").to_string();
        std::fs::write(dir.join("views.txt"), format!("{line}\n")).expect("views.txt");
        let reference = dir.join("reference");
        let output = Command::new(env!("CARGO_BIN_EXE_strata"))
            .args(["reference", "--no-cache", "--size"])
            .arg(format!("{}x{}", SIZE.0, SIZE.1))
            .arg("--level")
            .arg(&store)
            .arg("--views")
            .arg(dir.join("views.txt"))
            .arg("--out")
            .arg(&reference)
            .output()
            .expect("running strata reference");
        assert!(
            output.status.success(),
            "strata reference: {}",
            String::from_utf8_lossy(&output.stderr)
        );
        let size = store_size(&store);
        Fixture {
            dir,
            store,
            reference: reference.join(&view).join("color.png"),
            view,
            size,
            chunks: (size.0 / 256) * (size.1 / 256),
        }
    }

    /// A copy of the store whose heights chunks are all corrupt (every
    /// other one a byte flipped, the rest cut short) except the chunk under
    /// the view, which the page reads before its first frame.
    fn broken_copy(&self, keep: (u64, u64)) -> PathBuf {
        let broken = self.dir.join("broken");
        let status = Command::new("cp")
            .arg("-r")
            .arg(&self.store)
            .arg(&broken)
            .status()
            .expect("cp");
        assert!(status.success());
        let mut n = 0;
        for cy in 0..64u64 {
            for cx in 0..2u64 {
                if (cy, cx) == keep {
                    continue;
                }
                let path = broken.join(format!("heights/c/{cy}/{cx}"));
                let mut bytes = std::fs::read(&path).expect("a chunk object");
                if n % 2 == 0 {
                    let i = bytes.len() / 2;
                    bytes[i] ^= 0x5a;
                } else {
                    bytes.truncate(bytes.len() / 3);
                }
                std::fs::write(&path, bytes).expect("writing the broken chunk");
                n += 1;
            }
        }
        broken
    }
}

#[test]
fn a_store_past_the_texture_limit_streams_into_the_page() {
    let Some((chromium, driver, bundle)) = tools() else {
        return;
    };
    let fixture = Fixture::new();
    let (_server, url) = serve(&bundle, &fixture.store);
    // Without --level: the built-in world, as a store written once.
    let start = Instant::now();
    let (_default_server, default_url) = serve_with(&bundle, None);
    eprintln!(
        "strata serve without --level listening after {:.1} s",
        start.elapsed().as_secs_f64()
    );
    let (_driver, driver_url) = chromedriver(&driver);
    let store = fixture.store.clone();
    with_browser(&driver_url, &chromium, move |client| async move {
        drive(client.clone(), url, fixture, bundle).await;
        built_in_world(&client, &default_url).await;
        picked_store(&client, &store).await;
    });
}

/// Open `fixture`'s store at `url` with `ray-exact`: the first frame within
/// the bound, convergence (nothing pending or in flight), GPU bytes within
/// the budget, only part of the store fetched, and the canvas against the
/// CPU reference.
async fn stream_and_compare(client: &Client, url: &str, fixture: &Fixture) {
    let page = format!(
        "{url}/?level=/level/&method=ray-exact&size={}x{}&scale=1&view={}",
        SIZE.0, SIZE.1, fixture.view
    );
    let (s, load_s) = open(client, &page).await;
    let first_ms = s["page_to_first_frame_ms"].as_f64().unwrap_or(f64::NAN);
    eprintln!(
        "streamed {}x{} store: first frame {first_ms:.0} ms after navigation (metadata and first chunk {:.0} ms; 10 frames after {load_s:.1} s) on {}",
        fixture.size.0,
        fixture.size.1,
        s["stream_open_ms"].as_f64().unwrap_or(f64::NAN),
        s["adapter"]
    );
    assert_eq!(s["adapter"]["backend"], "browserwebgpu", "{s}");
    assert_eq!(s["active"], "ray-exact", "{s}");
    assert_eq!(
        s["level_size"],
        serde_json::json!([fixture.size.0, fixture.size.1]),
        "{s}"
    );
    assert!(
        first_ms <= FIRST_FRAME_BOUND_MS,
        "first frame {first_ms} ms after navigation, bound {FIRST_FRAME_BOUND_MS}"
    );
    run(client, "overlay off\nframes 2", 60).await;
    let start = Instant::now();
    let (s, _, _) = converge(client, 300).await;
    let (p, stream) = paging(&s);
    eprintln!(
        "converged in {:.1} s: {} pages resident ({} bytes), {} of {} GPU bytes; stream {stream}",
        start.elapsed().as_secs_f64(),
        p["resident_pages"],
        p["resident_bytes"],
        p["gpu_bytes"],
        p["gpu_budget"]
    );
    let gpu = p["gpu_bytes"].as_u64().unwrap_or(u64::MAX);
    assert!(gpu <= p["gpu_budget"].as_u64().unwrap_or(0), "{p}");
    let fetched = stream["done"].as_u64().unwrap_or(0);
    assert!(fetched > 0, "no page fetched: {stream}");
    assert!(
        fetched < fixture.chunks,
        "the whole store ({} chunks) was fetched: {stream}",
        fixture.chunks
    );
    assert_eq!(stream["failed"], 0, "{stream}");
    // The picture: the CPU reference of the same store, view and size.
    let canvas = canvas_pixels(client).await;
    assert_not_blank(&canvas, "streamed ray-exact");
    let reference = image::open(&fixture.reference)
        .expect("the reference's color.png")
        .to_rgba8();
    assert_eq!(canvas.dimensions(), reference.dimensions());
    let apart = differing(&canvas, &reference);
    let n = canvas.pixels().len();
    eprintln!(
        "streamed ray-exact differs from the CPU reference in {apart} of {n} pixels ({:.2} %)",
        100.0 * apart as f64 / n as f64
    );
    assert!(
        (apart as f64) <= MAX_DIFFERING * n as f64,
        "{apart} of {n} pixels differ from the CPU reference"
    );
}

/// A store far past WebGPU's limits (issue 34 asks for 32768² at least):
/// `strata generate --size 32768x32768 --to store --out DIR` (a few minutes
/// on two cores), then
/// `STRATA_BROWSER_BIG_STORE=DIR cargo test -p strata --test browser_stream -- --ignored`.
/// The same checks as the 512x16384 store's, at the store's first -30° view.
#[test]
#[ignore = "needs a large store: STRATA_BROWSER_BIG_STORE=DIR"]
fn a_large_store_streams_within_webgpus_default_limits() {
    let store = PathBuf::from(
        std::env::var_os("STRATA_BROWSER_BIG_STORE")
            .expect("STRATA_BROWSER_BIG_STORE=DIR: a store made by strata generate --to store"),
    );
    let Some((chromium, driver, bundle)) = tools() else {
        return;
    };
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("browser-stream-large");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("the fixture directory");
    let start = Instant::now();
    // A view at -30°: the generated worlds' first 0° view can stand on a
    // ridge whose 160x100 picture is all sky.
    let fixture = Fixture::over(dir, store, "-30");
    eprintln!(
        "{}x{} store: reference traced in {:.1} s",
        fixture.size.0,
        fixture.size.1,
        start.elapsed().as_secs_f64()
    );
    let (_server, url) = serve(&bundle, &fixture.store);
    let (_driver, driver_url) = chromedriver(&driver);
    with_browser(&driver_url, &chromium, move |client| async move {
        stream_and_compare(&client, &url, &fixture).await;
    });
}

/// The built-in world as `strata serve` offers it (the URL it prints, the
/// page's default canvas): the first frame within the bound.
async fn built_in_world(client: &Client, url: &str) {
    // A page left behind may still have frames queued in the GPU process
    // (SwiftShader's, on the CPU), which would delay this one's.
    client.goto("about:blank").await.expect("a blank page");
    tokio::time::sleep(Duration::from_secs(2)).await;
    let (s, _) = open(client, &format!("{url}/?level=/level/")).await;
    let first_ms = s["page_to_first_frame_ms"].as_f64().unwrap_or(f64::NAN);
    eprintln!(
        "the built-in world streamed: first frame {first_ms:.0} ms after navigation (metadata and first chunk {:.0} ms), drawing {}",
        s["stream_open_ms"].as_f64().unwrap_or(f64::NAN),
        s["active"]
    );
    assert_eq!(s["level_size"], serde_json::json!([2048, 16384]), "{s}");
    assert!(
        first_ms <= FIRST_FRAME_BOUND_MS,
        "first frame {first_ms} ms after navigation, bound {FIRST_FRAME_BOUND_MS}"
    );
}

/// The folder picker on a store: the viewer swaps to it, streamed from
/// the picked files.
async fn picked_store(client: &Client, store: &Path) {
    client
        .find(fantoccini::Locator::Id("strata-open"))
        .await
        .expect("the folder picker")
        .send_keys(&store.to_string_lossy())
        .await
        .expect("picking the store folder");
    let s = wait_for(client, "the picked store drawn", 300, |s| {
        s["level_size"] == serde_json::json!([512, 16384])
            && paging(s).0["resident_pages"].as_u64().unwrap_or(0) > 0
    })
    .await;
    let (p, stream) = paging(&s);
    eprintln!(
        "picked store: {} pages resident, {} drawing; stream {stream}",
        p["resident_pages"], s["active"]
    );
    assert_eq!(s["active"], "ray-exact", "{s}");
}

/// The page's paging numbers (`paging.stats`) and the stream's (`stream`).
fn paging(s: &Value) -> (&Value, &Value) {
    (&s["paging"]["stats"], &s["stream"])
}

async fn drive(client: Client, url: String, fixture: Fixture, bundle: PathBuf) {
    stream_and_compare(&client, &url, &fixture).await;
    // A URL with no world there: a clear message in the page.
    client
        .goto(&format!("{url}/?level=/level/nowhere/"))
        .await
        .expect("opening the page");
    let message = error_text(&client, 60).await;
    eprintln!("a URL with no world: {message}");
    assert!(
        message.contains("404") && message.contains("/level/nowhere"),
        "{message}"
    );

    // Corrupt and truncated chunks: the chunk under the view draws, every
    // other chunk fails its checks, is retried a bounded number of times,
    // then reported; the page goes on drawing.
    let root: Value =
        serde_json::from_slice(&std::fs::read(fixture.store.join("zarr.json")).expect("zarr.json"))
            .expect("JSON");
    let line = root["attributes"]["strata"]["views"]
        .as_str()
        .unwrap_or_default()
        .lines()
        .find(|l| l.split_whitespace().next() == Some(fixture.view.as_str()))
        .unwrap_or_default()
        .to_string();
    // `NAME X,Y:YAW:EYE PITCH`.
    let xy: Vec<f64> = line
        .split_whitespace()
        .nth(1)
        .and_then(|spec| spec.split(':').next())
        .map(|xy| xy.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_default();
    assert_eq!(xy.len(), 2, "the view's position in `{line}`");
    let keep = (
        (xy[1].floor() as u64 % 16384) / 256,
        (xy[0].floor() as u64 % 512) / 256,
    );
    let broken = fixture.broken_copy(keep);
    let (_bad_server, bad_url) = serve(&bundle, &broken);
    let page = format!(
        "{bad_url}/?level=/level/&method=ray-exact&size={}x{}&scale=1&view={}",
        SIZE.0, SIZE.1, fixture.view
    );
    let (s, _) = open(&client, &page).await;
    let frames = s["frames"].as_u64().unwrap_or(0);
    let s = wait_for(&client, "read errors reported", 300, |s| {
        paging(s).0["read_errors"].as_u64().unwrap_or(0) > 0
    })
    .await;
    let (p, stream) = paging(&s);
    let errors = p["read_errors"].as_u64().unwrap_or(0);
    eprintln!(
        "broken store: {errors} chunk(s) given up; first: {}; stream {stream}",
        p["first_error"]
    );
    let first = p["first_error"].as_str().unwrap_or_default();
    assert!(
        first.contains("checksum") || first.contains("truncated"),
        "{first}"
    );
    let failed = stream["failed"].as_u64().unwrap_or(0);
    // Three tries each (the paged terrain's read_tries), then given up.
    assert!(
        failed >= 3 * errors,
        "{failed} failed reads, {errors} errors"
    );
    let log = s["log"].to_string();
    assert!(
        log.contains("failed to read"),
        "no message in the log: {log}"
    );
    let s = run(&client, "frames 3", 120).await;
    assert!(
        s["frames"].as_u64().unwrap_or(0) >= frames + 3,
        "the page stopped drawing: {s}"
    );
    assert!(s.get("error").is_none(), "{s}");
    assert!(
        paging(&s).0["resident_pages"].as_u64().unwrap_or(0) >= 1,
        "the good chunk is not resident: {}",
        s["paging"]
    );
}
