//! `toonkit info FILE [--json]`: [`tkio::info::summary`] of what [`tkio::load`] read.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::Context;
use crate::flags::io::InputArgs;

/// Arguments of `toonkit info`.
#[derive(Debug, Args)]
pub(crate) struct InfoArgs {
    /// The file to describe (glTF, GLB, FBX, OBJ, PC2, MDD, BVH, STL).
    pub(crate) file: PathBuf,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

/// Runs `toonkit info`.
pub(crate) fn run(ctx: &Context, args: InfoArgs) -> Result<()> {
    let input = args.input.options();
    let (loaded, notes) = tkio::sampling::load_with_notes(&args.file, &input)?;
    let fps = input.fps();
    let summary = tkio::info::summary(&loaded, fps, &notes)?;
    ctx.report(&summary, || {
        tkio::info::summary_text(&args.file, &summary, fps)
    });
    Ok(())
}
