//! The error of the whole jobs ([`segment`](crate::segment()), [`library`](crate::library()),
//! [`run`](crate::run())).

use thiserror::Error;

use crate::library::LibraryError;
use crate::segment::SegmentError;

/// Why a stop-motion job failed. Stage errors are passed through unchanged (their sources
/// kept); [`Error::option`] names the option at fault so a front end can point at the flag,
/// keyword argument or file that supplied it.
#[derive(Debug, Error)]
pub enum Error {
    /// Segmentation or homogenization failed.
    #[error(transparent)]
    Segment(#[from] SegmentError),
    /// The library optimization or fabrication failed.
    #[error(transparent)]
    Library(#[from] LibraryError),
    /// A figure could not be drawn or encoded.
    #[error(transparent)]
    Render(#[from] render::RenderError),
    /// The animation data could not be assembled (e.g. parts with different frame counts).
    #[error(transparent)]
    Anim(#[from] anim::AnimError),
    /// An option is invalid; the message says what is expected.
    #[error("{option}: {reason}")]
    Option {
        /// The option's name in the options structs (`pieces`, `saliency`, `fixed`, …).
        option: &'static str,
        /// What is wrong and how to fix it.
        reason: String,
    },
}

impl Error {
    /// An [`Error::Option`].
    pub(crate) fn option_error(option: &'static str, reason: impl Into<String>) -> Error {
        Error::Option {
            option,
            reason: reason.into(),
        }
    }

    /// The option this error is about, when it is about one that names a separate input
    /// (`"saliency"`, `"fixed"`) or a size rule (`"pieces"`, `"max_error_mm"`), else `None`
    /// (the error is about the animation itself).
    pub fn option(&self) -> Option<&'static str> {
        match self {
            Error::Option { option, .. } => Some(option),
            Error::Library(LibraryError::BadSaliency { .. }) => Some("saliency"),
            Error::Library(LibraryError::BadFixedPiece { .. }) => Some("fixed"),
            Error::Library(LibraryError::PrintedBack { .. }) => Some("fixed"),
            _ => None,
        }
    }
}

/// Result alias of the jobs.
pub type Result<T, E = Error> = std::result::Result<T, E>;
