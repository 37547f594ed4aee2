//! Strata's own GL context (`strata_render::gl_context`, used where wgpu's
//! GL context mis-binds uniform blocks: NVIDIA's desktop 3.3 through EGL)
//! draws the same picture as wgpu's own context, on whatever GL adapter this
//! machine has (llvmpipe on a CPU machine). `STRATA_GL_OWN_CONTEXT=1` forces
//! it. Without a GL adapter it skips loudly; `STRATA_REQUIRE_GL=1` fails.

use std::path::PathBuf;
use std::process::Command;
use strata_render::BackendChoice;
use strata_render::adapter::list_adapters;

const STRATA: &str = env!("CARGO_BIN_EXE_strata");

#[test]
fn own_gl_context_draws_what_wgpus_context_draws() {
    if list_adapters(BackendChoice::Gl).is_empty() {
        let why = "no GL adapter for Strata's own GL context";
        if std::env::var_os("STRATA_REQUIRE_GL").is_some_and(|v| v == "1") {
            panic!("STRATA_REQUIRE_GL=1 but {why}");
        }
        eprintln!("\n*** SKIPPED GPU test: {why} ***\n");
        return;
    }
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gl-own-context");
    let _ = std::fs::remove_dir_all(&dir);
    let render = |own: &str, method: &str| -> (Vec<u8>, String) {
        let out_dir = dir.join(format!("{method}-{own}"));
        let out = Command::new(STRATA)
            .env("STRATA_GL_OWN_CONTEXT", own)
            .args(["render", "--backend", "gl", "--method", method])
            .args(["--view-name", "hangar", "--size", "96x60", "--frames", "1"])
            .arg("--out")
            .arg(&out_dir)
            .output()
            .expect("the strata binary starts");
        assert!(
            out.status.success(),
            "render {method} (STRATA_GL_OWN_CONTEXT={own}): {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let json = std::fs::read_to_string(out_dir.join("render.json")).unwrap();
        (std::fs::read(out_dir.join("color.png")).unwrap(), json)
    };
    for method in ["ray", "ray-exact-fragment"] {
        let (wgpus, wgpus_json) = render("0", method);
        let (own, own_json) = render("1", method);
        assert!(
            own_json.contains("Strata's own EGL context"),
            "{method}: the report names the own context"
        );
        assert!(!wgpus_json.contains("Strata's own EGL context"));
        assert!(
            wgpus == own,
            "{method}: the two contexts drew different pictures"
        );
    }
}
