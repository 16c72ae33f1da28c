//! `toonkit stopmo run IN -o DIR`: `stopmo segment` then `stopmo library` in one go.
//!
//! Writes `DIR/segmentation.glb` (the parts, as `stopmo segment -o` writes them),
//! `DIR/segmentation.json` (the segmentation report) and the library layout of
//! `stopmo library` in `DIR` (SPEC.md "Output layouts"); the part names are the
//! segmentation's part names made file-safe.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::json;

use super::{warn, LibraryOptionsArgs, SegmentOptionsArgs};
use crate::commands::Context;
use crate::flags::io::InputArgs;

/// Arguments of `toonkit stopmo run`.
#[derive(Debug, Args)]
pub(crate) struct RunArgs {
    /// Input mesh animation (fixed topology), any readable format.
    pub(crate) input: PathBuf,
    /// Output directory.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) segment: SegmentOptionsArgs,
    /// Also write the segmentation figure (paper Fig. 5) to DIR/segmentation.png.
    #[arg(long)]
    pub(crate) render: bool,
    #[command(flatten)]
    pub(crate) library: LibraryOptionsArgs,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

/// Runs `toonkit stopmo run`.
pub(super) fn run(ctx: &Context, args: RunArgs) -> Result<()> {
    let start = Instant::now();
    let segment = args.segment.options(args.render)?;
    // Part names are known before segmenting: the --part names, or part1… for --auto-parts.
    // (the saved part names with --segmentation).
    let names: Vec<String> = match (&segment.reuse, args.segment.auto_parts) {
        (Some(saved), _) => saved
            .parts
            .iter()
            .map(|n| stopmo::file_safe_name(n))
            .collect(),
        (None, Some(n)) => (1..=n).map(|i| format!("part{i}")).collect(),
        (None, None) => segment
            .parts
            .iter()
            .map(|p| stopmo::file_safe_name(&p.name))
            .collect(),
    };
    // --saliency is in the input's vertex order here; the crate carries it through the cut.
    let options = stopmo::RunOptions {
        segment,
        library: args.library.options(&names)?,
    };
    let anim = tkio::sampling::merged(
        &args.input,
        &tkio::open(&args.input, &args.input_args.options())?,
    )?;
    let spinner = crate::progress::spinner("segmenting and optimizing", ctx.json);
    let mut result = stopmo::run(&anim, &options).map_err(|e| match e {
        stopmo::Error::Segment(_) => {
            anyhow::Error::new(e).context(args.input.display().to_string())
        }
        e => args.library.context(e, &args.input).into(),
    })?;
    spinner.finish_and_clear();
    drop(anim);
    result.report.input = Some(args.input.display().to_string());
    let dir = &args.output;
    tkio::save_files(dir, &result.files()?)?;
    warn(ctx, &result);
    let seg = result
        .segmented
        .as_ref()
        .context("stopmo::run returned no segmentation")?;
    let mut summary = serde_json::to_value(seg.summary())?;
    summary["input"] = json!(args.input);
    summary["output"] = json!(dir.join("segmentation.glb"));
    summary["seconds"] = json!(seg.seconds);
    let report = json!({
        "input": args.input,
        "output": dir,
        "segmentation": summary,
        "library": serde_json::to_value(&result.report)?,
        "seconds": start.elapsed().as_secs_f64(),
    });
    if let Some(p) = &args.library.report {
        tkio::save(
            p,
            &tkio::Output::Text(&serde_json::to_string_pretty(&report)?),
        )?;
    }
    ctx.report(&report, || {
        format!(
            "wrote {}: {}\n{}; total {:.2} s",
            dir.join("segmentation.glb").display(),
            seg.describe(),
            super::library::describe(&result, dir),
            start.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
