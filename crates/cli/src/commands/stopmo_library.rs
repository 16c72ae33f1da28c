//! `toonkit stopmo library`: replacement libraries for 3D-printed stop-motion (StopShop
//! Sections 3.3–3.4, 5) and everything an animator needs to print and shoot them.
//!
//! Output layout (SPEC.md "Output layouts"): `DIR/pieces/<part>_<NN>.stl` (printable solids,
//! mm), `DIR/pieces/<part>_<NN>.obj` (piece surfaces, model units), `DIR/assembly.csv`,
//! `DIR/assembly.md`, `DIR/shooting_order.csv`, `DIR/report.json`, `DIR/reconstruction.glb`,
//! `DIR/reconstruction.pc2` + `DIR/rest.obj`, and `DIR/error_curve.csv` / `.png` (drawn by
//! [`super::stopmo_curve`]) after a size search.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anim::glam::Vec3;
use anim::MeshAnimation;
use anyhow::{bail, Context as _, Result};
use clap::{Args, ValueEnum};
use serde_json::json;
use stopmo::library::{
    build_library, plan_plugs, print_scale, scaled, shooting_order, Library, LibraryOptions,
    LibrarySize, Method, PartInput, PartSetup, Plug, PlugOptions, SolveOptions, DEFAULT_LAMBDA,
    DEFAULT_PRINT_HEIGHT_MM, DEFAULT_RESTARTS, DEFAULT_SEED, DEFAULT_THICKNESS_MM,
};

use super::Context;
use crate::input::{self, InputArgs};

/// Pieces per part when no size is given.
pub const DEFAULT_PIECES: usize = 20;

/// Which algorithm picks the pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum MethodArg {
    /// Positions and velocities (Eq. 10, λ from --lambda).
    #[default]
    Stopshop,
    /// λ = 0: k-means on positions only.
    Kmeans,
    /// Uniform temporal sampling (the naive baseline).
    Uniform,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Stopshop => Method::StopShop,
            MethodArg::Kmeans => Method::KMeans,
            MethodArg::Uniform => Method::Uniform,
        }
    }
}

/// Arguments of `toonkit stopmo library`.
#[derive(Debug, Args)]
pub struct LibraryArgs {
    /// Input animation; every mesh object is one part named after it (e.g. the .glb of
    /// `toonkit stopmo segment`), a single object is one part.
    pub input: PathBuf,
    /// Output directory.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub library: LibraryOptionsArgs,
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// Library options shared by `stopmo library` and `stopmo run`.
#[derive(Debug, Args)]
pub struct LibraryOptionsArgs {
    /// Pieces per part: `20` for every part, or `upper=20,lower=30`.
    #[arg(long, value_name = "N|PART=N,...", conflicts_with_all = ["max_error", "budget"])]
    pub pieces: Option<String>,
    /// Smallest library per part whose worst frame's mean position error is at most this many
    /// millimetres (at --print-height).
    #[arg(long, value_name = "MM", conflicts_with = "budget")]
    pub max_error: Option<f64>,
    /// Total number of pieces over all parts, allocated greedily.
    #[arg(long, value_name = "PIECES")]
    pub budget: Option<usize>,
    /// Velocity weight λ of Eq. 10.
    #[arg(long, default_value_t = DEFAULT_LAMBDA)]
    pub lambda: f64,
    /// Random restarts (run in parallel, the best is kept).
    #[arg(long, default_value_t = DEFAULT_RESTARTS)]
    pub restarts: usize,
    /// Seed of every random choice.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// Per-vertex saliency weights: float32 `.npy` of shape (vertices,) or (1, vertices), in
    /// the merged vertex order of the input (parts one after the other).
    #[arg(long, value_name = "FILE.npy")]
    pub saliency: Option<PathBuf>,
    /// Frames that start a new, unrelated shot (no velocity term across them).
    #[arg(long, value_delimiter = ',')]
    pub cuts: Vec<usize>,
    /// Directory of pre-made pieces `<part>_<NN>.obj` (e.g. `OLD/pieces` of an earlier run);
    /// they are kept and new pieces are added up to the library size.
    #[arg(long, value_name = "DIR")]
    pub fixed: Option<PathBuf>,
    /// Algorithm.
    #[arg(long, value_enum, default_value_t = MethodArg::Stopshop)]
    pub method: MethodArg,
    /// Printed height of the whole model in millimetres (scales the STL files and the errors).
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_PRINT_HEIGHT_MM)]
    pub print_height: f64,
    /// Wall thickness of the printed pieces in millimetres.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_THICKNESS_MM)]
    pub thickness: f64,
    /// Add male/female plugs (paper Fig. 13) across every seam shared by two parts: a pin
    /// under the first part, a socket tube under the second, fused into the pieces' STL files
    /// as extra shells (slicers union them). Placed on the rest geometry; listed in
    /// report.json under "plugs".
    #[arg(long)]
    pub plugs: bool,
    /// Pin radius of the plugs in millimetres.
    #[arg(long, value_name = "MM", requires = "plugs",
          default_value_t = stopmo::library::DEFAULT_PLUG_RADIUS_MM)]
    pub plug_radius: f64,
    /// Plug length (boss + pin) in millimetres.
    #[arg(long, value_name = "MM", requires = "plugs",
          default_value_t = stopmo::library::DEFAULT_PLUG_LENGTH_MM)]
    pub plug_length: f64,
    /// Radial clearance between pin and socket in millimetres (tune to the printer).
    #[arg(long, value_name = "MM", requires = "plugs",
          default_value_t = stopmo::library::DEFAULT_PLUG_CLEARANCE_MM)]
    pub plug_clearance: f64,
    /// Printer resolution in millimetres: pieces that differ from a sibling by less are
    /// reported (a warning and report.json "printing.parts[].below_resolution").
    #[arg(long, value_name = "MM", default_value_t = 0.05)]
    pub resolution: f64,
    /// No registration keys (domes on the shared back surface that fix all six degrees of
    /// freedom on the armature/head).
    #[arg(long)]
    pub no_keys: bool,
    /// No piece ID (`P-NN`) embossed on the back of every piece.
    #[arg(long)]
    pub no_ids: bool,
    /// Also write the JSON report here (it is always written to DIR/report.json).
    #[arg(long)]
    pub report: Option<PathBuf>,
}

/// Replaces characters that do not belong in a file name.
pub(super) fn file_safe(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "part".into()
    } else {
        s
    }
}

/// The parts of the input: one per mesh object, named after it.
pub(super) fn parts(path: &Path, args: &InputArgs) -> Result<Vec<MeshAnimation>> {
    let sampled = input::open(path, args)?;
    if sampled.objects.is_empty() {
        bail!("{}: the file has no mesh", path.display());
    }
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("part");
    let mut out: Vec<MeshAnimation> = Vec::new();
    for o in sampled.objects {
        let raw = if o.name.is_empty() { stem } else { &o.name };
        let name = file_safe(raw);
        if out.iter().any(|a| a.mesh.name == name) {
            bail!(
                "{}: two mesh objects are named '{name}'; part names must be unique",
                path.display()
            );
        }
        let mut a = o.animation;
        a.mesh.name = name;
        out.push(a);
    }
    Ok(out)
}

/// Parses `--pieces`: `N` or `PART=N,...` (every part named exactly once).
fn parse_pieces(spec: &str, names: &[&str]) -> Result<LibrarySize> {
    let spec = spec.trim();
    if let Ok(n) = spec.parse::<usize>() {
        return Ok(LibrarySize::Pieces(n));
    }
    let mut sizes: Vec<Option<usize>> = vec![None; names.len()];
    for item in spec.split(',') {
        let (name, n) = item
            .split_once('=')
            .with_context(|| format!("--pieces {spec}: expected N or PART=N,..."))?;
        let n: usize = n
            .trim()
            .parse()
            .with_context(|| format!("--pieces {spec}: bad count '{n}'"))?;
        let i = names
            .iter()
            .position(|p| *p == name.trim())
            .with_context(|| {
                format!(
                    "--pieces {spec}: no part '{}' (parts: {})",
                    name.trim(),
                    names.join(", ")
                )
            })?;
        sizes[i] = Some(n);
    }
    let missing: Vec<&str> = names
        .iter()
        .zip(&sizes)
        .filter(|(_, s)| s.is_none())
        .map(|(n, _)| *n)
        .collect();
    if !missing.is_empty() {
        bail!(
            "--pieces {spec}: no size for part(s) {}",
            missing.join(", ")
        );
    }
    Ok(LibrarySize::PerPart(sizes.into_iter().flatten().collect()))
}

/// Splits the saliency file into per-part weights.
pub(super) fn read_saliency(path: &Path, parts: &[MeshAnimation]) -> Result<Vec<Vec<f32>>> {
    let bytes = tkio::read_file(path)?;
    let (shape, values) = tkio::npy::read_f32(&bytes).map_err(|e| e.at(path))?;
    let total: usize = parts.iter().map(|p| p.vertex_count()).sum();
    let ok_shape = matches!(shape.as_slice(), [n] | [1, n] if *n == total);
    if !ok_shape {
        bail!(
            "{}: saliency shape {shape:?}, expected ({total},) or (1, {total}) (one weight per vertex)",
            path.display()
        );
    }
    let mut out = Vec::with_capacity(parts.len());
    let mut at = 0;
    for p in parts {
        out.push(values[at..at + p.vertex_count()].to_vec());
        at += p.vertex_count();
    }
    Ok(out)
}

/// Reads the fixed pieces `<part>_<NN>.obj` of one part from `dir`, in file-name order.
fn read_fixed(dir: &Path, part: &MeshAnimation) -> Result<Vec<Vec<Vec3>>> {
    let prefix = format!("{}_", part.mesh.name);
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("--fixed {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|x| x == "obj")
                && p.file_stem().and_then(|s| s.to_str()).is_some_and(|s| {
                    s.strip_prefix(&prefix)
                        .is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()))
                })
        })
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| {
            let mesh = tkio::obj::read(&tkio::read_file(f)?).map_err(|e| e.at(f))?;
            if mesh.vertex_count() != part.vertex_count() {
                bail!(
                    "{}: {} vertices, part '{}' has {}",
                    f.display(),
                    mesh.vertex_count(),
                    part.mesh.name,
                    part.vertex_count()
                );
            }
            Ok(mesh.positions)
        })
        .collect()
}

/// Runs `toonkit stopmo library`.
pub fn library(ctx: &Context, args: LibraryArgs) -> Result<()> {
    let anims = parts(&args.input, &args.input_args)?;
    let out = build_and_write(
        ctx,
        &args.input,
        &anims,
        &args.library,
        &args.output,
        Given::default(),
    )?;
    if let Some(p) = &args.library.report {
        tkio::write_atomic(p, serde_json::to_string_pretty(&out.report)?.as_bytes())?;
    }
    ctx.report(&out.report, || out.text.clone());
    Ok(())
}

/// What the caller of [`build_and_write`] already has: per-part saliency (e.g. mapped from the
/// input's vertex order through the cut) and the parts of the artist's animation before
/// homogenization (errors are reported against them).
#[derive(Default)]
pub(super) struct Given<'a> {
    /// Per-part saliency; read from `--saliency` when `None`.
    pub saliency: Option<Vec<Vec<f32>>>,
    /// Per-part input animations (the built animations themselves when `None`).
    pub inputs: Option<&'a [MeshAnimation]>,
}

/// What [`build_and_write`] produced.
pub(super) struct LibraryOutcome {
    /// The report written to `DIR/report.json`.
    pub report: serde_json::Value,
    /// One-line human summary.
    pub text: String,
}

/// Builds the library of `anims` (one animation per part, read from `input`) and writes the
/// SPEC layout into `dir`: the body of `stopmo library`, shared with `stopmo run`.
pub(super) fn build_and_write(
    ctx: &Context,
    input: &Path,
    anims: &[MeshAnimation],
    args: &LibraryOptionsArgs,
    dir: &Path,
    given: Given,
) -> Result<LibraryOutcome> {
    let start = Instant::now();
    let names: Vec<&str> = anims.iter().map(|a| a.mesh.name.as_str()).collect();
    let refs: Vec<&MeshAnimation> = anims.iter().collect();
    let size = match (&args.pieces, args.max_error, args.budget) {
        (Some(p), _, _) => parse_pieces(p, &names)?,
        (None, Some(e), _) => {
            if !(e.is_finite() && e > 0.0) {
                bail!("--max-error must be a positive number of millimetres, got {e}");
            }
            LibrarySize::MaxError(e / print_scale(&refs, args.print_height))
        }
        (None, None, Some(b)) => LibrarySize::Budget(b),
        (None, None, None) => LibrarySize::Pieces(DEFAULT_PIECES),
    };
    if !(args.thickness.is_finite() && args.thickness > 0.0) {
        bail!("--thickness must be a positive number of millimetres");
    }
    if !(args.resolution.is_finite() && args.resolution >= 0.0) {
        bail!("--resolution must be a number of millimetres >= 0");
    }
    let saliency = match (given.saliency, &args.saliency) {
        (Some(s), _) => Some(s),
        (None, Some(p)) => Some(read_saliency(p, anims)?),
        (None, None) => None,
    };
    let mut setups = Vec::with_capacity(anims.len());
    for (i, a) in anims.iter().enumerate() {
        let fixed = match &args.fixed {
            Some(dir) => read_fixed(dir, a)?,
            None => Vec::new(),
        };
        setups.push(PartSetup {
            saliency: saliency.as_ref().map(|s| s[i].clone()),
            fixed,
            cuts: args.cuts.clone(),
        });
    }
    let inputs: Vec<PartInput<'_>> = anims
        .iter()
        .zip(setups)
        .map(|(a, setup)| PartInput {
            animation: a,
            setup,
        })
        .collect();
    let opts = LibraryOptions {
        size,
        method: args.method.into(),
        solve: SolveOptions {
            lambda: args.lambda,
            restarts: args.restarts,
            seed: args.seed,
            ..SolveOptions::default()
        },
        print_height_mm: args.print_height,
        ..LibraryOptions::default()
    };
    let spinner = crate::progress::spinner("optimizing the library", ctx.json);
    let lib = build_library(&inputs, &opts).with_context(|| input.display().to_string())?;
    spinner.finish_and_clear();
    let input_errors = super::stopmo_print::input_errors(&lib, anims, given.inputs, &args.cuts)?;
    let plugs = if args.plugs {
        let opts = PlugOptions {
            radius_mm: args.plug_radius,
            length_mm: args.plug_length,
            clearance_mm: args.plug_clearance,
            thickness_mm: args.thickness,
            ..PlugOptions::default()
        };
        plan_part_plugs(&lib, anims, &opts)?
    } else {
        Vec::new()
    };
    let (printing, warnings) = super::stopmo_print::write_pieces(
        dir,
        &lib,
        anims,
        &super::stopmo_print::PrintOptions {
            thickness_mm: args.thickness,
            print_height_mm: args.print_height,
            resolution_mm: args.resolution,
            keys: !args.no_keys,
            ids: !args.no_ids,
        },
        &plugs,
    )?;
    for w in &warnings {
        if !ctx.json {
            eprintln!("toonkit: warning: {w}");
        }
    }
    super::stopmo_print::write_catalogue(dir, &lib, anims)?;
    let assembly = lib.assembly();
    let sheets =
        super::stopmo_print::write_assembly_sheets(dir, &lib, anims, &assembly, &args.cuts)?;
    let frames = assembly.frames.len();
    let ids: Vec<Vec<String>> = (0..frames).map(|f| assembly.frame_ids(f)).collect();
    let mut csv = format!("frame,{}\n", names.join(","));
    for (f, row) in ids.iter().enumerate() {
        let _ = writeln!(csv, "{f},{}", row.join(","));
    }
    tkio::write_atomic(&dir.join("assembly.csv"), csv.as_bytes())?;
    tkio::write_atomic(
        &dir.join("assembly.md"),
        super::stopmo_print::assembly_markdown(&lib, &names, &ids).as_bytes(),
    )?;
    let order = shooting_order(&assembly);
    let mut csv = format!("shot,{},frames\n", names.join(","));
    for (s, shot) in order.shots.iter().enumerate() {
        let pieces: Vec<String> = (0..names.len())
            .map(|p| ids[shot.frames[0]][p].clone())
            .collect();
        let frames: Vec<String> = shot.frames.iter().map(|f| f.to_string()).collect();
        let _ = writeln!(csv, "{s},{},{}", pieces.join(","), frames.join(" "));
    }
    tkio::write_atomic(&dir.join("shooting_order.csv"), csv.as_bytes())?;
    write_reconstruction(dir, &lib, anims)?;
    if lib.parts.iter().any(|p| !p.curve.is_empty()) {
        let mut csv = String::from("part,pieces,energy,worst_frame_error_mm,mean_error_mm\n");
        for p in &lib.parts {
            for c in &p.curve {
                let _ = writeln!(
                    csv,
                    "{},{},{},{},{}",
                    p.name,
                    c.pieces,
                    c.energy,
                    c.worst_frame_error * lib.mm_per_unit,
                    c.mean_error * lib.mm_per_unit
                );
            }
        }
        tkio::write_atomic(&dir.join("error_curve.csv"), csv.as_bytes())?;
        let png = super::stopmo_curve::plot(&lib)?;
        tkio::write_atomic(&dir.join("error_curve.png"), &png)?;
    }
    let report = json!({
        "input": input,
        "method": lib.method,
        "energy": lib.energy,
        "lambda": lib.lambda,
        "pieces": lib.total_pieces(),
        "frames": frames,
        "fps": anims[0].fps,
        "mm_per_unit": lib.mm_per_unit,
        "print_height_mm": args.print_height,
        "thickness_mm": args.thickness,
        "plugs": plugs.iter().map(|p| json!({
            "male": names[p.male],
            "female": names[p.female],
            "anchor_mm": p.anchor,
            "normal": p.normal,
            "axis": p.axis,
            "center_mm": p.center,
            "radius_mm": p.radius_mm,
            "socket_radius_mm": p.socket_radius_mm,
            "outer_radius_mm": p.outer_radius_mm,
            "length_mm": p.length_mm,
            "seam_vertices": p.seam_vertices,
        })).collect::<Vec<_>>(),
        "errors_mm": input_errors.total,
        "library_errors_mm": lib.errors_mm,
        "homogenization_errors_mm": input_errors.homogenization,
        "printing": printing,
        "warnings": warnings,
        "assembly_sheets": sheets,
        "parts": lib.parts.iter().enumerate().map(|(i, p)| json!({
            "name": p.name,
            "pieces": p.solution.pieces.len(),
            "vertices": p.vertices,
            "energy": p.solution.energy,
            "iterations": p.solution.iterations,
            "restarts": p.solution.restarts,
            "errors_mm": input_errors.parts[i],
            "library_errors_mm": p.errors_mm,
        })).collect::<Vec<_>>(),
        "iterations": lib.parts.iter().map(|p| p.solution.iterations).sum::<usize>(),
        "restarts": args.restarts,
        "shooting_order": {"shots": order.shots.len(), "swaps": order.swaps,
            "sequential_swaps": order.sequential_swaps},
        "seconds": lib.seconds,
        "total_seconds": start.elapsed().as_secs_f64(),
    });
    let json = serde_json::to_string_pretty(&report)?;
    tkio::write_atomic(&dir.join("report.json"), json.as_bytes())?;
    let text = {
        let e = input_errors.total;
        format!(
            "wrote {}: {} pieces over {} parts and {} frames; error mean {:.3} mm (max {:.3}), \
             velocity mean {:.3} mm (max {:.3}); {} shots, {} swaps (in sequence {}); {:.2} s",
            dir.display(),
            lib.total_pieces(),
            lib.parts.len(),
            frames,
            e.position_mean,
            e.position_max,
            e.velocity_mean,
            e.velocity_max,
            order.shots.len(),
            order.swaps,
            order.sequential_swaps,
            start.elapsed().as_secs_f64()
        )
    };
    Ok(LibraryOutcome { report, text })
}

/// One plug per seam between two parts, placed on the average geometry in millimetres (the
/// STL coordinates).
fn plan_part_plugs(
    lib: &Library,
    anims: &[MeshAnimation],
    opts: &PlugOptions,
) -> Result<Vec<Plug>> {
    let surfaces: Vec<anim::Mesh> = anims
        .iter()
        .map(|a| {
            let mut m = a.mesh.clone();
            m.positions = a.average_positions();
            scaled(&m, lib.mm_per_unit as f32)
        })
        .collect();
    Ok(plan_plugs(&surfaces, opts)?)
}

/// `DIR/reconstruction.glb` (one node per part), `DIR/reconstruction.pc2` + `DIR/rest.obj`
/// (all parts merged in part order), model units.
fn write_reconstruction(dir: &Path, lib: &Library, anims: &[MeshAnimation]) -> Result<()> {
    let recon: Vec<MeshAnimation> = anims
        .iter()
        .enumerate()
        .map(|(i, a)| {
            lib.reconstruction(i, a)
                .with_context(|| format!("reconstruction of part {}", a.mesh.name))
        })
        .collect::<Result<_>>()?;
    let glb = dir.join("reconstruction.glb");
    let layers: Vec<(&MeshAnimation, Option<&[[f32; 4]]>)> =
        recon.iter().map(|a| (a, None)).collect();
    let bytes = tkio::gltf::write_animations(&layers, tkio::gltf::AnimationLayout::Morph)
        .map_err(|e| e.at(&glb))?;
    tkio::write_atomic(&glb, &bytes)?;
    let merged = if recon.len() == 1 {
        recon[0].clone()
    } else {
        MeshAnimation::concat("reconstruction", &recon)?
    };
    tkio::write_atomic(&dir.join("reconstruction.pc2"), &tkio::pc2::write(&merged))?;
    tkio::write_atomic(
        &dir.join("rest.obj"),
        tkio::obj::write(&merged.mesh).as_bytes(),
    )?;
    Ok(())
}
