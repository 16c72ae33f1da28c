//! The one error type of a batch: one line, the manifest or file first.

use std::path::PathBuf;

use thiserror::Error;

/// What is wrong with a manifest or a shot.
#[derive(Debug, Error)]
pub enum BatchError {
    /// The manifest cannot be read.
    #[error("{}: cannot read the manifest: {}", path.display(), tkio::describe_io(source))]
    Read {
        /// The manifest.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The manifest is not valid TOML, has unknown keys, or breaks a rule (names, outputs,
    /// tools); the message says which.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The manifest.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A shot's input or style file cannot be read (for its hash).
    #[error("{}: cannot read: {}", path.display(), tkio::describe_io(source))]
    Input {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The worker threads of a batch cannot start.
    #[error("cannot start the worker threads: {0}")]
    Threads(String),
    /// A stamp or template cannot be written, or a path cannot be made absolute.
    #[error(transparent)]
    Write(#[from] tkio::IoError),
}

impl BatchError {
    pub(crate) fn invalid(path: &std::path::Path, message: impl Into<String>) -> BatchError {
        BatchError::Invalid {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}
