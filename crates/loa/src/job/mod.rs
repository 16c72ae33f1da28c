//! The scene-level job of `loa animate`: a character scene and keystrokes (or a line already
//! made from them) in, the motion, the character animated by it and a report out, written
//! through `tkio` — one call for the CLI, the Python module, the studio and Blender.
//!
//! * [`open_character`]: a skinned glTF/GLB or BVH file as a character scene (through
//!   `tkio::load`, refusing files without a skeleton).
//! * [`animate_scene`] (keystrokes → [`line()`](crate::line()) → motion) and
//!   [`animate_line`] (a line → motion), with [`SceneOptions`].
//! * [`SceneMotion`]: the line, the [`Motion`](crate::animate::Motion), the character scene
//!   holding the clip [`CLIP_NAME`](crate::animate::CLIP_NAME), its [`SceneReport`];
//!   [`SceneMotion::save`] writes `.glb` or `.bvh` ([`MOTION_FORMATS`]) and
//!   [`SceneMotion::save_preview`] a `.png` or `.gif` (`render::OutputFormat`).

mod error;
mod options;
mod output;
mod report;
mod run;

pub use error::SceneJobError;
pub use options::SceneOptions;
pub use output::{
    check_line_path, check_motion_path, check_preview_path, LINE_TEXT_EXTENSIONS, MOTION_FORMATS,
};
pub use report::{SceneReport, WorstPercent};
pub use run::{animate_character, animate_line, animate_scene, open_character, SceneMotion};
