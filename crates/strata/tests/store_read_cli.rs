//! `reference`, `fit --region` and `export --region` on a store read through
//! its chunk cache give what the same commands give on the same world as a
//! Vangers directory (file for file, number for number); a whole-world
//! command refuses a store above its limit, naming the size and the
//! commands that work on it. CPU only.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const STRATA: &str = env!("CARGO_BIN_EXE_strata");

fn strata(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(STRATA);
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("strata runs")
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

/// A 512² generated world and the same world as a store.
fn worlds() -> (PathBuf, PathBuf, PathBuf) {
    let d = std::env::temp_dir().join(format!("strata-store-read-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let (vangers, store) = (d.join("world"), d.join("store"));
    let out = strata(
        &[
            "generate",
            "--size",
            "512x512",
            "--seed",
            "3",
            "--out",
            p(&vangers),
        ],
        &[],
    );
    assert!(out.status.success(), "generate: {}", text(&out));
    let out = strata(
        &["convert", "--level", p(&vangers), "--out", p(&store)],
        &[],
    );
    assert!(out.status.success(), "convert: {}", text(&out));
    (d, vangers, store)
}

fn json_lines(o: &Output) -> Vec<serde_json::Value> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn store_commands_equal_the_in_memory_ones() {
    let (d, vangers, store) = worlds();
    let cache = d.join("refcache");
    // The reference: same files, same content hash (so one cache serves both).
    let mut outs = Vec::new();
    for (name, world) in [("v", &vangers), ("s", &store)] {
        let out_dir = d.join(format!("ref-{name}"));
        let out = strata(
            &[
                "reference",
                "--level",
                p(world),
                "--view",
                "500,20:200:60",
                "--pitch",
                "-30",
                "--size",
                "96x60",
                "--out",
                p(&out_dir),
                "--cache-dir",
                p(&cache),
                "--json",
                "--store-cache",
                "1",
            ],
            &[],
        );
        assert!(out.status.success(), "reference {name}: {}", text(&out));
        outs.push((out_dir.join("view"), json_lines(&out)));
    }
    for file in ["distance.f32", "class.u8", "terrain.u8", "color.png"] {
        let a = std::fs::read(outs[0].0.join(file)).unwrap();
        let b = std::fs::read(outs[1].0.join(file)).unwrap();
        assert!(a == b, "{file} differs between the world and its store");
    }
    let header = |dir: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(dir.join("reference.json")).unwrap()).unwrap()
    };
    assert_eq!(
        header(&outs[0].0)["level_hash"],
        header(&outs[1].0)["level_hash"]
    );
    // The store's second view came from the cache the world filled.
    assert_eq!(outs[1].1[0]["from_cache"], true, "{:?}", outs[1].1);
    assert!(outs[1].1[0]["store_cache"]["peak_bytes"].as_u64().unwrap() <= 1 << 20);
    // Computed over the store (no cache), within a 1 MiB chunk cache.
    let out = strata(
        &[
            "reference",
            "--level",
            p(&store),
            "--view",
            "500,20:200:60",
            "--pitch",
            "-30",
            "--size",
            "96x60",
            "--out",
            p(&d.join("ref-s2")),
            "--no-cache",
            "--json",
            "--store-cache",
            "1",
        ],
        &[],
    );
    assert!(out.status.success(), "{}", text(&out));
    let line = &json_lines(&out)[0];
    assert_eq!(line["from_cache"], false);
    assert!(
        line["store_cache"]["misses"].as_u64().unwrap() > 0,
        "{line}"
    );
    assert!(
        line["store_cache"]["peak_bytes"].as_u64().unwrap() <= 1 << 20,
        "{line}"
    );
    let a = std::fs::read(outs[0].0.join("distance.f32")).unwrap();
    assert_eq!(
        a,
        std::fs::read(d.join("ref-s2/view/distance.f32")).unwrap()
    );

    // fit --region: the same totals (times aside).
    let fit = |world: &Path, region: &str| {
        let out = strata(
            &[
                "fit",
                "--level",
                p(world),
                "--region",
                region,
                "--json",
                "--store-cache",
                "1",
            ],
            &[],
        );
        assert!(out.status.success(), "fit: {}", text(&out));
        let mut v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for k in [
            "fit_seconds",
            "fit_cpu_seconds",
            "triangles_per_second_per_core",
            "triangles_per_cpu_second",
            "store_cache",
            "world",
        ] {
            v.as_object_mut().unwrap().remove(k);
        }
        v
    };
    for region in ["10,20,200,150", "450,470,600,530"] {
        assert_eq!(fit(&vangers, region), fit(&store, region), "{region}");
    }
    // A whole store's fit (read through the cache) equals the world's.
    let whole = |world: &Path| {
        let out = strata(&["fit", "--level", p(world), "--json"], &[]);
        assert!(out.status.success(), "fit: {}", text(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (
            v["triangles"].clone(),
            v["vertices"].clone(),
            v["lods"].clone(),
        )
    };
    assert_eq!(whole(&vangers), whole(&store));

    // export --region: the same bytes.
    let mut files = Vec::new();
    for (name, world) in [("v", &vangers), ("s", &store)] {
        let f = d.join(format!("{name}.obj"));
        let out = strata(
            &[
                "export",
                "--level",
                p(world),
                "--region",
                "450,470,600,530",
                "--out",
                p(&f),
                "--store-cache",
                "1",
            ],
            &[],
        );
        assert!(out.status.success(), "export {name}: {}", text(&out));
        files.push(std::fs::read(&f).unwrap());
    }
    assert!(files[0] == files[1], "the store's export differs");

    // A whole-world command refuses a store above its limit, by name.
    let out = strata(
        &["collide", "--level", p(&store), "--rays", "10"],
        &[("STRATA_WHOLE_WORLD_LIMIT_MIB", "0")],
    );
    assert!(!out.status.success());
    let t = text(&out);
    assert!(
        t.contains("512x512") && t.contains("reference, fit, export --region"),
        "{t}"
    );
    // A store too large for a whole export asks for a region.
    let out = strata(
        &["export", "--level", p(&store), "--out", p(&d.join("w.obj"))],
        &[("STRATA_WHOLE_WORLD_LIMIT_MIB", "0")],
    );
    assert!(!out.status.success());
    assert!(text(&out).contains("--region"), "{}", text(&out));
    let _ = std::fs::remove_dir_all(&d);
}
