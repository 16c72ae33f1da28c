//! Picture sheets of a library: `catalogue.png` (every piece with its embossed ID) and one
//! `assembly_shotNN.png` per shot (the assembled face for every run of frames with the same
//! pieces, labelled with its first frame).

use anim::MeshAnimation;
use glam::Vec3;
use rayon::prelude::*;

use super::error::Result;
use super::print::piece_label;
use crate::library::{Assembly, Library};

/// Thumbnail size of the catalogue and the assembly sheets (pixels).
const THUMB: u32 = 128;
/// Most thumbnails on one assembly sheet.
const MAX_SHEET_CELLS: usize = 240;

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

/// Every piece rendered from the front in its part's colour, part by part: the catalogue's
/// thumbnails before their IDs, and, for a one-part library, each shot's assembled face.
pub(crate) fn piece_thumbnails(
    lib: &Library,
    anims: &[&MeshAnimation],
) -> Result<Vec<Vec<render::Image>>> {
    lib.parts
        .iter()
        .enumerate()
        .map(|(p, r)| {
            r.solution
                .pieces
                .par_iter()
                .map(|piece| thumbnail(piece, &anims[p].mesh.triangles, render::categorical(p)))
                .collect::<Result<Vec<_>>>()
        })
        .collect()
}

/// `catalogue.png`: every piece's thumbnail ([`piece_thumbnails`]) with its embossed ID.
pub(crate) fn catalogue_png(lib: &Library, thumbnails: &[Vec<render::Image>]) -> Result<Vec<u8>> {
    let jobs: Vec<(usize, usize)> = thumbnails
        .iter()
        .enumerate()
        .flat_map(|(p, t)| (0..t.len()).map(move |k| (p, k)))
        .collect();
    let images: Vec<render::Image> = jobs
        .par_iter()
        .map(|&(p, k)| {
            let mut img = thumbnails[p][k].clone();
            render::draw_text(
                &mut img,
                &piece_label(p, k),
                4,
                i64::from(THUMB) - 20,
                2,
                [20, 20, 20, 255],
                Some([255, 255, 255, 255]),
            );
            img
        })
        .collect();
    let columns = (images.len() as f64).sqrt().ceil().max(1.0) as usize;
    let widest = lib
        .parts
        .iter()
        .map(|p| p.solution.pieces.len())
        .max()
        .unwrap_or(1)
        .min(12);
    let sheet = render::contact_sheet(
        &images,
        None,
        &render::SheetOptions {
            columns: columns.max(widest),
            ..Default::default()
        },
    )?;
    Ok(render::encode_png(&sheet)?)
}

/// `assembly_shotNN.png`, one per shot (clips split at `cuts`), as (file name, PNG bytes).
/// A one-part library's assembled face is its piece, drawn as the catalogue draws it (part
/// 0's colour, the part's triangles), so its `thumbnails` are reused instead of rendered again.
pub(crate) fn assembly_sheets(
    lib: &Library,
    anims: &[&MeshAnimation],
    assembly: &Assembly,
    cuts: &[usize],
    thumbnails: &[Vec<render::Image>],
) -> Result<Vec<(String, Vec<u8>)>> {
    let frames = assembly.frames.len();
    let mut starts: Vec<usize> = std::iter::once(0)
        .chain(cuts.iter().copied().filter(|&c| c > 0 && c < frames))
        .collect();
    starts.sort_unstable();
    starts.dedup();
    // Shots side by side (each sheet's PNG is compressed on one thread), listed in order.
    let sheets = starts
        .par_iter()
        .enumerate()
        .map(|(s, &start)| -> Result<Option<(String, Vec<u8>)>> {
            let end = starts.get(s + 1).copied().unwrap_or(frames);
            let mut runs: Vec<usize> = (start..end)
                .filter(|&f| f == start || assembly.frames[f] != assembly.frames[f - 1])
                .collect();
            runs.truncate(MAX_SHEET_CELLS);
            let images: Vec<render::Image> = runs
                .par_iter()
                .map(|&f| shot_thumbnail(lib, anims, thumbnails, f))
                .collect::<Result<_>>()?;
            if images.is_empty() {
                return Ok(None);
            }
            let sheet = render::contact_sheet(
                &images,
                Some(&runs),
                &render::SheetOptions {
                    columns: 12,
                    ..Default::default()
                },
            )?;
            Ok(Some((
                format!("assembly_shot{:02}.png", s + 1),
                render::encode_png(&sheet)?,
            )))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(sheets.into_iter().flatten().collect())
}

/// The assembled face of frame `f` (every part's piece on that frame).
fn shot_thumbnail(
    lib: &Library,
    anims: &[&MeshAnimation],
    thumbnails: &[Vec<render::Image>],
    f: usize,
) -> Result<render::Image> {
    if let ([sol], [pieces]) = (&lib.parts[..], thumbnails) {
        return Ok(pieces[sol.solution.labels[f] as usize].clone());
    }
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (p, a) in anims.iter().enumerate() {
        let sol = &lib.parts[p].solution;
        let base = positions.len() as u32;
        positions.extend_from_slice(&sol.pieces[sol.labels[f] as usize]);
        triangles.extend(a.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    thumbnail(&positions, &triangles, render::categorical(0))
}
