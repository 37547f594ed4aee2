//! `strata video` end to end: bad input (a malformed path line, one
//! keyframe, no ffmpeg) is a clear error before any GPU work; a tiny video
//! of a small world to PNGs with the temporal metric in range; ffmpeg dying
//! half-way shows its stderr; a real ffmpeg (CI installs it) writes an MP4.
//! Over a store past the whole-world limit (issue 33; a small store made to
//! look too large with `STRATA_WHOLE_WORLD_LIMIT_MIB=1`, which would refuse
//! loading it whole): `ray-exact` films it through pages, the crater dug
//! into an edit layer and the store on disk left as it was, its frames
//! those of the same world loaded whole; a method that cannot draw pages is
//! refused up front naming the limit and the paged methods.
//! The GPU parts skip loudly without an adapter; with
//! `STRATA_REQUIRE_GPU=1` (CI) they fail.

use std::collections::BTreeMap;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use strata_render::BackendChoice;
use strata_render::adapter::list_adapters;

const STRATA: &str = env!("CARGO_BIN_EXE_strata");
/// Rows of a frame the method's label (with its frame time) may cover.
const LABEL_ROWS: u32 = 16;
const PAST_THE_LIMIT: (&str, &str) = ("STRATA_WHOLE_WORLD_LIMIT_MIB", "1");

fn skip_loudly(why: &str) {
    use std::io::Write;
    if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_GPU=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU test: {why} ***\n");
}

/// Run strata with `path_env` as PATH when given.
fn strata(args: &[&str], path_env: Option<&Path>) -> Output {
    strata_with(args, path_env, &[])
}

/// [`strata`] with the variables `env` set.
fn strata_with(args: &[&str], path_env: Option<&Path>, env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(STRATA);
    cmd.args(args).envs(env.iter().copied());
    if let Some(p) = path_env {
        cmd.env("PATH", p);
    }
    let out = cmd.output().expect("the strata binary starts");
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

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("video-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
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

#[test]
fn malformed_path_line_is_named() {
    let d = dir("malformed");
    let file = d.join("path.txt");
    std::fs::write(&file, "# flight\n10,20:0:40 -30 0\n10,20:0:40 -30\n").unwrap();
    let frames = d.join("frames");
    let out = strata(
        &["video", "--path", p(&file), "--frames-dir", p(&frames)],
        None,
    );
    assert_clean_error(&out, &["path.txt", "line 3:", "2 fields, expected 3"]);
}

#[test]
fn one_keyframe_is_not_a_path() {
    let d = dir("one-key");
    let file = d.join("path.txt");
    std::fs::write(&file, "10,20:0:40 -30 0\n").unwrap();
    let out = strata(
        &["video", "--path", p(&file), "--frames-dir", p(&d.join("f"))],
        None,
    );
    assert_clean_error(&out, &["at least two keyframes", "has 1"]);
}

#[test]
fn missing_ffmpeg_is_a_clear_error() {
    let d = dir("no-ffmpeg");
    let empty = d.join("empty-path");
    std::fs::create_dir_all(&empty).unwrap();
    let out = strata(
        &["video", "--methods", "ray", "--out", p(&d.join("v.mp4"))],
        Some(&empty),
    );
    assert_clean_error(
        &out,
        &[
            "`ffmpeg` is not on the PATH",
            "apt-get install ffmpeg",
            "--frames-dir",
        ],
    );
}

/// A small generated world (256 x 1024) with an edit site, or `None` (skipped) without an adapter.
fn small_world(d: &Path) -> Option<PathBuf> {
    if list_adapters(BackendChoice::Auto).is_empty() {
        skip_loudly("no GPU adapter for `strata video`");
        return None;
    }
    let world = d.join("world");
    let out = strata(
        &[
            "generate",
            "--size",
            "256x1024",
            "--seed",
            "7",
            "--out",
            p(&world),
        ],
        None,
    );
    assert!(out.status.success(), "generate: {}", stderr(&out));
    Some(world)
}

/// Tiny: two methods in 48x28 tiles, 2 s at 4 fps (9 frames), the crater dug midway.
const TINY: [&str; 8] = [
    "--methods",
    "ray,mesh",
    "--size",
    "96x28",
    "--fps",
    "4",
    "--duration",
    "2",
];

#[test]
fn tiny_video_to_frames_with_flicker_in_range() {
    let d = dir("frames");
    let Some(world) = small_world(&d) else {
        return;
    };
    let frames = d.join("frames");
    let mut args = vec!["video", "--level", p(&world), "--frames-dir", p(&frames)];
    args.extend(TINY);
    let out = strata(&args, None);
    assert!(out.status.success(), "{}", stderr(&out));
    for i in 0..9 {
        let f = frames.join(format!("frame-{i:05}.png"));
        let img = image::open(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert_eq!((img.width(), img.height()), (96, 28));
    }
    assert!(!frames.join("frame-00009.png").exists());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(frames.join("video.json")).unwrap()).unwrap();
    assert_eq!(json["frames"], 9);
    assert_eq!(json["tile_width"], 48);
    // The default path digs a little past its middle.
    let dig = json["dig_frame"].as_u64().expect("the crater was dug");
    assert!((4..=7).contains(&dig), "dig frame {dig}");
    let methods = json["methods"].as_array().unwrap();
    assert_eq!(methods.len(), 2);
    for m in methods {
        let f = &m["flicker"];
        let mean = f["mean_percent"].as_f64().unwrap();
        let worst = f["max_percent"].as_f64().unwrap();
        // Coarse frames of a fast flight: some flicker against the reference,
        // never most of the picture on average.
        assert!(
            (0.0..40.0).contains(&mean),
            "{}: mean flicker {mean}",
            m["method"]
        );
        assert!(
            worst >= mean && worst <= 100.0,
            "{}: worst {worst}",
            m["method"]
        );
        assert_eq!(f["pairs"], 8);
        assert!(m["first_post_edit_ms"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn ffmpeg_failing_half_way_shows_its_stderr() {
    let d = dir("ffmpeg-fails");
    let Some(world) = small_world(&d) else {
        return;
    };
    // An "ffmpeg" that answers -version, takes two frames' bytes, then dies.
    let bin = d.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let fake = bin.join("ffmpeg");
    std::fs::write(
        &fake,
        "#!/bin/sh\n[ \"$1\" = -version ] && exit 0\nhead -c 21504 > /dev/null\n\
         echo 'fake ffmpeg: no space left on device' >&2\nexit 1\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path_env = std::env::join_paths(std::iter::once(bin.clone()).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .unwrap();
    let mut args = vec!["video", "--level", p(&world), "--out"];
    let mp4 = d.join("v.mp4");
    args.push(p(&mp4));
    args.extend(TINY);
    let out = strata(&args, Some(Path::new(&path_env)));
    assert_clean_error(
        &out,
        &[
            "ffmpeg stopped after",
            "fake ffmpeg: no space left on device",
            "kept in",
        ],
    );
}

#[test]
fn real_ffmpeg_writes_an_mp4() {
    if Command::new("ffmpeg").arg("-version").output().is_err() {
        if std::env::var_os("STRATA_REQUIRE_FFMPEG").is_some_and(|v| v == "1") {
            panic!("STRATA_REQUIRE_FFMPEG=1 but no ffmpeg on the PATH");
        }
        eprintln!("\n*** SKIPPED: no ffmpeg on the PATH (apt-get install ffmpeg) ***\n");
        return;
    }
    let d = dir("mp4");
    let Some(world) = small_world(&d) else {
        return;
    };
    let mp4 = d.join("v.mp4");
    let mut args = vec![
        "video",
        "--level",
        p(&world),
        "--out",
        p(&mp4),
        "--no-temporal",
    ];
    args.extend(TINY);
    let out = strata(&args, None);
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = std::fs::read(&mp4).unwrap();
    // An MP4 starts with its `ftyp` box.
    assert_eq!(&bytes[4..8], b"ftyp");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("v.json")).unwrap()).unwrap();
    assert_eq!(json["frames"], 9);
    assert!(json["methods"][0]["flicker"].is_null());
}

/// A 1024² store (16 chunks, with an edit site), generated once.
fn store() -> &'static Path {
    static STORE: OnceLock<PathBuf> = OnceLock::new();
    STORE.get_or_init(|| {
        let store = dir("paged-store").join("world");
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
            None,
        );
        assert!(out.status.success(), "{}", stderr(&out));
        store
    })
}

/// `strata video` of [`store`] at a 16 MiB GPU budget with `methods`
/// into the directory `frames` (its path the 9th argument).
fn video_of_the_store<'a>(methods: &'a str, frames: &'a Path) -> Vec<&'a str> {
    vec![
        "video",
        "--level",
        p(store()),
        "--gpu-budget",
        "16MiB",
        "--methods",
        methods,
        "--frames-dir",
        p(frames),
    ]
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
    if list_adapters(BackendChoice::Auto).is_empty() {
        skip_loudly("no GPU adapter for a paged video");
        return;
    }
    let before = files(store());
    let frames = dir("paged-film").join("frames");
    let mut args = video_of_the_store("ray-exact", &frames);
    args.extend(["--size", "160x100", "--duration", "2", "--fps", "4"]);
    let out = strata_with(&args, None, &[PAST_THE_LIMIT]);
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
    let whole = dir("paged-film-whole").join("frames");
    let mut args = args.clone();
    args[8] = p(&whole);
    let out = strata(&args, None);
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
    let frames = dir("paged-refused").join("frames");
    let args = video_of_the_store("ray-exact,ray", &frames);
    let out = strata_with(&args, None, &[PAST_THE_LIMIT]);
    assert_clean_error(
        &out,
        &[
            "past the whole-world limit",
            "STRATA_WHOLE_WORLD_LIMIT_MIB",
            "`ray` draws whole worlds only",
            "ray-exact, ray-exact-fragment",
        ],
    );
    assert!(!frames.exists(), "refused before any frame");
}
