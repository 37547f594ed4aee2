//! What the browser tests share (`browser.rs`, `browser_stream.rs`):
//! finding Chromium, chromedriver and the bundle (or skipping loudly),
//! `strata serve`, the WebDriver session, the page's state and script
//! commands, the canvas's pixels.
#![allow(dead_code)]

use fantoccini::{Client, ClientBuilder};
use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The flags that give WebGPU on SwiftShader in headless Chromium (others
/// give a white canvas without an error).
pub const CHROMIUM_FLAGS: [&str; 7] = [
    "--headless=new",
    "--no-sandbox",
    "--enable-unsafe-webgpu",
    "--enable-features=Vulkan",
    "--use-vulkan=swiftshader",
    "--use-angle=swiftshader",
    "--window-size=800,600",
];

pub fn skip_loudly(why: &str) {
    if std::env::var_os("STRATA_REQUIRE_BROWSER").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_BROWSER=1 but {why}");
    }
    eprintln!("\n*** SKIPPED browser test: {why} ***\n");
}

pub fn find_program(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| names.iter().map(move |n| dir.join(n)))
        .find(|p| p.is_file())
}

/// A child process killed when the test ends, however it ends.
pub struct Killed(pub Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

/// `strata serve` on a free port (with `level` at `/level/`); its URL.
pub fn serve(bundle: &Path, level: &Path) -> (Killed, String) {
    serve_with(bundle, Some(level))
}

/// `strata serve` on a free port with `level` at `/level/`, or without
/// `--level` (the built-in world as a store, made once and cached); its URL.
pub fn serve_with(bundle: &Path, level: Option<&Path>) -> (Killed, String) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_strata"));
    command
        .args(["serve", "--port", "0", "--bundle"])
        .arg(bundle);
    if let Some(level) = level {
        command.arg("--level").arg(level);
    }
    let mut child = command
        .stdout(Stdio::piped())
        .spawn()
        .expect("starting strata serve");
    let stdout = child.stdout.take().expect("its stdout");
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .expect("strata serve prints its URL");
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap_or_else(|| panic!("no URL in `{line}`"))
        // The origin only (with --level it ends in `/?level=/level/`).
        .split('?')
        .next()
        .unwrap_or_default()
        .trim_end_matches('/')
        .to_string();
    (Killed(child), url)
}

pub fn chromedriver(driver: &Path) -> (Killed, String) {
    let port = free_port();
    let child = Command::new(driver)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("starting chromedriver");
    let start = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "chromedriver did not listen"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    (Killed(child), format!("http://127.0.0.1:{port}"))
}

pub async fn browser(driver_url: &str, chromium: &Path) -> Client {
    let mut caps = serde_json::Map::new();
    caps.insert("browserName".into(), "chrome".into());
    caps.insert(
        "goog:chromeOptions".into(),
        serde_json::json!({ "binary": chromium, "args": CHROMIUM_FLAGS }),
    );
    ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
        .capabilities(caps)
        .connect(driver_url)
        .await
        .expect("a WebDriver session with headless Chromium")
}

/// The page's state (the viewer's, after its last frame).
pub async fn state(client: &Client) -> Value {
    let text = client
        .execute(
            "return window.strata ? window.strata.strataState() : '{}'",
            vec![],
        )
        .await
        .expect("reading the page's state");
    serde_json::from_str(text.as_str().unwrap_or("{}")).unwrap_or(Value::Null)
}

/// Wait until `done` holds for the state (failing on a page error or after `secs`).
pub async fn wait_for(
    client: &Client,
    what: &str,
    secs: u64,
    done: impl Fn(&Value) -> bool,
) -> Value {
    let start = Instant::now();
    loop {
        let s = state(client).await;
        if let Some(error) = s.get("error") {
            panic!("the page shows an error while waiting for {what}: {error}");
        }
        if done(&s) {
            return s;
        }
        assert!(
            start.elapsed() < Duration::from_secs(secs),
            "timed out after {secs} s waiting for {what}; state {s}"
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
}

/// Run viewer script commands in the page and wait until they are done.
pub async fn run(client: &Client, commands: &str, secs: u64) -> Value {
    let result = client
        .execute(
            "try { return window.strata.strataRun(arguments[0]) } catch (e) { return String(e) }",
            vec![commands.into()],
        )
        .await
        .expect("running commands");
    let pushed = result
        .as_u64()
        .unwrap_or_else(|| panic!("`{commands}` refused: {result}"));
    // Done once the viewer has taken them and is idle again.
    wait_for(client, commands, secs, |s| {
        s["taken"].as_u64().unwrap_or(0) >= pushed && s["idle"] == true
    })
    .await
}

pub async fn open(client: &Client, url: &str) -> (Value, f64) {
    let start = Instant::now();
    client.goto(url).await.expect("opening the page");
    let s = wait_for(client, "the first frames", 240, |s| {
        s["phase"] == "running" && s["frames"].as_u64().unwrap_or(0) >= 10
    })
    .await;
    (s, start.elapsed().as_secs_f64())
}

/// The `views.txt` line of `store`'s first view at `pitch` degrees (else
/// its first view), from the store's `zarr.json`.
pub fn store_view_line(store: &Path, pitch: &str) -> String {
    let root: Value =
        serde_json::from_slice(&std::fs::read(store.join("zarr.json")).expect("zarr.json"))
            .expect("JSON");
    let views = root["attributes"]["strata"]["views"]
        .as_str()
        .expect("the store's views");
    views
        .lines()
        .find(|l| l.split_whitespace().last() == Some(pitch))
        .or_else(|| views.lines().next())
        .expect("a view")
        .to_string()
}

/// Draw frames one at a time until the paged terrain has converged (nothing
/// pending, nothing in flight, pages resident, three frames in a row: the
/// feedback comes a frame or two late in a page), failing after `secs`.
/// The state then, the frames drawn, and the slowest frame's wall ms (with
/// the script's round trip).
pub async fn converge(client: &Client, secs: u64) -> (Value, u32, f64) {
    let start = Instant::now();
    let (mut calm, mut frames, mut slowest) = (0, 0u32, 0.0f64);
    loop {
        let t = Instant::now();
        let s = run(client, "frames 1", 120).await;
        slowest = slowest.max(t.elapsed().as_secs_f64() * 1e3);
        frames += 1;
        let p = &s["paging"]["stats"];
        let settled = p["pending_pixels"] == 0
            && p["pending_shadow_texels"] == 0
            && p["in_flight"] == 0
            && p["resident_pages"].as_u64().unwrap_or(0) > 0;
        calm = if settled { calm + 1 } else { 0 };
        if calm >= 3 {
            return (s, frames, slowest);
        }
        assert!(
            start.elapsed() < Duration::from_secs(secs),
            "no convergence in {secs} s ({frames} frames): {}",
            s["paging"]
        );
    }
}

/// The canvas's pixels in a WebDriver screenshot (what the page shows).
pub async fn canvas_pixels(client: &Client) -> image::RgbaImage {
    let rect = client
        .execute(
            "const r = document.getElementById('strata-canvas').getBoundingClientRect();\
             return [r.left, r.top, r.width, r.height, window.devicePixelRatio];",
            vec![],
        )
        .await
        .expect("the canvas's rectangle");
    let r: Vec<f64> = serde_json::from_value(rect).expect("numbers");
    // SwiftShader draws on the CPU: on a loaded 2-core machine the renderer
    // can miss chromedriver's 10 s screenshot deadline while a frame is in
    // flight (seen twice while builds ran beside the test). Ask again.
    let mut attempt = 0;
    let png = loop {
        match client.screenshot().await {
            Ok(png) => break png,
            Err(e) if attempt < 3 => {
                attempt += 1;
                eprintln!("screenshot attempt {attempt} failed ({e}); retrying");
                tokio::time::sleep(Duration::from_secs(2)).await;
            }
            Err(e) => panic!("a screenshot: {e}"),
        }
    };
    let shot = image::load_from_memory(&png)
        .expect("a PNG screenshot")
        .to_rgba8();
    let (x, y) = ((r[0] * r[4]) as u32, (r[1] * r[4]) as u32);
    let (w, h) = ((r[2] * r[4]) as u32, (r[3] * r[4]) as u32);
    assert!(w >= 100 && h >= 60, "the canvas is {w}x{h}");
    image::imageops::crop_imm(&shot, x, y, w, h).to_image()
}

/// Not a blank canvas: many colours, little white.
pub fn assert_not_blank(image: &image::RgbaImage, what: &str) {
    let mut colours = std::collections::HashSet::new();
    let mut white = 0usize;
    for p in image.pixels() {
        colours.insert([p[0] >> 3, p[1] >> 3, p[2] >> 3]);
        white += usize::from(p[0] > 245 && p[1] > 245 && p[2] > 245);
    }
    let n = image.pixels().len();
    eprintln!(
        "{what}: {} colours, {:.1} % white",
        colours.len(),
        100.0 * white as f64 / n as f64
    );
    let out =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{}.png", what.replace(' ', "-")));
    let _ = image.save(&out);
    eprintln!("{what}: saved {}", out.display());
    assert!(colours.len() >= 4, "{what}: only {} colours", colours.len());
    assert!(white * 10 < n, "{what}: {white} of {n} pixels white");
}

pub fn differing(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).any(|i| p[i].abs_diff(q[i]) > 8))
        .count()
}

/// Chromium, chromedriver and the bundle, or `None` after a loud SKIPPED
/// line (a failure under `STRATA_REQUIRE_BROWSER=1`).
pub fn tools() -> Option<(PathBuf, PathBuf, PathBuf)> {
    let Some(chromium) = find_program(&["chromium", "chromium-browser", "google-chrome"]) else {
        skip_loudly("no chromium on PATH (apt-get install chromium chromium-driver)");
        return None;
    };
    let Some(driver) = find_program(&["chromedriver"]) else {
        skip_loudly("no chromedriver on PATH (apt-get install chromium-driver)");
        return None;
    };
    let bundle = std::env::var_os("STRATA_WEB_BUNDLE")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/web"));
    if !bundle.join("pkg/strata_web_bg.wasm").is_file() {
        skip_loudly(&format!(
            "no web bundle in {} (build it with crates/web/build.sh)",
            bundle.display()
        ));
        return None;
    }
    Some((chromium, driver, bundle))
}

/// Run `drive` with a headless Chromium session on `driver_url`, closing
/// the session however it ends.
pub fn with_browser<F, Fut>(driver_url: &str, chromium: &Path, drive: F)
where
    F: FnOnce(Client) -> Fut,
    Fut: std::future::Future<Output = ()> + Send + 'static,
{
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a tokio runtime")
        .block_on(async {
            let client = browser(driver_url, chromium).await;
            let result = tokio::spawn(drive(client.clone())).await;
            let _ = client.close().await;
            if let Err(e) = result {
                std::panic::resume_unwind(e.into_panic());
            }
        });
}

/// The page's error box, once it says something.
pub async fn error_text(client: &Client, secs: u64) -> String {
    let start = Instant::now();
    loop {
        let text = client
            .find(fantoccini::Locator::Id("strata-error"))
            .await
            .expect("the error box")
            .text()
            .await
            .unwrap_or_default();
        if !text.is_empty() {
            return text;
        }
        assert!(
            start.elapsed() < Duration::from_secs(secs),
            "no error in the page after {secs} s"
        );
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
}
