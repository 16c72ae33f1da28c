//! Opening inputs: detect the format, pick a clip, sample at a frame rate.

use std::path::{Path, PathBuf};

use anim::{MeshAnimation, SampleOptions, SampledScene, DEFAULT_FPS};
use anyhow::{Context as _, Result};
use clap::Args;
use tkio::{LoadOptions, Loaded};

/// Options shared by every command that reads an animation.
#[derive(Debug, Clone, Args)]
pub struct InputArgs {
    /// Clip to sample, by name or index (default: the first clip).
    #[arg(long)]
    pub clip: Option<String>,
    /// Frames per second to sample at.
    #[arg(long, default_value_t = DEFAULT_FPS)]
    pub fps: f32,
    /// Only this mesh object (by name; repeat or comma-separate for several).
    #[arg(long, value_delimiter = ',')]
    pub mesh: Vec<String>,
    /// Rest mesh (.obj) for a PC2/MDD point cache (default: same name .obj, or rest.obj).
    #[arg(long)]
    pub rest: Option<PathBuf>,
    /// Scene of a multi-scene glTF file, by name or index (default: the file's default scene).
    #[arg(long)]
    pub scene: Option<String>,
}

impl Default for InputArgs {
    fn default() -> Self {
        InputArgs {
            clip: None,
            fps: DEFAULT_FPS,
            mesh: Vec::new(),
            rest: None,
            scene: None,
        }
    }
}

/// Reads a file of any supported format.
pub fn load(path: &Path, args: &InputArgs) -> Result<Loaded> {
    load_with_notes(path, args).map(|(loaded, _)| loaded)
}

/// Reads a file of any supported format, with the reader's notes (glTF extensions accepted,
/// scene read, FBX units and axes converted).
pub fn load_with_notes(path: &Path, args: &InputArgs) -> Result<(Loaded, Vec<String>)> {
    if !(args.fps.is_finite() && args.fps > 0.0) {
        anyhow::bail!("--fps must be a positive number, got {}", args.fps);
    }
    let options = LoadOptions {
        fps: args.fps,
        rest: args.rest.clone(),
        scene: args.scene.clone(),
    };
    Ok(tkio::load_with_notes(path, &options)?)
}

/// Samples what was loaded into per-object point caches (and skeleton, cameras).
pub fn sample(path: &Path, loaded: &Loaded, args: &InputArgs) -> Result<SampledScene> {
    let with_path = |e: anim::AnimError| anyhow::anyhow!("{}: {e}", path.display());
    match loaded {
        Loaded::Scene(scene) => {
            let clip = match &args.clip {
                Some(name) => Some(scene.find_clip(name).map_err(with_path)?),
                None => None,
            };
            let options = SampleOptions {
                fps: args.fps,
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
pub fn open(path: &Path, args: &InputArgs) -> Result<SampledScene> {
    let loaded = load(path, args)?;
    sample(path, &loaded, args)
}

/// All mesh objects merged into one point cache (the vertex order every per-vertex output
/// uses, and that `toonkit convert IN rest.obj` writes).
pub fn merged(path: &Path, sampled: &SampledScene) -> Result<MeshAnimation> {
    if sampled.objects.is_empty() {
        anyhow::bail!("{}: the file has no mesh", path.display());
    }
    sampled
        .merged(&merged_name(path))
        .with_context(|| path.display().to_string())
}

/// Name of the merged point cache of an input: its file stem (`mesh` when it has none).
pub fn merged_name(path: &Path) -> String {
    path.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("mesh")
        .to_string()
}
