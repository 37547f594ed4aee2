//! Paged terrain from the command line (issue 33): `fly` over a small
//! generated store (its per-frame file and summary, resident bytes within the
//! budget), `render --gpu-budget` over a small world, `compare --gpu-budget`
//! (the paged method through pages with its paging numbers, the other whole),
//! a budget too small refused up front with the smallest that works, and a
//! whole-world method refused on a paged world naming the methods that draw
//! it. The GPU parts skip loudly without an adapter; with
//! `STRATA_REQUIRE_GPU=1` (CI) they fail.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use strata_render::BackendChoice;
use strata_render::adapter::list_adapters;

const STRATA: &str = env!("CARGO_BIN_EXE_strata");
/// A view into the middle of the 1024² world, looking along it.
const VIEW: &str = "512,512:45:60";

fn has_gpu() -> bool {
    if list_adapters(BackendChoice::Auto).is_empty() {
        use std::io::Write;
        if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
            panic!("STRATA_REQUIRE_GPU=1 but no GPU adapter");
        }
        let _ = writeln!(
            std::io::stderr(),
            "\n*** SKIPPED GPU test: no GPU adapter for paged rendering ***\n"
        );
        return false;
    }
    true
}

fn strata(args: &[&str]) -> Output {
    strata_with(args, &[])
}

fn strata_with(args: &[&str], env: &[(&str, &str)]) -> Output {
    let out = Command::new(STRATA)
        .args(args)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .envs(env.iter().copied())
        .output()
        .expect("the strata binary starts");
    eprintln!(
        "strata {}:\n{}{}",
        args.join(" "),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("paged-cli-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 1024² store (16 chunks), generated once for every test here.
fn store() -> &'static Path {
    static STORE: OnceLock<PathBuf> = OnceLock::new();
    STORE.get_or_init(|| {
        let d = dir("store");
        let store = d.join("world");
        let out = strata(&[
            "generate",
            "--size",
            "1024x1024",
            "--seed",
            "11",
            "--to",
            "store",
            "--out",
            p(&store),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        store
    })
}

/// `strata render` over the store at the middle view, 160x100, into `out`.
fn render(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        "--level",
        p(store()),
        "--view",
        VIEW,
        "--pitch",
        "-20",
        "--size",
        "160x100",
        "--out",
        p(out),
    ];
    args.extend_from_slice(extra);
    strata(&args)
}

/// A failure that is an error message, not a panic.
fn assert_clean_error(out: &Output, wanted: &[&str]) {
    let e = stderr(out);
    assert!(!out.status.success(), "should fail: {e}");
    assert!(!e.contains("panicked"), "a panic, not an error: {e}");
    for w in wanted {
        assert!(e.contains(w), "`{w}` missing from: {e}");
    }
}

fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

#[test]
fn fly_over_a_store_writes_frames_and_a_summary_within_the_budget() {
    if !has_gpu() {
        return;
    }
    let out_dir = dir("fly");
    let budget: u64 = 4 << 20;
    let out = strata(&[
        "fly",
        "--level",
        p(store()),
        "--gpu-budget",
        "4MiB",
        "--frames",
        "24",
        "--fps",
        "6",
        "--size",
        "160x100",
        "--out",
        p(&out_dir),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report = read_json(&out_dir.join("fly.json"));
    assert_eq!(report["world_size"], serde_json::json!([1024, 1024]));
    assert_eq!(report["gpu_budget"].as_u64(), Some(budget));
    let paged = report["paged_gpu_bytes"].as_u64().unwrap();
    assert!(paged > 0 && paged <= budget, "paged GPU bytes {paged}");
    assert!(report["resident_bytes_max"].as_u64().unwrap() <= budget);
    assert_eq!(report["frames"].as_u64(), Some(24));
    assert!(
        report["start_frames"].as_u64().is_some(),
        "the start pose converged"
    );
    // The per-frame file: a header and one parsed row per frame.
    let csv = std::fs::read_to_string(out_dir.join("frames.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("frame,gpu_ms,cpu_ms,pending_pct,uploaded_bytes,resident_bytes,gpu_bytes")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 24);
    for row in &rows {
        let pending: f64 = row[3].parse().unwrap();
        let resident: u64 = row[5].parse().unwrap();
        let cpu: f64 = row[2].parse().unwrap();
        assert!((0.0..=100.0).contains(&pending), "{row:?}");
        assert!(resident <= budget, "{row:?}");
        assert!(cpu >= 0.0);
        let _: u64 = row[4].parse().unwrap();
    }
    let pending_max = report["pending_pct"]["max"].as_f64().unwrap();
    assert!((0.0..=100.0).contains(&pending_max));
}

#[test]
fn render_with_a_gpu_budget_converges_and_reports_its_paging() {
    if !has_gpu() {
        return;
    }
    let out_dir = dir("render");
    let out = render(
        &out_dir,
        &[
            "--method",
            "ray-exact",
            "--gpu-budget",
            "4MiB",
            "--frames",
            "2",
            "--warmup",
            "1",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report = read_json(&out_dir.join("render.json"));
    let paging = &report["paging"];
    assert!(paging.is_object(), "render.json has paging: {report}");
    assert_eq!(paging["gpu_budget"].as_u64(), Some(4 << 20));
    assert!(paging["gpu_bytes"].as_u64().unwrap() <= 4 << 20);
    assert!(paging["resident_pages"].as_u64().unwrap() >= 1);
    assert_eq!(paging["pending_pixels"].as_u64(), Some(0), "converged");
    assert!(report["converge_frames"].as_u64().unwrap() >= 1);
}

#[test]
fn compare_with_a_gpu_budget_pages_the_paged_method_only() {
    if !has_gpu() {
        return;
    }
    let d = dir("compare");
    let views = d.join("views.txt");
    std::fs::write(&views, format!("middle {VIEW} -20\n")).unwrap();
    let out_dir = d.join("out");
    let out = strata(&[
        "compare",
        "--level",
        p(store()),
        "--gpu-budget",
        "4MiB",
        "--methods",
        "ray-exact,ray",
        "--views",
        p(&views),
        "--quick",
        "--no-edits",
        "--cache",
        p(&d.join("cache")),
        "--out",
        p(&out_dir),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let run = results_of(&out_dir);
    let failures = run["failures"].as_array().map_or(0, Vec::len);
    assert_eq!(failures, 0, "{}", run["failures"]);
    let rows = run["rows"].as_array().unwrap();
    let row = |m: &str| {
        rows.iter()
            .find(|r| r["method"].as_str().unwrap().split(':').next() == Some(m))
            .unwrap_or_else(|| panic!("no {m} row in {rows:?}"))
    };
    let exact = row("ray-exact");
    assert!(exact["paging"].is_object(), "{exact}");
    assert!(exact["paging"]["gpu_bytes"].as_u64().unwrap() <= 4 << 20);
    assert_eq!(exact["paging"]["pending_pixels"].as_u64(), Some(0));
    // Converged, the paged picture is the exact one: nothing seen through.
    assert!(exact["see_through"].as_f64().unwrap() < 0.5, "{exact}");
    assert!(row("ray")["paging"].is_null(), "ray draws the world whole");
}

/// The one results file of a compare run in `out`.
fn results_of(out: &Path) -> serde_json::Value {
    let results: Vec<PathBuf> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|f| {
            f.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("results-")
        })
        .collect();
    assert_eq!(results.len(), 1, "{results:?}");
    read_json(&results[0])
}

#[test]
fn compare_over_a_store_past_the_limit_measures_paged_methods_and_refuses_the_rest() {
    if !has_gpu() {
        return;
    }
    let d = dir("compare-big");
    let views = d.join("views.txt");
    std::fs::write(&views, format!("middle {VIEW} -20\n")).unwrap();
    let out_dir = d.join("out");
    // A 1 MiB limit puts the 1024² store (2 MiB of map) past it.
    let out = strata_with(
        &[
            "compare",
            "--level",
            p(store()),
            "--gpu-budget",
            "4MiB",
            "--methods",
            "ray-exact,ray",
            "--views",
            p(&views),
            "--quick",
            "--out",
            p(&out_dir),
        ],
        &[("STRATA_WHOLE_WORLD_LIMIT_MIB", "1")],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let run = results_of(&out_dir);
    assert_eq!(run["complete"], serde_json::json!(true));
    let rows = run["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert!(rows[0]["method"].as_str().unwrap().starts_with("ray-exact"));
    assert!(rows[0]["paging"]["gpu_bytes"].as_u64().unwrap() <= 4 << 20);
    assert!(
        rows[0]["see_through"].as_f64().unwrap() < 0.5,
        "{}",
        rows[0]
    );
    let failures = run["failures"].as_array().unwrap();
    assert_eq!(failures.len(), 1, "{failures:?}");
    let error = failures[0]["error"].as_str().unwrap();
    for wanted in [
        "`ray` draws whole worlds only",
        "past the whole-world limit",
        "STRATA_WHOLE_WORLD_LIMIT_MIB",
        "ray-exact, ray-exact-fragment, mesh draw it through pages",
    ] {
        assert!(error.contains(wanted), "`{wanted}` missing from: {error}");
    }
    assert!(out_dir.join("report.md").is_file());
}

#[test]
fn a_store_past_the_memory_limit_renders_paged_without_the_flag() {
    if !has_gpu() {
        return;
    }
    let out_dir = dir("past-memory");
    let mut args = vec![
        "render",
        "--level",
        p(store()),
        "--view",
        VIEW,
        "--pitch",
        "-20",
        "--size",
        "160x100",
        "--method",
        "ray-exact",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--out",
    ];
    args.push(p(&out_dir));
    let out = strata_with(&args, &[("STRATA_WHOLE_WORLD_LIMIT_MIB", "1")]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report = read_json(&out_dir.join("render.json"));
    assert_eq!(
        report["paging"]["gpu_budget"].as_u64(),
        Some(256 << 20),
        "paged at the default budget: {report}"
    );
}

#[test]
fn a_budget_too_small_is_refused_with_the_smallest_that_works() {
    if !has_gpu() {
        return;
    }
    let out_dir = dir("small-budget");
    let out = render(
        &out_dir,
        &["--method", "ray-exact", "--gpu-budget", "16KiB"],
    );
    assert_clean_error(&out, &["16384 bytes", "the smallest budget that works is"]);
    // The budget it names works.
    let e = stderr(&out);
    let at = e.find("the smallest budget that works is ").unwrap();
    let smallest: u64 = e[at + "the smallest budget that works is ".len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let out = render(
        &out_dir,
        &[
            "--method",
            "ray-exact",
            "--gpu-budget",
            &smallest.to_string(),
            "--frames",
            "1",
            "--warmup",
            "0",
            "--converge-frames",
            "2",
        ],
    );
    assert!(
        !stderr(&out).contains("the smallest budget that works"),
        "the named budget is accepted: {}",
        stderr(&out)
    );
}

#[test]
fn a_whole_world_method_on_a_paged_world_names_the_paged_methods() {
    if !has_gpu() {
        return;
    }
    let out_dir = dir("refused");
    let out = render(&out_dir, &["--method", "voxel", "--gpu-budget", "4MiB"]);
    assert_clean_error(
        &out,
        &[
            "`voxel` draws whole worlds only",
            "ray-exact, ray-exact-fragment, mesh",
        ],
    );
}

#[test]
fn video_with_a_gpu_budget_streams_the_paged_method_through_the_dig() {
    if !has_gpu() {
        return;
    }
    let d = dir("video");
    let frames = d.join("frames");
    let out = strata(&[
        "video",
        "--level",
        p(store()),
        "--gpu-budget",
        "4MiB",
        "--methods",
        "ray-exact,ray",
        "--size",
        "320x100",
        "--duration",
        "2",
        "--fps",
        "4",
        "--no-temporal",
        "--frames-dir",
        p(&frames),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let sidecar = read_json(&frames.join("video.json"));
    assert!(
        sidecar["dig_frame"].as_u64().is_some(),
        "the default path digs"
    );
    let methods = sidecar["methods"].as_array().unwrap();
    for m in ["ray-exact", "ray"] {
        let track = methods
            .iter()
            .find(|t| t["method"].as_str().unwrap().split(':').next() == Some(m))
            .unwrap_or_else(|| panic!("no {m} track: {sidecar}"));
        assert!(track["error"].is_null(), "{track}");
        assert!(track["first_post_edit_ms"].as_f64().unwrap() > 0.0);
    }
}
