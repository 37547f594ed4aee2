//! The revision a binary reports (`--version`, and `source_revision` in every
//! results file and report, from the same constant) is baked in at build
//! time: running it from another directory, even another git checkout,
//! changes nothing.

use std::path::Path;
use std::process::Command;

fn version_from(dir: &Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_strata"))
        .arg("--version")
        .current_dir(dir)
        .output()
        .expect("running strata --version");
    assert!(out.status.success(), "strata --version failed: {out:?}");
    String::from_utf8(out.stdout).unwrap().trim().to_string()
}

fn git(dir: &Path, args: &[&str]) -> bool {
    Command::new("git")
        .args(args)
        .current_dir(dir)
        .env("GIT_AUTHOR_NAME", "t")
        .env("GIT_AUTHOR_EMAIL", "t@example.com")
        .env("GIT_COMMITTER_NAME", "t")
        .env("GIT_COMMITTER_EMAIL", "t@example.com")
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn revision_does_not_depend_on_the_working_directory() {
    let checkout = Path::new(env!("CARGO_MANIFEST_DIR"));
    let here = version_from(checkout);
    assert!(
        here.starts_with("strata ") && here.contains("(revision "),
        "unexpected --version output: {here}"
    );
    assert_eq!(
        here,
        format!(
            "strata {} (revision {})",
            env!("CARGO_PKG_VERSION"),
            strata_bench::plan::SOURCE_REVISION
        )
    );

    // Another directory that is a git checkout of its own, with a commit: a
    // revision read at run time would name that commit.
    let other = std::env::temp_dir().join(format!("strata-revision-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&other);
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("f"), "x").unwrap();
    let foreign_commit = git(&other, &["init", "-q"])
        && git(&other, &["add", "f"])
        && git(&other, &["commit", "-q", "-m", "other"]);
    let there = version_from(&other);
    std::fs::remove_dir_all(&other).ok();
    assert_eq!(
        here, there,
        "the revision changed with the working directory"
    );
    if !foreign_commit {
        eprintln!("(git unavailable: checked a plain directory only)");
    }
}
