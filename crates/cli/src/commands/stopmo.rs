//! `toonkit stopmo …`: replacement libraries for 3D-printed stop-motion (StopShop).
//!
//! `segment` cuts a face animation into parts and homogenizes the seams (Sections 3.1–3.2);
//! `library` ([`super::stopmo_library`]) builds the replacement library; `run`
//! ([`super::stopmo_run`]) chains both.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anim::glam::Vec3;
use anim::MeshAnimation;
use anyhow::{bail, Context as _, Result};
use clap::{Args, Subcommand, ValueEnum};
use serde_json::json;
use stopmo::segment::{PartSpec, Seed, SegmentOptions, Segmentation};

use super::Context;
use crate::input::{self, InputArgs};

/// Arguments of `toonkit stopmo`.
#[derive(Debug, Args)]
pub struct StopmoArgs {
    #[command(subcommand)]
    pub command: StopmoCommand,
}

/// Subcommands of `toonkit stopmo`.
#[derive(Debug, Subcommand)]
pub enum StopmoCommand {
    /// Cut the animation into parts along low-motion seams and make the seams identical in
    /// every frame (StopShop Sections 3.1–3.2).
    Segment(SegmentArgs),
    /// Build a replacement library of printable pieces per part, the assembly sheet and a
    /// shooting order (StopShop Sections 3.3–3.4, 5).
    Library(super::stopmo_library::LibraryArgs),
    /// Segment, then build the library of every part: `segment` and `library` in one go,
    /// writing DIR/segmentation.glb, DIR/segmentation.json and the library layout in DIR.
    Run(super::stopmo_run::RunArgs),
}

/// glTF layout of the segmented parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum PartsLayout {
    /// One mesh node per part with a morph target per frame.
    #[default]
    Morph,
    /// One flipbook per part.
    Flipbook,
}

/// Arguments of `toonkit stopmo segment`.
#[derive(Debug, Args)]
pub struct SegmentArgs {
    /// Input mesh animation (fixed topology), any readable format.
    pub input: PathBuf,
    /// Output `.glb`: one mesh node per part, named after the part, all with the same frames.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub segment: SegmentOptionsArgs,
    /// Write the JSON report (parts, triangle_part, seam_vertices, gamma, cut_length).
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write a PNG: parts on the average mesh and the average displacement (paper Fig. 5).
    #[arg(long)]
    pub render: Option<PathBuf>,
    /// glTF layout of the parts.
    #[arg(long = "as", value_enum, default_value_t = PartsLayout::Morph)]
    pub layout: PartsLayout,
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// Segmentation options shared by `stopmo segment` and `stopmo run`.
#[derive(Debug, Args)]
pub struct SegmentOptionsArgs {
    /// A part and its seed: `NAME=tri:ID` (triangle id) or `NAME=point:X,Y,Z` (snapped to the
    /// nearest triangle). Repeat for each part; repeat a name for several seeds.
    #[arg(long = "part", value_name = "NAME=SEED")]
    pub parts: Vec<String>,
    /// Choose N parts automatically (farthest seeds on per-triangle motion statistics).
    #[arg(long, conflicts_with = "parts")]
    pub auto_parts: Option<usize>,
    /// Weight γ of the seam term (Eq. 1), after scaling the model to a unit box; ~1000 makes
    /// the cut independent of the exact seed placement (Fig. 4), much more collapses it.
    #[arg(long, default_value_t = stopmo::segment::DEFAULT_GAMMA)]
    pub gamma: f64,
    /// Laplacian smoothing iterations of the part boundaries (0: cut along mesh edges).
    #[arg(long = "smooth-iters")]
    pub smooth_iters: Option<usize>,
    /// Keep the seams as they move (skip Section 3.2).
    #[arg(long)]
    pub no_homogenize: bool,
    /// Reuse the cut and seam targets of an earlier segmentation of the same mesh (its
    /// `segmentation.json`, or the `.glb` next to it): parts of both clips assemble together.
    #[arg(long, value_name = "SEG.json|SEG.glb", conflicts_with_all = ["parts", "auto_parts"])]
    pub segmentation: Option<PathBuf>,
}

/// Runs `toonkit stopmo …`.
pub fn run(ctx: &Context, args: StopmoArgs) -> Result<()> {
    match args.command {
        StopmoCommand::Segment(a) => segment(ctx, a),
        StopmoCommand::Library(a) => super::stopmo_library::library(ctx, a),
        StopmoCommand::Run(a) => super::stopmo_run::run(ctx, a),
    }
}

/// Parses `NAME=tri:ID` or `NAME=point:X,Y,Z` and groups seeds by part name (in order).
fn parse_parts(specs: &[String]) -> Result<Vec<PartSpec>> {
    let mut parts: Vec<PartSpec> = Vec::new();
    for s in specs {
        let (name, seed) = s
            .split_once('=')
            .with_context(|| format!("--part {s}: expected NAME=tri:ID or NAME=point:X,Y,Z"))?;
        let seed = if let Some(id) = seed.strip_prefix("tri:") {
            Seed::Triangle(
                id.trim()
                    .parse()
                    .with_context(|| format!("--part {s}: bad triangle id"))?,
            )
        } else if let Some(p) = seed.strip_prefix("point:") {
            let v: Vec<f32> = p
                .split(',')
                .map(|x| x.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--part {s}: bad point"))?;
            if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
                bail!("--part {s}: a point needs three finite coordinates");
            }
            Seed::Point(Vec3::new(v[0], v[1], v[2]))
        } else {
            bail!("--part {s}: the seed must start with tri: or point:");
        };
        match parts.iter_mut().find(|p| p.name == name) {
            Some(p) => p.seeds.push(seed),
            None => parts.push(PartSpec::new(name, vec![seed])),
        }
    }
    Ok(parts)
}

fn segment(ctx: &Context, args: SegmentArgs) -> Result<()> {
    let start = Instant::now();
    let sampled = input::open(&args.input, &args.input_args)?;
    let anim = input::merged(&args.input, &sampled)?;
    let out = segment_and_write(
        ctx,
        &args.input,
        &anim,
        &args.segment,
        &SegmentOutputs {
            glb: &args.output,
            layout: args.layout,
            report: args.report.as_deref(),
            render: args.render.as_deref(),
        },
    )?;
    let mut summary = out.summary;
    summary["seconds"] = json!(start.elapsed().as_secs_f64());
    ctx.report(&summary, || {
        format!("{}, {:.2} s", out.text, start.elapsed().as_secs_f64())
    });
    Ok(())
}

/// Where [`segment_and_write`] writes.
pub(super) struct SegmentOutputs<'a> {
    /// The parts (`.glb`).
    pub glb: &'a Path,
    /// Their glTF layout.
    pub layout: PartsLayout,
    /// The JSON report, if wanted.
    pub report: Option<&'a Path>,
    /// The Fig. 5 PNG, if wanted.
    pub render: Option<&'a Path>,
}

/// What [`segment_and_write`] produced.
pub(super) struct Segmented {
    /// The parts, named after the segmentation's part names.
    pub parts: Vec<stopmo::segment::Part>,
    /// JSON summary (no timing).
    pub summary: serde_json::Value,
    /// One-line human summary (no timing).
    pub text: String,
    /// The segmentation itself.
    pub segmentation: Segmentation,
}

/// Segments `anim` (read from `input`) and writes the parts, the report and the render:
/// the body of `stopmo segment`, shared with `stopmo run`.
pub(super) fn segment_and_write(
    ctx: &Context,
    input: &Path,
    anim: &MeshAnimation,
    opts: &SegmentOptionsArgs,
    out: &SegmentOutputs<'_>,
) -> Result<Segmented> {
    if tkio::Format::from_extension(out.glb) != Some(tkio::Format::Glb) {
        bail!(
            "{}: the segmented animation is written as .glb",
            out.glb.display()
        );
    }
    let mut options = SegmentOptions {
        gamma: opts.gamma,
        homogenize: !opts.no_homogenize,
        ..SegmentOptions::default()
    };
    if let Some(k) = opts.smooth_iters {
        options.smooth_iterations = k;
    }
    let seg = match &opts.segmentation {
        Some(path) => {
            let saved = read_saved(path)?;
            stopmo::segment::segment_reusing(anim, &saved, &options)
                .with_context(|| format!("--segmentation {}", path.display()))?
        }
        None => {
            let parts = match opts.auto_parts {
                Some(n) => stopmo::segment::auto_parts(anim, n)
                    .with_context(|| input.display().to_string())?,
                None => parse_parts(&opts.parts)?,
            };
            if parts.len() < 2 {
                bail!("give at least two parts (--part NAME=SEED twice, or --auto-parts N)");
            }
            let spinner = crate::progress::spinner("segmenting", ctx.json);
            let seg = stopmo::segment::segment(anim, &parts, &options)
                .with_context(|| input.display().to_string())?;
            spinner.finish_and_clear();
            seg
        }
    };
    seg.check_parts()
        .with_context(|| input.display().to_string())?;
    let pieces = seg.parts()?;
    let layout = match out.layout {
        PartsLayout::Morph => tkio::gltf::AnimationLayout::Morph,
        PartsLayout::Flipbook => tkio::gltf::AnimationLayout::Flipbook,
    };
    let refs: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)> =
        pieces.iter().map(|p| (&p.animation, None)).collect();
    let bytes = tkio::gltf::write_animations(&refs, layout).map_err(|e| e.at(out.glb))?;
    tkio::write_atomic(out.glb, &bytes)?;
    let report = serde_json::to_value(seg.report())?;
    if let Some(path) = out.report {
        let mut file = report.clone();
        file["reuse"] =
            serde_json::to_value(seg.saved(anim.vertex_count(), anim.mesh.triangle_count()))?;
        tkio::write_atomic(path, serde_json::to_string(&file)?.as_bytes())?;
    }
    if let Some(path) = out.render {
        tkio::write_atomic(path, &render_parts(&seg)?)?;
    }
    let summary = json!({
        "input": input,
        "output": out.glb,
        "parts": pieces.iter().map(|p| json!({"name": p.name, "vertices": p.animation.vertex_count(),
            "triangles": p.animation.mesh.triangle_count()})).collect::<Vec<_>>(),
        "frames": anim.frame_count(),
        "gamma": seg.gamma,
        "cut_length": seg.cut_length,
        "seam_vertices": seg.seam_vertices.len(),
        "homogenization": report["homogenization"],
    });
    let names: Vec<String> = pieces
        .iter()
        .map(|p| {
            format!(
                "{} ({} triangles)",
                p.name,
                p.animation.mesh.triangle_count()
            )
        })
        .collect();
    let text = format!(
        "wrote {}: {} over {} frames, cut length {:.3}, {} seam vertices",
        out.glb.display(),
        names.join(", "),
        anim.frame_count(),
        seg.cut_length,
        seg.seam_vertices.len(),
    );
    Ok(Segmented {
        parts: pieces,
        summary,
        text,
        segmentation: seg,
    })
}

/// Reads the reusable segmentation: `"reuse"` of a `segmentation.json` (a `.glb` stands for
/// the `.json` of the same name next to it, as `stopmo run` writes them).
fn read_saved(path: &Path) -> Result<stopmo::segment::SavedSegmentation> {
    let json = if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
    {
        path.with_extension("json")
    } else {
        path.to_path_buf()
    };
    let bytes =
        tkio::read_file(&json).with_context(|| format!("--segmentation {}", path.display()))?;
    let value: serde_json::Value = serde_json::from_slice(&bytes)
        .with_context(|| format!("--segmentation {}: not JSON", json.display()))?;
    let reuse = value.get("reuse").with_context(|| {
        format!(
            "--segmentation {}: no \"reuse\" section; write it with `stopmo segment --report` or `stopmo run`",
            json.display()
        )
    })?;
    serde_json::from_value(reuse.clone())
        .with_context(|| format!("--segmentation {}: bad \"reuse\" section", json.display()))
}

/// Paper Fig. 5: the parts on the average mesh, beside the mean displacement from the
/// average mesh (of the output: homogenized seams show as still).
fn render_parts(seg: &Segmentation) -> Result<Vec<u8>> {
    let out = &seg.animation;
    let avg = out.average_positions();
    let mesh = &out.mesh;
    let part_colors: Vec<render::Color> = seg
        .triangle_part
        .iter()
        .map(|&p| render::categorical(p as usize))
        .collect();
    let frames = out.frame_count() as f32;
    let mut disp = vec![0f32; out.vertex_count()];
    for f in out.frames() {
        for (v, (p, a)) in f.iter().zip(&avg).enumerate() {
            disp[v] += (*p - *a).length() / frames;
        }
    }
    let max = disp.iter().copied().fold(0.0f32, f32::max).max(1e-12);
    let disp_colors: Vec<render::Color> = disp
        .iter()
        .map(|d| render::ColorMap::Sequential.map(d / max))
        .collect();
    let renderer = render::Renderer::new(480, 480)?;
    let view = render::View::fit(
        anim::Aabb::from_points(&avg),
        render::ViewDirection::Front,
        renderer.aspect(),
    );
    let item = |colors| render::MeshItem::new(&avg, &mesh.triangles).colors(colors);
    let left = renderer.render(
        &render::DrawList::new().mesh(item(render::MeshColors::PerTriangle(&part_colors))),
        &view,
    )?;
    let right = renderer.render(
        &render::DrawList::new().mesh(item(render::MeshColors::PerVertex(&disp_colors))),
        &view,
    )?;
    let sheet = render::contact_sheet(
        &[left, right],
        None,
        &render::SheetOptions {
            columns: 2,
            ..Default::default()
        },
    )?;
    Ok(render::encode_png(&sheet)?)
}
