//! Options shared by several commands, defined once (one name, type and default per concept)
//! and reused with `#[command(flatten)]`: [`LayoutArgs`] (`--layout`, `--frame`) and
//! [`SeedArg`] (`--seed`). The input options (`--clip`, `--fps`, `--mesh`, `--rest`) are
//! [`crate::input::InputArgs`]. `tests/help_consistency.rs` checks that every subcommand
//! spells them the same way.

use std::path::PathBuf;

use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::Args;

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

impl Default for LayoutArgs {
    fn default() -> Self {
        LayoutArgs {
            layout: tkio::Layout::Flipbook,
            frame: None,
        }
    }
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

/// `--seed`: every random choice of a command takes it. Without it each tool uses its own
/// fixed default seed, so runs are reproducible either way.
#[derive(Debug, Clone, Copy, Default, Args)]
pub(crate) struct SeedArg {
    /// Seed of every random choice (default: the tool's fixed seed; runs are reproducible).
    #[arg(long, value_name = "SEED")]
    pub(crate) seed: Option<u64>,
}

impl SeedArg {
    /// The seed, or `default` (the tool's own) when none was given.
    pub(crate) fn or(self, default: u64) -> u64 {
        self.seed.unwrap_or(default)
    }
}

fn layout_parser() -> impl TypedValueParser<Value = tkio::Layout> {
    let names = tkio::Layout::NAMED.map(tkio::Layout::name);
    PossibleValuesParser::new(names).map(|s| s.parse().unwrap_or_default())
}

/// What a write produced, for the summary line: "out.obj", or "out_0001.obj … out_0048.obj
/// (48 files)" for a sequence.
pub(crate) fn files(written: &[PathBuf]) -> String {
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
pub(crate) fn frames_written(layout: tkio::Layout, frames: usize) -> String {
    match layout {
        tkio::Layout::Frame(f) => format!("frame {f} of {frames}"),
        _ if frames == 1 => "1 frame".into(),
        _ => format!("{frames} frames"),
    }
}

fn is_sequence(written: &[PathBuf]) -> bool {
    let ext = |p: &PathBuf| p.extension().map(|e| e.to_ascii_lowercase());
    written.len() > 2 && written.iter().all(|p| ext(p) == ext(&written[0]))
}
