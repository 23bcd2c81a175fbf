use std::path::PathBuf;

/// Everything that can go wrong reading or writing an artifact. Each variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// The OS error is part of the message and deliberately not a `source`, so that
    /// `{:#}` chains print it once.
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{path}: not a {expected} file (magic bytes are {found:?})")]
    Magic {
        path: PathBuf,
        expected: &'static str,
        found: String,
    },
    #[error("{path}: {kind} format version {found}, this build reads version {supported}; re-run the stage that made it")]
    Version {
        path: PathBuf,
        kind: &'static str,
        found: u32,
        supported: u32,
    },
    #[error("{path}: truncated: {detail}")]
    Truncated { path: PathBuf, detail: String },
    #[error("{path}: corrupted: {detail}")]
    Corrupt { path: PathBuf, detail: String },
    #[error("{path}: cannot encode: {detail}")]
    Encode { path: PathBuf, detail: String },
}

impl FormatError {
    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        FormatError::Io {
            path: path.to_path_buf(),
            error: source,
        }
    }
}
