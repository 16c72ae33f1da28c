//! `toonkit smear elongate | multiples | lines`: the smear effects of Basset et al. 2024,
//! Section 4, driven by motion offsets computed with the same options as `smear offsets`.
//!
//! * `elongate IN -o OUT [--preset linear|speed|noise] [--beta-max X] [--kappa K]
//!   [--expr "..."]`: every frame replaced by its elongated in-between (Eq. 10); `.glb`
//!   (flipbook or `--layout morph`), `.pc2`/`.mdd` + rest `.obj`, or an `.obj` sequence
//!   (`--layout sequence`), on the input topology.
//! * `multiples IN -o OUT.glb --past M --future M [--spacing DF | --overlap N] [--m-max X]
//!   [--opacity-expr "..."]`: the original plus displaced copies with per-vertex opacity
//!   (Eqs. 11–12), each an alpha-blended flipbook node.
//! * `lines IN -o OUT.glb --count K --length-max T [--seed S] [--length-expr "..."]`: the
//!   original as a flipbook plus one motion-line tube mesh per frame (Eq. 13).
//!
//! Expressions are those of `smear::Expression` (inputs `delta`, `speed`, `weight`, `noise`,
//! `frame`, `m`, `t`, …) with the command's maximum bound as a parameter (`beta_max`,
//! `m_max`, `tau_max`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anim::glam::Vec3;
use anim::{Channel, Clip, MeshAnimation, Node, Scene, SceneMesh};
use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use smear::{
    EffectInputs, ElongateOptions, FunctionSpec, LineFrame, LineOptions, LineStyle, MotionOffsets,
    MultiplesOptions, OffsetSolver, Spacing, StyleFunction, StyleInput, SurfacePoint,
};
use tkio::Format;

use super::smear::OffsetArgs;
use super::Context;
use crate::input::{self, InputArgs};
use crate::output::{self, Layout};

/// Options of every effect: the motion-offset options of `toonkit smear offsets` and the
/// frame step.
#[derive(Debug, Clone, Args)]
pub struct EffectArgs {
    #[command(flatten)]
    pub offsets: OffsetArgs,
    /// Frame step: 2 = "on twos" (displacements scaled by 2, drawings held two frames).
    #[arg(long, default_value_t = smear::DEFAULT_FRAME_STEP)]
    pub step: usize,
}

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
    /// Input animation (glTF/GLB with skins, OBJ sequence, PC2/MDD + rest OBJ).
    pub input: PathBuf,
    /// Output: `.glb`, `.pc2`, `.mdd` or `.obj` (with `--layout sequence`: one per frame).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub input_args: InputArgs,
    #[command(flatten)]
    pub offsets: EffectArgs,
    /// Stylization preset S_E.
    #[arg(long, value_enum, default_value_t = ElongatePreset::Linear)]
    pub preset: ElongatePreset,
    /// Maximum elongation β_max in frames.
    #[arg(long, default_value_t = 1.0)]
    pub beta_max: f32,
    /// Noise scale κ of the `noise` preset.
    #[arg(long, default_value_t = 1.0)]
    pub kappa: f32,
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
    /// Input animation.
    pub input: PathBuf,
    /// Output `.glb` (original + copies, alpha-blended flipbooks).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub input_args: InputArgs,
    #[command(flatten)]
    pub offsets: EffectArgs,
    /// Copies in the past, m_p.
    #[arg(long, default_value_t = 1)]
    pub past: usize,
    /// Copies in the future, m_n.
    #[arg(long, default_value_t = 1)]
    pub future: usize,
    /// Temporal spacing Δf between copies, in frames.
    #[arg(long, conflicts_with = "overlap")]
    pub spacing: Option<f32>,
    /// Copies overlapping between consecutive frames, N∩: Δf = 1/(m_p + m_n + 1 − N∩).
    #[arg(long)]
    pub overlap: Option<usize>,
    /// m_max of Eq. 12 (default: max(m_p, m_n)).
    #[arg(long)]
    pub m_max: Option<f32>,
    /// User expression for the opacity (replaces Eq. 12), e.g. "step(delta * m)".
    #[arg(long)]
    pub opacity_expr: Option<String>,
}

/// Arguments of `toonkit smear lines`.
#[derive(Debug, Args)]
pub struct LinesArgs {
    /// Input animation.
    pub input: PathBuf,
    /// Output `.glb` (original flipbook + a motion-line mesh per frame).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub input_args: InputArgs,
    #[command(flatten)]
    pub offsets: EffectArgs,
    /// Number of seeds K (random surface points, area-weighted).
    #[arg(long, default_value_t = smear::DEFAULT_LINE_COUNT)]
    pub count: usize,
    /// Maximum length τ_max in frames: S_L(δ; τ_max) = τ_max·δ (Eq. 13).
    #[arg(long, default_value_t = 1.0)]
    pub length_max: f32,
    /// Seed of the random seed placement.
    #[arg(long, default_value_t = smear::DEFAULT_SEED)]
    pub seed: u64,
    /// User expression for τ (replaces the linear one), e.g. "tau_max * speed * past(delta)".
    #[arg(long)]
    pub length_expr: Option<String>,
    /// Tube radius in scene units (default: 0.002 × bounding-box diagonal).
    #[arg(long)]
    pub thickness: Option<f32>,
    /// User expression for the opacity along the line (`t` = 0 at the surface), e.g. "1 - t".
    #[arg(long)]
    pub opacity_expr: Option<String>,
    /// Gap between surface and line, in frames along the trajectory.
    #[arg(long, default_value_t = 0.0)]
    pub gap: f32,
    /// Seeds slower than this (units per frame) draw no line.
    #[arg(long, default_value_t = 0.0)]
    pub min_speed: f32,
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

/// The input opened, merged, with its motion offsets.
struct Prepared {
    sampled: anim::SampledScene,
    merged: MeshAnimation,
    offsets: MotionOffsets,
    seeds: Option<(Vec<SurfacePoint>, MotionOffsets)>,
    seconds: f64,
}

/// Opens and merges the input and computes its offsets; with `seeds = Some((K, seed))` also
/// samples K motion-line seeds (sorted by triangle) and their offsets, with the same solver.
fn prepare(
    path: &Path,
    input_args: &InputArgs,
    a: &EffectArgs,
    seeds: Option<(usize, u64)>,
) -> Result<Prepared> {
    let start = Instant::now();
    if a.step == 0 {
        bail!("--step must be ≥ 1 (1 = on ones, 2 = on twos)");
    }
    let sampled = input::open(path, input_args)?;
    let merged = input::merged(path, &sampled)?;
    let options = a.offsets.options(&sampled);
    let solver = OffsetSolver::new(&sampled, &options).map_err(at_input(path))?;
    let offsets = MotionOffsets::concat(&solver.all())?;
    let seeds = match seeds {
        Some((count, seed)) => Some(seed_offsets(path, &sampled, &merged, &solver, count, seed)?),
        None => None,
    };
    drop(solver);
    Ok(Prepared {
        sampled,
        merged,
        offsets,
        seeds,
        seconds: start.elapsed().as_secs_f64(),
    })
}

fn compile(spec: FunctionSpec, what: &str) -> Result<StyleFunction> {
    spec.compile().map_err(|e| anyhow::anyhow!("{what}: {e}"))
}

fn at_input(path: &Path) -> impl Fn(smear::SmearError) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("{}: {e}", path.display())
}

fn require_glb(path: &Path, what: &str) -> Result<()> {
    if Format::from_extension(path) != Some(Format::Glb) {
        bail!("{}: smear {what} writes .glb", path.display());
    }
    Ok(())
}

/// Runs `toonkit smear elongate`.
pub fn elongate(ctx: &Context, args: ElongateArgs) -> Result<()> {
    let start = Instant::now();
    if Format::from_extension(&args.output).is_none() {
        bail!(
            "{}: unknown output extension (use .glb, .pc2, .mdd or .obj)",
            args.output.display()
        );
    }
    let spec = match &args.expr {
        Some(e) => FunctionSpec::expr(e, &[("beta_max", args.beta_max)]),
        None => match args.preset {
            ElongatePreset::Linear => FunctionSpec::linear(args.beta_max),
            ElongatePreset::Speed => FunctionSpec::speed(args.beta_max),
            ElongatePreset::Noise => FunctionSpec::noise(args.kappa, args.beta_max),
        },
    };
    let style = compile(spec, "--expr")?;
    let spinner = crate::progress::spinner("elongating", ctx.json);
    let p = prepare(&args.input, &args.input_args, &args.offsets, None)?;
    let t = Instant::now();
    let inputs = EffectInputs::new(&p.merged, &p.offsets).map_err(at_input(&args.input))?;
    let options = ElongateOptions {
        step: args.offsets.step,
    };
    let out = smear::elongate(&p.merged, &inputs, &style, &options)?;
    let effect_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let written = output::write_animation(&args.output, &out, args.layout, None)?;
    spinner.finish_and_clear();
    let (mut max_d, mut sum_d) = (0.0f32, 0.0f64);
    for (a, b) in out.positions().iter().zip(p.merged.positions()) {
        let d = a.distance(*b);
        max_d = max_d.max(d);
        sum_d += d as f64;
    }
    let mean_d = sum_d / out.positions().len().max(1) as f64;
    let summary = json!({
        "input": args.input, "output": args.output, "files": written,
        "frames": out.frame_count(), "vertices": out.vertex_count(),
        "objects": p.sampled.objects.len(), "step": options.step,
        "max_displacement": max_d, "mean_displacement": mean_d,
        "seconds": {"offsets": p.seconds, "effect": effect_seconds,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames × {} vertices, elongated in-betweens)",
            args.output.display(),
            out.frame_count(),
            out.vertex_count()
        )
    });
    Ok(())
}

/// Runs `toonkit smear multiples`.
pub fn multiples(ctx: &Context, args: MultiplesArgs) -> Result<()> {
    let start = Instant::now();
    require_glb(&args.output, "multiples")?;
    if args.past + args.future == 0 {
        bail!("--past and --future are both 0: there is no copy to draw");
    }
    let spacing = match (args.spacing, args.overlap) {
        (_, Some(n)) => Spacing::Overlap(n),
        (Some(df), None) => Spacing::Frames(df),
        (None, None) => Spacing::Frames(smear::DEFAULT_SPACING),
    };
    let options = MultiplesOptions {
        past: args.past,
        future: args.future,
        spacing,
        step: args.offsets.step,
    };
    let df = options.spacing_frames()?;
    let m_max = args.m_max.unwrap_or(args.past.max(args.future) as f32);
    let spec = match &args.opacity_expr {
        Some(e) => FunctionSpec::expr(e, &[("m_max", m_max)]),
        None => FunctionSpec::multiples(m_max),
    };
    let style = compile(spec, "--opacity-expr")?;
    let spinner = crate::progress::spinner("drawing multiple in-betweens", ctx.json);
    let p = prepare(&args.input, &args.input_args, &args.offsets, None)?;
    let t = Instant::now();
    let inputs = EffectInputs::new(&p.merged, &p.offsets).map_err(at_input(&args.input))?;
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
    let bytes = tkio::gltf::write_animations(&parts, tkio::gltf::AnimationLayout::Flipbook)
        .map_err(|e| e.at(&args.output))?;
    tkio::write_atomic(&args.output, &bytes)?;
    spinner.finish_and_clear();
    let copies_json: Vec<_> = copies
        .iter()
        .map(|c| {
            let visible = c.alpha.iter().filter(|a| **a > 0.0).count();
            json!({"m": c.m, "beta": c.beta, "visible_fraction": visible as f64 / c.alpha.len().max(1) as f64})
        })
        .collect();
    let summary = json!({
        "input": args.input, "output": args.output,
        "frames": p.merged.frame_count(), "vertices": p.merged.vertex_count(),
        "spacing": df, "m_max": m_max, "step": options.step, "copies": copies_json,
        "seconds": {"offsets": p.seconds, "effect": effect_seconds,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} copies spaced {df:.3} frames)",
            args.output.display(),
            p.merged.frame_count(),
            copies.len()
        )
    });
    Ok(())
}

/// Seeds on the merged mesh, sorted by triangle so they group by object, with their offsets
/// from each object's solver (Eq. 8 at the seeds' own positions).
fn seed_offsets(
    path: &Path,
    sampled: &anim::SampledScene,
    merged: &MeshAnimation,
    solver: &OffsetSolver<'_>,
    count: usize,
    seed: u64,
) -> Result<(Vec<SurfacePoint>, MotionOffsets)> {
    let mut pts = smear::sample_surface(merged.frame(0), &merged.mesh.triangles, count, seed);
    pts.sort_by_key(|s| s.triangle);
    let mut parts = Vec::new();
    let (mut base, mut k) = (0u32, 0usize);
    for (i, o) in sampled.objects.iter().enumerate() {
        let end = base + o.animation.mesh.triangles.len() as u32;
        let local: Vec<SurfacePoint> = pts[k..]
            .iter()
            .take_while(|s| s.triangle < end)
            .map(|s| SurfacePoint {
                triangle: s.triangle - base,
                ..*s
            })
            .collect();
        k += local.len();
        parts.push(solver.surface_offsets(i, &local).map_err(at_input(path))?);
        base = end;
    }
    let frames = merged.frame_count();
    let offsets = if parts.is_empty() {
        MotionOffsets::zeros(frames, 0)
    } else {
        MotionOffsets::concat(&parts)?
    };
    Ok((pts, offsets))
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
    require_glb(&args.output, "lines")?;
    if let Some(t) = args.thickness.filter(|t| !(t.is_finite() && *t > 0.0)) {
        bail!("--thickness must be a positive number, got {t}");
    }
    let length_spec = match &args.length_expr {
        Some(e) => FunctionSpec::expr(e, &[("tau_max", args.length_max)]),
        None => FunctionSpec::linear(args.length_max),
    };
    let length = compile(length_spec, "--length-expr")?;
    let opacity = match &args.opacity_expr {
        Some(e) => Some(compile(FunctionSpec::expr(e, &[]), "--opacity-expr")?),
        None => None,
    };
    let spinner = crate::progress::spinner("tracing motion lines", ctx.json);
    let mut p = prepare(
        &args.input,
        &args.input_args,
        &args.offsets,
        Some((args.count, args.seed)),
    )?;
    let t = Instant::now();
    let Some((pts, offsets)) = p.seeds.take() else {
        bail!("{}: no motion-line seeds", args.input.display());
    };
    let seeds =
        EffectInputs::at_surface_points(&p.merged, &pts, offsets).map_err(at_input(&args.input))?;
    let radius = args
        .thickness
        .unwrap_or(smear::DEFAULT_LINE_THICKNESS * p.merged.bbox().diagonal());
    let thickness = move |_: &StyleInput| radius;
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
        gap: args.gap,
        min_speed: args.min_speed,
        past_only: args.past_only,
        step: args.offsets.step,
        ..Default::default()
    };
    let frames = smear::motion_lines(&seeds, &style, &line_options)?;
    let effect_seconds = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let scene = lines_scene(&p.merged, &frames);
    let bytes = tkio::gltf::write_glb(&scene).map_err(|e| e.at(&args.output))?;
    tkio::write_atomic(&args.output, &bytes)?;
    spinner.finish_and_clear();
    let per_frame: Vec<usize> = frames.iter().map(|f| f.lines).collect();
    let summary = json!({
        "input": args.input, "output": args.output,
        "frames": p.merged.frame_count(), "vertices": p.merged.vertex_count(),
        "seeds": pts.len(), "radius": radius, "step": line_options.step,
        "lines_per_frame": per_frame,
        "seconds": {"offsets": p.seconds, "effect": effect_seconds,
                    "write": t.elapsed().as_secs_f64(), "total": start.elapsed().as_secs_f64()},
    });
    ctx.report(&summary, || {
        format!(
            "wrote {} ({} frames, {} seeds, up to {} lines per frame)",
            args.output.display(),
            frames.len(),
            pts.len(),
            per_frame.iter().max().unwrap_or(&0)
        )
    });
    Ok(())
}
