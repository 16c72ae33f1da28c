//! `toonkit smear offsets IN -o OUT [--clip NAME] [--fps F] [--smooth N] [--whole-body]
//! [--prune BONE,...] [--camera NODE] [--mesh NAME] [--no-collinear]`.
//!
//! Motion offsets of SMEAR Section 3 ([`smear::offsets`]). `OUT.npy`: float32 (frames ×
//! vertices), vertices of all mesh objects merged in object order (as `toonkit convert IN
//! rest.obj` writes them). `OUT.glb`: a flipbook with the offsets as vertex colours
//! (positive red, negative blue, zero white).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::Args;
use serde_json::json;
use tkio::{Format, Output};

use super::{at_input, Context, OffsetArgs};
use crate::flags::io::InputArgs;
use crate::output;

/// Arguments of `toonkit smear offsets`.
#[derive(Debug, Args)]
pub(crate) struct OffsetsArgs {
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub(crate) input: PathBuf,
    /// Output: `.npy` (float32, frames × vertices) or `.glb` (flipbook coloured by offset).
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
    #[command(flatten)]
    pub(crate) offsets: OffsetArgs,
}

/// What `smear offsets` writes: the field itself (`.npy`) or a flipbook coloured by it.
const OFFSETS_FORMATS: [Format; 2] = [Format::Npy, Format::Glb];

/// Runs `toonkit smear offsets`.
pub(crate) fn run(ctx: &Context, args: OffsetsArgs) -> Result<()> {
    let start = Instant::now();
    let format = Format::from_extension(&args.output);
    if !format.is_some_and(|f| OFFSETS_FORMATS.contains(&f)) {
        bail!(
            "{}: smear offsets writes {}",
            args.output.display(),
            Format::list(&OFFSETS_FORMATS)
        );
    }
    let sampled = tkio::open(&args.input, &args.input_args.options())?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", args.input.display());
    }
    let options = args.offsets.options(&sampled);
    let spinner = crate::progress::spinner("computing motion offsets", ctx.json);
    let result = smear::offsets(&sampled, &options).map_err(at_input(&args.input))?;
    let merged = &result.offsets;
    let (frames, vertices) = (merged.frame_count(), merged.vertex_count());
    if format == Some(Format::Npy) {
        let values = merged.values();
        tkio::save(
            &args.output,
            &Output::Field {
                frames,
                vertices,
                values,
            },
        )?;
    } else {
        let anim = tkio::sampling::merged(&args.input, &sampled)?;
        let colors = render::offset_colors(merged.values());
        output::write_animation(
            &args.output,
            &anim,
            tkio::Layout::Flipbook,
            Some(&colors),
            ctx.save,
        )?;
    }
    spinner.finish_and_clear();
    let report = &result.report;
    let (lo, hi) = report.range;
    let summary = json!({
        "input": args.input,
        "output": args.output,
        "frames": frames,
        "vertices": vertices,
        "fps": sampled.fps,
        "smooth": args.offsets.smooth,
        "objects": report.objects,
        "min": lo,
        "max": hi,
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({frames} frames × {vertices} vertices, {} object(s), offsets in [{lo:.3}, {hi:.3}])",
            args.output.display(),
            report.objects.len()
        )
    });
    Ok(())
}
