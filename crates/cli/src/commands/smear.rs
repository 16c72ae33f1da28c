//! `toonkit smear offsets IN -o OUT [--clip NAME] [--fps F] [--smooth N] [--whole-body]
//! [--prune BONE,...] [--camera NODE] [--mesh NAME] [--no-collinear]`.
//!
//! Motion offsets of Basset et al. 2024, Section 3. `OUT.npy`: float32 (frames × vertices),
//! vertices of all mesh objects merged in object order (as `toonkit convert IN rest.obj`
//! writes them). `OUT.glb`: a flipbook with the offsets as vertex colours (positive red,
//! negative blue, zero white).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Result};
use clap::{Args, Subcommand};
use serde_json::json;
use smear::{CameraSelect, MotionOffsets, OffsetMode, OffsetOptions, OffsetSolver};
use tkio::Format;

use super::Context;
use crate::input::{self, InputArgs};
use crate::output::{self, Layout};

/// Arguments of `toonkit smear`: a subcommand, or `IN --style STYLE.toml -o OUT.glb`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct SmearArgs {
    #[command(subcommand)]
    pub command: Option<SmearCommand>,
    #[command(flatten)]
    pub style: super::smear_style::StyleArgs,
}

/// Subcommands of `toonkit smear`.
#[derive(Debug, Subcommand)]
pub enum SmearCommand {
    /// Motion offsets per frame and vertex: leading parts > 0, trailing parts < 0 (§3).
    Offsets(OffsetsArgs),
    /// Elongated in-betweens: vertices slid along their trajectories by β = S_E(δ) (§4.1).
    Elongate(super::smear_effects::ElongateArgs),
    /// Multiple in-betweens: displaced copies with per-vertex opacity (§4.2).
    Multiples(super::smear_effects::MultiplesArgs),
    /// Motion lines: tubes along seed trajectories, length τ = S_L(δ) (§4.3).
    Lines(super::smear_effects::LinesArgs),
}

/// Arguments of `toonkit smear offsets`.
#[derive(Debug, Args)]
pub struct OffsetsArgs {
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub input: PathBuf,
    /// Output: `.npy` (float32, frames × vertices) or `.glb` (flipbook coloured by offset).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub input_args: InputArgs,
    #[command(flatten)]
    pub offsets: OffsetArgs,
}

/// Motion-offset options (Section 3), shared by `smear offsets` and every effect.
#[derive(Debug, Clone, Args)]
pub struct OffsetArgs {
    /// Temporal smoothing half-window N of Eq. 2 (0 = off).
    #[arg(long, default_value_t = smear::DEFAULT_SMOOTH)]
    pub smooth: usize,
    /// Treat each skinned character as one object with one separation plane (Fig. 14).
    #[arg(long)]
    pub whole_body: bool,
    /// Bones to toggle off (comma-separated): their vertices follow the nearest kept ancestor.
    #[arg(long, value_delimiter = ',')]
    pub prune: Vec<String>,
    /// Compute offsets relative to this camera (node name, or index).
    #[arg(long)]
    pub camera: Option<String>,
    /// Disable the collinear weight of the ribbons (paper Fig. 7, shows the shearing it
    /// prevents).
    #[arg(long)]
    pub no_collinear: bool,
}

impl OffsetArgs {
    /// The library options; `--camera` is a camera name, or an index when no camera has that
    /// name.
    pub fn options(&self, sampled: &anim::SampledScene) -> OffsetOptions {
        let camera = self.camera.as_ref().map(|c| match c.parse::<usize>() {
            Ok(i) if !sampled.cameras.iter().any(|cam| cam.name == *c) => CameraSelect::Index(i),
            _ => CameraSelect::Name(c.clone()),
        });
        OffsetOptions {
            smooth: self.smooth,
            whole_body: self.whole_body,
            prune: self.prune.clone(),
            camera,
            collinear_weight: !self.no_collinear,
        }
    }
}

/// Runs `toonkit smear`.
pub fn run(ctx: &Context, args: SmearArgs) -> Result<()> {
    match args.command {
        None => super::smear_style::run(ctx, args.style),
        Some(SmearCommand::Offsets(a)) => offsets(ctx, a),
        Some(SmearCommand::Elongate(a)) => super::smear_effects::elongate(ctx, a),
        Some(SmearCommand::Multiples(a)) => super::smear_effects::multiples(ctx, a),
        Some(SmearCommand::Lines(a)) => super::smear_effects::lines(ctx, a),
    }
}

/// Linear-space RGBA of an offset: white at 0, red at +1, blue at −1.
pub(crate) fn color(delta: f32) -> [f32; 4] {
    let d = if delta.is_finite() {
        delta.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    if d >= 0.0 {
        [1.0, 1.0 - d, 1.0 - d, 1.0]
    } else {
        [1.0 + d, 1.0 + d, 1.0, 1.0]
    }
}

fn offsets(ctx: &Context, args: OffsetsArgs) -> Result<()> {
    let start = Instant::now();
    let format = Format::from_extension(&args.output);
    if !matches!(format, Some(Format::Npy) | Some(Format::Glb)) {
        bail!(
            "{}: smear offsets writes .npy or .glb",
            args.output.display()
        );
    }
    let sampled = input::open(&args.input, &args.input_args)?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", args.input.display());
    }
    let options = args.offsets.options(&sampled);
    let spinner = crate::progress::spinner("computing motion offsets", ctx.json);
    let solver = OffsetSolver::new(&sampled, &options)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.input.display()))?;
    let per_object = solver.all();
    let merged = MotionOffsets::concat(&per_object)?;
    let (frames, vertices) = (merged.frame_count(), merged.vertex_count());
    match format {
        Some(Format::Npy) => {
            output::write_npy_field(&args.output, frames, vertices, merged.values())?
        }
        _ => {
            let anim = input::merged(&args.input, &sampled)?;
            let colors: Vec<[f32; 4]> = merged.values().iter().map(|&d| color(d)).collect();
            output::write_animation(&args.output, &anim, Layout::Flipbook, Some(&colors))?;
        }
    }
    spinner.finish_and_clear();
    let mode_name = |m: Option<OffsetMode>| match m {
        Some(OffsetMode::Articulated) => "articulated",
        Some(OffsetMode::WholeBody) => "whole-body",
        _ => "simple",
    };
    let objects: Vec<_> = per_object
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let (lo, hi) = d.range();
            json!({"name": sampled.objects[i].name, "vertices": d.vertex_count(),
                   "mode": mode_name(solver.mode(i)), "min": lo, "max": hi})
        })
        .collect();
    let (lo, hi) = merged.range();
    let summary = json!({
        "input": args.input,
        "output": args.output,
        "frames": frames,
        "vertices": vertices,
        "fps": sampled.fps,
        "smooth": args.offsets.smooth,
        "objects": objects,
        "min": lo,
        "max": hi,
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({frames} frames × {vertices} vertices, {} object(s), offsets in [{lo:.3}, {hi:.3}])",
            args.output.display(),
            per_object.len()
        )
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_colors_are_red_white_blue() {
        assert_eq!(color(1.0), [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(color(0.0), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(color(-1.0), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(color(-1.4), color(-1.0));
        assert_eq!(color(f32::NAN), [1.0; 4]);
        let half = color(0.5);
        assert!(half[0] == 1.0 && (half[1] - 0.5).abs() < 1e-6);
    }
}
