//! A Strata world as a chunked Zarr v3 store (DESIGN §10), with the
//! [`zarrs`] crate: a directory (or any Zarr storage) that Python's `zarr`,
//! xarray and Dask open without Strata, whose chunks a static web server or
//! an object store can serve.
//!
//! # Layout
//!
//! ```text
//! DIR/zarr.json           the root group; attribute `strata` (WorldAttrs):
//!                         format "strata-world", format_version, width, height,
//!                         chunk [rows, cols], name, world_ini (text), palette
//!                         (the .pal's 768 bytes), water, views (views.txt text),
//!                         edit (edit.txt text), decoding (how to decode, in words)
//! DIR/heights/            uint8 [height, width], chunks [256, 256]
//! DIR/metas/              uint8 [height, width], chunks [256, 256]
//! DIR/summary/            uint32 [height/256, width/256, 8], chunks [64, 64, 8]:
//!                         low_min, low_max, top_min, top_max, slab_bottom_min,
//!                         slab_bottom_max, dual_texels, pair_disagreements
//! DIR/vangers_vpr/        uint8 [bytes]: the .vpr (when the world has water levels)
//! DIR/.strata-journal/    only while an edit batch is being saved (see [`fs`])
//! ```
//!
//! Every array's codecs are `bytes` -> `gzip` (level 6) -> `crc32c`, so a
//! corrupt or truncated chunk is an error naming the array and chunk
//! ([`StoreError::Chunk`]); every chunk is stored (also one of all zeros),
//! so a missing chunk object is an error too, never silent zeros.
//!
//! **Why the Vangers planes rather than decoded floor/slab/terrain arrays:**
//! the two planes round-trip byte for byte (the meta byte's shadow bits and
//! half-flagged pairs included, which decoded arrays would lose or need
//! extra arrays for) at 2 bytes per texel decoded, where decoded `low`,
//! `mid`, `high`, two terrain types and a dual flag are 6; the decoding
//! (DESIGN §1) is a few lines, written into the `strata.decoding`
//! attribute for Python users. The cave-ceiling rule is a load-time choice
//! ([`strata_level::MidRule`]), as for a Vangers world, and not stored.
//!
//! # Chunk shape, codec, sharding: measured
//!
//! The default world (2048x16384, seed 1997; its `.vmc` is 0.563 B/texel),
//! `examples/store_layouts.rs`, this 2-core machine shared with three other
//! builds (load average 4-6), **debug profile** (this crate at opt-level 1,
//! dependencies at 2 as the workspace sets). "Allocated" is the file
//! system's 4 KiB blocks; "sharded" is what the same inner chunks would take
//! packed in 2048x2048 `sharding_indexed` shards (16 B index per chunk,
//! computed from the measured chunk sizes). Decode is one thread reading
//! every chunk of both planes in order (MB of decoded samples per second);
//! the random read opens the store afresh (metadata read and checked) and
//! reads one chunk of both planes, files in the page cache (median of 9).
//!
//! | chunk | gzip | objects | B/texel apparent | allocated | sharded | write s | decode MB/s/core | random chunk ms |
//! |---|---|---|---|---|---|---|---|---|
//! | 64² | 1 | 16394 | 0.567 | 2.004 | 0.577 | 13.4 | 31 | 0.18 |
//! | 64² | 6 | 16394 | 0.443 | 2.003 | 0.453 | 44.9 | 39 | 0.18 |
//! | 64² | 9 | 16394 | 0.441 | 2.003 | 0.451 | 26.6 | 26 | 0.17 |
//! | 128² | 1 | 4104 | 0.583 | 0.806 | 0.587 | 7.3 | 66 | 0.28 |
//! | 128² | 6 | 4104 | 0.433 | 0.750 | 0.437 | 16.6 | 59 | 0.22 |
//! | 128² | 9 | 4104 | 0.430 | 0.750 | 0.434 | 23.5 | 63 | 0.24 |
//! | 256² | 1 | 1031 | 0.616 | 0.678 | 0.618 | 4.3 | 66 | 0.64 |
//! | **256²** | **6** | 1031 | **0.444** | **0.507** | 0.446 | 8.9 | **118** | **0.43** |
//! | 256² | 9 | 1031 | 0.438 | 0.500 | 0.440 | 15.3 | 100 | 0.42 |
//! | 512² | 1 | 263 | 0.632 | 0.648 | 0.633 | 1.7 | 86 | 6.12 |
//! | 512² | 6 | 263 | 0.451 | 0.468 | 0.453 | 9.9 | 87 | 1.24 |
//! | 512² | 9 | 263 | 0.442 | 0.458 | 0.444 | 20.1 | 130 | 1.36 |
//!
//! The choice, [`Layout::default`]: **256x256 chunks, gzip 6, no sharding**:
//! 0.444 B/texel of chunk bytes (0.507 allocated) against the target 1.0
//! and the `.vmc`'s 0.563 — gzip over 256-texel rows finds the terrain's
//! repetition better than the `.vmc`'s per-row Huffman code; what is left
//! above the apparent size is block rounding of the ~30 KB objects, the
//! metadata and the summary. Smaller chunks waste blocks (64²: 2.0
//! B/texel allocated) and decode slower per byte; 512² reads 4x the bytes
//! for one random chunk; gzip 9 saves 1 % for twice the write time.
//! Sharding would save the block rounding (0.507 -> 0.446) but makes an
//! edit rewrite a whole 2048² shard object; at 256² a 65536² world is
//! 131,072 objects, which file systems and object stores hold well, and
//! 65,536 summaries (DESIGN §10). The numbers are noisy (shared cores):
//! treat decode speed as ±30 %.
//! (Measured with flate2's miniz_oxide backend; stores are now compressed
//! with zlib-rs, below: the same gzip format, 0.7 % larger, written in
//! half the CPU time.)
//!
//! # Other measurements (same machine, debug profile)
//!
//! - **65536x65536 store, written chunk by chunk** (`examples/store_big.rs`:
//!   a synthetic pattern, not the world generator, through
//!   [`DirStore::create_with`], both cores): 65,536 chunks in 235.5 s, peak
//!   RSS 33 MiB; 401 MB apparent, 771 MB allocated (the pattern compresses
//!   better than terrain).
//! - **`strata info` on it**: 0.044 s wall for the whole command (open 4.0
//!   ms, the 65,536 summaries 13.1 ms; no chunk read).
//! - **Fault injection** (`examples/store_crash.rs`, 200 SIGKILLs at random
//!   moments of a child saving edit batches into a 256² store of 64²
//!   chunks): every reopen was the state before or after the batch in
//!   flight (94 before, 106 after; 139 batches committed; 26.4 s). The test
//!   (`tests/crash.rs`) adds aborts at exact commit steps.
//! - **wasm32**: `cargo check --target wasm32-unknown-unknown -p
//!   strata-store --no-default-features` builds (zarrs with gzip, crc32c,
//!   sharding; no filesystem store, one thread: zarrs' storage is not
//!   Send/Sync there).
//!
//! # Generating a world straight into a store
//!
//! `strata generate --to store --size WxH --out DIR` (sides powers of two
//! from 256 to 65536) writes each chunk where it is generated: the
//! generator's [`strata_level::generate::Chunked`] makes any rectangle of a
//! world without the rest of it, [`DirStore::create_with`] calls it for
//! every chunk on every core (rayon), so memory holds only the chunks in
//! flight. Its bytes are the in-memory generator's wherever both apply
//! (`crates/level/tests/chunked.rs`; `crates/strata/tests/generate_store.rs`
//! converts a generated store back and compares the `.vmc`). The gzip
//! codec runs on flate2's zlib-rs backend (pure Rust, wasm32 too): about
//! half miniz_oxide's CPU time for 0.7 % more bytes.
//!
//! Release build, this 2-core machine (AMD EPYC), `/usr/bin/time -v`, seed
//! 1997, stores under `/tmp` (bench/store-gen has the runs and the load):
//!
//! | size | chunks | wall | CPU (user + sys) | CPU share | peak RSS | apparent B/texel | allocated B/texel |
//! |---|---|---|---|---|---|---|---|
//! | 16384² | 4,096 | 25.2 s | 46.9 s | 186 % | 20 MiB | 0.452 | 0.514 |
//! | 32768² | 16,384 | 154.0 s | 193.1 s | 125 % | 24 MiB | 0.451 | 0.514 |
//! | 65536² | 65,536 | 843.0 s | 784.5 s | 93 % | 40 MiB | 0.451 | 0.514 |
//!
//! About 5.5 million texels per CPU-second (three quarters generating,
//! the rest gzip and files); on two otherwise idle cores a 65536² world
//! takes about 6.5 minutes (CPU time / 2), in 40 MiB or less whatever
//! the size. The runs shared the machine with other helpers' builds (load
//! average 1.2 to 6.9): "CPU share" is what the run got of the two cores;
//! the 65536² run got less than one, hence its 14 minutes.
//!
//! A big world looks like a big world, not the default one tiled:
//! `examples/store_windows.rs` samples 2048x2048 windows of a store; in the
//! 65536² world all 24 sampled windows differ, their dual fraction is the
//! default world's +5.7 % on average (−6 % … +20 % per window; the
//! default world's own windows: −5 % … +6 %) and their floor roughness
//! +1.8 % (−2 % … +8 %). The dual fraction sits higher because most of a
//! big world's windows have no river valley, which crosses every window
//! of the 2048-wide default world. The twelve default views and the edit
//! site are placed by the generator along the whole world (the landmarks
//! spread over its length, alternating sides of the river).
//!
//! # Reading in bounded memory (issue 32)
//!
//! [`ChunkCache`] is a [`strata_level::ColumnSource`]: the CPU reference
//! (`strata_reference::Tracer::over`), the region fit
//! (`strata_mesh::region`) and the export read a store through it, chunk by
//! chunk within its byte budget (`--store-cache MIB`, default 512), and
//! give exactly what they give on the same world loaded whole. The tracer
//! takes its coarsest pyramid level from the summaries' `top_max` and builds
//! each chunk's finer levels when a ray first enters it, kept with the chunk
//! in the cache ([`CachedChunk`], counted in the budget). [`read`] streams
//! the map's content hash (equal to `Level::content_hash`) and gives the
//! world without its map. Measured (`bench/store-read/`, release build, this
//! 2-core machine shared with other builds, load average 4-6): a 65536²
//! store tiled from the default world (`examples/store_tile.rs`; 1.8 GB
//! apparent, 2.1 GB allocated, written in 776 s at 54 % of a core, peak
//! RSS 104 MiB):
//!
//! - **CPU reference, 320x200, the default world's 12 views**: traced over
//!   the store 0.51-0.80 s in all (2-4 chunks per view, 17-22 misses, hit
//!   rate 99.3 % with one cache lookup per chunk change), against 0.33-0.66 s
//!   in memory on the default world (2048x16384): 1.2-1.8x, within the 2x
//!   target; whole runs 0.52-0.84 s against 0.83-1.51 s (the in-memory run
//!   loads the world, 0.28-0.44 s, and builds its whole-map pyramid,
//!   0.22-0.48 s). **Peak RSS 9 MiB** over the store (chunk cache peak
//!   1.9-2.3 MiB) against 105 MiB in memory. Views spread over the store,
//!   page cache dropped first: 0.82 s, still 9 MiB.
//! - **Cold random chunk read** (page cache dropped with `echo 3 >
//!   /proc/sys/vm/drop_caches`, 50 random chunks, both planes checked and
//!   decoded, `examples/store_cold.rs`): median 1.84 ms, p90 3.98 ms; the
//!   same chunks again (warm) median 0.39 ms.
//! - `strata fit --region` of 1024² texels (81 fit chunks, 36 store chunks
//!   read) 1.37 s, 31 MiB RSS; `strata export --region` of 1000² across the
//!   map's corner 1.31 s, 56 MiB RSS (debug build).
//!
//! Whole-world commands (`view`, `render`, `compare`, `collide`, ...) load a
//! store whole and refuse one above half the available memory (at most 4
//! GiB), naming its size and the commands that read it in bounded memory.
//!
//! # Not done yet (issue 32)
//!
//! The paged renderer reads stores through this cache
//! (`strata_render::paged::StorePages`; issue 33, `bench/paged/`). Not yet:
//! a store above 2^28 texels is not content-hashed (that would read all of
//! it), so its references are computed rather than cached; a whole fit of a
//! 65536² store runs in bounded memory but takes the time of 262,144 chunk
//! fits.

#![warn(missing_docs)]

// The `zarr` feature (default; `fs` needs it): the store through zarrs.
// Without it (a browser page streaming a store: `http`) zarrs is not built
// at all, which keeps its codec registry out of the .wasm.
#[cfg(feature = "zarr")]
pub mod cache;
#[cfg(feature = "fs")]
#[doc(hidden)]
pub mod crashtest;
pub mod error;
pub mod format;
#[cfg(feature = "fs")]
pub mod fs;
pub mod http;
#[cfg(feature = "zarr")]
pub mod lod;
#[cfg(feature = "zarr")]
pub mod read;
#[cfg(feature = "zarr")]
pub mod store;

#[cfg(feature = "zarr")]
pub use cache::{CacheStats, CachedChunk, ChunkCache};
pub use error::StoreError;
pub use format::{ChunkSummary, FORMAT_VERSION, Layout, WorldAttrs};
#[cfg(feature = "fs")]
pub use fs::{DirKind, DirStore, dir_kind, load_any};
#[cfg(feature = "zarr")]
pub use store::{Chunk, Storage, WorldStore};
