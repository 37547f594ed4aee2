//! The example's window mode: under a display (the session's, or an Xvfb
//! this test starts) it opens, draws frames into the surface through
//! `render_into` and closes after `--seconds`; without one it says so and
//! exits 1, without a panic. No display and no Xvfb: a loud skip
//! (`STRATA_REQUIRE_DISPLAY=1` makes that a failure).

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const DRIVE: &str = env!("CARGO_BIN_EXE_strata-example-drive");

/// The session's display, or an Xvfb of the test's own (the viewer's helper,
/// shared with `strata soak` and the viewer's window tests).
fn display() -> Option<strata_viewer::x_display::XDisplay> {
    strata_viewer::x_display::XDisplay::open().ok()
}

/// Run to the end or kill after `limit`: (exited 0, stdout, stderr).
fn run(mut command: Command, limit: Duration) -> (bool, String, String) {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the example starts");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn without_a_display_the_window_mode_says_so() {
    let mut command = Command::new(DRIVE);
    command
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET");
    let (ok, _, stderr) = run(command, Duration::from_secs(60));
    println!("{stderr}");
    assert!(!ok, "it claimed success without a display");
    assert!(stderr.contains("no display"), "{stderr}");
    assert!(stderr.contains("--frames N --out DIR"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn the_window_draws_frames_and_closes() {
    let Some(display) = display() else {
        let why = "no DISPLAY and no Xvfb on the PATH";
        if std::env::var_os("STRATA_REQUIRE_DISPLAY").is_some_and(|v| v == "1") {
            panic!("STRATA_REQUIRE_DISPLAY=1 but {why}");
        }
        eprintln!("\n*** SKIPPED drive window test: {why} ***\n");
        return;
    };
    let mut command = Command::new(DRIVE);
    command
        .args(["ray", "--size", "160x100", "--seconds", "2"])
        .env("DISPLAY", &display.name)
        .env_remove("WAYLAND_DISPLAY");
    let (ok, stdout, stderr) = run(command, Duration::from_secs(120));
    println!("{stdout}{stderr}");
    assert!(ok, "the window mode failed: {stderr}");
    // "drive: N frames in S s (ray into FORMAT + Depth32Float)"
    let frames: u32 = stdout
        .split_once("drive: ")
        .and_then(|(_, rest)| rest.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("no frame count in {stdout:?}"));
    assert!(frames >= 1, "{frames} frames drawn");
}
