//! `strata view` over a store drawn through paged terrain (issue 33), in a
//! real window: the `memory` line's paging numbers (GPU bytes within the
//! budget), a dig that shows on the next frame and an undo that gives the
//! picture back exactly, Ctrl+S (`save`) writing the edited chunks into the
//! store in place, which a fresh viewer then shows, and a whole-world method
//! refused with the paged methods named. Needs a display (`DISPLAY`, or
//! `Xvfb` on the PATH) and a GPU adapter; skips loudly without them.

use image::RgbaImage;
use std::path::{Path, PathBuf};
use std::process::Command;

const STRATA: &str = env!("CARGO_BIN_EXE_strata");
const BUDGET: u64 = 8 << 20;

fn skip_loudly(why: &str, required_by: &str) {
    use std::io::Write;
    if std::env::var_os(required_by).is_some_and(|v| v == "1") {
        panic!("{required_by}=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED window test: {why} ***\n");
}

fn load(path: &Path) -> RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

/// `key=value` fields of a `memory` line.
fn field(line: &str, key: &str) -> f64 {
    line.split_whitespace()
        .find_map(|f| f.strip_prefix(&format!("{key}=")))
        .unwrap_or_else(|| panic!("no {key} in {line}"))
        .parse()
        .unwrap_or_else(|e| panic!("{key} in {line}: {e}"))
}

struct Run {
    ok: bool,
    stdout: String,
    stderr: String,
}

fn view(display: &str, runtime: &Path, store: &Path, script: &Path, overwrite: bool) -> Run {
    let mut command = Command::new(STRATA);
    command
        .args(["view", "--level"])
        .arg(store)
        .args(["--gpu-budget", &BUDGET.to_string()])
        .args(["--method", "ray-exact", "--size", "320x200"])
        .args(["--render-scale", "1", "--script"])
        .arg(script)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", runtime);
    if overwrite {
        command.arg("--overwrite");
    }
    let out = command.output().expect("the strata binary starts");
    let run = Run {
        ok: out.status.success(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    };
    eprintln!("{}\n{}", run.stdout, run.stderr);
    run
}

#[test]
fn the_viewer_flies_digs_and_saves_a_paged_store() {
    let Ok(display) = strata_viewer::x_display::XDisplay::open() else {
        skip_loudly(
            "no display (set DISPLAY or install xvfb)",
            "STRATA_REQUIRE_DISPLAY",
        );
        return;
    };
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("view_paged");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let store = dir.join("store");
    let generated = Command::new(STRATA)
        .args([
            "generate",
            "--size",
            "1024x1024",
            "--seed",
            "5",
            "--to",
            "store",
        ])
        .arg("--out")
        .arg(&store)
        .output()
        .unwrap();
    assert!(generated.status.success(), "{generated:?}");
    let runtime = dir.join("xdg");
    std::fs::create_dir_all(&runtime).unwrap();
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&runtime, std::fs::Permissions::from_mode(0o700)).unwrap();
    }
    let shots = dir.join("shots");
    let script = dir.join("dig.txt");
    std::fs::write(
        &script,
        format!(
            "view edit\noverlay off\nframes 30\nmemory\n\
             screenshot {s}/before.png\n\
             dig 0.5 0.5\nscreenshot {s}/dug.png\n\
             undo\nscreenshot {s}/undone.png\n\
             dig 0.5 0.5\nframes 2\nmemory\nsave {store}\n\
             fly 300 0 0 20\nmemory\n\
             method voxel\n",
            s = shots.display(),
            store = store.display()
        ),
    )
    .unwrap();
    let run = view(&display.name, &runtime, &store, &script, true);
    if !run.ok && run.stderr.contains("no GPU adapter") {
        skip_loudly("no GPU adapter", "STRATA_REQUIRE_GPU");
        return;
    }
    // The script ends on a refused method: an error naming the paged ones.
    assert!(!run.ok, "`method voxel` should stop the script");
    assert!(
        run.stderr
            .contains("`voxel` draws whole worlds only; paged worlds are drawn by ray-exact"),
        "{}",
        run.stderr
    );
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    let memory: Vec<&str> = run
        .stdout
        .lines()
        .filter(|l| l.starts_with("memory "))
        .collect();
    assert_eq!(memory.len(), 3, "{}", run.stdout);
    for line in &memory {
        assert_eq!(field(line, "paged_budget") as u64, BUDGET);
        let gpu = field(line, "paged_gpu_bytes") as u64;
        assert!(gpu > 0 && gpu <= BUDGET, "{line}");
        assert!(field(line, "resident_pages") >= 1.0, "{line}");
        assert!(
            (0.0..=100.0).contains(&field(line, "pending_pct")),
            "{line}"
        );
        assert_eq!(field(line, "read_errors"), 0.0, "{line}");
    }
    assert_eq!(
        field(memory[0], "pending_pixels"),
        0.0,
        "converged after 30 frames"
    );
    assert_eq!(field(memory[1], "edited_chunks"), 1.0, "{}", memory[1]);
    assert_eq!(
        field(memory[2], "edited_chunks"),
        0.0,
        "saved: {}",
        memory[2]
    );
    assert!(
        run.stderr.contains("edited chunk(s) into the store"),
        "{}",
        run.stderr
    );
    // The crater shows on the next frame; undo gives the picture back.
    let before = load(&shots.join("before.png"));
    let dug = load(&shots.join("dug.png"));
    let undone = load(&shots.join("undone.png"));
    assert!(dug != before, "the dig did not show");
    assert!(undone == before, "undo left a different picture");
    // A fresh viewer of the saved store shows the crater.
    let script = dir.join("reopen.txt");
    std::fs::write(
        &script,
        format!(
            "view edit\noverlay off\nframes 30\nscreenshot {s}/reopened.png\n",
            s = shots.display()
        ),
    )
    .unwrap();
    let run = view(&display.name, &runtime, &store, &script, false);
    assert!(run.ok, "{}", run.stderr);
    let reopened = load(&shots.join("reopened.png"));
    assert!(reopened == dug, "the saved store does not show the crater");
}
