//! The command-line flags every toonkit command shares (cargo feature `clap`), defined once
//! (one name, type and default per concept) and flattened into each command: [`InputArgs`]
//! (`--clip`, `--fps`, `--mesh`, `--rest`, `--scene`) with the load → sample steps they drive,
//! [`LayoutArgs`] (`--layout`, `--frame`) and [`SeedArg`] (`--seed`).
//! `crates/cli/tests/help_consistency.rs` checks that every subcommand spells them the same.

use std::path::{Path, PathBuf};

use anim::{MeshAnimation, SampleOptions, SampledScene, DEFAULT_FPS};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::Args;

use crate::{IoError, LoadOptions, Loaded};

mod deferred;

pub use deferred::{built, Deferred};

/// Why the shared flags cannot open an input, in the user's terms.
#[derive(Debug, thiserror::Error)]
pub enum ArgsError {
    /// A flag's value or the input is wrong; the text names it.
    #[error("{0}")]
    Flag(String),
    /// The input (`at`) cannot be merged into one point cache.
    #[error("{at}")]
    At {
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

type Result<T, E = ArgsError> = std::result::Result<T, E>;

/// Options shared by every command that reads an animation.
#[derive(Debug, Clone, Default, Args)]
pub struct InputArgs {
    /// Clip to sample, by name or index (default: the first clip).
    #[arg(long)]
    pub clip: Option<String>,
    /// Frames per second to sample at (default: 24).
    #[arg(long, value_name = "FPS", allow_negative_numbers = true)]
    pub fps: Option<f32>,
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

impl InputArgs {
    /// The sampling rate: `--fps`, or 24.
    pub fn fps(&self) -> f32 {
        self.fps.unwrap_or(DEFAULT_FPS)
    }
}

/// Checks an `--fps` value: a positive, finite number.
///
/// # Errors
/// Zero, negative or not finite.
pub fn check_fps(fps: f32) -> Result<f32> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(ArgsError::Flag(format!(
            "--fps: must be a positive number of frames per second, got {fps}"
        )));
    }
    Ok(fps)
}

/// Reads a file of any supported format.
pub fn load(path: &Path, args: &InputArgs) -> Result<Loaded> {
    load_with_notes(path, args).map(|(loaded, _)| loaded)
}

/// Reads a file of any supported format, with the reader's notes (glTF extensions accepted,
/// scene read, FBX units and axes converted).
pub fn load_with_notes(path: &Path, args: &InputArgs) -> Result<(Loaded, Vec<String>)> {
    let options = LoadOptions {
        fps: check_fps(args.fps())?,
        rest: args.rest.clone(),
        scene: args.scene.clone(),
    };
    Ok(crate::load_with_notes(path, &options)?)
}

/// Samples what was loaded into per-object point caches (and skeleton, cameras).
pub fn sample(path: &Path, loaded: &Loaded, args: &InputArgs) -> Result<SampledScene> {
    match loaded {
        Loaded::Scene(scene) => {
            let options = sample_options(path, scene, args)?;
            anim::sample(scene, &options).map_err(with_path(path))
        }
        Loaded::Cache(cache) => Ok(SampledScene::from_animation(cache.clone())),
        Loaded::Mesh(mesh) => Ok(SampledScene::from_animation(MeshAnimation::still(
            mesh.clone(),
        ))),
    }
}

/// An animation error as one line naming the input.
fn with_path(path: &Path) -> impl Fn(anim::AnimError) -> ArgsError + '_ {
    move |e| ArgsError::Flag(format!("{}: {e}", path.display()))
}

/// What `--clip`, `--fps` and `--mesh` ask to sample of `scene`.
fn sample_options(path: &Path, scene: &anim::Scene, args: &InputArgs) -> Result<SampleOptions> {
    let clip = match &args.clip {
        Some(name) => Some(scene.find_clip(name).map_err(with_path(path))?),
        None => None,
    };
    Ok(SampleOptions {
        fps: args.fps(),
        clip,
        meshes: args.mesh.clone(),
    })
}

/// Loads and samples in one call (the loaded scene's geometry moves into the result).
pub fn open(path: &Path, args: &InputArgs) -> Result<SampledScene> {
    match load(path, args)? {
        // The loaded scene is not kept: its geometry moves into the sampled objects.
        Loaded::Scene(scene) => {
            let options = sample_options(path, &scene, args)?;
            anim::sample_owned(*scene, &options).map_err(with_path(path))
        }
        loaded => sample(path, &loaded, args),
    }
}

/// All mesh objects merged into one point cache (the vertex order every per-vertex output
/// uses, and that `toonkit convert IN rest.obj` writes).
pub fn merged(path: &Path, sampled: &SampledScene) -> Result<MeshAnimation> {
    if sampled.objects.is_empty() {
        return Err(ArgsError::Flag(format!(
            "{}: the file has no mesh",
            path.display()
        )));
    }
    sampled
        .merged(&merged_name(path))
        .map_err(|e| ArgsError::At {
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

/// How an animation result is laid out in its file: `--layout` (`--as` is a hidden alias)
/// and `--frame`. The rule itself (a single-frame format gets a sequence, one frame, or a
/// refusal) is [`crate::save`]'s.
#[derive(Debug, Clone, Args)]
pub struct LayoutArgs {
    /// Layout of an animation in the output: flipbook (glTF: one node per frame), morph
    /// (glTF: one morph target per frame) or sequence (one .obj/.stl per frame,
    /// name_0001.obj, …). Other formats hold every frame in one file.
    #[arg(long, alias = "as", value_name = "LAYOUT", default_value = "flipbook",
          value_parser = layout_parser())]
    pub layout: crate::Layout,
    /// Write only this frame (0-based), e.g. one .obj of a clip.
    #[arg(long, value_name = "N", conflicts_with = "layout")]
    pub frame: Option<usize>,
}

impl Default for LayoutArgs {
    fn default() -> Self {
        LayoutArgs {
            layout: crate::Layout::Flipbook,
            frame: None,
        }
    }
}

impl LayoutArgs {
    /// The layout to hand to [`crate::save`].
    pub fn layout(&self) -> crate::Layout {
        match self.frame {
            Some(frame) => crate::Layout::Frame(frame),
            None => self.layout,
        }
    }
}

/// `--seed`: every random choice of a command takes it. Without it each tool uses its own
/// fixed default seed, so runs are reproducible either way.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct SeedArg {
    /// Seed of every random choice (default: the tool's fixed seed; runs are reproducible).
    #[arg(long, value_name = "SEED")]
    pub seed: Option<u64>,
}

impl SeedArg {
    /// The seed, or `default` (the tool's own) when none was given.
    pub fn or(self, default: u64) -> u64 {
        self.seed.unwrap_or(default)
    }
}

fn layout_parser() -> impl TypedValueParser<Value = crate::Layout> {
    let names = crate::Layout::NAMED.map(crate::Layout::name);
    PossibleValuesParser::new(names).map(|s| s.parse().unwrap_or_default())
}

/// What a write produced, for the summary line: "out.obj", or "out_0001.obj … out_0048.obj
/// (48 files)" for a sequence.
pub fn files(written: &[PathBuf]) -> String {
    match written {
        [] => "nothing".into(),
        [one] => one.display().to_string(),
        [first, .., last] if is_sequence(written) => format!(
            "{} … {} ({} files)",
            first.display(),
            last.display(),
            written.len()
        ),
        many => many
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The frames a write holds, for the summary line: "48 frames" or "frame 5 of 48".
pub fn frames_written(layout: crate::Layout, frames: usize) -> String {
    match layout {
        crate::Layout::Frame(f) => format!("frame {f} of {frames}"),
        _ if frames == 1 => "1 frame".into(),
        _ => format!("{frames} frames"),
    }
}

fn is_sequence(written: &[PathBuf]) -> bool {
    let ext = |p: &PathBuf| p.extension().map(|e| e.to_ascii_lowercase());
    written.len() > 2 && written.iter().all(|p| ext(p) == ext(&written[0]))
}

/// Refuses an output whose format cannot hold scenes (one mesh per part, a topology that
/// changes per frame): `.glb`, `.usda`, `.usdc`, `.usdz` and `.abc` can; `why` says what
/// needs one.
///
/// # Errors
/// `PATH: why` for any other extension.
pub fn require_scenes(path: &Path, why: &str) -> Result<()> {
    if !crate::Format::from_extension(path).is_some_and(crate::Format::holds_scenes) {
        return Err(ArgsError::Flag(format!("{}: {why}", path.display())));
    }
    Ok(())
}
