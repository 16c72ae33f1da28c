//! Errors of the scene-level loa job. Every variant's documentation says how to fix the
//! input.

use std::path::PathBuf;

use thiserror::Error;

use crate::animate::AnimateError;
use crate::preview::PreviewError;
use crate::LoaError;

/// Any error of the scene-level job ([`animate_scene`](super::animate_scene) and its
/// outputs).
#[derive(Debug, Error)]
pub enum SceneJobError {
    /// The character file cannot be read; the message says why (fix or replace the file).
    #[error(transparent)]
    Read(tkio::IoError),
    /// The file holds no scene (a point cache or a bare mesh). Use a skinned glTF/GLB or a
    /// BVH file.
    #[error("{}: not a character (use a skinned glTF/GLB or a BVH file)", .0.display())]
    NotACharacter(PathBuf),
    /// The keystrokes cannot become a line; the message names the keystroke or option to fix.
    #[error(transparent)]
    Line(LoaError),
    /// The character has no usable skeleton or pose; the message says which joint or clip.
    #[error(transparent)]
    Character(AnimateError),
    /// The camera named in the options is not in the character's file (the message lists the
    /// file's cameras); name one of them or leave the camera out.
    #[error("camera {name}: {source}")]
    Camera {
        /// The camera asked for.
        name: String,
        /// Why it cannot be used.
        source: AnimateError,
    },
    /// The solve was refused (unknown joints or presets, keys outside the line's frames, over
    /// the memory budget); the message names the option to fix.
    #[error(transparent)]
    Animate(AnimateError),
    /// An output's extension is not one the job writes: use one of those listed.
    #[error("{}: unknown {what} extension (use {expected})", .path.display())]
    Extension {
        /// The output path.
        path: PathBuf,
        /// Which output (`output`, `render`).
        what: &'static str,
        /// The extensions accepted, as a message lists them.
        expected: String,
    },
    /// The motion cannot be written; the message names the file and the reason.
    #[error(transparent)]
    Write(tkio::IoError),
    /// The preview cannot be drawn.
    #[error("{}: {source}", .path.display())]
    Preview {
        /// The preview's path.
        path: PathBuf,
        /// Why.
        source: PreviewError,
    },
}

impl SceneJobError {
    /// Whether the job was refused for its memory budget (the input is too large, not wrong).
    pub fn over_budget(&self) -> bool {
        matches!(
            self,
            SceneJobError::Line(LoaError::OverBudget(_))
                | SceneJobError::Animate(AnimateError::OverBudget(_))
        )
    }
}
