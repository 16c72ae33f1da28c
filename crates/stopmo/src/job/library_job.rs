//! The library job: size rule → StopShop Eq. 10 libraries and labels → printable pieces,
//! assembly, shooting order, reconstruction, report; and `run` (segment, then library).

use std::borrow::{Borrow, Cow};
use std::time::Instant;

use anim::{MeshAnimation, MeshFrames};

use super::error::{Error, Result};
use super::library_memory::{
    check_memory, frames_memory, library_memory, LIBRARY_COPIES, MEMORY_HINT,
};
use super::options::{
    LibraryJobOptions, PieceCount, RunOptions, CLEARANCE_RANGE_MM, PLATE_SIDE_RANGE_MM,
    PRINTER_MINIMUM_RANGE_MM,
};
use super::plates::library_3mf;
use super::print::{print_pieces, surface_pieces, PrintSettings};
use super::report::{FramesForm, InputErrors, LibraryReport, ReportInputs};
use super::result::{LibraryResult, Reconstruction};
use super::segment_job::segment;
use super::sheets::{assembly_sheets, catalogue_png, piece_thumbnails};
use crate::library::{
    build_sources, compare_frames, plan_plugs, print_scale_of, scaled, shooting_order,
    ErrorSummary, Library, LibraryOptions, LibrarySize, PartSetup, Plug, PlugOptions, Source,
};

/// A name that is safe as a file stem: every character other than letters, digits, `-` and
/// `_` becomes `_` (`"part"` when empty). Part names name the piece files.
pub fn file_safe_name(name: &str) -> String {
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

/// Builds the replacement library of `parts` (one animation per part, named by its mesh
/// name) and everything needed to print and shoot it (StopShop Sections 3.3–3.4, 5): the
/// whole job of `toonkit stopmo library`. The parts are borrowed, owned or behind
/// references (`&[MeshAnimation]` or `&[&MeshAnimation]`): the job never copies their
/// frames.
///
/// # Errors
/// [`Error::Option`] for an invalid size rule, thickness, saliency or fixed pieces (see
/// [`Error::option`]); the optimization's and fabrication's own errors
/// ([`Error::Library`]).
pub fn library<A: Borrow<MeshAnimation>>(
    parts: &[A],
    opts: &LibraryJobOptions,
) -> Result<LibraryResult> {
    library_memory(parts)
        .check(MEMORY_HINT)
        .map_err(anim::AnimError::from)?;
    let refs: Vec<&MeshAnimation> = parts.iter().map(Borrow::borrow).collect();
    let names: Vec<String> = refs.iter().map(|a| a.mesh.name.clone()).collect();
    build(&refs, &names, opts, None)
}

/// [`library`] of parts given as positions or as morph weights ([`MeshFrames`], as
/// `tkio::open_frames` reads them): a morph-only clip on a still node is solved from its
/// weights (exact, `docs/stopmo-scale.md`) and never expanded into positions, so a long clip
/// fits in a fraction of the memory; the report's `frames_form` says which form was used.
///
/// # Errors
/// As [`library`].
pub fn library_frames(parts: &[MeshFrames], opts: &LibraryJobOptions) -> Result<LibraryResult> {
    frames_memory(parts)
        .check(MEMORY_HINT)
        .map_err(anim::AnimError::from)?;
    let sources: Vec<Source<'_>> = parts.iter().map(Source::of).collect();
    let names: Vec<String> = parts.iter().map(|a| a.mesh().name.clone()).collect();
    let start = Instant::now();
    let lib = solve_sources(&sources, &names, opts)?;
    // Printing, sheets and the reconstruction read the topology, timing and average shape:
    // a morph clip stands in as its one average frame.
    let stand_ins: Vec<Cow<'_, MeshAnimation>> = parts
        .iter()
        .map(|p| match p {
            MeshFrames::Positions(a) => Ok(Cow::Borrowed(a)),
            MeshFrames::Morph(m) => Ok(Cow::Owned(m.average_frame()?)),
        })
        .collect::<Result<_>>()?;
    let anims: Vec<&MeshAnimation> = stand_ins.iter().map(AsRef::as_ref).collect();
    let mut result = finish(lib, &anims, &names, opts, None, start)?;
    result.report.frames_form = FramesForm::of(parts);
    result.report.total_seconds = start.elapsed().as_secs_f64();
    result.report.peak_memory_mib = super::report::peak_memory_mib();
    Ok(result)
}

/// Segments `anim`, then builds the library of its parts (named after the parts, made
/// file-safe): the whole job of `toonkit stopmo run`. The result carries the segmentation in
/// [`LibraryResult::segmented`].
///
/// # Errors
/// Those of [`crate::segment()`] and [`library`].
pub fn run(anim: &MeshAnimation, opts: &RunOptions) -> Result<LibraryResult> {
    // Saliency is given in the input's vertex order: check it before segmenting.
    if let Some(s) = &opts.library.saliency {
        if s.len() != anim.vertex_count() {
            return Err(Error::option_error(
                "saliency",
                format!(
                    "{} weights, expected {}: one weight per input vertex, in the input's order",
                    s.len(),
                    anim.vertex_count()
                ),
            ));
        }
    }
    // The input and its segmentation stay held while the library is built.
    check_memory(anim.frame_count(), anim.vertex_count(), 2 + LIBRARY_COPIES)?;
    let segmented = segment(anim, &opts.segment)?;
    let names: Vec<String> = segmented
        .parts
        .iter()
        .map(|p| file_safe_name(&p.name))
        .collect();
    let mut library = opts.library.clone();
    if let Some(values) = &opts.library.saliency {
        let mapped = segmented.segmentation.map_vertex_values(values)?;
        library.saliency = Some(
            segmented
                .parts
                .iter()
                .flat_map(|p| p.vertices.iter().map(|&v| mapped[v as usize]))
                .collect(),
        );
    }
    // Errors are reported against the artist's animation, before homogenization.
    let inputs: Vec<MeshAnimation> = segmented
        .segmentation
        .input_parts(anim)?
        .into_iter()
        .map(|p| p.animation)
        .collect();
    let input_refs: Vec<&MeshAnimation> = inputs.iter().collect();
    let mut result = build(
        &segmented.part_animations(),
        &names,
        &library,
        Some(&input_refs),
    )?;
    result.segmented = Some(segmented);
    Ok(result)
}

/// Reconstruction errors against `inputs` (the parts before homogenization; the built parts
/// themselves when `None`), and what homogenization alone changed.
fn input_errors(
    lib: &Library,
    anims: &[&MeshAnimation],
    inputs: Option<&[&MeshAnimation]>,
    cuts: &[usize],
) -> Result<InputErrors> {
    let Some(inputs) = inputs else {
        return Ok(InputErrors {
            total: lib.errors_mm,
            parts: lib.parts.iter().map(|p| p.errors_mm).collect(),
            homogenization: None,
        });
    };
    let mm = lib.mm_per_unit;
    let mut parts = Vec::new();
    let mut homog = Vec::new();
    for (p, (a, x)) in anims.iter().zip(inputs).enumerate() {
        let e = lib.errors_against(p, x, cuts).ok_or_else(|| {
            Error::option_error(
                "parts",
                format!("part {}: input and library disagree", a.mesh.name),
            )
        })?;
        parts.push(e.summary(mm));
        let h = compare_frames(a.frame_count(), cuts, |f| x.frame(f), |f| a.frame(f));
        homog.push((h.summary(mm), a.vertex_count()));
    }
    let weighted: Vec<(ErrorSummary, usize)> = parts
        .iter()
        .zip(anims)
        .map(|(e, a)| (*e, a.vertex_count()))
        .collect();
    Ok(InputErrors {
        total: ErrorSummary::combine(&weighted),
        parts,
        homogenization: Some(ErrorSummary::combine(&homog)),
    })
}

/// The library size rule of the options, resolved against the parts.
fn library_size(
    opts: &LibraryJobOptions,
    sources: &[Source<'_>],
    names: &[String],
) -> Result<LibrarySize> {
    Ok(match &opts.pieces {
        PieceCount::Each(n) => LibrarySize::Pieces(*n),
        PieceCount::PerPart(sizes) => {
            if let Some(unknown) = sizes.keys().find(|k| !names.contains(k)) {
                return Err(Error::option_error(
                    "pieces",
                    format!("no part '{unknown}' (parts: {})", names.join(", ")),
                ));
            }
            let missing: Vec<&str> = names
                .iter()
                .filter(|n| !sizes.contains_key(*n))
                .map(String::as_str)
                .collect();
            if !missing.is_empty() {
                return Err(Error::option_error(
                    "pieces",
                    format!("no size for part(s) {}", missing.join(", ")),
                ));
            }
            LibrarySize::PerPart(names.iter().map(|n| sizes[n]).collect())
        }
        PieceCount::MaxErrorMm(e) => {
            super::check_positive_mm("max_error_mm", *e)?;
            LibrarySize::MaxError(e / print_scale_of(sources, opts.print_height_mm))
        }
        PieceCount::Budget(b) => LibrarySize::Budget(*b),
    })
}

/// Per-part saliency, fixed pieces and cuts.
fn setups(
    opts: &LibraryJobOptions,
    vertices: &[usize],
    names: &[String],
) -> Result<Vec<PartSetup>> {
    let total: usize = vertices.iter().sum();
    if let Some(s) = &opts.saliency {
        if s.len() != total {
            return Err(Error::option_error(
                "saliency",
                format!(
                    "{} weights, expected {total} (one per vertex of the parts, in part order)",
                    s.len()
                ),
            ));
        }
    }
    if let Some(unknown) = opts.fixed.keys().find(|k| !names.contains(k)) {
        return Err(Error::option_error(
            "fixed",
            format!("no part '{unknown}' (parts: {})", names.join(", ")),
        ));
    }
    let mut at = 0;
    Ok(vertices
        .iter()
        .zip(names)
        .map(|(&n, name)| {
            let saliency = opts.saliency.as_ref().map(|s| s[at..at + n].to_vec());
            at += n;
            PartSetup {
                saliency,
                fixed: opts.fixed.get(name).cloned().unwrap_or_default(),
                cuts: opts.cuts.clone(),
            }
        })
        .collect())
}

/// The library of `anims`, named `names` (unique), and everything built from it.
fn build(
    anims: &[&MeshAnimation],
    names: &[String],
    opts: &LibraryJobOptions,
    inputs: Option<&[&MeshAnimation]>,
) -> Result<LibraryResult> {
    let start = Instant::now();
    let lib = solve(anims, names, opts)?;
    finish(lib, anims, names, opts, inputs, start)
}

/// The first half of [`build`]: checks the options and solves StopShop Eq. 10 for every
/// part (the library's parts renamed `names`). The size-versus-error curve calls it once per
/// size and keeps the solves for [`finish`].
pub(super) fn solve(
    anims: &[&MeshAnimation],
    names: &[String],
    opts: &LibraryJobOptions,
) -> Result<Library> {
    let sources: Vec<Source<'_>> = anims.iter().map(|a| Source::Positions(a)).collect();
    solve_sources(&sources, names, opts)
}

/// [`solve`] of parts given as positions or morph weights.
fn solve_sources(
    sources: &[Source<'_>],
    names: &[String],
    opts: &LibraryJobOptions,
) -> Result<Library> {
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(Error::option_error(
                "parts",
                format!("two parts are named '{n}'; part names must be unique"),
            ));
        }
    }
    let size = library_size(opts, sources, names)?;
    super::check_positive_mm("thickness_mm", opts.thickness_mm)?;
    if !(opts.resolution_mm.is_finite() && opts.resolution_mm >= 0.0) {
        return Err(Error::option_error(
            "resolution_mm",
            "must be a number of millimetres >= 0",
        ));
    }
    let vertices: Vec<usize> = sources.iter().map(Source::vertex_count).collect();
    let setups = setups(opts, &vertices, names)?;
    let part_inputs: Vec<(Source<'_>, &PartSetup)> = sources.iter().copied().zip(&setups).collect();
    let lib_opts = LibraryOptions {
        size,
        method: opts.method,
        solve: opts.solve,
        print_height_mm: opts.print_height_mm,
        ..LibraryOptions::default()
    };
    let mut lib = build_sources(&part_inputs, &lib_opts)?;
    for (p, n) in lib.parts.iter_mut().zip(names) {
        p.name.clone_from(n);
    }
    Ok(lib)
}

/// The second half of [`build`]: everything printed and shot from a solved library (plugs,
/// pieces, catalogue, assembly, shooting order, reconstruction, report).
pub(super) fn finish(
    lib: Library,
    anims: &[&MeshAnimation],
    names: &[String],
    opts: &LibraryJobOptions,
    inputs: Option<&[&MeshAnimation]>,
    start: Instant,
) -> Result<LibraryResult> {
    let plugs = match &opts.plugs {
        Some(p) => plan_part_plugs(
            &lib,
            anims,
            &PlugOptions {
                thickness_mm: opts.thickness_mm,
                ..*p
            },
        )?,
        None => Vec::new(),
    };
    let segments = opts.plugs.map(|p| p.segments);
    check_print_options(opts)?;
    let errors = input_errors(&lib, anims, inputs, &opts.cuts)?;
    let printed = if opts.print {
        print_pieces(
            &lib,
            anims,
            &PrintSettings {
                thickness_mm: opts.thickness_mm,
                print_height_mm: opts.print_height_mm,
                resolution_mm: opts.resolution_mm,
                keys: opts.keys,
                ids: opts.ids,
                plugs: &plugs,
                plug_segments: segments.unwrap_or(crate::library::DEFAULT_PLUG_SEGMENTS),
                backs: &opts.backs,
                magnet: opts.magnets,
                clearance_mm: opts.clearance(),
                plate_mm: opts.plate_mm,
                print_format: opts.print_format,
                min_wall_mm: opts.min_wall_mm,
                min_feature_mm: opts.min_feature_mm,
            },
        )?
    } else {
        surface_pieces(&lib, anims, opts.resolution_mm)?
    };
    let mut printed = printed;
    let library_3mf = lay_out_plates(&mut printed, names, opts)?;
    let thumbnails = piece_thumbnails(&lib, anims)?;
    let assembly = lib.assembly();
    // Each sheet's PNG is compressed on one thread: the catalogue and the shots' sheets
    // side by side.
    let (catalogue, sheets) = rayon::join(
        || catalogue_png(&lib, &thumbnails),
        || assembly_sheets(&lib, anims, &assembly, &opts.cuts, &thumbnails),
    );
    let (catalogue, sheets) = (catalogue?, sheets?);
    drop(thumbnails);
    let order = shooting_order(&assembly);
    let reconstruction = anims
        .iter()
        .zip(names)
        .map(|(a, name)| {
            let mut mesh = a.mesh.clone();
            mesh.name.clone_from(name);
            Reconstruction {
                mesh,
                fps: a.fps,
                start_time: a.start_time,
            }
        })
        .collect();
    let mut report = LibraryReport::new(
        &lib,
        ReportInputs {
            names,
            plugs: &plugs,
            order: &order,
            frames: assembly.frames.len(),
            fps: anims[0].fps,
            print_height_mm: opts.print_height_mm,
            thickness_mm: opts.thickness_mm,
            restarts: opts.solve.restarts,
            errors,
            printing: printed.report,
            warnings: printed.warnings,
            sheets: sheets.iter().map(|(n, _)| n.clone()).collect(),
        },
    );
    report.total_seconds = start.elapsed().as_secs_f64();
    report.peak_memory_mib = super::report::peak_memory_mib();
    Ok(LibraryResult {
        segmented: None,
        part_names: names.to_vec(),
        library: lib,
        pieces: printed.pieces,
        backs: printed.backs,
        mounts: printed.mounts,
        library_3mf,
        assembly,
        shooting_order: order,
        plugs,
        reconstruction,
        catalogue,
        sheets,
        report,
    })
}

/// `library.3mf` when it was asked for: the pieces laid out on build plates, the plates
/// and every piece's plate in the report, a warning for pieces larger than a plate.
fn lay_out_plates(
    printed: &mut super::print::Printed,
    names: &[String],
    opts: &LibraryJobOptions,
) -> Result<Option<Vec<u8>>> {
    let Some(report) = printed.report.as_mut() else {
        return Ok(None);
    };
    if !opts.print_format.three_mf() {
        return Ok(None);
    }
    let (plates, bytes, too_large) = library_3mf(&printed.pieces, names, opts.plate_mm)?;
    for piece in &mut report.pieces {
        piece.plate = plates
            .iter()
            .find(|p| p.pieces.contains(&piece.id))
            .map(|p| p.plate);
    }
    if !too_large.is_empty() {
        printed.warnings.push(format!(
            "{} pieces are larger than the {} x {} mm build plate and do not fit on it: {}; give a larger --plate",
            too_large.len(),
            opts.plate_mm[0],
            opts.plate_mm[1],
            too_large.join(", ")
        ));
    }
    report.plates = plates;
    Ok(Some(bytes))
}

/// Refuses magnets, clearances and plates no printer can use.
fn check_print_options(opts: &LibraryJobOptions) -> Result<()> {
    if let Some(m) = &opts.magnets {
        m.validate()
            .map_err(|e| Error::option_error("magnets", e.to_string()))?;
    }
    let c = opts.clearance();
    let r = CLEARANCE_RANGE_MM;
    if !(c.is_finite() && r.contains(&c)) {
        return Err(Error::option_error(
            "clearance_mm",
            format!(
                "must be between {} and {} millimetres, got {c}",
                r.start(),
                r.end()
            ),
        ));
    }
    for (name, v) in [
        ("min_wall_mm", opts.min_wall_mm),
        ("min_feature_mm", opts.min_feature_mm),
    ] {
        let r = PRINTER_MINIMUM_RANGE_MM;
        if !(v.is_finite() && r.contains(&v)) {
            return Err(Error::option_error(
                name,
                format!(
                    "the printer's minimum must be {} to {} millimetres, got {v}",
                    r.start(),
                    r.end()
                ),
            ));
        }
    }
    if !opts
        .plate_mm
        .iter()
        .all(|v| v.is_finite() && PLATE_SIDE_RANGE_MM.contains(v))
    {
        return Err(Error::option_error(
            "plate_mm",
            format!(
                "the build plate must be {} to {} millimetres each way, got {:?}",
                PLATE_SIDE_RANGE_MM.start(),
                PLATE_SIDE_RANGE_MM.end(),
                opts.plate_mm
            ),
        ));
    }
    Ok(())
}

/// One plug per seam between two parts, placed on the average geometry in millimetres (the
/// STL coordinates).
fn plan_part_plugs(
    lib: &Library,
    anims: &[&MeshAnimation],
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
