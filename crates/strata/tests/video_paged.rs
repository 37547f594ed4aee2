//! `strata video` over a store past the whole-world limit (issue 33): a
//! small generated store made to look too large with
//! `STRATA_WHOLE_WORLD_LIMIT_MIB=1` is never loaded whole (that limit would
//! refuse it): its ground is read through the chunk cache, `ray-exact`
//! films the default path (the crater dug into an edit layer over the
//! pages) with the temporal metric, and the store on disk is left as it
//! was. A method that cannot draw pages is refused up front, naming the
//! limit and the paged methods. The GPU part skips loudly without an
//! adapter; with `STRATA_REQUIRE_GPU=1` (CI) it fails.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use strata_render::BackendChoice;
use strata_render::adapter::list_adapters;

const STRATA: &str = env!("CARGO_BIN_EXE_strata");
/// 1 MiB puts the 1024² store (2 MiB of map) past the whole-world limit.
/// Rows of a frame the method's label (with its frame time) may cover.
const LABEL_ROWS: u32 = 16;
const PAST_THE_LIMIT: (&str, &str) = ("STRATA_WHOLE_WORLD_LIMIT_MIB", "1");

fn has_gpu() -> bool {
    if list_adapters(BackendChoice::Auto).is_empty() {
        use std::io::Write;
        if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
            panic!("STRATA_REQUIRE_GPU=1 but no GPU adapter");
        }
        let _ = writeln!(
            std::io::stderr(),
            "\n*** SKIPPED GPU test: no GPU adapter for a paged video ***\n"
        );
        return false;
    }
    true
}

fn strata(args: &[&str], env: &[(&str, &str)]) -> Output {
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
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("video-paged-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 1024² store (16 chunks, with an edit site), generated once.
fn store() -> &'static Path {
    static STORE: OnceLock<PathBuf> = OnceLock::new();
    STORE.get_or_init(|| {
        let store = dir("store").join("world");
        let out = strata(
            &[
                "generate",
                "--size",
                "1024x1024",
                "--seed",
                "11",
                "--to",
                "store",
                "--out",
                p(&store),
            ],
            &[],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        store
    })
}

/// Every file under `root` with its bytes.
fn files(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.insert(path.clone(), std::fs::read(&path).unwrap());
            }
        }
    }
    out
}

#[test]
fn a_store_past_the_limit_films_through_pages_and_digs_without_writing_it() {
    if !has_gpu() {
        return;
    }
    let before = files(store());
    let frames = dir("film").join("frames");
    let args = [
        "video",
        "--level",
        p(store()),
        "--gpu-budget",
        "16MiB",
        "--methods",
        "ray-exact",
        "--size",
        "160x100",
        "--duration",
        "2",
        "--fps",
        "4",
        "--frames-dir",
        p(&frames),
    ];
    let out = strata(&args, &[PAST_THE_LIMIT]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(frames.join("video.json")).unwrap();
    let sidecar: serde_json::Value = serde_json::from_str(&text).unwrap();
    let count = sidecar["frames"].as_u64().unwrap();
    assert_eq!(count, 9, "2 s at 4 fps, both ends: {sidecar}");
    let dig = sidecar["dig_frame"]
        .as_u64()
        .expect("the default path digs");
    assert!(dig > 0 && dig < count, "dig at frame {dig} of {count}");
    let methods = sidecar["methods"].as_array().unwrap();
    assert_eq!(methods.len(), 1, "{sidecar}");
    let track = &methods[0];
    assert!(track["error"].is_null(), "{track}");
    assert!(track["method"].as_str().unwrap().starts_with("ray-exact"));
    assert!(
        track["first_post_edit_ms"].as_f64().unwrap() > 0.0,
        "{track}"
    );
    // The CPU reference over the store's chunks (the crater included after
    // the dig) against the paged frames: flicker measured, and small.
    let flicker = track["flicker"]["mean_percent"].as_f64().unwrap();
    assert!(
        (0.0..5.0).contains(&flicker),
        "flicker {flicker} %: {track}"
    );
    // The same video of the same world loaded whole (below the limit,
    // paged from memory): the frames match but for the labels' frame times.
    let whole = dir("film-whole").join("frames");
    let mut args = args.to_vec();
    *args.last_mut().unwrap() = p(&whole);
    let out = strata(&args, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let pngs = |dir: &Path| {
        let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension() == Some("png".as_ref()))
            .collect();
        names.sort();
        names
    };
    let (paged, loaded) = (pngs(&frames), pngs(&whole));
    assert_eq!(paged.len() as u64, count, "one PNG per frame");
    assert_eq!(loaded.len(), paged.len());
    let mut colours = std::collections::HashSet::new();
    for (a, b) in paged.iter().zip(&loaded) {
        let (a, b) = (
            image::open(a).unwrap().to_rgba8(),
            image::open(b).unwrap().to_rgba8(),
        );
        // Below the label (its frame time differs from run to run).
        let below = |i: &image::RgbaImage| -> Vec<[u8; 4]> {
            i.enumerate_pixels()
                .filter(|(_, y, _)| *y >= LABEL_ROWS)
                .map(|(_, _, p)| p.0)
                .collect()
        };
        let (a_px, b_px) = (below(&a), below(&b));
        let differ = a_px.iter().zip(&b_px).filter(|(x, y)| x != y).count();
        let share = differ as f64 / a_px.len() as f64;
        eprintln!("{:.3} % of pixels differ", share * 100.0);
        assert!(share < 0.005, "{:.2} % of pixels differ", share * 100.0);
        colours.extend(a.pixels().map(|p| p.0));
    }
    // Terrain, not sky.
    assert!(colours.len() > 16, "{} colours", colours.len());
    // The crater went into an edit layer, never into the store.
    assert!(before == files(store()), "the store on disk changed");
}

#[test]
fn a_whole_world_method_is_refused_up_front_naming_the_limit_and_the_paged_methods() {
    let frames = dir("refused").join("frames");
    let out = strata(
        &[
            "video",
            "--level",
            p(store()),
            "--gpu-budget",
            "16MiB",
            "--methods",
            "ray-exact,ray",
            "--frames-dir",
            p(&frames),
        ],
        &[PAST_THE_LIMIT],
    );
    let e = stderr(&out);
    assert!(!out.status.success(), "should fail: {e}");
    assert!(!e.contains("panicked"), "a panic, not an error: {e}");
    for wanted in [
        "past the whole-world limit",
        "STRATA_WHOLE_WORLD_LIMIT_MIB",
        "`ray` draws whole worlds only",
        "ray-exact, ray-exact-fragment",
    ] {
        assert!(e.contains(wanted), "`{wanted}` missing from: {e}");
    }
    assert!(!frames.exists(), "refused before any frame: {e}");
}
