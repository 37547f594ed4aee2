//! Issue 35, bad edit input through the CLI: a world's crater (`edit.txt`)
//! of radius 0 or a depth that is not a number is refused with the line
//! named; one centred far outside the map wraps onto it and one wider than
//! the map lowers the whole map, and the commands that dig it (`strata
//! collide`: the crater, then frames of small edits) run to the end.

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

fn world() -> PathBuf {
    let d = std::env::temp_dir().join(format!("strata-edit-input-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let world = d.join("world");
    let out = strata(&[
        "generate", "--size", "256x256", "--seed", "3", "--out", p(&world),
    ]);
    assert!(out.status.success(), "generate: {}", text(&out));
    world
}

/// `strata collide` on the world with this crater line in `edit.txt`.
fn collide_with(world: &Path, crater: &str) -> Output {
    let edit = world.join("edit.txt");
    let text = std::fs::read_to_string(&edit).unwrap();
    let camera = text
        .lines()
        .find(|l| l.starts_with("camera"))
        .expect("a camera line")
        .to_string();
    std::fs::write(&edit, format!("{crater}\n{camera}\n")).unwrap();
    strata(&[
        "collide", "--level", p(world), "--rays", "200", "--edits", "4", "--json",
    ])
}

#[test]
fn bad_craters_are_refused_or_wrapped_never_a_panic() {
    let world = world();
    for (crater, why) in [
        ("crater 10,12 0 20", "radius must be > 0"),
        ("crater 10,12 8 nan", "depth finite"),
        ("crater 10,12 8 inf", "depth finite"),
        ("crater 1e9,12 8 20", "must be integers"),
        ("crater 10,12 -3 20", "positive integer"),
    ] {
        let out = collide_with(&world, crater);
        let t = text(&out);
        assert!(!out.status.success(), "{crater}: accepted: {t}");
        assert!(
            t.contains(why) && t.contains("edit.txt") && !t.contains("panicked"),
            "{crater}: {t}"
        );
    }
    for crater in [
        "crater 9223372036854775807,-9223372036854775808 8 20",
        "crater 100010,-99990 8 20",
        "crater 10,12 100000 20",
    ] {
        let out = collide_with(&world, crater);
        let t = text(&out);
        assert!(out.status.success(), "{crater}: {t}");
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(
            report["crater_chunks"].as_u64().is_some_and(|n| n > 0),
            "{crater}: the crater changed nothing: {t}"
        );
    }
    let _ = std::fs::remove_dir_all(world.parent().unwrap());
}
