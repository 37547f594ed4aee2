//! Bakes the source revision into the library at build time, so a results
//! file names the code it came from wherever the binary later runs (a run
//! started outside the checkout used to stamp that directory's commit).
//!
//! `STRATA_SOURCE_REVISION` at build time wins (a build from a tarball, or the
//! web bundle's own stamp); otherwise `git describe --always --dirty --tags`
//! of this checkout, where "dirty" means the sources that build the binary
//! (`crates/`, `examples/`, `Cargo.toml`, `Cargo.lock`) differ from the
//! commit; `unknown` when built outside git.

use std::path::{Path, PathBuf};
use std::process::Command;

const SOURCES: &[&str] = &["crates", "examples", "Cargo.toml", "Cargo.lock"];

fn git(root: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("-C")
        .arg(root)
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    println!("cargo:rerun-if-env-changed=STRATA_SOURCE_REVISION");
    if let Ok(rev) = std::env::var("STRATA_SOURCE_REVISION")
        && !rev.trim().is_empty()
    {
        println!("cargo:rustc-env=STRATA_BUILD_REVISION={}", rev.trim());
        return;
    }
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    // crates/bench -> the workspace root.
    let root = manifest
        .ancestors()
        .nth(2)
        .unwrap_or(&manifest)
        .to_path_buf();
    let revision = revision(&root).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=STRATA_BUILD_REVISION={revision}");
}

fn revision(root: &Path) -> Option<String> {
    // Sources unpacked inside some other repository are not that repository's.
    let top = PathBuf::from(git(root, &["rev-parse", "--show-toplevel"])?);
    if top.canonicalize().ok()? != root.canonicalize().ok()? {
        return None;
    }
    let commit = git(root, &["describe", "--always", "--tags", "--abbrev=7"])?;
    // Rerun when HEAD moves, when the index changes (commit, add) and when
    // any tracked source file is edited, so the dirty flag stays true.
    // (A path that does not exist would make cargo rerun this every build.)
    let mut watched = vec!["HEAD".to_string(), "index".into(), "packed-refs".into()];
    watched.extend(git(root, &["symbolic-ref", "-q", "HEAD"]));
    for rel in &watched {
        if let Some(p) = git(root, &["rev-parse", "--git-path", rel]) {
            let p = PathBuf::from(p);
            let p = if p.is_absolute() { p } else { root.join(p) };
            if p.exists() {
                println!("cargo:rerun-if-changed={}", p.display());
            }
        }
    }
    let mut args = vec!["ls-files", "--"];
    args.extend_from_slice(SOURCES);
    for file in git(root, &args)?.lines() {
        println!("cargo:rerun-if-changed={}", root.join(file).display());
    }
    // No optional locks: a plain `git status` may rewrite the index, which
    // would make the next build rerun this script.
    let mut args = vec![
        "--no-optional-locks",
        "status",
        "--porcelain",
        "--untracked-files=no",
        "--",
    ];
    args.extend_from_slice(SOURCES);
    let dirty = !git(root, &args)?.is_empty();
    Some(if dirty {
        format!("{commit}-dirty")
    } else {
        commit
    })
}
