//! `toonkit smear elongate | multiples | lines`: the smear effects of Basset et al. 2024,
//! Section 4, driven by motion offsets computed with the same options as `smear offsets`.
//!
//! * `elongate IN -o OUT [--preset linear|speed|noise] [--beta-max X] [--kappa K]
//!   [--expr "..."]`: every frame replaced by its elongated in-between (Eq. 10); `.glb`
//!   (flipbook or `--layout morph`), `.usda`, `.pc2`/`.mdd` + rest `.obj`, or an `.obj`
//!   sequence (`--layout sequence`), on the input topology.
//! * `multiples IN -o OUT.glb|OUT.usda --past M --future M [--spacing DF | --overlap N]
//!   [--m-max X] [--opacity-expr "..."]`: the original plus displaced copies with per-vertex
//!   opacity (Eqs. 11–12), each an alpha-blended flipbook node (a Mesh prim in `.usda`).
//! * `lines IN -o OUT.glb|OUT.usda --count K --length-max T [--seed S]
//!   [--length-expr "..."]`: the original as a flipbook plus one motion-line tube mesh per
//!   frame (Eq. 13); in `.usda`, one Mesh prim whose topology changes per frame.
//!
//! Expressions are those of `smear::Expression` (inputs `delta`, `speed`, `weight`, `noise`,
//! `frame`, `m`, `t`, …) with the command's maximum bound as a parameter (`beta_max`,
//! `m_max`, `tau_max`).

use std::path::Path;
use std::time::Instant;

use anim::glam::Vec3;
use anim::{Channel, Clip, MeshAnimation, Node, Scene, SceneMesh};
use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use smear::{
    ElongateOptions, FunctionSpec, LineFrame, LineOptions, LineStyle, MultiplesOptions, Param,
    Spacing, StyleFunction, StyleInput,
};
use tkio::Format;

use super::smear_prepare::{prepare, EffectArgs, EffectIo};
use super::Context;
use crate::output::{self, Layout};

/// Presets of S_E (Section 5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ElongatePreset {
    /// S_E(δ; β_max) = β_max·δ (Eq. 10 example, Fig. 9b, 11b).
    Linear,
    /// S_E(δ; v, β_max) = β_max‖v‖δ (Fig. 11c).
    Speed,
    /// S_E(δ⁻; v, κ, β_max) = β_max‖v‖F1(p(0), κ)δ⁻ (Fig. 11d).
    Noise,
}

/// Arguments of `toonkit smear elongate`.
#[derive(Debug, Args)]
pub struct ElongateArgs {
    #[command(flatten)]
    pub io: EffectIo,
    #[command(flatten)]
    pub offsets: EffectArgs,
    /// Stylization preset S_E.
    #[arg(long, value_enum, default_value_t = ElongatePreset::Linear)]
    pub preset: ElongatePreset,
    /// Maximum elongation β_max in frames; keyframes as FRAME:VALUE,... (e.g. 0:0,12:3).
    #[arg(long, default_value = "1")]
    pub beta_max: Param,
    /// Noise scale κ of the `noise` preset (keyframeable).
    #[arg(long, default_value = "1")]
    pub kappa: Param,
    /// User expression for β (replaces the preset), e.g. "beta_max * speed * past(delta)".
    #[arg(long)]
    pub expr: Option<String>,
    /// Output layout.
    #[arg(long, value_enum, default_value_t = Layout::Flipbook)]
    pub layout: Layout,
}

/// Arguments of `toonkit smear multiples`.
#[derive(Debug, Args)]
pub struct MultiplesArgs {
    #[command(flatten)]
    pub io: EffectIo,
    #[command(flatten)]
    pub offsets: EffectArgs,
    /// Copies in the past, m_p; keyframes (FRAME:VALUE,...) fade copies in and out.
    #[arg(long, default_value = "1")]
    pub past: Param,
    /// Copies in the future, m_n; keyframeable.
    #[arg(long, default_value = "1")]
    pub future: Param,
    /// Temporal spacing Δf between copies, in frames; keyframes as FRAME:VALUE,...
    #[arg(long, conflicts_with = "overlap")]
    pub spacing: Option<Param>,
    /// Copies overlapping between consecutive frames, N∩: Δf = 1/(m_p + m_n + 1 − N∩);
    /// keyframeable.
    #[arg(long)]
    pub overlap: Option<Param>,
    /// m_max of Eq. 12 (default: max(m_p, m_n); keyframeable).
    #[arg(long)]
    pub m_max: Option<Param>,
    /// User expression for the opacity (replaces Eq. 12), e.g. "step(delta * m)".
    #[arg(long)]
    pub opacity_expr: Option<String>,
}

/// Arguments of `toonkit smear lines`.
#[derive(Debug, Args)]
pub struct LinesArgs {
    #[command(flatten)]
    pub io: EffectIo,
    #[command(flatten)]
    pub offsets: EffectArgs,
    /// Number of lines K (random surface points, area-weighted). Keyframes (FRAME:VALUE,...)
    /// sample as many seeds as the largest key and draw a fixed random subset per frame.
    #[arg(long, default_value_t = Param::Constant(smear::DEFAULT_LINE_COUNT as f32))]
    pub count: Param,
    /// Maximum length τ_max in frames: S_L(δ; τ_max) = τ_max·δ (Eq. 13); keyframeable.
    #[arg(long, default_value = "1")]
    pub length_max: Param,
    /// Seed of the random seed placement.
    #[arg(long, default_value_t = smear::DEFAULT_SEED)]
    pub seed: u64,
    /// User expression for τ (replaces the linear one), e.g. "tau_max * speed * past(delta)".
    #[arg(long)]
    pub length_expr: Option<String>,
    /// Tube radius in scene units (default: 0.002 × bounding-box diagonal); keyframeable.
    #[arg(long, conflicts_with = "thickness_expr")]
    pub thickness: Option<Param>,
    /// User expression for the tube radius along the line (`t` = 0 at the surface), e.g.
    /// "0.01 * (1 - t)" for tapering lines.
    #[arg(long)]
    pub thickness_expr: Option<String>,
    /// User expression for the opacity along the line (`t` = 0 at the surface), e.g. "1 - t".
    #[arg(long)]
    pub opacity_expr: Option<String>,
    /// Gap between surface and line, in frames along the trajectory; keyframeable.
    #[arg(long, default_value = "0")]
    pub gap: Param,
    /// Seeds slower than this (units per frame) draw no line; keyframeable.
    #[arg(long, default_value = "0")]
    pub min_speed: Param,
    /// Line colour, linear R,G,B in [0, 1] (default near-black).
    #[arg(long, value_delimiter = ',')]
    pub color: Vec<f32>,
    /// Only trace the past (τ clamped to ≤ 0).
    #[arg(long)]
    pub past_only: bool,
    /// Sides of each tube.
    #[arg(long, default_value_t = smear::DEFAULT_LINE_SIDES)]
    pub sides: usize,
    /// Rings along each line.
    #[arg(long, default_value_t = smear::DEFAULT_LINE_SAMPLES)]
    pub samples: usize,
}

fn compile(spec: FunctionSpec, what: &str) -> Result<StyleFunction> {
    spec.compile().map_err(|e| anyhow::anyhow!("{what}: {e}"))
}

fn require_scene_output(path: &Path, what: &str) -> Result<()> {
    if !matches!(
        Format::from_extension(path),
        Some(Format::Glb | Format::Usda)
    ) {
        bail!("{}: smear {what} writes .glb or .usda", path.display());
    }
    Ok(())
}

/// True when `path` names a USD layer (`.usda`).
fn is_usda(path: &Path) -> bool {
    Format::from_extension(path) == Some(Format::Usda)
}

/// Runs `toonkit smear elongate`.
pub fn elongate(ctx: &Context, args: ElongateArgs) -> Result<()> {
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
    let style = compile(spec, "--expr")?;
    let spinner = crate::progress::spinner("elongating", ctx.json);
    let p = prepare(&args.io, &args.offsets, None)?;
    let t = Instant::now();
    let inputs = p.vertex_inputs()?;
    let options = ElongateOptions {
        step: args.offsets.step,
    };
    let out = smear::elongate(&p.merged, &inputs, &style, &options)?;
    let effect_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let written = output::write_animation(&args.io.output, &out, args.layout, None)?;
    spinner.finish_and_clear();
    let (mut max_d, mut sum_d) = (0.0f32, 0.0f64);
    for (a, b) in out.positions().iter().zip(p.merged.positions()) {
        let d = a.distance(*b);
        max_d = max_d.max(d);
        sum_d += d as f64;
    }
    let mean_d = sum_d / out.positions().len().max(1) as f64;
    let summary = json!({
        "input": args.io.input, "output": args.io.output, "files": written,
        "frames": out.frame_count(), "vertices": out.vertex_count(),
        "objects": p.sampled.objects.len(), "step": options.step,
        "weighted": p.weights.is_some(), "camera_speed": p.camera.is_some(),
        "max_displacement": max_d, "mean_displacement": mean_d,
        "seconds": {"offsets": p.seconds, "effect": effect_seconds,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames × {} vertices, elongated in-betweens)",
            args.io.output.display(),
            out.frame_count(),
            out.vertex_count()
        )
    });
    Ok(())
}

/// Runs `toonkit smear multiples`.
pub fn multiples(ctx: &Context, args: MultiplesArgs) -> Result<()> {
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
    let style = compile(spec, "--opacity-expr")?;
    let spinner = crate::progress::spinner("drawing multiple in-betweens", ctx.json);
    let p = prepare(&args.io, &args.offsets, None)?;
    let t = Instant::now();
    let inputs = p.vertex_inputs()?;
    let copies = smear::multiples(&p.merged, &inputs, &style, &options)?;
    let effect_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let colors: Vec<Vec<[f32; 4]>> = copies
        .iter()
        .map(|c| c.alpha.iter().map(|&a| [1.0, 1.0, 1.0, a]).collect())
        .collect();
    let mut parts: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)> = vec![(&p.merged, None)];
    parts.extend(
        copies
            .iter()
            .zip(&colors)
            .map(|(c, col)| (&c.animation, Some(col.as_slice()))),
    );
    let bytes = if is_usda(&args.io.output) {
        tkio::usda::write_parts(&parts).map(String::into_bytes)
    } else {
        tkio::gltf::write_animations(&parts, tkio::gltf::AnimationLayout::Flipbook)
    }
    .map_err(|e| e.at(&args.io.output))?;
    tkio::write_atomic(&args.io.output, &bytes)?;
    spinner.finish_and_clear();
    let copies_json: Vec<_> = copies
        .iter()
        .map(|c| {
            let visible = c.alpha.iter().filter(|a| **a > 0.0).count();
            json!({"m": c.m, "beta": c.beta, "visible_fraction": visible as f64 / c.alpha.len().max(1) as f64})
        })
        .collect();
    let summary = json!({
        "input": args.io.input, "output": args.io.output,
        "frames": p.merged.frame_count(), "vertices": p.merged.vertex_count(),
        "spacing": df, "spacing_keyframed": matches!(&options.spacing, Spacing::Frames(Param::Curve(_))),
        "m_max": m_max, "step": options.step, "copies": copies_json,
        "seconds": {"offsets": p.seconds, "effect": effect_seconds,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} copies spaced {df:.3} frames)",
            args.io.output.display(),
            p.merged.frame_count(),
            copies.len()
        )
    });
    Ok(())
}

/// A flipbook scene: the body (one node per frame) and the lines (one node per frame, none
/// when the frame has no line), visibility keyed with STEP scale.
fn lines_scene(body: &MeshAnimation, lines: &[LineFrame]) -> Scene {
    let frames = body.frame_count();
    let times: Vec<f32> = (0..frames).map(|f| f as f32 / body.fps).collect();
    let mut scene = Scene::default();
    let mut channels = Vec::new();
    let mut group =
        |scene: &mut Scene, name: &str, mesh_of: &dyn Fn(usize) -> Option<anim::Mesh>| {
            let root = scene.nodes.len();
            scene.nodes.push(Node {
                name: name.to_string(),
                ..Default::default()
            });
            for f in 0..frames {
                let id = scene.nodes.len();
                let mesh = mesh_of(f).filter(|m| m.vertex_count() > 0).map(|m| {
                    scene.meshes.push(SceneMesh {
                        mesh: m,
                        ..Default::default()
                    });
                    scene.meshes.len() - 1
                });
                let mut node = Node {
                    name: format!("{name}_f{:04}", f + 1),
                    parent: Some(root),
                    mesh,
                    ..Default::default()
                };
                if f != 0 {
                    node.transform.scale = Vec3::ZERO;
                }
                scene.nodes.push(node);
                scene.nodes[root].children.push(id);
                channels.extend(Channel::flipbook_visibility(id, f, &times));
            }
        };
    group(&mut scene, &body.mesh.name, &|f| Some(body.mesh_at(f)));
    group(&mut scene, "motion_lines", &|f| Some(lines[f].mesh.clone()));
    if !channels.is_empty() {
        scene.clips.push(Clip {
            name: format!("{}_lines", body.mesh.name),
            channels,
        });
    }
    scene
}

/// Runs `toonkit smear lines`.
pub fn lines(ctx: &Context, args: LinesArgs) -> Result<()> {
    let start = Instant::now();
    require_scene_output(&args.io.output, "lines")?;
    if let Some(t) = &args.thickness {
        if t.validate("--thickness", (0.0, true), (f32::MAX, false))
            .is_err()
        {
            bail!("--thickness must be positive numbers, got {t:?}");
        }
    }
    let length_spec = match &args.length_expr {
        Some(e) => FunctionSpec::expr(e, &[("tau_max", args.length_max.clone())]),
        None => args
            .offsets
            .weighted(FunctionSpec::linear(args.length_max.clone())),
    };
    let length = compile(length_spec, "--length-expr")?;
    let opacity = match &args.opacity_expr {
        Some(e) => Some(compile(FunctionSpec::expr(e, &[]), "--opacity-expr")?),
        None => None,
    };
    let spinner = crate::progress::spinner("tracing motion lines", ctx.json);
    if args
        .count
        .validate("--count", (0.0, false), (1e7, false))
        .is_err()
    {
        bail!(
            "--count must be a number of lines ≥ 0, got {:?}",
            args.count
        );
    }
    let seed_count = args.count.max_value().round() as usize;
    let mut p = prepare(&args.io, &args.offsets, Some((seed_count, args.seed)))?;
    let t = Instant::now();
    let (seeds, seed_total) = p
        .seed_inputs()
        .map_err(|e| anyhow::anyhow!("{}: {e:#}", args.io.input.display()))?;
    let radius = args.thickness.clone().unwrap_or(Param::Constant(
        smear::DEFAULT_LINE_THICKNESS * p.merged.bbox().diagonal(),
    ));
    let thickness = match &args.thickness_expr {
        Some(e) => compile(FunctionSpec::expr(e, &[]), "--thickness-expr")?,
        None => compile(
            FunctionSpec::stages(vec![smear::Stage::Set {
                value: radius.clone(),
            }]),
            "--thickness",
        )?,
    };
    let opaque = |_: &StyleInput| 1.0;
    let style = LineStyle {
        length: &length,
        thickness: &thickness,
        opacity: match &opacity {
            Some(o) => o,
            None => &opaque,
        },
    };
    let line_options = LineOptions {
        sides: args.sides,
        samples: args.samples,
        gap: args.gap.clone(),
        min_speed: args.min_speed.clone(),
        count: args.count.is_keyframed().then(|| args.count.clone()),
        color: match args.color.as_slice() {
            [] => LineOptions::default().color,
            &[r, g, b] => [r, g, b].map(Param::Constant),
            c => bail!(
                "--color takes R,G,B (3 numbers in [0, 1]), got {} numbers",
                c.len()
            ),
        },
        past_only: args.past_only,
        step: args.offsets.step,
    };
    let frames = smear::motion_lines(&seeds, &style, &line_options)?;
    let effect_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let bytes = if is_usda(&args.io.output) {
        use tkio::usda::{UsdMesh, UsdStage};
        let lines = UsdMesh::frames("motion_lines", frames.iter().map(|f| &f.mesh).collect());
        let stage = UsdStage::new(
            p.merged.fps,
            vec![UsdMesh::animation(&p.merged, None), lines],
        );
        tkio::usda::write(&stage).map(String::into_bytes)
    } else {
        tkio::gltf::write_glb(&lines_scene(&p.merged, &frames))
    }
    .map_err(|e| e.at(&args.io.output))?;
    tkio::write_atomic(&args.io.output, &bytes)?;
    spinner.finish_and_clear();
    let per_frame: Vec<usize> = frames.iter().map(|f| f.lines).collect();
    let summary = json!({
        "input": args.io.input, "output": args.io.output,
        "frames": p.merged.frame_count(), "vertices": p.merged.vertex_count(),
        "seeds": seed_total, "radius": radius, "weighted": p.weights.is_some(), "step": line_options.step,
        "lines_per_frame": per_frame,
        "seconds": {"offsets": p.seconds, "effect": effect_seconds,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} seeds, up to {} lines per frame)",
            args.io.output.display(),
            frames.len(),
            seed_total,
            per_frame.iter().max().unwrap_or(&0)
        )
    });
    Ok(())
}
