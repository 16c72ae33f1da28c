//! Opening inputs: detect the format, pick a clip, sample at a frame rate.

use std::path::{Path, PathBuf};

use anim::{MeshAnimation, SampleOptions, SampledScene, DEFAULT_FPS};
use anyhow::{Context as _, Result};
use clap::Args;
use tkio::{LoadOptions, Loaded};

/// Options shared by every command that reads an animation.
#[derive(Debug, Clone, Default, Args)]
pub(crate) struct InputArgs {
    /// Clip to sample, by name or index (default: the first clip).
    #[arg(long)]
    pub(crate) clip: Option<String>,
    /// Frames per second to sample at (default: 24).
    #[arg(long, value_name = "FPS")]
    pub(crate) fps: Option<f32>,
    /// Only this mesh object (by name; repeat or comma-separate for several).
    #[arg(long, value_delimiter = ',')]
    pub(crate) mesh: Vec<String>,
    /// Rest mesh (.obj) for a PC2/MDD point cache (default: same name .obj, or rest.obj).
    #[arg(long)]
    pub(crate) rest: Option<PathBuf>,
    /// Scene of a multi-scene glTF file, by name or index (default: the file's default scene).
    #[arg(long)]
    pub(crate) scene: Option<String>,
}

impl InputArgs {
    /// The sampling rate: `--fps`, or 24.
    pub(crate) fn fps(&self) -> f32 {
        self.fps.unwrap_or(DEFAULT_FPS)
    }
}

/// Checks an `--fps` value: a positive, finite number.
pub(crate) fn check_fps(fps: f32) -> Result<f32> {
    if !(fps.is_finite() && fps > 0.0) {
        anyhow::bail!("--fps: must be a positive number of frames per second, got {fps}");
    }
    Ok(fps)
}

/// Reads a file of any supported format.
pub(crate) fn load(path: &Path, args: &InputArgs) -> Result<Loaded> {
    load_with_notes(path, args).map(|(loaded, _)| loaded)
}

/// Reads a file of any supported format, with the reader's notes (glTF extensions accepted,
/// scene read, FBX units and axes converted).
pub(crate) fn load_with_notes(path: &Path, args: &InputArgs) -> Result<(Loaded, Vec<String>)> {
    let options = LoadOptions {
        fps: check_fps(args.fps())?,
        rest: args.rest.clone(),
        scene: args.scene.clone(),
    };
    Ok(tkio::load_with_notes(path, &options)?)
}

/// Samples what was loaded into per-object point caches (and skeleton, cameras).
pub(crate) fn sample(path: &Path, loaded: &Loaded, args: &InputArgs) -> Result<SampledScene> {
    let with_path = |e: anim::AnimError| anyhow::anyhow!("{}: {e}", path.display());
    match loaded {
        Loaded::Scene(scene) => {
            let clip = match &args.clip {
                Some(name) => Some(scene.find_clip(name).map_err(with_path)?),
                None => None,
            };
            let options = SampleOptions {
                fps: args.fps(),
                clip,
                meshes: args.mesh.clone(),
            };
            anim::sample(scene, &options).map_err(with_path)
        }
        Loaded::Cache(cache) => Ok(SampledScene::from_animation(cache.clone())),
        Loaded::Mesh(mesh) => Ok(SampledScene::from_animation(MeshAnimation::still(
            mesh.clone(),
        ))),
    }
}

/// Loads and samples in one call.
pub(crate) fn open(path: &Path, args: &InputArgs) -> Result<SampledScene> {
    let loaded = load(path, args)?;
    sample(path, &loaded, args)
}

/// All mesh objects merged into one point cache (the vertex order every per-vertex output
/// uses, and that `toonkit convert IN rest.obj` writes).
pub(crate) fn merged(path: &Path, sampled: &SampledScene) -> Result<MeshAnimation> {
    if sampled.objects.is_empty() {
        anyhow::bail!("{}: the file has no mesh", path.display());
    }
    sampled
        .merged(&merged_name(path))
        .with_context(|| path.display().to_string())
}

/// Name of the merged point cache of an input: its file stem (`mesh` when it has none).
pub(crate) fn merged_name(path: &Path) -> String {
    path.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("mesh")
        .to_string()
}
