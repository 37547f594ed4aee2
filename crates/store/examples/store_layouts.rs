//! Measure chunk shapes and gzip levels on a generated world: bytes per
//! texel on disk (apparent and allocated, with one object per chunk and as
//! if sharded), decode throughput per core, and a random read of one chunk
//! from a freshly opened store.
//!
//! `cargo run --release -p strata-store --example store_layouts [-- WxH [SEED]]`
//! (default: the default generated world, 2048x16384, seed 1997).

use std::os::unix::fs::MetadataExt;
use std::path::Path;
use std::time::Instant;
use strata_level::generate::{GenerateParams, generate};
use strata_store::{DirStore, Layout};

/// (apparent bytes, allocated bytes, object sizes by key)
fn sizes(dir: &Path) -> (u64, u64, Vec<(String, u64)>) {
    let (mut apparent, mut allocated, mut objects) = (0, 0, Vec::new());
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            let m = e.metadata().unwrap();
            if m.is_dir() {
                stack.push(e.path());
            } else {
                apparent += m.len();
                allocated += m.blocks() * 512;
                let key = e
                    .path()
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                objects.push((key, m.len()));
            }
        }
    }
    (apparent, allocated, objects)
}

/// Allocated bytes if the plane chunks were packed `s x s` per shard
/// object (Zarr sharding: each inner chunk as now, plus a 16-byte index
/// entry per chunk and a 4-byte crc32c of the index), in 4 KiB blocks.
fn sharded_allocated(objects: &[(String, u64)], s: u64) -> (u64, usize) {
    use std::collections::HashMap;
    let mut shards: HashMap<(String, u64, u64), u64> = HashMap::new();
    let mut other = 0;
    for (key, len) in objects {
        let parts: Vec<&str> = key.split('/').collect();
        if parts.len() == 4 && (parts[0] == "heights" || parts[0] == "metas") && parts[1] == "c" {
            let (y, x): (u64, u64) = (parts[2].parse().unwrap(), parts[3].parse().unwrap());
            *shards.entry((parts[0].into(), y / s, x / s)).or_default() += len + 16;
        } else {
            other += len.div_ceil(4096) * 4096;
        }
    }
    let n = shards.len();
    (
        other
            + shards
                .values()
                .map(|b| (b + 4).div_ceil(4096) * 4096)
                .sum::<u64>(),
        n,
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut params = GenerateParams::default();
    if let Some(size) = args.first() {
        let (w, h) = strata_level::generate::parse_size(size).unwrap();
        (params.width, params.height) = (w, h);
    }
    if let Some(seed) = args.get(1) {
        params.seed = seed.parse().unwrap();
    }
    let t = Instant::now();
    let world = generate(&params).unwrap();
    let texels = f64::from(params.width) * f64::from(params.height);
    eprintln!(
        "generated {}x{} seed {} in {:.1} s",
        params.width,
        params.height,
        params.seed,
        t.elapsed().as_secs_f64()
    );
    let vmc = strata_level::vmc::encode_vmc(&world.level, Path::new("x.vmc")).unwrap();
    println!("vmc: {:.3} B/texel", vmc.len() as f64 / texels);
    let root = std::env::temp_dir().join(format!("strata-store-layouts-{}", std::process::id()));
    println!(
        "| chunk | gzip | objects | B/texel apparent | B/texel allocated | sharded 2048² alloc | write s | decode MB/s/core | random chunk ms (fresh open) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for chunk in [64u32, 128, 256, 512] {
        for gzip in [1u32, 6, 9] {
            let layout = Layout {
                chunk_height: chunk,
                chunk_width: chunk,
                gzip_level: gzip,
            };
            let dir = root.join(format!("c{chunk}-g{gzip}"));
            let t = Instant::now();
            let store = DirStore::create(&dir, &world, &layout).unwrap();
            let write_s = t.elapsed().as_secs_f64();
            let (apparent, allocated, objects) = sizes(&dir);
            let s = u64::from(2048 / chunk).max(1);
            let (sharded, _) = sharded_allocated(&objects, s);
            // Decode on one core: every chunk in order, this thread only.
            let (gy, gx) = store.store().grid();
            let t = Instant::now();
            let mut decoded = 0usize;
            for cy in 0..gy {
                for cx in 0..gx {
                    decoded += store.store().read_chunk(cy, cx).unwrap().bytes();
                }
            }
            let mbps = decoded as f64 / 1e6 / t.elapsed().as_secs_f64();
            drop(store);
            // A random chunk from a store opened afresh (metadata read and
            // checked, then one chunk of both planes read and decoded).
            let mut ms = Vec::new();
            for i in 0..9u64 {
                let t = Instant::now();
                let store = DirStore::open(&dir).unwrap();
                let (cy, cx) = ((i * 7919) % gy, (i * 104729) % gx);
                store.store().read_chunk(cy, cx).unwrap();
                ms.push(t.elapsed().as_secs_f64() * 1e3);
            }
            ms.sort_by(f64::total_cmp);
            println!(
                "| {chunk}² | {gzip} | {} | {:.3} | {:.3} | {:.3} | {write_s:.1} | {mbps:.0} | {:.2} |",
                objects.len(),
                apparent as f64 / texels,
                allocated as f64 / texels,
                sharded as f64 / texels,
                ms[ms.len() / 2]
            );
            let _ = std::fs::remove_dir_all(&dir);
        }
    }
    let _ = std::fs::remove_dir_all(&root);
}
