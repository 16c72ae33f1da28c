//! `toonkit stopmo …`: replacement libraries for 3D-printed stop-motion (StopShop).
//!
//! `segment` cuts a face animation into parts and homogenizes the seams (Sections 3.1–3.2);
//! `library` builds the replacement library; `run` chains both. Each command parses its
//! arguments into the `stopmo` crate's options, loads with `tkio`, makes one `stopmo` call,
//! writes the result's files with `tkio::save` and prints a summary. The option flags the
//! commands share are declared in [`crate::flags::stopmo`].

mod library;
mod run;
mod segment;

pub(crate) use crate::flags::stopmo::{LibraryOptionsArgs, SegmentOptionsArgs};
use anyhow::Result;
use clap::{Args, Subcommand};

use super::Context;

/// Arguments of `toonkit stopmo`.
#[derive(Debug, Args)]
pub(crate) struct StopmoArgs {
    #[command(subcommand)]
    pub(crate) command: StopmoCommand,
}

/// Subcommands of `toonkit stopmo`.
#[derive(Debug, Subcommand)]
pub(crate) enum StopmoCommand {
    /// Cut the animation into parts along low-motion seams and make the seams identical in
    /// every frame (StopShop Sections 3.1–3.2).
    Segment(crate::flags::Deferred<segment::SegmentArgs>),
    /// Build a replacement library of printable pieces per part, the assembly sheet and a
    /// shooting order (StopShop Sections 3.3–3.4, 5).
    Library(crate::flags::Deferred<library::LibraryArgs>),
    /// Segment, then build the library of every part: `segment` and `library` in one go,
    /// writing DIR/segmentation.glb, DIR/segmentation.json and the library layout in DIR.
    Run(crate::flags::Deferred<run::RunArgs>),
}

/// Runs `toonkit stopmo …`.
pub(crate) fn run(ctx: &Context, args: StopmoArgs) -> Result<()> {
    match args.command {
        StopmoCommand::Segment(a) => segment::segment(ctx, a.0),
        StopmoCommand::Library(a) => library::library(ctx, a.0),
        StopmoCommand::Run(a) => run::run(ctx, a.0),
    }
}

/// Prints the printing warnings of a library (not with `--json`: they are in the report).
fn warn(ctx: &Context, result: &stopmo::LibraryResult) {
    if !ctx.json {
        for w in &result.report.warnings {
            eprintln!("toonkit: warning: {w}");
        }
    }
}
