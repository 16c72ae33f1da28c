//! Opening an input as a sampled scene: load (frame rate, rest mesh, scene) → sample (clip,
//! frame rate, mesh selection) → merge into one point cache. [`OpenOptions`] holds what the
//! CLI's input flags (`--clip`, `--fps`, `--mesh`, `--rest`, `--scene`) ask for; the steps and
//! their checks are defined here once.

use std::path::{Path, PathBuf};

use anim::{MeshAnimation, SampleOptions, SampledScene, DEFAULT_FPS};

use crate::{IoError, LoadOptions, Loaded};

/// Why an input cannot be opened, in the user's terms.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// An option's value or the input is wrong; the text names it and the fix.
    #[error("{0}")]
    Invalid(String),
    /// The input (`at`) cannot be merged into one point cache: give objects of one frame
    /// count and rate (or pick some with `--mesh`).
    #[error("{at}")]
    Merge {
        /// The input file.
        at: String,
        /// What is wrong.
        #[source]
        source: anim::AnimError,
    },
    /// The input cannot be read.
    #[error(transparent)]
    Io(#[from] IoError),
}

type Result<T, E = OpenError> = std::result::Result<T, E>;

/// What to read of an input and how to sample it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OpenOptions {
    /// Clip to sample, by name or index (default: the first clip).
    pub clip: Option<String>,
    /// Frames per second to sample at (default: [`DEFAULT_FPS`]).
    pub fps: Option<f32>,
    /// Only these mesh objects, by name (default: all).
    pub meshes: Vec<String>,
    /// Rest mesh (.obj) of a PC2/MDD point cache (default: same name .obj, or rest.obj).
    pub rest: Option<PathBuf>,
    /// Scene of a multi-scene glTF file, by name or index (default: the file's default scene).
    pub scene: Option<String>,
}

impl OpenOptions {
    /// The sampling rate: [`OpenOptions::fps`], or [`DEFAULT_FPS`].
    pub fn fps(&self) -> f32 {
        self.fps.unwrap_or(DEFAULT_FPS)
    }
}

/// Checks a sampling rate: a positive, finite number.
///
/// # Errors
/// Zero, negative or not finite.
pub fn check_fps(fps: f32) -> Result<f32> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(OpenError::Invalid(format!(
            "--fps: must be a positive number of frames per second, got {fps}"
        )));
    }
    Ok(fps)
}

/// Reads a file of any supported format.
///
/// # Errors
/// A bad frame rate, or an unreadable file.
pub fn load(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    load_with_notes(path, options).map(|(loaded, _)| loaded)
}

/// Reads a file of any supported format, with the reader's notes (glTF extensions accepted,
/// scene read, FBX units and axes converted).
///
/// # Errors
/// A bad frame rate, or an unreadable file.
pub fn load_with_notes(path: &Path, options: &OpenOptions) -> Result<(Loaded, Vec<String>)> {
    let load = LoadOptions {
        fps: check_fps(options.fps())?,
        rest: options.rest.clone(),
        scene: options.scene.clone(),
    };
    Ok(crate::load_with_notes(path, &load)?)
}

/// Samples what was loaded into per-object point caches (and skeleton, cameras).
///
/// # Errors
/// An unknown clip or mesh, or a scene that cannot be sampled, naming the input.
pub fn sample(path: &Path, loaded: &Loaded, options: &OpenOptions) -> Result<SampledScene> {
    match loaded {
        Loaded::Scene(scene) => {
            let sample = sample_options(path, scene, options)?;
            anim::sample(scene, &sample).map_err(with_path(path))
        }
        Loaded::Cache(cache) => Ok(SampledScene::from_animation(cache.clone())),
        Loaded::Mesh(mesh) => Ok(SampledScene::from_animation(MeshAnimation::still(
            mesh.clone(),
        ))),
    }
}

/// An animation error as one line naming the input.
fn with_path(path: &Path) -> impl Fn(anim::AnimError) -> OpenError + '_ {
    move |e| OpenError::Invalid(format!("{}: {e}", path.display()))
}

/// What the clip, frame rate and mesh selection ask to sample of `scene`.
fn sample_options(
    path: &Path,
    scene: &anim::Scene,
    options: &OpenOptions,
) -> Result<SampleOptions> {
    let clip = match &options.clip {
        Some(name) => Some(scene.find_clip(name).map_err(with_path(path))?),
        None => None,
    };
    Ok(SampleOptions {
        fps: options.fps(),
        clip,
        meshes: options.meshes.clone(),
    })
}

/// Loads and samples in one call (the loaded scene's geometry moves into the result).
///
/// # Errors
/// As [`load`] and [`sample`].
pub fn open(path: &Path, options: &OpenOptions) -> Result<SampledScene> {
    match load(path, options)? {
        // The loaded scene is not kept: its geometry moves into the sampled objects.
        Loaded::Scene(scene) => {
            let sample = sample_options(path, &scene, options)?;
            anim::sample_owned(*scene, &sample).map_err(with_path(path))
        }
        loaded => sample(path, &loaded, options),
    }
}

/// Loads the mesh objects of an input for a job that can use morph weights
/// ([`anim::MeshFrames`]): a scene clip whose selected objects are all unskinned, on nodes that
/// do not move, comes back as weights ([`anim::sample_morph`]); anything else is sampled into
/// positions as by [`open`]. In file order, named after the objects.
///
/// # Errors
/// As [`open`].
pub fn open_frames(path: &Path, options: &OpenOptions) -> Result<Vec<anim::MeshFrames>> {
    match load(path, options)? {
        Loaded::Scene(scene) => {
            let sample = sample_options(path, &scene, options)?;
            if let Some(morphs) = anim::sample_morph(&scene, &sample).map_err(with_path(path))? {
                return Ok(morphs.into_iter().map(anim::MeshFrames::Morph).collect());
            }
            let sampled = anim::sample_owned(*scene, &sample).map_err(with_path(path))?;
            Ok(positions(sampled))
        }
        // A point cache or still mesh: sampled from what was loaded, not read again.
        loaded => Ok(positions(sample(path, &loaded, options)?)),
    }
}

/// The objects' positions, each mesh named after its object.
fn positions(sampled: SampledScene) -> Vec<anim::MeshFrames> {
    sampled
        .objects
        .into_iter()
        .map(|o| {
            let mut a = o.animation;
            a.mesh.name = o.name;
            anim::MeshFrames::Positions(a)
        })
        .collect()
}

/// All mesh objects merged into one point cache (the vertex order every per-vertex output
/// uses, and that `toonkit convert IN rest.obj` writes).
///
/// # Errors
/// No mesh at all, or objects that cannot be merged.
pub fn merged(path: &Path, sampled: &SampledScene) -> Result<MeshAnimation> {
    if sampled.objects.is_empty() {
        return Err(OpenError::Invalid(format!(
            "{}: the file has no mesh",
            path.display()
        )));
    }
    sampled
        .merged(&merged_name(path))
        .map_err(|e| OpenError::Merge {
            at: path.display().to_string(),
            source: e,
        })
}

/// Name of the merged point cache of an input: its file stem (`mesh` when it has none).
pub fn merged_name(path: &Path) -> String {
    path.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("mesh")
        .to_string()
}
