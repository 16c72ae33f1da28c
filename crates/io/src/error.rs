use std::fmt;
use std::path::{Path, PathBuf};

use anim::AnimError;
use thiserror::Error;

/// A file path for messages; empty until the caller that knows the path attaches it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FilePath(pub PathBuf);

impl fmt::Display for FilePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.as_os_str().is_empty() {
            f.write_str("<input>")
        } else {
            write!(f, "{}", self.0.display())
        }
    }
}

/// The one error type of toonkit-io. Every message is one line naming the file.
#[derive(Debug, Error)]
pub enum IoError {
    /// The file could not be read or written. Check the path and permissions.
    #[error("{path}: {}", describe_io(source))]
    Io {
        /// File.
        path: FilePath,
        /// Operating-system error.
        source: std::io::Error,
    },
    /// The bytes are not a valid file of the format. Re-export the file from its source
    /// application; the message says what is wrong.
    #[error("{path}: invalid {format}: {message}")]
    Malformed {
        /// File.
        path: FilePath,
        /// Format name (glTF, OBJ, PC2, …).
        format: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The file is valid but uses something toonkit cannot handle (yet), or the format cannot
    /// hold the data asked for. The message says which.
    #[error("{path}: {message}")]
    Unsupported {
        /// File.
        path: FilePath,
        /// What is not supported.
        message: String,
    },
    /// A format library failed to encode the data (USD binary, USDZ). The message says why;
    /// report it as a bug with the command that produced it.
    #[error("{path}: cannot write {format}: {source}")]
    Encode {
        /// File.
        path: FilePath,
        /// Format name.
        format: &'static str,
        /// The library's error.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// Several frames asked to be written to a format that holds one frame (`.obj`, `.stl`)
    /// without saying how: write the sequence ([`Layout::Sequence`](crate::Layout::Sequence),
    /// `--layout sequence`) or one frame ([`Layout::Frame`](crate::Layout::Frame), `--frame N`).
    #[error("{path}: {frames} frames do not fit in one .{extension}: use --layout sequence, or --frame N for one frame")]
    FramesDoNotFit {
        /// File.
        path: FilePath,
        /// Number of frames of the result.
        frames: usize,
        /// Extension of the single-frame format.
        extension: &'static str,
    },
    /// A frame was asked for that the result does not have.
    #[error("{path}: --frame {frame} is past the last frame ({last}): frames are numbered from 0")]
    NoSuchFrame {
        /// File.
        path: FilePath,
        /// The frame asked for (0-based).
        frame: usize,
        /// The last frame (0-based).
        last: usize,
    },
    /// The output is a file the job reads (the same file by device and inode: a symlink or
    /// another spelling of the path counts; a point cache's rest `.obj` too). Name another
    /// output file.
    #[error("{path}: is the input {} of this job (the same file): refusing to write over it; name another output file", .input.display())]
    WouldOverwriteInput {
        /// The output.
        path: FilePath,
        /// The input it is.
        input: PathBuf,
    },
    /// A size derived from the file or an option is over its budget
    /// ([`anim::budget`]): allocating it could exhaust memory. Lower the option the message
    /// names, or split the input.
    #[error("{path}: {source}")]
    OverBudget {
        /// File.
        path: FilePath,
        /// What is over which limit.
        source: anim::OverBudget,
    },
    /// The file parsed but its content is inconsistent (e.g. NaN positions, bad indices).
    #[error("{path}: {source}")]
    Anim {
        /// File.
        path: FilePath,
        /// The data-model error.
        source: AnimError,
    },
}

impl IoError {
    /// A format error without a path yet.
    pub fn malformed(format: &'static str, message: impl Into<String>) -> IoError {
        IoError::Malformed {
            path: FilePath::default(),
            format,
            message: message.into(),
        }
    }

    /// An unsupported-feature error without a path yet.
    pub fn unsupported(message: impl Into<String>) -> IoError {
        IoError::Unsupported {
            path: FilePath::default(),
            message: message.into(),
        }
    }

    /// An encoding error of a format library, without a path yet.
    pub fn encode(
        format: &'static str,
        source: impl Into<Box<dyn std::error::Error + Send + Sync + 'static>>,
    ) -> IoError {
        IoError::Encode {
            path: FilePath::default(),
            format,
            source: source.into(),
        }
    }

    /// An OS error on `path`.
    pub fn io(path: &Path, source: std::io::Error) -> IoError {
        IoError::Io {
            path: FilePath(path.to_path_buf()),
            source,
        }
    }

    /// Attaches `path` when none is set.
    pub fn at(mut self, p: &Path) -> IoError {
        let slot = match &mut self {
            IoError::Io { path, .. }
            | IoError::Malformed { path, .. }
            | IoError::Unsupported { path, .. }
            | IoError::Encode { path, .. }
            | IoError::FramesDoNotFit { path, .. }
            | IoError::NoSuchFrame { path, .. }
            | IoError::WouldOverwriteInput { path, .. }
            | IoError::OverBudget { path, .. }
            | IoError::Anim { path, .. } => path,
        };
        if slot.0.as_os_str().is_empty() {
            slot.0 = p.to_path_buf();
        }
        self
    }
}

/// An operating-system error in the user's terms, with how to fix it: "is a directory: name a
/// file", not "Is a directory (os error 21)".
pub fn describe_io(e: &std::io::Error) -> String {
    use std::io::ErrorKind as K;
    match e.kind() {
        K::NotFound => "no such file or directory (check the path)".into(),
        K::PermissionDenied => {
            "permission denied (check the file's and folder's permissions)".into()
        }
        K::IsADirectory => "is a directory: name a file".into(),
        K::NotADirectory => "a part of the path is a file, not a folder".into(),
        K::ReadOnlyFilesystem => "the file system is read-only: write somewhere else".into(),
        K::StorageFull => "no space left on the device: free some space and run again".into(),
        K::FileTooLarge => "the file is larger than this system allows".into(),
        K::QuotaExceeded => "disk quota exceeded: free some space and run again".into(),
        K::UnexpectedEof => "the file ends early (truncated?)".into(),
        K::InvalidData => "not valid UTF-8 text".into(),
        _ => {
            // The OS text without its "(os error N)" suffix, lower-cased first letter.
            let text = e.to_string();
            let text = match text.rfind(" (os error ") {
                Some(i) => text[..i].to_string(),
                None => text,
            };
            let mut c = text.chars();
            match c.next() {
                Some(f) => f.to_lowercase().chain(c).collect(),
                None => "input/output error".into(),
            }
        }
    }
}

impl From<anim::OverBudget> for IoError {
    fn from(source: anim::OverBudget) -> IoError {
        IoError::OverBudget {
            path: FilePath::default(),
            source,
        }
    }
}

impl From<AnimError> for IoError {
    fn from(source: AnimError) -> IoError {
        IoError::Anim {
            path: FilePath::default(),
            source,
        }
    }
}

/// Result alias for this crate.
pub type Result<T, E = IoError> = std::result::Result<T, E>;
