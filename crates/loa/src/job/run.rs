//! The job itself: character → line → motion → the character scene holding the motion.

use std::path::Path;
use std::time::Instant;

use anim::{Scene, Skeleton};
use glam::DVec2;

use super::{SceneJobError, SceneOptions, SceneReport};
use crate::animate::{ActionCamera, Character, Motion, ScreenMap};
use crate::{Keystrokes, Line};

/// The outcome of [`animate_scene`] / [`animate_line`].
#[derive(Debug, Clone)]
pub struct SceneMotion {
    /// The dynamic line the character follows.
    pub line: Line,
    /// The joint motion.
    pub motion: Motion,
    /// The character's scene with its clips replaced by the motion's clip
    /// [`CLIP_NAME`](crate::animate::CLIP_NAME) (what a `.glb` output holds).
    pub scene: Scene,
    /// The character's skeleton (what a `.bvh` output holds).
    pub skeleton: Skeleton,
    /// Joint names, in the order of the motion's joint axis.
    pub joint_names: Vec<String>,
    /// The scene camera drawn through, when the options named one (previews use it).
    pub camera: Option<anim::Camera>,
    /// Measurements.
    pub report: SceneReport,
}

/// Reads a character file (a skinned glTF/GLB or a BVH file) through `tkio`, point caches
/// given `fps`.
///
/// # Errors
/// [`SceneJobError::Read`] (the file), [`SceneJobError::NotACharacter`] (no scene in it).
pub fn open_character(path: &Path, fps: f64) -> Result<Scene, SceneJobError> {
    let load = tkio::LoadOptions {
        fps: fps as f32,
        ..Default::default()
    };
    match tkio::load(path, &load).map_err(SceneJobError::Read)? {
        tkio::Loaded::Scene(scene) => Ok(*scene),
        _ => Err(SceneJobError::NotACharacter(path.to_path_buf())),
    }
}

/// The whole `loa animate` job on a character `scene`: `keys` become the line
/// ([`line()`](crate::line()) with `options.line`), which the character follows
/// ([`animate_line`]).
///
/// # Errors
/// [`SceneJobError::Line`] for the keystrokes, else as [`animate_line`].
pub fn animate_scene(
    scene: &Scene,
    keys: &Keystrokes,
    options: &SceneOptions,
) -> Result<SceneMotion, SceneJobError> {
    let line = crate::line(keys, &options.line).map_err(SceneJobError::Line)?;
    animate_line(scene, line, options)
}

/// The character of `scene` (in `options.pose`) follows `line` (LoA Section 4), through the
/// camera `options.camera` names if any; `options.line` is not used (the line is made).
///
/// # Errors
/// [`SceneJobError::Character`] (skeleton, pose), [`SceneJobError::Camera`] (unknown
/// camera), [`SceneJobError::Animate`] (the solve).
pub fn animate_line(
    scene: &Scene,
    line: Line,
    options: &SceneOptions,
) -> Result<SceneMotion, SceneJobError> {
    let character = Character::from_scene(scene, &options.pose, line.animation.fps)
        .map_err(SceneJobError::Character)?;
    animate_character(scene, &character, line, options)
}

/// [`animate_line`] for a `character` already made from `scene` (in `options.pose`, at the
/// line's rate): a front end that keeps the character between strokes (the studio) skips
/// [`Character::from_scene`], and gets the same motion.
///
/// # Errors
/// As [`animate_line`], without [`SceneJobError::Character`].
pub fn animate_character(
    scene: &Scene,
    character: &Character,
    line: Line,
    options: &SceneOptions,
) -> Result<SceneMotion, SceneJobError> {
    let fps = line.animation.fps;
    let mut motion_options = options.motion.clone();
    let camera =
        match &options.camera {
            Some(name) => {
                let (action, camera) = ActionCamera::from_scene(scene, name, character, fps)
                    .map_err(|source| SceneJobError::Camera {
                        name: name.clone(),
                        source,
                    })?;
                motion_options.camera = Some(action);
                Some(camera)
            }
            None => None,
        };
    if let Some([width, height]) = options.canvas {
        let (min, max) = character.bounds();
        let cam = *motion_options
            .camera
            .get_or_insert_with(|| ActionCamera::front_fitted(min, max));
        motion_options.screen = Some(ScreenMap {
            anchor: DVec2::new(width / 2.0, height / 2.0),
            origin: DVec2::ZERO,
            scale: 2.0 * cam.half_height / height,
        });
    }
    let start = Instant::now();
    let motion =
        crate::animate(character, &line, &motion_options).map_err(SceneJobError::Animate)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let report = SceneReport::new(character, &line, &motion, solve_seconds);
    let (skeleton, _) = scene.skeleton();
    Ok(SceneMotion {
        scene: motion.to_scene(scene),
        skeleton,
        joint_names: character.joint_names().to_vec(),
        camera,
        report,
        line,
        motion,
    })
}
