//! The scene-level job's outputs, written through `tkio` (atomically, never over a file the
//! job read): the motion as `.glb` or `.bvh`, a preview as `.png` or `.gif`; and the
//! extension checks of every loa output (`loa line`'s too), made before any work.

use std::path::Path;

use tkio::Format;

use super::{SceneJobError, SceneMotion};

/// The formats a motion is written as: the character with the clip (`.glb`) or the skeleton
/// and motion (`.bvh`), in the order messages list them.
pub const MOTION_FORMATS: [Format; 2] = [Format::Glb, Format::Bvh];

/// The outputs of a line (`loa line`) besides the images ([`render::OutputFormat`]): its
/// frames as JSON, its onion skin as SVG.
pub const LINE_TEXT_EXTENSIONS: [&str; 2] = ["json", "svg"];

/// The motion format of `path` (by extension) among `formats`, checked before any work;
/// `what` names the output in the message (`output`, `--bvh`).
///
/// # Errors
/// [`SceneJobError::Extension`] for any other extension.
pub fn check_motion_path(
    path: &Path,
    what: &'static str,
    formats: &[Format],
) -> Result<Format, SceneJobError> {
    Format::from_extension(path)
        .filter(|f| formats.contains(f))
        .ok_or_else(|| SceneJobError::Extension {
            path: path.to_path_buf(),
            what,
            expected: Format::list(formats),
        })
}

/// Whether the preview at `path` is a GIF (else a PNG, the first frame), checked before any
/// work.
///
/// # Errors
/// [`SceneJobError::Extension`] for another extension.
pub fn check_preview_path(path: &Path) -> Result<bool, SceneJobError> {
    match render::OutputFormat::from_extension(path) {
        Some(format) => Ok(format == render::OutputFormat::Gif),
        None => Err(SceneJobError::Extension {
            path: path.to_path_buf(),
            what: "render",
            expected: render::OutputFormat::list(),
        }),
    }
}

/// The extension of a line output `path` (`json`, `svg`, `png` or `gif`, lower case),
/// checked before any work.
///
/// # Errors
/// [`SceneJobError::Extension`] for another extension.
pub fn check_line_path(path: &Path) -> Result<String, SceneJobError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let known = LINE_TEXT_EXTENSIONS
        .iter()
        .chain(&render::OutputFormat::EXTENSIONS);
    if known.clone().any(|e| *e == ext) {
        return Ok(ext);
    }
    let dotted: Vec<String> = known.map(|e| format!(".{e}")).collect();
    let expected = match dotted.split_last() {
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    };
    Err(SceneJobError::Extension {
        path: path.to_path_buf(),
        what: "output",
        expected,
    })
}

impl SceneMotion {
    /// The skeleton and motion as BVH text.
    ///
    /// # Errors
    /// [`SceneJobError::Animate`] when the motion does not fit the skeleton,
    /// [`SceneJobError::Write`] when BVH cannot hold it.
    pub fn bvh(&self) -> Result<String, SceneJobError> {
        let skeletal = self
            .motion
            .skeletal_animation(&self.skeleton)
            .map_err(SceneJobError::Animate)?;
        tkio::bvh::write(&self.skeleton, &skeletal).map_err(SceneJobError::Write)
    }

    /// The character with the motion's clip as binary glTF.
    ///
    /// # Errors
    /// [`SceneJobError::Write`] when glTF cannot hold the scene.
    pub fn glb(&self) -> Result<Vec<u8>, SceneJobError> {
        tkio::gltf::write_glb(&self.scene).map_err(SceneJobError::Write)
    }

    /// Writes the motion as `.glb` (the character with the clip) or `.bvh`, by `path`'s
    /// extension, atomically.
    ///
    /// # Errors
    /// [`SceneJobError::Extension`] for another extension, else as [`SceneMotion::bvh`],
    /// [`SceneMotion::glb`] and the write.
    pub fn save(&self, path: &Path) -> Result<(), SceneJobError> {
        let saved = match check_motion_path(path, "output", &MOTION_FORMATS)? {
            Format::Bvh => tkio::save(path, &tkio::Output::Text(&self.bvh()?)),
            _ => tkio::save(path, &tkio::Output::Bytes(&self.glb()?)),
        };
        saved.map(|_| ()).map_err(SceneJobError::Write)
    }

    /// Writes a preview of the character with the line, in a view that follows the character
    /// (or through the options' scene camera): `.gif` (every frame) or `.png` (the first).
    ///
    /// # Errors
    /// [`SceneJobError::Extension`], [`SceneJobError::Preview`], or the write.
    pub fn save_preview(&self, path: &Path) -> Result<(), SceneJobError> {
        let gif = check_preview_path(path)?;
        let bytes = crate::preview::motion_preview(
            &self.scene,
            &self.motion,
            &self.skeleton,
            self.camera.as_ref(),
            gif,
        )
        .map_err(|source| SceneJobError::Preview {
            path: path.to_path_buf(),
            source,
        })?;
        tkio::save(path, &tkio::Output::Bytes(&bytes))
            .map(|_| ())
            .map_err(SceneJobError::Write)
    }
}
