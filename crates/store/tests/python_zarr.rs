//! Python's `zarr` (v3) opens a store Strata wrote and reads a chunk equal
//! to Strata's. Without python3 or its `zarr` package the test prints a
//! loud SKIPPED line and passes, unless `STRATA_REQUIRE_PYTHON_ZARR=1`
//! (CI: `python3 -m pip install 'zarr>=3,<4'`).

use std::process::Command;
use strata_level::generate::{GenerateParams, generate};
use strata_store::{DirStore, Layout};

const SCRIPT: &str = r#"
import json, sys, zarr
g = zarr.open_group(sys.argv[1], mode="r")
a = g.attrs["strata"]
assert a["format"] == "strata-world", a["format"]
cy, cx = int(sys.argv[2]), int(sys.argv[3])
ch, cw = a["chunk"]
h = g["heights"][cy*ch:(cy+1)*ch, cx*cw:(cx+1)*cw]
m = g["metas"][cy*ch:(cy+1)*ch, cx*cw:(cx+1)*cw]
s = g["summary"][cy, cx, :]
print(json.dumps({"shape": list(g["heights"].shape), "dtype": str(g["heights"].dtype),
    "heights": h.ravel().tolist(), "metas": m.ravel().tolist(), "summary": s.tolist()}))
"#;

#[test]
fn python_zarr_reads_what_strata_wrote() {
    let required = std::env::var("STRATA_REQUIRE_PYTHON_ZARR").is_ok_and(|v| v == "1");
    let probe = Command::new("python3")
        .args([
            "-c",
            "import zarr; assert int(zarr.__version__.split('.')[0]) >= 3",
        ])
        .output();
    if !probe.as_ref().is_ok_and(|o| o.status.success()) {
        let why = match &probe {
            Err(e) => format!("python3 not runnable: {e}"),
            Ok(o) => String::from_utf8_lossy(&o.stderr).trim().to_string(),
        };
        assert!(
            !required,
            "STRATA_REQUIRE_PYTHON_ZARR=1 but Python zarr v3 is missing: {why}"
        );
        eprintln!(
            "*** SKIPPED python_zarr_reads_what_strata_wrote: no python3 with zarr v3 ({why}); install with `python3 -m pip install 'zarr>=3,<4'` ***"
        );
        return;
    }
    let dir = std::env::temp_dir().join(format!("strata-store-python-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let world = generate(&GenerateParams {
        seed: 8,
        width: 256,
        height: 512,
    })
    .unwrap();
    let layout = Layout {
        chunk_height: 64,
        chunk_width: 128,
        ..Layout::default()
    };
    let store = DirStore::create(&dir, &world, &layout).unwrap();
    let (cy, cx) = (5u64, 1u64);
    let out = Command::new("python3")
        .args(["-c", SCRIPT])
        .arg(&dir)
        .args([cy.to_string(), cx.to_string()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "python failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let list = |k: &str| -> Vec<u64> { serde_json::from_value(v[k].clone()).unwrap() };
    assert_eq!(list("shape"), vec![512, 256]);
    assert_eq!(v["dtype"], "uint8");
    let chunk = store.store().read_chunk(cy, cx).unwrap();
    let bytes = |l: Vec<u64>| l.into_iter().map(|b| b as u8).collect::<Vec<u8>>();
    assert_eq!(bytes(list("heights")), chunk.heights);
    assert_eq!(bytes(list("metas")), chunk.metas);
    let sums = store.store().summaries().unwrap();
    let want: Vec<u64> = sums[(cy * 2 + cx) as usize]
        .to_fields()
        .iter()
        .map(|&f| u64::from(f))
        .collect();
    assert_eq!(list("summary"), want);
    let _ = std::fs::remove_dir_all(&dir);
}
