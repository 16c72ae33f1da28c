//! The printing side of a library (issue 19): solids closed onto one shared back surface per
//! part with registration keys and an embossed ID, the printer-resolution check and the
//! material and print-time estimates of `report.json` `"printing"`.
//!
//! Piece IDs: `P-NN`, the part's number (1-based, part order) and the piece number — the
//! digits the built-in font can draw and a printer can emboss; `upper_07` is `1-07`.

use anim::{Mesh, MeshAnimation};
use glam::Vec3;
use rayon::prelude::*;

use super::error::{Error, Result};
use super::magnets::{cut_mount, cut_piece_pocket, find_pocket, MagnetPlan};
pub(crate) use super::options::PrintSettings;
pub use super::options::DEFAULT_RESOLUTION_MM;
pub use super::piece::Piece;
use super::printability::{measure_part, printability, PartGeometry};
use super::report::{PartPrintReport, PieceReport, PrintReport, PrintTime};
use super::resolution::below_resolution;
use crate::library::{
    add_plugs, build_shells, first_thinnest, material, regularize, self_intersecting_triangles,
    volume, Bitmap, Key, KeyOptions, Library, PartShell, ShellInput, ShellOptions,
    DEFAULT_ID_RELIEF_MM,
};

/// Resin layer height assumed by the print-time estimate (mm).
const LAYER_MM: f64 = 0.05;
/// Seconds per resin layer (exposure plus peel), independent of how many pieces are on the
/// plate.
const SECONDS_PER_LAYER: f64 = 8.0;

/// The ID embossed on piece `k` of part `part` (`P-NN`, 1-based part number).
pub fn piece_label(part: usize, k: usize) -> String {
    format!("{}-{k:02}", part + 1)
}

/// What [`print_pieces`] makes.
pub(crate) struct Printed {
    /// Every piece, part by part.
    pub(crate) pieces: Vec<Piece>,
    /// `report.json` `"printing"` (none for surfaces alone).
    pub(crate) report: Option<PrintReport>,
    /// Warnings (pieces below the printer resolution, walls thinner than asked, pieces whose
    /// solid crosses itself).
    pub(crate) warnings: Vec<String>,
    /// The back surface of every part before keys and IDs (`pieces/<part>_back.obj`).
    pub(crate) backs: Vec<Mesh>,
    /// With magnets, every part's mount with the matching pocket and key sockets
    /// (`pieces/<part>_back.stl`).
    pub(crate) mounts: Vec<Mesh>,
}

/// One piece as [`print_pieces`] made it.
struct Made {
    piece: Piece,
    /// Crossing triangles of the solid as built.
    built: usize,
    /// Crossing triangles of the written solid (after regularizing, when it was).
    crossing: usize,
    /// Volume of the chips and cavities dropped when the solid was regularized (mm³); `None`
    /// when it was not.
    dropped: Option<f64>,
    /// Where the piece's animated surface alone crosses: count and a place.
    surface_crossing: Option<(usize, Vec3)>,
}

/// A part's back surface with what it was built from (millimetres).
struct BuiltShell {
    shell: PartShell,
    average: Vec<Vec3>,
    pieces_mm: Vec<Vec<Vec3>>,
    /// `(average, back)` of its boundary vertices ([`PartShell::boundary_pairs`]).
    boundary: Vec<(Vec3, Vec3)>,
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

/// Surface (model units) and printable solid (mm, on the part's shared back surface, with
/// keys, ID and plug shells) of every piece; the `"printing"` report and warnings.
pub(crate) fn print_pieces(
    lib: &Library,
    anims: &[&MeshAnimation],
    s: &PrintSettings<'_>,
) -> Result<Printed> {
    let mm = lib.mm_per_unit as f32;
    let mut parts_report = Vec::new();
    let mut warnings = Vec::new();
    let mut pieces_out: Vec<Piece> = Vec::new();
    let mut mounts_out: Vec<Mesh> = Vec::new();
    let mut measured = Vec::new();
    // One back surface per part, seam walls shared between the parts that meet.
    let averages: Vec<Vec<Vec3>> = anims
        .iter()
        .map(|a| a.average_positions().iter().map(|x| *x * mm).collect())
        .collect();
    let pieces_of = pieces_in_mm(lib);
    let inputs: Vec<ShellInput<'_>> = anims
        .iter()
        .enumerate()
        .map(|(p, a)| ShellInput {
            topology: &a.mesh,
            average: &averages[p],
            pieces: pieces_of[p].iter().map(Vec::as_slice).collect(),
            printed_back: s.backs.get(&lib.parts[p].name).map(Vec::as_slice),
        })
        .collect();
    let shell_opts = ShellOptions {
        wall_mm: s.thickness_mm,
        model_height_mm: s.print_height_mm,
        ..ShellOptions::default()
    };
    let built = build_shells(&inputs, &shell_opts)?;
    drop(inputs);
    let mut shells: Vec<BuiltShell> = Vec::new();
    let mut backs: Vec<Mesh> = Vec::new();
    for ((shell, avg), pieces_mm) in built.into_iter().zip(averages).zip(pieces_of) {
        backs.push(shell.back_mesh(&format!("{}_back", lib.parts[shells.len()].name)));
        let pairs = shell.boundary_pairs(&avg);
        shells.push(BuiltShell {
            shell,
            average: avg,
            pieces_mm,
            boundary: pairs,
        });
    }
    let boundaries: Vec<Vec<(Vec3, Vec3)>> = shells.iter().map(|b| b.boundary.clone()).collect();
    for (p, built) in shells.into_iter().enumerate() {
        let BuiltShell {
            mut shell,
            average: avg,
            pieces_mm,
            ..
        } = built;
        let part = &lib.parts[p];
        let a = anims[p];
        let seams = shell.shared_seams(&avg, &boundaries, p);
        // The mount is the back as it is before keys and IDs (what the pieces seat on); how
        // thick it is depends on the pocket found once the keys are placed.
        let unkeyed = s.magnet.map(|_| shell.clone());
        let keys = if s.keys {
            shell.add_seam_keys(&KeyOptions::for_print_height(s.print_height_mm), &seams)?
        } else {
            Vec::new()
        };
        let pixel = (s.print_height_mm * 0.02).clamp(0.3, 1.0);
        let refs: Vec<&[Vec3]> = pieces_mm.iter().map(Vec::as_slice).collect();
        let pocket = match &s.magnet {
            Some(m) => Some(find_pocket(
                &shell,
                &refs,
                &MagnetPlan::new(m, s),
                &keys,
                &part.name,
            )?),
            None => None,
        };
        // The ID keeps away from the pocket as it keeps away from the keys.
        let id_keys: Vec<Key> = keys
            .iter()
            .cloned()
            .chain(pocket.map(|q| q.as_key()))
            .collect();
        if let (Some(unkeyed), Some(m), Some(q)) = (unkeyed, &s.magnet, &pocket) {
            let mount = unkeyed.mount(
                MagnetPlan::new(m, s).mount_mm(q),
                &format!("{}_back", part.name),
            );
            mounts_out.push(cut_mount(&shell, &mount, q, &keys, &id_keys, s)?);
        }
        // Every piece's thinnest wall, once: the printability check lists them, the part's
        // statistics and warning take the thinnest.
        let walls = shell.thinnest_walls(&refs);
        measured.push(measure_part(
            &PartGeometry {
                part: p,
                name: &part.name,
                shell: &shell,
                pieces: &refs,
                keys: &keys,
                pocket: pocket.as_ref(),
                id_keys: &id_keys,
                thinnest: &walls,
            },
            s,
        ));
        // The ID sits at the same place on every piece of the part.
        let id_frame = shell.id_frame(&id_keys);
        let made: Vec<Made> = (0..pieces_mm.len())
            .into_par_iter()
            .map(|k| -> Result<Made> {
                let surface = piece_surface(lib, p, k, &a.mesh)?;
                let id = if s.ids {
                    text_bitmap(&piece_label(p, k))?
                } else {
                    Bitmap::default()
                };
                let solid = shell.solid_with_id_at(
                    &pieces_mm[k],
                    &surface.name,
                    &id,
                    (pixel, DEFAULT_ID_RELIEF_MM),
                    id_frame,
                )?;
                // Measured on what is written (keys and ID included), not assumed: a
                // coordinate beyond the exact test's range counts every triangle.
                let count = |m: &Mesh| {
                    self_intersecting_triangles(&m.positions, &m.triangles)
                        .map_or(m.triangles.len(), |t| t.len())
                };
                let built = shell
                    .solid_crossings(&solid)
                    .unwrap_or(solid.triangles.len());
                let surface_crossing = if built > 0 {
                    shell.surface_crossings(&pieces_mm[k])
                } else {
                    None
                };
                // What the construction could not keep apart is regularized (measured
                // again: the new vertices are rounded to f32); a solid the exact
                // arrangement refuses stays as built, and its crossings are reported.
                let (solid, crossing, dropped) = match (built > 0).then(|| regularize(&solid)) {
                    Some(Ok(r)) => {
                        let c = count(&r.mesh);
                        (r.mesh, c, Some(r.dropped_volume))
                    }
                    _ => (solid, built, None),
                };
                let (solid, crossing) = match &pocket {
                    Some(q) => cut_piece_pocket(&solid, q, s.thickness_mm as f32)?,
                    None => (solid, crossing),
                };
                let solid = add_plugs(&solid, p, s.plugs, s.plug_segments);
                let piece = Piece {
                    id: surface.name.clone(),
                    part: p,
                    index: k,
                    surface,
                    solid: Some(solid),
                };
                Ok(Made {
                    piece,
                    built,
                    crossing,
                    dropped,
                    surface_crossing,
                })
            })
            .collect::<Result<_>>()?;
        let listed = |f: &dyn Fn(&Made) -> usize| -> Vec<String> {
            made.iter()
                .filter(|m| f(m) > 0)
                .map(|m| format!("{} ({})", m.piece.id, f(m)))
                .collect()
        };
        let crossing_pieces = listed(&|m| m.crossing);
        let regularized: Vec<&Made> = made.iter().filter(|m| m.dropped.is_some()).collect();
        let built_crossing: usize = made.iter().map(|m| m.built).sum();
        shell.stats.self_intersecting_triangles = made.iter().map(|m| m.crossing).sum();
        let dropped_mm3 = regularized
            .iter()
            .filter_map(|m| m.dropped)
            .fold(0.0, |a, b| a + b);
        let surface: Vec<(&Piece, usize, Vec3)> = made
            .iter()
            .filter_map(|m| m.surface_crossing.map(|(n, at)| (&m.piece, n, at)))
            .collect();
        let surface_triangles: usize = surface.iter().map(|(_, n, _)| n).sum();
        let thinnest = first_thinnest(walls.iter().copied());
        if let Some(t) = thinnest {
            shell.stats.min_wall_mm = t.mm;
        }
        if let Some(t) = thinnest.filter(|t| t.mm < s.thickness_mm * 0.99) {
            warnings.push(format!(
                "part {}: the wall is {:.2} mm thin in piece {} at ({:.1}, {:.1}, {:.1}) mm{}, under the {} mm wall; a printer may leave a hole there",
                part.name,
                t.mm,
                piece_label(p, t.piece),
                t.at.x,
                t.at.y,
                t.at.z,
                if t.on_boundary { " (on the part boundary)" } else { "" },
                s.thickness_mm
            ));
        }
        if !regularized.is_empty() {
            warnings.push(format!(
                "part {}: {} of {} pieces crossed their own surface as built ({built_crossing} triangles: {}); each was regularized to the material it encloses, as a slicer reads it ({} crossing triangles left{}): the printed shape differs from the animated surface there, look at those places before printing",
                part.name,
                regularized.len(),
                made.len(),
                listed(&|m| m.built).join(", "),
                shell.stats.self_intersecting_triangles,
                if dropped_mm3 > 0.0 {
                    format!("; {dropped_mm3:.3} mm³ of chips apart from the pieces or sealed cavities dropped")
                } else {
                    String::new()
                }
            ));
        }
        if !crossing_pieces.is_empty() {
            warnings.push(format!(
                "part {}: {} triangles of {} of {} pieces cross the solid's own surface (a slicer may misprint there): {}",
                part.name,
                shell.stats.self_intersecting_triangles,
                crossing_pieces.len(),
                made.len(),
                crossing_pieces.join(", ")
            ));
        }
        if let Some((first, _, at)) = surface.first() {
            warnings.push(format!(
                "part {}: in {} of these pieces the animated surface itself crosses ({} triangles, e.g. piece {} at ({:.1}, {:.1}, {:.1}) mm): the input presses into itself inside the part (lips or lids on a face) or has degenerate triangles there, which no back surface can undo (the regularized solid prints them merged there); to keep them apart, cut the parts so that a seam runs between the touching surfaces (one side in each part), or mend the input there",
                part.name,
                surface.len(),
                surface_triangles,
                first.id,
                at.x,
                at.y,
                at.z,
            ));
        }
        let regularized_pieces: Vec<String> =
            regularized.iter().map(|m| m.piece.id.clone()).collect();
        let made: Vec<Piece> = made.into_iter().map(|m| m.piece).collect();
        let (close, nearest) = below_resolution(&part.name, &pieces_mm, s.resolution_mm);
        warn_below_resolution(
            &mut warnings,
            &part.name,
            &close,
            pieces_mm.len(),
            s.resolution_mm,
        );
        parts_report.push(PartPrintReport {
            name: part.name.clone(),
            shell: shell.stats,
            keys,
            below_resolution: close,
            min_sibling_distance_mm: nearest,
            surface_self_intersecting_triangles: surface_triangles,
            built_self_intersecting_triangles: built_crossing,
            regularized_pieces,
            dropped_volume_mm3: dropped_mm3,
            magnet_pocket: pocket,
        });
        pieces_out.extend(made);
    }
    // The solids are measured where they are (a piece's solid is ~30k triangles).
    let solids: Vec<&Mesh> = pieces_out.iter().filter_map(|p| p.solid.as_ref()).collect();
    let (checked, thin) = printability(measured, s);
    warnings.extend(thin);
    let report = PrintReport {
        material: material(solids.iter().copied()),
        print_time: print_time(&solids, s.plate_mm),
        resolution_mm: s.resolution_mm,
        keys: s.keys,
        ids: s.ids,
        clearance_mm: s.clearance_mm,
        magnet: s.magnet,
        print_format: s.print_format,
        plates: Vec::new(),
        parts: parts_report,
        pieces: piece_reports(lib, &pieces_out, s.magnet.is_some()),
        printability: checked,
    };
    Ok(Printed {
        pieces: pieces_out,
        report: Some(report),
        warnings,
        backs,
        mounts: mounts_out,
    })
}

/// The per-piece lines of the report (plates are filled in once `library.3mf` is laid out).
fn piece_reports(lib: &Library, pieces: &[Piece], magnet: bool) -> Vec<PieceReport> {
    pieces
        .iter()
        .map(|p| {
            let labels = &lib.parts[p.part].solution.labels;
            PieceReport {
                id: p.id.clone(),
                label: piece_label(p.part, p.index),
                part: lib.parts[p.part].name.clone(),
                frames: (0..labels.len())
                    .filter(|&f| labels[f] as usize == p.index)
                    .collect(),
                volume_mm3: p.solid.as_ref().map_or(0.0, volume),
                magnet,
                plate: None,
            }
        })
        .collect()
}

/// The pieces' surfaces alone, without solids, backs or the `"printing"` report (a look at a
/// library before printing it); still warns about pieces closer than the printer resolution,
/// which says as much about the library size as about printing.
pub(crate) fn surface_pieces(
    lib: &Library,
    anims: &[&MeshAnimation],
    resolution_mm: f64,
) -> Result<Printed> {
    let mut pieces = Vec::new();
    let mut warnings = Vec::new();
    for (p, ((part, a), pieces_mm)) in lib
        .parts
        .iter()
        .zip(anims)
        .zip(pieces_in_mm(lib))
        .enumerate()
    {
        let (close, _) = below_resolution(&part.name, &pieces_mm, resolution_mm);
        warn_below_resolution(
            &mut warnings,
            &part.name,
            &close,
            pieces_mm.len(),
            resolution_mm,
        );
        for k in 0..pieces_mm.len() {
            let surface = piece_surface(lib, p, k, &a.mesh)?;
            pieces.push(Piece {
                id: surface.name.clone(),
                part: p,
                index: k,
                surface,
                solid: None,
            });
        }
    }
    Ok(Printed {
        pieces,
        report: None,
        warnings,
        backs: Vec::new(),
        mounts: Vec::new(),
    })
}

/// Piece `k` of part `p` as a surface ([`Library::piece_surface`]), or an error naming it.
fn piece_surface(lib: &Library, p: usize, k: usize, topology: &Mesh) -> Result<Mesh> {
    lib.piece_surface(p, k, topology)
        .ok_or_else(|| Error::option_error("pieces", format!("no piece {k} of part {p}")))
}

/// Every part's pieces in millimetres (the STL coordinates), part by part.
fn pieces_in_mm(lib: &Library) -> Vec<Vec<Vec<Vec3>>> {
    let mm = lib.mm_per_unit as f32;
    lib.parts
        .iter()
        .map(|part| {
            part.solution
                .pieces
                .iter()
                .map(|q| q.iter().map(|x| *x * mm).collect())
                .collect()
        })
        .collect()
}

/// The warning about pieces closer to a sibling than the printer resolution.
fn warn_below_resolution(
    warnings: &mut Vec<String>,
    part: &str,
    close: &[String],
    n: usize,
    resolution_mm: f64,
) {
    if !close.is_empty() {
        warnings.push(format!(
            "part {part}: {} of {n} pieces differ from a sibling by less than the printer resolution ({resolution_mm} mm): {}; print larger (print height) or use fewer pieces",
            close.len(),
            close.join(", ")
        ));
    }
}

/// Resin print time: plates by footprint (pieces laid on their smallest extent, 50 % margin),
/// layers by the tallest piece.
fn print_time(solids: &[&Mesh], plate_mm: [f64; 2]) -> PrintTime {
    let tallest = solids
        .iter()
        .map(|s| {
            let b = s.bbox();
            f64::from((b.max - b.min).min_element())
        })
        .fold(0.0, f64::max);
    let footprint: f64 = solids
        .iter()
        .map(|s| {
            let b = s.bbox();
            let e = b.max - b.min;
            let mut d = [f64::from(e.x), f64::from(e.y), f64::from(e.z)];
            d.sort_by(f64::total_cmp);
            d[1] * d[2] * 1.5
        })
        .sum();
    let plates = (footprint / (plate_mm[0] * plate_mm[1])).ceil().max(1.0);
    let layers = (tallest / LAYER_MM).ceil();
    PrintTime {
        hours: plates * layers * SECONDS_PER_LAYER / 3600.0,
        plates,
        layers_per_plate: layers,
        layer_mm: LAYER_MM,
        seconds_per_layer: SECONDS_PER_LAYER,
        plate_mm,
        assumes: "resin printer, pieces laid flat on their smallest extent".into(),
    }
}
