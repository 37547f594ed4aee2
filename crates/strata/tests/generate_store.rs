//! `strata generate --to store` end to end: the store it writes chunk by
//! chunk holds the same world as the Vangers directory the in-memory
//! generator writes (converted back, the same `.vmc`, views and edit
//! site), its preview is made without the whole map, and bad sizes are
//! clear errors that leave an existing directory alone.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const STRATA: &str = env!("CARGO_BIN_EXE_strata");

fn strata(args: &[&str]) -> Output {
    Command::new(STRATA)
        .args(args)
        .output()
        .expect("strata runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("strata-gen-store-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_generated_store_is_the_generated_world() {
    let d = scratch("same");
    let (store, vangers, back) = (d.join("store"), d.join("vangers"), d.join("back"));
    let png = d.join("preview.png");
    let common = [
        "--size",
        "512x1024",
        "--seed",
        "11",
        "--dual-fraction",
        "0.2",
    ];
    let out = strata(
        &[
            &["generate", "--to", "store", "--out", p(&store)][..],
            &common,
            &["--preview", p(&png)],
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("chunks of 256x256"),
        "the report names the chunks: {}",
        text(&out)
    );
    assert!(png.is_file(), "the preview is written");
    let out = strata(&[&["generate", "--out", p(&vangers)][..], &common].concat());
    assert!(out.status.success(), "{}", text(&out));
    let out = strata(&[
        "convert",
        "--level",
        p(&store),
        "--out",
        p(&back),
        "--to",
        "vangers",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    for file in ["output.vmc", "views.txt", "edit.txt"] {
        let a = std::fs::read(vangers.join(file)).unwrap();
        let b = std::fs::read(back.join(file)).unwrap();
        assert!(a == b, "{file} differs between the two paths");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_sizes_are_clear_errors_and_keep_the_directory() {
    let d = scratch("bad");
    let keep = d.join("keep");
    std::fs::create_dir_all(&keep).unwrap();
    std::fs::write(keep.join("world.ini"), "not touched").unwrap();
    let out = strata(&[
        "generate",
        "--to",
        "store",
        "--force",
        "--size",
        "131072x256",
        "--out",
        p(&keep),
    ]);
    assert!(!out.status.success());
    assert!(text(&out).contains("at most 65536"), "{}", text(&out));
    assert!(keep.join("world.ini").is_file(), "--force removed nothing");
    // Too big for a Vangers directory, not for a store: the error says so.
    let out = strata(&[
        "generate",
        "--size",
        "65536x256",
        "--out",
        p(&d.join("vangers")),
    ]);
    assert!(!out.status.success());
    assert!(text(&out).contains("--to store"), "{}", text(&out));
    let _ = std::fs::remove_dir_all(&d);
}
