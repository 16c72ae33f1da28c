//! `toonkit smear elongate | multiples | lines`: the smear effects of SMEAR Section 4, driven
//! by motion offsets computed with the same options as `smear offsets`, on all objects merged
//! into one.
//!
//! * `elongate IN -o OUT [--preset linear|speed|noise] [--beta-max X] [--kappa K]
//!   [--expr "..."]`: every frame replaced by its elongated in-between (SMEAR Eq. 10); `.glb`
//!   (flipbook or `--layout morph`), `.usda`, `.pc2`/`.mdd` + rest `.obj`, or an `.obj`
//!   sequence (`--layout sequence`), on the input topology.
//! * `multiples IN -o OUT.glb|OUT.usda --past M --future M [--spacing DF | --overlap N]
//!   [--m-max X] [--opacity-expr "..."]`: the original plus displaced copies with per-vertex
//!   opacity (SMEAR Eqs. 11–12), each an alpha-blended flipbook node (a Mesh prim in `.usda`).
//! * `lines IN -o OUT.glb|OUT.usda --count K --length-max T [--seed S]
//!   [--length-expr "..."]`: the original as a flipbook plus one motion-line tube mesh per
//!   frame (SMEAR Eq. 13); in `.usda`, one Mesh prim whose topology changes per frame.
//!
//! Each command turns its flags into a [`smear::Style`] and calls [`smear::stylize`].
//! Expressions are those of `smear::Expression` (inputs `delta`, `speed`, `weight`, `noise`,
//! `frame`, `m`, `t`, …) with the command's maximum bound as a parameter (`beta_max`,
//! `m_max`, `tau_max`).

use std::path::Path;
use std::time::Instant;

use anim::{FlipbookPart, MeshAnimation};
use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use smear::{
    ElongateStyle, FunctionSpec, LinesStyle, MultiplesOptions, MultiplesStyle, Param, Prepared,
    Spacing, Stage, Style, Stylized,
};
use tkio::{Format, Output};

use super::{at_input, prepare, Context, EffectArgs, EffectIo};
use crate::output;
use crate::shared::{self, LayoutArgs};

/// Presets of S_E (SMEAR Section 5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ElongatePreset {
    /// S_E(δ; β_max) = β_max·δ (SMEAR Eq. 10 example, Fig. 9b, 11b).
    Linear,
    /// S_E(δ; v, β_max) = β_max‖v‖δ (Fig. 11c).
    Speed,
    /// S_E(δ⁻; v, κ, β_max) = β_max‖v‖F1(p(0), κ)δ⁻ (Fig. 11d).
    Noise,
}

/// Arguments of `toonkit smear elongate`.
#[derive(Debug, Args)]
pub(crate) struct ElongateArgs {
    #[command(flatten)]
    pub(crate) io: EffectIo,
    #[command(flatten)]
    pub(crate) offsets: EffectArgs,
    /// Stylization preset S_E.
    #[arg(long, value_enum, default_value_t = ElongatePreset::Linear)]
    pub(crate) preset: ElongatePreset,
    /// Maximum elongation β_max in frames; keyframes as FRAME:VALUE,... (e.g. 0:0,12:3).
    #[arg(long, default_value = "1")]
    pub(crate) beta_max: Param,
    /// Noise scale κ of the `noise` preset (keyframeable).
    #[arg(long, default_value = "1")]
    pub(crate) kappa: Param,
    /// User expression for β (replaces the preset), e.g. "beta_max * speed * past(delta)".
    #[arg(long)]
    pub(crate) expr: Option<String>,
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
    /// Copies in the past, m_p; keyframes (FRAME:VALUE,...) fade copies in and out.
    #[arg(long, default_value = "1")]
    pub(crate) past: Param,
    /// Copies in the future, m_n; keyframeable.
    #[arg(long, default_value = "1")]
    pub(crate) future: Param,
    /// Temporal spacing Δf between copies, in frames; keyframes as FRAME:VALUE,...
    #[arg(long, conflicts_with = "overlap")]
    pub(crate) spacing: Option<Param>,
    /// Copies overlapping between consecutive frames, N∩: Δf = 1/(m_p + m_n + 1 − N∩);
    /// keyframeable.
    #[arg(long)]
    pub(crate) overlap: Option<Param>,
    /// m_max of SMEAR Eq. 12 (default: max(m_p, m_n); keyframeable).
    #[arg(long)]
    pub(crate) m_max: Option<Param>,
    /// User expression for the opacity (replaces SMEAR Eq. 12), e.g. "step(delta * m)".
    #[arg(long)]
    pub(crate) opacity_expr: Option<String>,
}

/// Arguments of `toonkit smear lines`.
#[derive(Debug, Args)]
pub(crate) struct LinesArgs {
    #[command(flatten)]
    pub(crate) io: EffectIo,
    #[command(flatten)]
    pub(crate) offsets: EffectArgs,
    /// Number of lines K (random surface points, area-weighted). Keyframes (FRAME:VALUE,...)
    /// sample as many seeds as the largest key and draw a fixed random subset per frame.
    #[arg(long, default_value_t = Param::Constant(smear::DEFAULT_LINE_COUNT as f32))]
    pub(crate) count: Param,
    /// Maximum length τ_max in frames: S_L(δ; τ_max) = τ_max·δ (SMEAR Eq. 13); keyframeable.
    #[arg(long, default_value = "1")]
    pub(crate) length_max: Param,
    #[command(flatten)]
    pub(crate) seed: crate::shared::SeedArg,
    /// User expression for τ (replaces the linear one), e.g. "tau_max * speed * past(delta)".
    #[arg(long)]
    pub(crate) length_expr: Option<String>,
    /// Tube radius in scene units (default: 0.002 × bounding-box diagonal); keyframeable.
    #[arg(long, conflicts_with = "thickness_expr")]
    pub(crate) thickness: Option<Param>,
    /// User expression for the tube radius along the line (`t` = 0 at the surface), e.g.
    /// "0.01 * (1 - t)" for tapering lines.
    #[arg(long)]
    pub(crate) thickness_expr: Option<String>,
    /// User expression for the opacity along the line (`t` = 0 at the surface), e.g. "1 - t".
    #[arg(long)]
    pub(crate) opacity_expr: Option<String>,
    /// Gap between surface and line, in frames along the trajectory; keyframeable.
    #[arg(long, default_value = "0")]
    pub(crate) gap: Param,
    /// Seeds slower than this (units per frame) draw no line; keyframeable.
    #[arg(long, default_value = "0")]
    pub(crate) min_speed: Param,
    /// Line colour, linear R,G,B in [0, 1] (default near-black).
    #[arg(long, value_delimiter = ',')]
    pub(crate) color: Vec<f32>,
    /// Only trace the past (τ clamped to ≤ 0).
    #[arg(long)]
    pub(crate) past_only: bool,
    /// Sides of each tube.
    #[arg(long, default_value_t = smear::DEFAULT_LINE_SIDES)]
    pub(crate) sides: usize,
    /// Rings along each line.
    #[arg(long, default_value_t = smear::DEFAULT_LINE_SAMPLES)]
    pub(crate) samples: usize,
}

/// Checks that a user function compiles, naming the flag that gave it.
fn check(spec: &FunctionSpec, flag: &str) -> Result<()> {
    spec.compile()
        .map(|_| ())
        .map_err(|e| anyhow!("{flag}: {e}"))
}

fn require_scene_output(path: &Path, what: &str) -> Result<()> {
    if !Format::from_extension(path).is_some_and(Format::holds_scenes) {
        bail!(
            "{}: smear {what} writes .glb, .usda, .usdc, .usdz or .abc",
            path.display()
        );
    }
    Ok(())
}

/// A style with only the offsets `p` was prepared with and the subdivision and contact
/// settings of the flags (effects are added by the caller).
fn base_style(p: &Prepared, a: &EffectArgs) -> Result<Style> {
    let (subdivide, contact) = a.shaping()?;
    Ok(Style {
        offsets: p.options().offsets.clone(),
        subdivide,
        contact,
        ..Style::default()
    })
}

/// Refuses an output format that cannot hold a mesh whose topology changes per frame.
fn require_per_frame_topology(path: &Path) -> Result<()> {
    if !Format::from_extension(path).is_some_and(Format::holds_scenes) {
        bail!(
            "{}: --subdivide changes the mesh per frame, which .pc2/.mdd/.obj point caches cannot \
             store (one vertex count for all frames); write .glb, .usda, .usdc, .usdz or .abc",
            path.display()
        );
    }
    Ok(())
}

/// Runs the style on the prepared input, naming the input in errors.
fn run_style(io: &EffectIo, p: &Prepared, style: &Style) -> Result<Stylized> {
    smear::stylize(p, style).map_err(|e| at_input(&io.input)(e))
}

/// The point cache of part `i` of a result (the body is part 0, copies follow).
fn part(out: &Stylized, i: usize) -> Result<&MeshAnimation> {
    out.animation(i)
        .ok_or_else(|| anyhow!("internal: part {i} of the result is not a point cache"))
}

/// Runs `toonkit smear elongate`.
pub(crate) fn elongate(ctx: &Context, args: ElongateArgs) -> Result<()> {
    let start = Instant::now();
    if Format::from_extension(&args.io.output).is_none() {
        bail!(
            "{}: unknown output extension (use .glb, .usda, .pc2, .mdd or .obj)",
            args.io.output.display()
        );
    }
    let spec = match &args.expr {
        Some(e) => FunctionSpec::expr(e, &[("beta_max", args.beta_max.clone())]),
        None => args.offsets.weighted(match args.preset {
            ElongatePreset::Linear => FunctionSpec::linear(args.beta_max.clone()),
            ElongatePreset::Speed => FunctionSpec::speed(args.beta_max.clone()),
            ElongatePreset::Noise => FunctionSpec::noise(args.kappa.clone(), args.beta_max.clone()),
        }),
    };
    check(
        &spec,
        if args.expr.is_some() {
            "--expr"
        } else {
            "--beta-max/--kappa"
        },
    )?;
    args.offsets.shaping()?;
    if args.offsets.subdivide.is_some() {
        require_per_frame_topology(&args.io.output)?;
    }
    let spinner = crate::progress::spinner("elongating", ctx.json);
    let p = prepare(&args.io, &args.offsets)?;
    let style = Style {
        elongate: Some(ElongateStyle {
            enabled: true,
            step: args.offsets.step,
            function: spec,
        }),
        ..base_style(&p, &args.offsets)?
    };
    let out = run_style(&args.io, &p, &style)?;
    let t = Instant::now();
    let layout = args.layout.layout();
    let written = match out.animation(0) {
        Some(body) => output::write_animation(&args.io.output, body, layout, None, ctx.save)?,
        None => {
            tkio::save_with(&args.io.output, &Output::Flipbook(&out.flipbook), ctx.save)?;
            vec![args.io.output.clone()]
        }
    };
    spinner.finish_and_clear();
    let stats = &out.report.objects[0];
    let body = p.animation(0);
    let summary = json!({
        "input": args.io.input, "output": args.io.output, "files": written,
        "frames": body.frame_count(), "vertices": body.vertex_count(),
        "subdivision_max_stretch": stats.subdivision_max_stretch,
        "subdivision_max_triangles": stats.subdivision_max_triangles,
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
            shared::files(&written),
            shared::frames_written(layout, body.frame_count()),
            body.vertex_count()
        )
    });
    Ok(())
}

/// Runs `toonkit smear multiples`.
pub(crate) fn multiples(ctx: &Context, args: MultiplesArgs) -> Result<()> {
    let start = Instant::now();
    require_scene_output(&args.io.output, "multiples")?;
    let spacing = match (args.spacing.clone(), args.overlap.clone()) {
        (_, Some(n)) => Spacing::Overlap(n),
        (Some(df), None) => Spacing::Frames(df),
        (None, None) => Spacing::Frames(smear::DEFAULT_SPACING.into()),
    };
    let options = MultiplesOptions {
        past: args.past.clone(),
        future: args.future.clone(),
        spacing,
        step: args.offsets.step,
    };
    if options.indices().is_empty() {
        bail!("--past and --future are both 0: there is no copy to draw");
    }
    let df = options.spacing_at(0.0)?;
    let largest = args.past.max_value().max(args.future.max_value()).round();
    let m_max = args.m_max.clone().unwrap_or(Param::Constant(largest));
    let spec = match &args.opacity_expr {
        Some(e) => FunctionSpec::expr(e, &[("m_max", m_max.clone())]),
        None => args
            .offsets
            .weighted(FunctionSpec::multiples(m_max.clone())),
    };
    check(&spec, "--opacity-expr")?;
    let spinner = crate::progress::spinner("drawing multiple in-betweens", ctx.json);
    let p = prepare(&args.io, &args.offsets)?;
    let style = Style {
        multiples: Some(MultiplesStyle {
            enabled: true,
            past: args.past.clone(),
            future: args.future.clone(),
            spacing: args.spacing.clone(),
            overlap: args.overlap.clone(),
            step: args.offsets.step,
            opacity: Some(spec),
            color: [1.0; 3],
        }),
        ..base_style(&p, &args.offsets)?
    };
    let out = run_style(&args.io, &p, &style)?;
    let t = Instant::now();
    if args.offsets.subdivide.is_some() {
        tkio::save_with(&args.io.output, &Output::Flipbook(&out.flipbook), ctx.save)?;
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
        tkio::save_with(
            &args.io.output,
            &Output::Parts {
                parts: &parts,
                layout: tkio::Layout::Flipbook,
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
        "input": args.io.input, "output": args.io.output,
        "frames": body.frame_count(), "vertices": body.vertex_count(),
        "spacing": df, "spacing_keyframed": matches!(&options.spacing, Spacing::Frames(Param::Curve(_))),
        "m_max": m_max, "step": options.step, "copies": copies_json,
        "seconds": {"offsets": p.report().seconds, "effect": out.report.seconds.total,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} copies spaced {df:.3} frames)",
            args.io.output.display(),
            body.frame_count(),
            copies_json.len()
        )
    });
    Ok(())
}

/// Runs `toonkit smear lines`.
pub(crate) fn lines(ctx: &Context, args: LinesArgs) -> Result<()> {
    let start = Instant::now();
    require_scene_output(&args.io.output, "lines")?;
    if let Some(t) = &args.thickness {
        if t.validate("--thickness", (0.0, true), (f32::MAX, false))
            .is_err()
        {
            bail!("--thickness {t}: the tube radius must be a positive number (scene units)");
        }
    }
    let length = match &args.length_expr {
        Some(e) => FunctionSpec::expr(e, &[("tau_max", args.length_max.clone())]),
        None => args
            .offsets
            .weighted(FunctionSpec::linear(args.length_max.clone())),
    };
    check(&length, "--length-expr")?;
    let opacity = match &args.opacity_expr {
        Some(e) => FunctionSpec::expr(e, &[]),
        None => FunctionSpec::stages(vec![Stage::Set { value: 1.0.into() }]),
    };
    check(&opacity, "--opacity-expr")?;
    let spinner = crate::progress::spinner("tracing motion lines", ctx.json);
    if args
        .count
        .validate("--count", (0.0, false), (1e7, false))
        .is_err()
    {
        bail!(
            "--count {}: give a number of lines from 0 to 10000000",
            args.count
        );
    }
    let color = match args.color.as_slice() {
        [] => smear::LineOptions::default().color,
        &[r, g, b] => [r, g, b].map(Param::Constant),
        c => bail!(
            "--color takes R,G,B (3 numbers in [0, 1]), got {} numbers",
            c.len()
        ),
    };
    let p = prepare(&args.io, &args.offsets)?;
    let radius = args.thickness.clone().unwrap_or(Param::Constant(
        smear::DEFAULT_LINE_THICKNESS * p.animation(0).bbox().diagonal(),
    ));
    let thickness = match &args.thickness_expr {
        Some(e) => FunctionSpec::expr(e, &[]),
        None => FunctionSpec::stages(vec![Stage::Set {
            value: radius.clone(),
        }]),
    };
    let flag = if args.thickness_expr.is_some() {
        "--thickness-expr"
    } else {
        "--thickness"
    };
    check(&thickness, flag)?;
    let style = Style {
        lines: Some(LinesStyle {
            enabled: true,
            count: args.count.clone(),
            seed: args.seed.or(smear::DEFAULT_SEED),
            gap: args.gap.clone(),
            min_speed: args.min_speed.clone(),
            past_only: args.past_only,
            sides: args.sides,
            samples: args.samples,
            step: args.offsets.step,
            color,
            length,
            thickness: Some(thickness),
            opacity,
        }),
        ..base_style(&p, &args.offsets)?
    };
    let out = run_style(&args.io, &p, &style)?;
    let t = Instant::now();
    let body = part(&out, 0)?;
    let Some(FlipbookPart::Frames { meshes, .. }) =
        out.objects[0].lines.and_then(|i| out.flipbook.parts.get(i))
    else {
        bail!("internal: the result has no motion lines");
    };
    tkio::save_with(
        &args.io.output,
        &Output::MotionLines {
            body,
            lines: meshes,
        },
        ctx.save,
    )?;
    spinner.finish_and_clear();
    let stats = &out.report.objects[0];
    let per_frame = stats.lines_per_frame.clone().unwrap_or_default();
    let seed_total = stats.seeds.unwrap_or(0);
    let summary = json!({
        "input": args.io.input, "output": args.io.output,
        "frames": body.frame_count(), "vertices": body.vertex_count(),
        "seeds": seed_total, "radius": radius, "weighted": p.weights(0).is_some(), "step": args.offsets.step,
        "lines_per_frame": per_frame,
        "seconds": {"offsets": p.report().seconds, "effect": out.report.seconds.total,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} seeds, up to {} lines per frame)",
            args.io.output.display(),
            meshes.len(),
            seed_total,
            per_frame.iter().max().unwrap_or(&0)
        )
    });
    Ok(())
}
