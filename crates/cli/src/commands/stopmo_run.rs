//! `toonkit stopmo run IN -o DIR`: `stopmo segment` then `stopmo library` in one go.
//!
//! Writes `DIR/segmentation.glb` (the parts, as `stopmo segment -o` writes them),
//! `DIR/segmentation.json` (the segmentation report) and the library layout of
//! `stopmo library` in `DIR` (SPEC.md "Output layouts"). The library is built from the
//! segmented parts in memory (no glTF round trip); its part names are the segmentation's part
//! names made file-safe.

use std::path::PathBuf;
use std::time::Instant;

use anim::MeshAnimation;
use anyhow::Result;
use clap::Args;
use serde_json::json;

use super::stopmo::{segment_and_write, PartsLayout, SegmentOptionsArgs, SegmentOutputs};
use super::stopmo_library::{build_and_write, file_safe, Given, LibraryOptionsArgs};
use super::Context;
use crate::input::{self, InputArgs};

/// Arguments of `toonkit stopmo run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Input mesh animation (fixed topology), any readable format.
    pub input: PathBuf,
    /// Output directory.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub segment: SegmentOptionsArgs,
    /// Also write the segmentation figure (paper Fig. 5) to DIR/segmentation.png.
    #[arg(long)]
    pub render: bool,
    #[command(flatten)]
    pub library: LibraryOptionsArgs,
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// Reads `--saliency` for `stopmo run`: one weight per vertex of the input mesh, in its order.
fn read_input_saliency(path: &std::path::Path, vertices: usize) -> Result<Vec<f32>> {
    let bytes = tkio::read_file(path)?;
    let (shape, values) = tkio::npy::read_f32(&bytes).map_err(|e| e.at(path))?;
    if !matches!(shape.as_slice(), [n] | [1, n] if *n == vertices) {
        anyhow::bail!(
            "{}: saliency shape {shape:?}, expected ({vertices},) or (1, {vertices}): one weight per input vertex, in the input's order",
            path.display()
        );
    }
    Ok(values)
}

/// Runs `toonkit stopmo run`.
pub fn run(ctx: &Context, args: RunArgs) -> Result<()> {
    let start = Instant::now();
    let sampled = input::open(&args.input, &args.input_args)?;
    let anim = input::merged(&args.input, &sampled)?;
    drop(sampled);
    // Saliency is given in the input's vertex order: check it before writing anything.
    let saliency = match &args.library.saliency {
        Some(p) => Some(read_input_saliency(p, anim.vertex_count())?),
        None => None,
    };
    let dir = &args.output;
    let png = dir.join("segmentation.png");
    let seg = segment_and_write(
        ctx,
        &args.input,
        &anim,
        &args.segment,
        &SegmentOutputs {
            glb: &dir.join("segmentation.glb"),
            layout: PartsLayout::Morph,
            report: Some(&dir.join("segmentation.json")),
            render: args.render.then_some(png.as_path()),
        },
    )?;
    let seg_seconds = start.elapsed().as_secs_f64();
    let per_part_saliency = match &saliency {
        Some(values) => {
            let mapped = seg.segmentation.map_vertex_values(values)?;
            Some(
                seg.parts
                    .iter()
                    .map(|p| p.vertices.iter().map(|&v| mapped[v as usize]).collect())
                    .collect(),
            )
        }
        None => None,
    };
    let inputs: Vec<MeshAnimation> = seg
        .segmentation
        .input_parts(&anim)?
        .into_iter()
        .map(|p| p.animation)
        .collect();
    drop(anim);
    let parts: Vec<MeshAnimation> = seg
        .parts
        .into_iter()
        .map(|p| {
            let mut a = p.animation;
            a.mesh.name = file_safe(&p.name);
            a
        })
        .collect();
    let lib = build_and_write(
        ctx,
        &args.input,
        &parts,
        &args.library,
        dir,
        Given {
            saliency: per_part_saliency,
            inputs: Some(&inputs),
        },
    )?;
    let mut summary = seg.summary;
    summary["seconds"] = json!(seg_seconds);
    let report = json!({
        "input": args.input,
        "output": dir,
        "segmentation": summary,
        "library": lib.report,
        "seconds": start.elapsed().as_secs_f64(),
    });
    if let Some(p) = &args.library.report {
        tkio::write_atomic(p, serde_json::to_string_pretty(&report)?.as_bytes())?;
    }
    ctx.report(&report, || {
        format!(
            "{}\n{}; total {:.2} s",
            seg.text,
            lib.text,
            start.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
