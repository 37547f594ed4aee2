//! `strata export` and `strata collide` end to end on a small generated
//! world (CPU only): a written glTF and OBJ, clear errors for a bad region
//! and an unwritable path, and the collider report's numbers.

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

fn small_world(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("strata-export-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let world = d.join("world");
    let out = strata(&[
        "generate",
        "--size",
        "256x256",
        "--seed",
        "3",
        "--out",
        p(&world),
    ]);
    assert!(out.status.success(), "generate: {}", text(&out));
    world
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

#[test]
fn export_writes_files_and_names_bad_input() {
    let world = small_world("export");
    let glb = world.with_file_name("t.glb");
    let out = strata(&[
        "export",
        "--level",
        p(&world),
        "--format",
        "glb",
        "--out",
        p(&glb),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let bytes = std::fs::read(&glb).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    assert!(bytes.len() > 10_000, "{} bytes", bytes.len());

    // `.gltf` holds JSON by convention: the format follows the extension.
    let gltf = world.with_file_name("t.gltf");
    let out = strata(&[
        "export",
        "--level",
        p(&world),
        "--region",
        "0,0,64,64",
        "--out",
        p(&gltf),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&gltf).unwrap()).expect("a .gltf file is JSON");
    assert_eq!(json["asset"]["version"], "2.0");

    let obj = world.with_file_name("t.obj");
    let args = [
        "export",
        "--level",
        p(&world),
        "--format",
        "obj",
        "--region",
        "200,0,300,64",
        "--out",
        p(&obj),
    ];
    let out = strata(&args);
    assert!(out.status.success(), "{}", text(&out));
    let faces = std::fs::read_to_string(&obj)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("f "))
        .count();
    assert!(faces > 100, "{faces} faces");

    for (args, expect) in [
        (
            vec!["--region", "0,0,300,10", "--out", p(&obj)],
            "wider or taller than the map",
        ),
        (vec!["--region", "5,5,5,9", "--out", p(&obj)], "empty"),
        (
            vec!["--out", "/nonexistent-dir/x.glb"],
            "cannot write the export to /nonexistent-dir/x.glb",
        ),
        (
            vec!["--format", "fbx", "--out", p(&obj)],
            "expected glb, gltf or obj",
        ),
        (
            vec!["--format", "glb", "--out", p(&gltf)],
            "--format glb but",
        ),
        (
            vec!["--out", "/tmp/terrain.mesh"],
            "cannot tell the format from /tmp/terrain.mesh",
        ),
        (
            vec!["--quality", "2", "--out", p(&obj)],
            "quality 2 is outside [0, 1]",
        ),
    ] {
        let mut all = vec!["export", "--level", p(&world)];
        all.extend(args);
        let out = strata(&all);
        assert!(!out.status.success());
        let t = text(&out);
        assert!(
            t.contains(expect) && !t.contains("panicked"),
            "{all:?}: {t}"
        );
    }
}

#[test]
fn collide_reports_its_numbers() {
    let world = small_world("collide");
    let out = strata(&["collide", "--level", p(&world), "--rays", "500", "--json"]);
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The exact column collider (issue 35): a few bytes per texel, every
    // ray and every grazing ray where the CPU reference puts it.
    assert!(v["memory_bytes"].as_u64().unwrap() > 10_000, "{v}");
    assert!(v["memory_bytes_per_texel"].as_f64().unwrap() <= 12.0, "{v}");
    assert!(v["collider_rays_per_second"].as_f64().unwrap() > 0.0);
    assert!(v["hits_both"].as_u64().unwrap() > 400, "{v}");
    assert!(v["agree_percent"].as_f64().unwrap() >= 99.0, "{v}");
    assert!(v["grazing_agree_percent"].as_f64().unwrap() >= 99.0, "{v}");
    assert!(
        v["edit_frame_refit_ms_median"].as_f64().unwrap() >= 0.0,
        "{v}"
    );
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
        "collide",
        "--level",
        p(world),
        "--rays",
        "200",
        "--edits",
        "4",
        "--json",
    ])
}

/// Issue 35, bad edit input through the CLI: a world's crater (`edit.txt`)
/// of radius 0 or a depth that is not a number is refused with the file
/// named; one centred far outside the map wraps onto it and one wider than
/// the map lowers the whole map, and `strata collide` (the crater, then
/// frames of small edits) runs to the end.
#[test]
fn bad_craters_are_refused_or_wrapped_never_a_panic() {
    let world = small_world("bad-craters");
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
