//! `toonkit smear elongate | multiples | lines`: the smear effects of SMEAR Section 4, driven
//! by motion offsets computed with the same options as `smear offsets`, on all objects merged
//! into one.
//!
//! * `elongate IN -o OUT [--preset linear|speed|noise] [--beta-max X] [--kappa K]
//!   [--expr "..."]`: every frame replaced by its elongated in-between (SMEAR Eq. 10); `.glb`
//!   (flipbook or `--layout morph`), `.usda`, `.pc2`/`.mdd` + rest `.obj`, or an `.obj`
//!   sequence (`--layout sequence`), on the input topology; with `--subdivide`, each
//!   frame's own mesh (a scene file or an `.obj`/`.stl` sequence).
//! * `multiples IN -o OUT.glb|OUT.usda --past M --future M [--spacing DF | --overlap N]
//!   [--m-max X] [--opacity-expr "..."]`: the original plus displaced copies with per-vertex
//!   opacity (SMEAR Eqs. 11–12), each an alpha-blended flipbook node (a Mesh prim in `.usda`);
//!   or an `.obj` sequence (`--layout sequence`), each file the frame's body and copies.
//! * `lines IN -o OUT.glb|OUT.usda --count K --length-max T [--seed S]
//!   [--length-expr "..."]`: the original as a flipbook plus one motion-line tube mesh per
//!   frame (SMEAR Eq. 13); in `.usda`, one Mesh prim whose topology changes per frame; in an
//!   `.obj` sequence (`--layout sequence`), each file the frame's body and lines.
//!
//! Each command turns its flags into a [`smear::Style`] and calls [`smear::stylize`].
//! Expressions are those of `smear::Expression` (inputs `delta`, `speed`, `weight`, `noise`,
//! `frame`, `m`, `t`, …) with the command's maximum bound as a parameter (`beta_max`,
//! `m_max`, `tau_max`).

use std::time::Instant;

use anim::{FlipbookPart, MeshAnimation};
use anyhow::{bail, Context as _, Result};
use clap::Args;
use serde_json::json;
use smear::{Param, Prepared, Spacing, Style, Stylized};
use tkio::{Format, Output};

use super::{at_input, prepare, Context, EffectArgs, EffectIo};
use crate::flags::io::LayoutArgs;
use crate::flags::smear::{Elongate, Lines, Multiples};
use crate::output;

/// Arguments of `toonkit smear elongate`.
#[derive(Debug, Args)]
pub(crate) struct ElongateArgs {
    #[command(flatten)]
    pub(crate) io: EffectIo,
    #[command(flatten)]
    pub(crate) offsets: EffectArgs,
    #[command(flatten)]
    pub(crate) effect: Elongate,
    #[command(flatten)]
    pub(crate) layout: LayoutArgs,
}

/// Arguments of `toonkit smear multiples`.
#[derive(Debug, Args)]
pub(crate) struct MultiplesArgs {
    #[command(flatten)]
    pub(crate) io: EffectIo,
    #[command(flatten)]
    pub(crate) offsets: EffectArgs,
    #[command(flatten)]
    pub(crate) effect: Multiples,
    #[command(flatten)]
    pub(crate) layout: LayoutArgs,
}

/// Arguments of `toonkit smear lines`.
#[derive(Debug, Args)]
pub(crate) struct LinesArgs {
    #[command(flatten)]
    pub(crate) io: EffectIo,
    #[command(flatten)]
    pub(crate) offsets: EffectArgs,
    #[command(flatten)]
    pub(crate) effect: Lines,
    #[command(flatten)]
    pub(crate) layout: LayoutArgs,
}

/// Refuses an output that cannot hold a mesh that changes per frame (`why` says what
/// changes it): scene files ([`Format::SCENES`]) can, and so can an
/// OBJ/STL sequence (one file per frame, each with its frame's own mesh).
fn require_frames(output: &std::path::Path, layout: &LayoutArgs, why: &str) -> Result<()> {
    let format = Format::from_extension(output);
    if format.is_some_and(Format::holds_one_frame) {
        if layout.layout() != tkio::Layout::Sequence {
            bail!(
                "{}: {why}: write one file per frame with --layout sequence, or a {}",
                output.display(),
                Format::list(&Format::SCENES)
            );
        }
        return Ok(());
    }
    if !matches!(layout.layout(), tkio::Layout::Flipbook) {
        bail!(
            "{}: {why}: the {} layout does not apply (use --layout sequence with .obj or .stl)",
            output.display(),
            layout.layout().name()
        );
    }
    let why = format!(
        "{why}, which only scene files hold: write {}, or an .obj/.stl sequence (--layout sequence)",
        Format::list(&Format::SCENES)
    );
    crate::output::require_scenes(output, &why)
}

/// Runs the style on the prepared input, naming the input in errors.
fn run_style(io: &EffectIo, p: &Prepared, style: &Style) -> Result<Stylized> {
    smear::stylize(p, style).map_err(|e| at_input(&io.input)(e))
}

/// Runs `toonkit smear elongate`.
pub(crate) fn elongate(ctx: &Context, args: ElongateArgs) -> Result<()> {
    let start = Instant::now();
    if Format::from_extension(&args.io.output).is_none() {
        bail!(
            "{}: unknown output extension (use {})",
            args.io.output.display(),
            Format::list(&Format::MESH_ANIMATIONS)
        );
    }
    args.effect.function(&args.offsets)?;
    args.offsets.shaping()?;
    if args.offsets.subdivide.is_some() {
        require_frames(
            &args.io.output,
            &args.layout,
            "--subdivide changes the mesh per frame",
        )?;
    }
    let spinner = crate::progress::spinner("elongating", ctx.json);
    let p = prepare(&args.io, &args.offsets)?;
    let style = args.effect.style(&args.offsets, &p)?;
    let out = run_style(&args.io, &p, &style)?;
    let t = Instant::now();
    let layout = args.layout.layout();
    let written = match out.animation(0) {
        Some(body) => output::write_animation(&args.io.output, body, layout, None, ctx.save)?,
        None => tkio::save_with(&args.io.output, &Output::Flipbook(&out.flipbook), ctx.save)?,
    };
    spinner.finish_and_clear();
    let stats = &out.report.objects[0];
    let body = p.animation(0);
    let summary = json!({
        "input": args.io.input, "output": args.io.output, "files": written,
        "frames": body.frame_count(), "vertices": body.vertex_count(),
        "subdivision_max_stretch": stats.subdivision_max_stretch,
        "subdivision_max_triangles": stats.subdivision_max_triangles,
        "subdivision_max_vertices": stats.subdivision_max_vertices,
        "subdivision_max_error": stats.subdivision_max_error,
        "squashed_frames": stats.squashed_frames, "causal": args.offsets.offsets.causal,
        "objects": p.scene().objects.len(), "step": args.offsets.step,
        "weighted": p.weights(0).is_some(), "camera_speed": p.camera().is_some(),
        "max_displacement": stats.elongation_max, "mean_displacement": stats.elongation_mean,
        "seconds": {"offsets": p.report().seconds, "effect": out.report.seconds.total,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} × {} vertices, elongated in-betweens)",
            output::files(&written),
            output::frames_written(layout, body.frame_count()),
            body.vertex_count()
        )
    });
    Ok(())
}

/// Runs `toonkit smear multiples`.
pub(crate) fn multiples(ctx: &Context, args: MultiplesArgs) -> Result<()> {
    let start = Instant::now();
    require_frames(
        &args.io.output,
        &args.layout,
        "smear multiples adds copies per frame",
    )?;
    let plan = args.effect.plan(&args.offsets)?;
    let spinner = crate::progress::spinner("drawing multiple in-betweens", ctx.json);
    let p = prepare(&args.io, &args.offsets)?;
    let style = args.effect.style(&args.offsets, &plan, &p)?;
    let out = run_style(&args.io, &p, &style)?;
    let t = Instant::now();
    let mut written = Vec::new();
    if args.offsets.subdivide.is_some() {
        written = tkio::save_with(&args.io.output, &Output::Flipbook(&out.flipbook), ctx.save)?;
    }
    let parts: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)> = out
        .flipbook
        .parts
        .iter()
        .filter_map(|part| match part {
            FlipbookPart::Animation { animation, colors } => Some((animation, colors.as_deref())),
            FlipbookPart::Frames { .. } => None,
        })
        .collect();
    if args.offsets.subdivide.is_none() {
        written = tkio::save_with(
            &args.io.output,
            &Output::Parts {
                parts: &parts,
                layout: args.layout.layout(),
            },
            ctx.save,
        )?;
    }
    spinner.finish_and_clear();
    let body = p.animation(0);
    let copies_json: Vec<_> = out.report.objects[0]
        .copies
        .iter()
        .map(|c| {
            json!({"m": c.m, "beta": c.beta, "visible_fraction": c.visible as f64 / c.total.max(1) as f64})
        })
        .collect();
    let summary = json!({
        "input": args.io.input, "output": args.io.output, "files": written,
        "frames": body.frame_count(), "vertices": body.vertex_count(),
        "spacing": plan.spacing, "spacing_keyframed": matches!(&plan.options.spacing, Spacing::Frames(Param::Curve(_))),
        "m_max": plan.m_max, "step": plan.options.step, "copies": copies_json,
        "seconds": {"offsets": p.report().seconds, "effect": out.report.seconds.total,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} copies spaced {:.3} frames)",
            output::files(&written),
            body.frame_count(),
            copies_json.len(),
            plan.spacing
        )
    });
    Ok(())
}

/// Runs `toonkit smear lines`.
pub(crate) fn lines(ctx: &Context, args: LinesArgs) -> Result<()> {
    let start = Instant::now();
    require_frames(
        &args.io.output,
        &args.layout,
        "smear lines adds new lines per frame",
    )?;
    let plan = args.effect.plan(&args.offsets)?;
    let spinner = crate::progress::spinner("tracing motion lines", ctx.json);
    let p = prepare(&args.io, &args.offsets)?;
    let radius = args.effect.radius(&args.offsets, &p)?;
    let style = args.effect.style(&args.offsets, &plan, &p)?;
    let out = run_style(&args.io, &p, &style)?;
    let t = Instant::now();
    let body = (out.animation(0)).context("internal: part 0 of the result is not a point cache")?;
    let Some(FlipbookPart::Frames { meshes, curves, .. }) =
        out.objects[0].lines.and_then(|i| out.flipbook.parts.get(i))
    else {
        bail!("internal: the result has no motion lines");
    };
    let written = tkio::save_with(
        &args.io.output,
        &Output::MotionLines {
            body,
            lines: meshes,
            curves: curves.as_deref(),
        },
        ctx.save,
    )?;
    spinner.finish_and_clear();
    let stats = &out.report.objects[0];
    let per_frame = stats.lines_per_frame.clone().unwrap_or_default();
    let seed_total = stats.seeds.unwrap_or(0);
    let summary = json!({
        "input": args.io.input, "output": args.io.output, "files": written,
        "frames": body.frame_count(), "vertices": body.vertex_count(),
        "seeds": seed_total, "radius": radius, "weighted": p.weights(0).is_some(), "step": args.offsets.step,
        "lines_per_frame": per_frame,
        "seconds": {"offsets": p.report().seconds, "effect": out.report.seconds.total,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} seeds, up to {} lines per frame)",
            output::files(&written),
            meshes.len(),
            seed_total,
            per_frame.iter().max().unwrap_or(&0)
        )
    });
    Ok(())
}
