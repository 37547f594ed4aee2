//! Errors reading and writing world files. Every variant names the file.

use std::path::{Path, PathBuf};

/// Why a world file could not be read or written; [`LevelError::path`] names it.
#[derive(Debug, thiserror::Error)]
pub enum LevelError {
    /// The file could not be opened, read or written. The OS error is part
    /// of the message and not also a `source()`, so an error chain printed
    /// whole (`{:#}`) says it once.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The operating system's error.
        error: std::io::Error,
    },
    /// The file's contents are not a valid file of its format (wrong size,
    /// corrupt Huffman tree, a value out of range, ...).
    #[error("{path}: {msg}")]
    Format {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong with it.
        msg: String,
    },
    /// A `world.ini` key that is missing or does not parse.
    #[error("{path}: [{section}] {key}: {msg}")]
    Ini {
        /// The `world.ini` file.
        path: PathBuf,
        /// The `[section]` the key belongs to.
        section: String,
        /// The key.
        key: String,
        /// What is wrong with it.
        msg: String,
    },
}

impl LevelError {
    /// An [`Io`](LevelError::Io) error about `path`.
    pub fn io(path: &Path, error: std::io::Error) -> Self {
        LevelError::Io {
            path: path.to_path_buf(),
            error,
        }
    }

    /// A [`Format`](LevelError::Format) error about `path`.
    pub fn format(path: &Path, msg: impl Into<String>) -> Self {
        LevelError::Format {
            path: path.to_path_buf(),
            msg: msg.into(),
        }
    }

    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            LevelError::Io { path, .. }
            | LevelError::Format { path, .. }
            | LevelError::Ini { path, .. } => path,
        }
    }
}

/// Read a whole file, naming it on failure.
pub fn read_file(path: &Path) -> Result<Vec<u8>, LevelError> {
    std::fs::read(path).map_err(|e| LevelError::io(path, e))
}

/// Write a whole file, naming it on failure.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), LevelError> {
    std::fs::write(path, bytes).map_err(|e| LevelError::io(path, e))
}

/// The real Fostral files of the shared data folder, for tests:
/// `$STRATA_FOSTRAL_DIR`, else `../shared/data/fostral` beside the repository.
#[cfg(test)]
pub(crate) fn fostral_file(name: &str) -> PathBuf {
    let dir = std::env::var_os("STRATA_FOSTRAL_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let beside = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/fostral");
            if beside.exists() {
                beside
            } else {
                PathBuf::from("/work/shared/data/fostral")
            }
        });
    dir.join(name)
}
