//! `strata info` on a Strata store: from its attributes and per-chunk
//! summaries alone, never a chunk, so a 65536² store answers at once.

use anyhow::Context;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;
use strata_store::{ChunkSummary, DirStore};

#[derive(Serialize)]
struct StoreInfo {
    world: String,
    store: String,
    format_version: u32,
    width: u32,
    height: u32,
    chunk: [u32; 2],
    chunks: u64,
    /// Levels of detail written (`strata_store::lod`), of those it can have.
    lod_levels: u32,
    lod_possible: u32,
    dual_percent: f64,
    height_min: u8,
    height_max: u8,
    pair_disagreements: u64,
    open_ms: f64,
    summaries_ms: f64,
}

/// Whether `dir` is a store (`zarr.json`), which `info` answers from summaries.
pub fn is_store(dir: &Path) -> bool {
    dir.join(strata_store::fs::ZARR_JSON).is_file()
}

pub fn run(dir: &Path, json: bool) -> anyhow::Result<()> {
    let t = Instant::now();
    let store =
        DirStore::open(dir).with_context(|| format!("opening the store {}", dir.display()))?;
    let open_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let summaries: Vec<ChunkSummary> = store.store().summaries()?;
    let summaries_ms = t.elapsed().as_secs_f64() * 1e3;
    let s = store.store();
    let a = s.attrs();
    let texels = f64::from(a.width) * f64::from(a.height);
    let dual: u64 = summaries.iter().map(|c| u64::from(c.dual_texels)).sum();
    let info = StoreInfo {
        world: a.name.clone(),
        store: dir.display().to_string(),
        format_version: a.format_version,
        width: a.width,
        height: a.height,
        chunk: a.chunk,
        chunks: summaries.len() as u64,
        lod_levels: store.store().lod_levels(),
        lod_possible: store.store().possible_lod_levels(),
        dual_percent: 100.0 * dual as f64 / texels,
        height_min: summaries.iter().map(|c| c.low_min).min().unwrap_or(0),
        height_max: summaries.iter().map(|c| c.top_max).max().unwrap_or(0),
        pair_disagreements: summaries
            .iter()
            .map(|c| u64::from(c.pair_disagreements))
            .sum(),
        open_ms,
        summaries_ms,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        println!(
            "world        {} (Strata store, format version {})",
            info.world, info.format_version
        );
        println!("store        {}", info.store);
        println!("size         {} x {}", info.width, info.height);
        println!(
            "chunks       {} of {} x {} (rows x columns)",
            info.chunks, info.chunk[0], info.chunk[1]
        );
        println!(
            "levels of detail {} of {}{}",
            info.lod_levels,
            info.lod_possible,
            if info.lod_levels < info.lod_possible {
                " (`strata convert --add-lod --level DIR` writes them)"
            } else {
                ""
            }
        );
        println!("dual         {:.2} % of texels", info.dual_percent);
        println!("heights      {} .. {}", info.height_min, info.height_max);
        println!("pair disagreements {}", info.pair_disagreements);
        println!(
            "read         open {:.1} ms, summaries {:.1} ms (no chunk read)",
            info.open_ms, info.summaries_ms
        );
    }
    Ok(())
}
