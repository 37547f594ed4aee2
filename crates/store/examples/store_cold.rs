//! Time random chunk reads of a store: each chunk once (cold when the page
//! cache was dropped first, `echo 3 > /proc/sys/vm/drop_caches`), then the
//! same chunks again (warm). Each read is both planes of one chunk, checked
//! and decoded, through `WorldStore::read_chunk` (what the chunk cache does
//! on a miss). Prints the median and 90th percentile in milliseconds.
//!
//! `cargo run --release -p strata-store --example store_cold -- DIR [N] [SEED]`

use std::path::PathBuf;
use std::time::Instant;
use strata_store::DirStore;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(PathBuf::from) else {
        eprintln!("usage: store_cold DIR [N] [SEED]");
        std::process::exit(2);
    };
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(50);
    let mut seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(7);
    let t = Instant::now();
    let store = DirStore::open(&dir).expect("opening the store");
    let open_ms = t.elapsed().as_secs_f64() * 1e3;
    let (gy, gx) = store.store().grid();
    let mut cells = Vec::with_capacity(n);
    for _ in 0..n {
        // xorshift64*: cheap, deterministic.
        seed ^= seed >> 12;
        seed ^= seed << 25;
        seed ^= seed >> 27;
        let r = seed.wrapping_mul(0x2545_f491_4f6c_dd1d);
        cells.push(((r >> 32) % gy, (r & 0xffff_ffff) % gx));
    }
    let time = |label: &str| {
        let mut ms: Vec<f64> = cells
            .iter()
            .map(|&(cy, cx)| {
                let t = Instant::now();
                let c = store.store().read_chunk(cy, cx).expect("reading a chunk");
                std::hint::black_box(c);
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        ms.sort_by(f64::total_cmp);
        println!(
            "{label}: {n} random chunks of {gy}x{gx}: median {:.2} ms, p90 {:.2} ms, max {:.2} ms",
            ms[ms.len() / 2],
            ms[ms.len() * 9 / 10],
            ms[ms.len() - 1]
        );
    };
    println!("open {open_ms:.1} ms");
    time("first read");
    time("again");
}
