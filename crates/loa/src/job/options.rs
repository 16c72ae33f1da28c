//! Options of the scene-level loa job.

use serde::{Deserialize, Serialize};

use crate::animate::{AnimateOptions, InitialPose};
use crate::LineOptions;

/// Everything [`animate_scene`](super::animate_scene) needs besides the character scene and
/// the keystrokes. Serde-ready: every field is optional in a TOML/JSON file.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SceneOptions {
    /// How the keystrokes become a line (LoA Section 3); its `physics.fps` is the motion's.
    pub line: LineOptions,
    /// Bone sets, contacts, twists, weights of the solve (LoA Section 4).
    pub motion: AnimateOptions,
    /// The pose the character starts from.
    pub pose: InitialPose,
    /// A camera node of the character's file to draw through (perspective allowed); it
    /// replaces `motion.camera`. Default: `motion.camera`, else an orthographic front view
    /// fitted to the character.
    pub camera: Option<String>,
    /// The keystrokes were drawn on a canvas of this size (pixels, y down) showing the
    /// camera's view: the screen map then puts the canvas on the camera's image plane (its
    /// centre on the view's centre, its height the view's height) instead of fitting the
    /// keystrokes to the bone sets, so the character follows the line where it was drawn.
    pub canvas: Option<[f64; 2]>,
}
