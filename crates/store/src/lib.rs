//! A Strata world as a chunked Zarr v3 store (DESIGN §10).
//!
//! MEASUREMENTS_PLACEHOLDER

#![warn(missing_docs)]

pub mod cache;
#[cfg(feature = "fs")]
#[doc(hidden)]
pub mod crashtest;
pub mod error;
pub mod format;
#[cfg(feature = "fs")]
pub mod fs;
pub mod store;

pub use cache::{CacheStats, ChunkCache};
pub use error::StoreError;
pub use format::{ChunkSummary, FORMAT_VERSION, Layout, WorldAttrs};
#[cfg(feature = "fs")]
pub use fs::{DirKind, DirStore, dir_kind, load_any};
pub use store::{Chunk, Storage, WorldStore};
