//! What can go wrong reading or writing a store. Every error about stored
//! data names the array, and the chunk when one is at fault.

use std::path::PathBuf;

/// An error reading, writing or editing a store.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// A file or directory could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The directory has no `zarr.json`: not a Zarr store (nor, without a
    /// `world.ini`, a Vangers world).
    #[error("{}: no zarr.json (not a Strata store) and no world.ini (not a Vangers world)", path.display())]
    NotAStore {
        /// The directory.
        path: PathBuf,
    },
    /// A Zarr group, but not a Strata world (no `strata` attribute).
    #[error("{what}: {msg}")]
    NotAWorld {
        /// The store (a path or a name).
        what: String,
        /// What is missing or wrong.
        msg: String,
    },
    /// Written by a newer Strata than this one.
    #[error(
        "{what}: a Strata store of format version {found}; this build reads versions up to {supported} (update Strata)"
    )]
    NewerVersion {
        /// The store.
        what: String,
        /// The store's `format_version`.
        found: u32,
        /// The newest version this build reads.
        supported: u32,
    },
    /// An array is missing, or has the wrong shape, type or chunking.
    #[error("array `{array}`: {msg}")]
    Array {
        /// The array's name in the group (`heights`, `metas`, `summary`, …).
        array: String,
        /// What is wrong with it.
        msg: String,
    },
    /// A chunk could not be read or decoded (truncated, bad checksum, missing).
    #[error("array `{array}`, chunk {chunk:?}: {msg}")]
    Chunk {
        /// The array's name.
        array: String,
        /// The chunk's grid indices (row, column[, …]).
        chunk: Vec<u64>,
        /// What is wrong with it.
        msg: String,
    },
    /// An edit or a conversion was asked something the store cannot do.
    #[error("{0}")]
    Invalid(String),
    /// A world file inside the store's attributes did not parse.
    #[error(transparent)]
    Level(#[from] strata_level::LevelError),
}

impl StoreError {
    #[cfg_attr(not(feature = "fs"), allow(dead_code))]
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        StoreError::Io {
            path: path.into(),
            source,
        }
    }

    pub(crate) fn array(array: &str, msg: impl std::fmt::Display) -> Self {
        StoreError::Array {
            array: array.into(),
            msg: msg.to_string(),
        }
    }

    pub(crate) fn chunk(array: &str, chunk: &[u64], msg: impl std::fmt::Display) -> Self {
        StoreError::Chunk {
            array: array.into(),
            chunk: chunk.to_vec(),
            msg: msg.to_string(),
        }
    }
}
