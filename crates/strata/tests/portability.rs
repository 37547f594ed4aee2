//! `strata compare --all-adapters` end to end at a tiny size on whatever
//! adapters this machine offers (lavapipe and llvmpipe on a CPU machine),
//! then `strata merge --portability` over the same results files. Without
//! any adapter it skips loudly; with `STRATA_REQUIRE_GPU=1` (CI) it fails.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use strata_bench::portability::Portability;
use strata_render::BackendChoice;
use strata_render::adapter::list_adapters;

const STRATA: &str = env!("CARGO_BIN_EXE_strata");

fn skip_loudly(why: &str) {
    use std::io::Write;
    if std::env::var_os("STRATA_REQUIRE_GPU").is_some_and(|v| v == "1") {
        panic!("STRATA_REQUIRE_GPU=1 but {why}");
    }
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED GPU test: {why} ***\n");
}

fn strata(args: &[&str]) -> Output {
    let out = Command::new(STRATA)
        .args(args)
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

fn read_report(dir: &Path) -> Portability {
    let text = std::fs::read_to_string(dir.join("portability.json")).unwrap();
    serde_json::from_str(&text).expect("portability.json parses into its struct")
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn all_adapters_batch_and_portability_merge() {
    let adapters = list_adapters(BackendChoice::Auto);
    if adapters.is_empty() {
        skip_loudly("no GPU adapter for `compare --all-adapters`");
        return;
    }
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("portability");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let world = dir.join("world");
    assert!(
        strata(&[
            "generate",
            "--size",
            "256x512",
            "--seed",
            "5",
            "--out",
            p(&world)
        ])
        .status
        .success()
    );
    let views = dir.join("views.txt");
    std::fs::write(&views, "level 100,100:0:30 0\ndown 128,300:90:60 -60\n").unwrap();
    let out = dir.join("batch");
    let run = strata(&[
        "compare",
        "--all-adapters",
        "--level",
        p(&world),
        "--views",
        p(&views),
        "--methods",
        "ray,painted",
        "--size",
        "64x40",
        "--frames",
        "1",
        "--warmup",
        "1",
        "--no-edits",
        "--cache",
        p(&dir.join("cache")),
        "--out",
        p(&out),
    ]);
    assert!(run.status.success(), "compare --all-adapters failed");
    assert!(out.join("portability.md").is_file());
    let report = read_report(&out);
    // Every adapter either ran or is listed as skipped, with its reason.
    assert_eq!(
        report.runs.len() + report.skipped.len(),
        adapters.len(),
        "{report:#?}"
    );
    assert!(
        !report.runs.is_empty(),
        "no adapter ran: {:?}",
        report.skipped
    );
    // CI installs llvmpipe's GL beside lavapipe: there the batch must cover both APIs.
    if std::env::var_os("STRATA_REQUIRE_GL").is_some_and(|v| v == "1") {
        for backend in ["vulkan", "gl"] {
            assert!(
                report.runs.iter().any(|r| r.adapter.backend == backend),
                "STRATA_REQUIRE_GL=1 but no {backend} run: {:?} skipped {:?}",
                report.runs,
                report.skipped
            );
        }
    }
    // One protocol (the size and frames were explicit): one group.
    assert_eq!(report.groups.len(), 1, "{report:#?}");
    let g = &report.groups[0];
    assert_eq!(g.cells.len(), 4);
    assert_eq!(g.adapters.len(), report.runs.len());
    for cell in &g.cells {
        // Complete runs: each adapter has the cell or a recorded refusal.
        assert_eq!(cell.values.len() + cell.absent.len(), report.runs.len());
        assert!(cell.absent.iter().all(|a| a.failure.is_some()), "{cell:?}");
        assert!(!cell.disagrees.contains(&"cell".to_string()));
        for v in &cell.values {
            let pic = v.picture.as_ref().expect("the cell picture is found");
            assert!(out.join(pic).is_file(), "{pic}");
        }
        assert!(cell.reference_picture.is_some());
        if !cell.disagrees.is_empty() {
            let sbs = cell.side_by_side.as_ref().expect("a side-by-side picture");
            assert!(out.join(sbs).is_file(), "{sbs}");
        }
    }
    // Disagreeing cells come first.
    let flags: Vec<bool> = g.cells.iter().map(|c| !c.disagrees.is_empty()).collect();
    assert!(flags.windows(2).all(|w| w[0] >= w[1]), "{flags:?}");
    // Each run has its own folder with its results and pictures.
    let results: Vec<PathBuf> = report.runs.iter().map(|r| out.join(&r.results)).collect();
    for (r, path) in report.runs.iter().zip(&results) {
        assert!(path.is_file(), "{}", path.display());
        assert!(r.complete, "{r:?}");
        assert!(r.results.contains('/'), "{} is in a subfolder", r.results);
    }
    eprintln!(
        "{}",
        std::fs::read_to_string(out.join("portability.md")).unwrap()
    );

    // The same report from the results files.
    let merged = dir.join("merged");
    let mut args = vec!["merge", "--portability", "--out", p(&merged)];
    args.extend(results.iter().map(|r| p(r)));
    assert!(strata(&args).status.success());
    let again = read_report(&merged);
    assert_eq!(again.groups.len(), 1);
    assert_eq!(again.groups[0].cells, {
        // Picture paths are relative to each report's folder.
        let mut cells = g.cells.clone();
        let fix = |s: &mut Option<String>| {
            if let Some(x) = s {
                *x = if x.starts_with("disagreements/") {
                    x.clone()
                } else {
                    format!("../batch/{x}")
                };
            }
        };
        for c in &mut cells {
            fix(&mut c.reference_picture);
            for v in &mut c.values {
                fix(&mut v.picture);
            }
        }
        cells
    });

    // Bad input is an error, not a panic.
    let bad = strata(&["merge", "--portability", p(&dir.join("nope.json"))]);
    assert!(!bad.status.success());
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        stderr.contains("error:") && stderr.contains("nope.json"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}
