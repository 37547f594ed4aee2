//! Errors reading and writing world files.

#[derive(Debug, thiserror::Error)]
pub enum LevelError {
    #[error("{path}: {source}")]
    Io {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {msg}")]
    Format { path: std::path::PathBuf, msg: String },
}
