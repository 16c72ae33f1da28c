//! The command-line flags every toonkit command shares, defined once (one name, type and
//! default per concept) and flattened into each command: [`InputArgs`] (`--clip`, `--fps`,
//! `--mesh`, `--rest`, `--scene`) → [`tkio::OpenOptions`], and [`LayoutArgs`] (`--layout`,
//! `--frame`) → [`tkio::Layout`]. `crates/cli/tests/help_consistency.rs` checks that every
//! subcommand spells them the same.

use std::path::PathBuf;

use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::Args;

/// Options shared by every command that reads an animation.
#[derive(Debug, Clone, Default, Args)]
pub(crate) struct InputArgs {
    /// Clip to sample, by name or index (default: the first clip).
    #[arg(long)]
    pub(crate) clip: Option<String>,
    /// Frames per second to sample at (default: 24).
    #[arg(long, value_name = "FPS", allow_negative_numbers = true)]
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
    /// What the flags ask to read and sample.
    pub(crate) fn options(&self) -> tkio::OpenOptions {
        tkio::OpenOptions {
            clip: self.clip.clone(),
            fps: self.fps,
            meshes: self.mesh.clone(),
            rest: self.rest.clone(),
            scene: self.scene.clone(),
        }
    }
}

/// How an animation result is laid out in its file: `--layout` (`--as` is a hidden alias)
/// and `--frame`. The rule itself (a single-frame format gets a sequence, one frame, or a
/// refusal) is [`tkio::save`]'s.
#[derive(Debug, Clone, Args)]
pub(crate) struct LayoutArgs {
    /// Layout of an animation in the output: flipbook (glTF: one node per frame), morph
    /// (glTF: one morph target per frame) or sequence (one .obj/.stl per frame,
    /// name_0001.obj, …). Other formats hold every frame in one file.
    #[arg(long, alias = "as", value_name = "LAYOUT", default_value = "flipbook",
          value_parser = layout_parser())]
    pub(crate) layout: tkio::Layout,
    /// Write only this frame (0-based), e.g. one .obj of a clip.
    #[arg(long, value_name = "N", conflicts_with = "layout")]
    pub(crate) frame: Option<usize>,
}

impl LayoutArgs {
    /// The layout to hand to [`tkio::save`].
    pub(crate) fn layout(&self) -> tkio::Layout {
        match self.frame {
            Some(frame) => tkio::Layout::Frame(frame),
            None => self.layout,
        }
    }
}

/// `--layout` takes the names of [`tkio::Layout::NAMED`].
fn layout_parser() -> impl TypedValueParser<Value = tkio::Layout> {
    let names = tkio::Layout::NAMED.map(tkio::Layout::name);
    PossibleValuesParser::new(names).map(|s| s.parse().unwrap_or_default())
}
