//! `toonkit loa line|animate`: argument parsing and printing around `loa::line` and
//! `loa::animate` (Guay et al. 2015, the LoA paper).

mod animate;
mod line;

use std::path::Path;

pub(crate) use crate::flags::loa::LineFlags;
use anyhow::{Context as _, Result};
use clap::{Args, Subcommand};

use super::Context;

/// Arguments of `toonkit loa`.
#[derive(Debug, Args)]
pub(crate) struct LoaArgs {
    #[command(subcommand)]
    pub(crate) command: LoaCommand,
}

/// Subcommands of `toonkit loa`.
#[derive(Debug, Subcommand)]
pub(crate) enum LoaCommand {
    /// Interpolate sketched keystrokes into a dynamic line of action (Guay et al. 2015, §3).
    Line(crate::flags::Deferred<line::LineArgs>),
    /// Synthesize 3D character motion that follows the dynamic line (Guay et al. 2015, §4).
    Animate(crate::flags::Deferred<Box<animate::AnimateArgs>>),
}

/// Runs `toonkit loa …`.
pub(crate) fn run(ctx: &Context, args: LoaArgs) -> Result<()> {
    match args.command {
        LoaCommand::Line(a) => line::run(ctx, a.0),
        LoaCommand::Animate(a) => animate::run(ctx, *a.0),
    }
}

/// Reads keystrokes (JSON or SVG).
fn read_keystrokes(path: &Path) -> Result<loa::Keystrokes> {
    // Through tkio: a keystroke file is an input the job's outputs may not replace.
    let bytes = tkio::read_file(path)?;
    let text = String::from_utf8(bytes).map_err(|_| {
        anyhow::anyhow!(
            "{}: keystrokes are UTF-8 text (JSON or SVG)",
            path.display()
        )
    })?;
    loa::Keystrokes::parse(&text).with_context(|| path.display().to_string())
}

/// Prints the line's warnings (reversed keystrokes) on stderr, one line each.
fn warn(line: &loa::Line, keys: &Path) {
    for w in &line.warnings {
        eprintln!("warning: {}: {w}", keys.display());
    }
}
