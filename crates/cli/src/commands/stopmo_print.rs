//! The printing side of `stopmo library` / `stopmo run` (issue 19): solids on one shared back
//! surface per part with registration keys and an embossed ID, the printer-resolution check,
//! material and print-time estimates, `catalogue.png` (a render and the ID of every piece) and
//! one assembly sheet with thumbnails per shot.
//!
//! Piece IDs: `P-NN`, the part's number (1-based, part order) and the piece number — the
//! digits the built-in font can draw and a printer can emboss; `upper_07` is `1-07`.

use std::fmt::Write as _;
use std::path::Path;

use anim::glam::Vec3;
use anim::{Mesh, MeshAnimation};
use anyhow::{Context as _, Result};
use rayon::prelude::*;
use serde_json::json;
use stopmo::library::{
    add_plugs, material, Assembly, Bitmap, KeyOptions, Library, PartShell, Plug, ShellOptions,
    DEFAULT_ID_RELIEF_MM,
};

/// Resin layer height assumed by the print-time estimate (mm).
const LAYER_MM: f64 = 0.05;
/// Seconds per resin layer (exposure plus peel), independent of how many pieces are on the
/// plate.
const SECONDS_PER_LAYER: f64 = 8.0;
/// Build plate of a small resin printer (mm).
const PLATE_MM: [f64; 2] = [120.0, 68.0];
/// Thumbnail size of the catalogue and the assembly sheets (pixels).
const THUMB: u32 = 128;
/// Most thumbnails on one assembly sheet.
const MAX_SHEET_CELLS: usize = 240;

/// Printing options of `stopmo library` / `stopmo run`.
pub(super) struct PrintOptions {
    /// Minimum wall (mm).
    pub thickness_mm: f64,
    /// Printed height (mm).
    pub print_height_mm: f64,
    /// Printer resolution (mm): pieces closer than this to a sibling are reported.
    pub resolution_mm: f64,
    /// Registration keys on the back surface.
    pub keys: bool,
    /// Embossed IDs.
    pub ids: bool,
}

/// The ID embossed on piece `k` of part `part`.
pub(super) fn piece_label(part: usize, k: usize) -> String {
    format!("{}-{k:02}", part + 1)
}

/// Renders `text` with the built-in font into a bitmap (one font pixel per bitmap pixel).
fn text_bitmap(text: &str) -> Result<Bitmap> {
    let (w, h) = render::text_size(text, 1);
    let mut img = render::Image::new(w.max(1), h.max(1), [0, 0, 0, 0])?;
    render::draw_text(&mut img, text, 0, 0, 1, [255, 255, 255, 255], None);
    Ok(Bitmap {
        width: w as usize,
        height: h as usize,
        pixels: img.pixels().iter().map(|p| p[3] > 0).collect(),
    })
}

/// Writes `DIR/pieces/<id>.obj` (surface, model units) and `<id>.stl` (solid, mm) for every
/// piece, and returns the report's `"printing"` section plus warnings.
pub(super) fn write_pieces(
    dir: &Path,
    lib: &Library,
    anims: &[MeshAnimation],
    opts: &PrintOptions,
    plugs: &[Plug],
) -> Result<(serde_json::Value, Vec<String>)> {
    let mm = lib.mm_per_unit as f32;
    let mut parts_report = Vec::new();
    let mut warnings = Vec::new();
    let mut all_solids: Vec<Mesh> = Vec::new();
    let mut shared: Vec<(Vec3, Vec3)> = Vec::new();
    for (p, a) in anims.iter().enumerate() {
        let part = &lib.parts[p];
        let avg: Vec<Vec3> = a.average_positions().iter().map(|x| *x * mm).collect();
        let pieces_mm: Vec<Vec<Vec3>> = part
            .solution
            .pieces
            .iter()
            .map(|q| q.iter().map(|x| *x * mm).collect())
            .collect();
        let refs: Vec<&[Vec3]> = pieces_mm.iter().map(Vec::as_slice).collect();
        let shell_opts = ShellOptions {
            wall_mm: opts.thickness_mm,
            ..ShellOptions::default()
        };
        let mut shell = PartShell::new_sharing(&a.mesh, &avg, &refs, &shell_opts, &shared)
            .with_context(|| format!("part {}: back surface", a.mesh.name))?;
        shared.extend(shell.boundary_pairs(&avg));
        let keys = if opts.keys {
            shell.add_keys(&KeyOptions::for_print_height(opts.print_height_mm))?
        } else {
            Vec::new()
        };
        let pixel = (opts.print_height_mm * 0.02).clamp(0.3, 1.0);
        let solids: Vec<Mesh> = (0..pieces_mm.len())
            .into_par_iter()
            .map(|k| -> Result<Mesh> {
                let surface = lib
                    .piece_surface(p, k, &a.mesh)
                    .context("piece index out of range")?;
                let base = dir.join("pieces").join(&surface.name);
                tkio::write_atomic(
                    &base.with_extension("obj"),
                    tkio::obj::write(&surface).as_bytes(),
                )?;
                let id = if opts.ids {
                    text_bitmap(&piece_label(p, k))?
                } else {
                    Bitmap::default()
                };
                let solid = shell
                    .solid_with_id(
                        &pieces_mm[k],
                        &surface.name,
                        &id,
                        pixel,
                        DEFAULT_ID_RELIEF_MM,
                        &keys,
                    )
                    .with_context(|| format!("piece {}", surface.name))?;
                let solid = add_plugs(&solid, p, plugs, stopmo::library::DEFAULT_PLUG_SEGMENTS);
                tkio::write_atomic(
                    &base.with_extension("stl"),
                    &tkio::stl::write_binary(&solid),
                )?;
                Ok(solid)
            })
            .collect::<Result<_>>()?;
        // Pieces closer to a sibling than the printer resolves.
        let n = pieces_mm.len();
        let mut nearest = vec![f64::INFINITY; n];
        for i in 0..n {
            for j in i + 1..n {
                let d = pieces_mm[i]
                    .iter()
                    .zip(&pieces_mm[j])
                    .map(|(x, y)| x.distance(*y))
                    .fold(0.0f32, f32::max) as f64;
                nearest[i] = nearest[i].min(d);
                nearest[j] = nearest[j].min(d);
            }
        }
        let close: Vec<String> = (0..n)
            .filter(|&k| nearest[k] < opts.resolution_mm)
            .map(|k| stopmo::library::piece_id(&part.name, k, n))
            .collect();
        if !close.is_empty() {
            warnings.push(format!(
                "part {}: {} of {n} pieces differ from a sibling by less than the printer resolution ({} mm): {}; print larger (--print-height) or use fewer pieces",
                part.name,
                close.len(),
                opts.resolution_mm,
                close.join(", ")
            ));
        }
        parts_report.push(json!({
            "name": part.name,
            "shell": shell.stats,
            "keys": keys,
            "below_resolution": close,
            "min_sibling_distance_mm": nearest.iter().copied().fold(f64::INFINITY, f64::min),
        }));
        all_solids.extend(solids);
    }
    let mat = material(&all_solids);
    let tallest = all_solids
        .iter()
        .map(|s| {
            let b = s.bbox();
            f64::from((b.max - b.min).min_element())
        })
        .fold(0.0, f64::max);
    let footprint: f64 = all_solids
        .iter()
        .map(|s| {
            let b = s.bbox();
            let e = b.max - b.min;
            // Laid on its smallest extent, with a 50 % margin around it.
            let mut d = [f64::from(e.x), f64::from(e.y), f64::from(e.z)];
            d.sort_by(f64::total_cmp);
            d[1] * d[2] * 1.5
        })
        .sum();
    let plates = (footprint / (PLATE_MM[0] * PLATE_MM[1])).ceil().max(1.0);
    let layers = (tallest / LAYER_MM).ceil();
    let hours = plates * layers * SECONDS_PER_LAYER / 3600.0;
    let report = json!({
        "material": mat,
        "print_time": {
            "hours": hours,
            "plates": plates,
            "layers_per_plate": layers,
            "layer_mm": LAYER_MM,
            "seconds_per_layer": SECONDS_PER_LAYER,
            "plate_mm": PLATE_MM,
            "assumes": "resin printer, pieces laid flat on their smallest extent",
        },
        "resolution_mm": opts.resolution_mm,
        "keys": opts.keys,
        "ids": opts.ids,
        "parts": parts_report,
    });
    Ok((report, warnings))
}

fn thumbnail(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    color: render::Color,
) -> Result<render::Image> {
    let renderer = render::Renderer::new(THUMB, THUMB)?;
    let view = render::View::fit(
        anim::Aabb::from_points(positions),
        render::ViewDirection::Front,
        renderer.aspect(),
    );
    Ok(renderer.render(
        &render::DrawList::new().mesh(render::MeshItem::new(positions, triangles).color(color)),
        &view,
    )?)
}

/// `DIR/catalogue.png`: every piece rendered from the front with its embossed ID.
pub(super) fn write_catalogue(dir: &Path, lib: &Library, anims: &[MeshAnimation]) -> Result<()> {
    let jobs: Vec<(usize, usize)> = lib
        .parts
        .iter()
        .enumerate()
        .flat_map(|(p, r)| (0..r.solution.pieces.len()).map(move |k| (p, k)))
        .collect();
    let images: Vec<render::Image> = jobs
        .par_iter()
        .map(|&(p, k)| -> Result<render::Image> {
            let mut img = thumbnail(
                &lib.parts[p].solution.pieces[k],
                &anims[p].mesh.triangles,
                render::categorical(p),
            )?;
            render::draw_text(
                &mut img,
                &piece_label(p, k),
                4,
                i64::from(THUMB) - 20,
                2,
                [20, 20, 20, 255],
                Some([255, 255, 255, 255]),
            );
            Ok(img)
        })
        .collect::<Result<_>>()?;
    let columns = (images.len() as f64).sqrt().ceil().max(1.0) as usize;
    let sheet = render::contact_sheet(
        &images,
        None,
        &render::SheetOptions {
            columns: columns.max(
                lib.parts
                    .iter()
                    .map(|p| p.solution.pieces.len())
                    .max()
                    .unwrap_or(1)
                    .min(12),
            ),
            ..Default::default()
        },
    )?;
    tkio::write_atomic(&dir.join("catalogue.png"), &render::encode_png(&sheet)?)?;
    Ok(())
}

/// `DIR/assembly_shotNN.png`, one per shot (clips split at `cuts`): a thumbnail of the
/// assembled face for every run of frames with the same pieces, labelled with its first
/// frame. Returns the file names.
pub(super) fn write_assembly_sheets(
    dir: &Path,
    lib: &Library,
    anims: &[MeshAnimation],
    assembly: &Assembly,
    cuts: &[usize],
) -> Result<Vec<String>> {
    let frames = assembly.frames.len();
    let mut starts: Vec<usize> = std::iter::once(0)
        .chain(cuts.iter().copied().filter(|&c| c > 0 && c < frames))
        .collect();
    starts.sort_unstable();
    starts.dedup();
    let mut names = Vec::new();
    for (s, &start) in starts.iter().enumerate() {
        let end = starts.get(s + 1).copied().unwrap_or(frames);
        let mut runs: Vec<usize> = Vec::new();
        for f in start..end {
            if f == start || assembly.frames[f] != assembly.frames[f - 1] {
                runs.push(f);
            }
        }
        runs.truncate(MAX_SHEET_CELLS);
        let images: Vec<render::Image> = runs
            .par_iter()
            .map(|&f| -> Result<render::Image> {
                let mut positions = Vec::new();
                let mut triangles = Vec::new();
                for (p, a) in anims.iter().enumerate() {
                    let sol = &lib.parts[p].solution;
                    let base = positions.len() as u32;
                    positions.extend_from_slice(&sol.pieces[sol.labels[f] as usize]);
                    triangles.extend(a.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
                }
                thumbnail(&positions, &triangles, render::categorical(0))
            })
            .collect::<Result<_>>()?;
        if images.is_empty() {
            continue;
        }
        let sheet = render::contact_sheet(
            &images,
            Some(&runs),
            &render::SheetOptions {
                columns: 12,
                ..Default::default()
            },
        )?;
        let name = format!("assembly_shot{:02}.png", s + 1);
        tkio::write_atomic(&dir.join(&name), &render::encode_png(&sheet)?)?;
        names.push(name);
    }
    Ok(names)
}

/// A readable assembly sheet: pieces per part, then runs of frames with the same assembly.
pub(super) fn assembly_markdown(lib: &Library, names: &[&str], ids: &[Vec<String>]) -> String {
    let mut md = String::from("# Assembly sheet\n\n");
    let _ = writeln!(
        md,
        "{} frames, {} pieces ({}).\n",
        ids.len(),
        lib.total_pieces(),
        lib.parts
            .iter()
            .map(|p| format!("{}: {}", p.name, p.solution.pieces.len()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        md,
        "Piece IDs embossed on the backs: {}; renders in catalogue.png, thumbnails per shot in assembly_shotNN.png.\n",
        lib.parts
            .iter()
            .enumerate()
            .map(|(p, part)| format!("{} = {}-NN", part.name, p + 1))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(md, "| frames | {} |", names.join(" | "));
    let _ = writeln!(md, "|---|{}", "---|".repeat(names.len()));
    let mut f = 0;
    while f < ids.len() {
        let mut end = f;
        while end + 1 < ids.len() && ids[end + 1] == ids[f] {
            end += 1;
        }
        let range = if end == f {
            f.to_string()
        } else {
            format!("{f}–{end}")
        };
        let _ = writeln!(md, "| {range} | {} |", ids[f].join(" | "));
        f = end + 1;
    }
    md
}

/// Errors against the artist's animation, in millimetres.
pub(super) struct InputErrors {
    /// All parts.
    pub total: stopmo::library::ErrorSummary,
    /// Per part.
    pub parts: Vec<stopmo::library::ErrorSummary>,
    /// What homogenization alone changed (homogenized parts against the input), when the
    /// input is known.
    pub homogenization: Option<stopmo::library::ErrorSummary>,
}

/// Reconstruction errors against `inputs` (the parts before homogenization; the built parts
/// themselves when `None`), and what homogenization added.
pub(super) fn input_errors(
    lib: &Library,
    anims: &[MeshAnimation],
    inputs: Option<&[MeshAnimation]>,
    cuts: &[usize],
) -> Result<InputErrors> {
    use stopmo::library::{compare_frames, ErrorSummary};
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
        let e = lib
            .errors_against(p, x, cuts)
            .with_context(|| format!("part {}: input and library disagree", a.mesh.name))?;
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
