//! `toonkit stopmo segment IN -o OUT.glb`: parts along low-motion seams, seams homogenized.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context as _, Result};
use clap::Args;
use serde_json::json;

use super::SegmentOptionsArgs;
use crate::commands::Context;
use crate::flags::io::{InputArgs, LayoutArgs};

/// Arguments of `toonkit stopmo segment`.
#[derive(Debug, Args)]
#[command(mut_arg("layout", |a| a.default_value("morph")))]
pub(crate) struct SegmentArgs {
    /// Input mesh animation (fixed topology), any readable format.
    pub(crate) input: PathBuf,
    /// Output `.glb`: one mesh node per part, named after the part, all with the same frames.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) segment: SegmentOptionsArgs,
    /// Write the JSON report (parts, triangle_part, seam_vertices, gamma, cut_length).
    #[arg(long)]
    pub(crate) report: Option<PathBuf>,
    /// Write a PNG: parts on the average mesh and the average displacement (paper Fig. 5).
    #[arg(long)]
    pub(crate) render: Option<PathBuf>,
    /// glTF layout of the parts: morph (default: one mesh per part, what `stopmo library`
    /// reads) or flipbook.
    #[command(flatten)]
    pub(crate) layout: LayoutArgs,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

/// Runs `toonkit stopmo segment`.
pub(super) fn segment(ctx: &Context, args: SegmentArgs) -> Result<()> {
    let start = Instant::now();
    if tkio::Format::from_extension(&args.output) != Some(tkio::Format::Glb) {
        anyhow::bail!(
            "{}: the segmented animation is written as .glb",
            args.output.display()
        );
    }
    let options = args.segment.options(args.render.is_some())?;
    let anim = tkio::sampling::merged(
        &args.input,
        &tkio::open(&args.input, &args.input_args.options())?,
    )?;
    let spinner = crate::progress::spinner("segmenting", ctx.json);
    let seg = stopmo::segment(&anim, &options).with_context(|| args.input.display().to_string())?;
    let layers: Vec<(&anim::MeshAnimation, Option<&[[f32; 4]]>)> = seg
        .part_animations()
        .into_iter()
        .map(|a| (a, None))
        .collect();
    let layout = args.layout.layout();
    tkio::save(
        &args.output,
        &tkio::Output::Parts {
            parts: &layers,
            layout,
        },
    )?;
    if let Some(path) = &args.report {
        tkio::save(path, &tkio::Output::Text(&seg.report_json()))?;
    }
    if let (Some(path), Some(png)) = (&args.render, &seg.figure) {
        tkio::save(path, &tkio::Output::Bytes(png))?;
    }
    spinner.finish_and_clear();
    let mut summary = serde_json::to_value(seg.summary())?;
    summary["input"] = json!(args.input);
    summary["output"] = json!(args.output);
    summary["seconds"] = json!(start.elapsed().as_secs_f64());
    ctx.report(&summary, || {
        format!(
            "wrote {}: {}, {:.2} s",
            args.output.display(),
            seg.describe(),
            start.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
