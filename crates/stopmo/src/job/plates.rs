//! The pieces laid out on build plates for `library.3mf`: a deterministic shelf packing of
//! their footprints (axis-aligned, as printed: the STL orientation), tallest rows first, and
//! the package with every piece a named object coloured by its part.
//!
//! Several plates are laid side by side along x in the one build, a plate and a gap apart
//! (`PLATE_GAP_MM`); `report.json` `"plates"` lists which pieces are on which plate and where
//! its origin is, so a print shop can split the build per plate.

use anim::Mesh;
use serde::Serialize;

use super::error::{Error, Result};
use super::piece::Piece;

/// Space between pieces on a plate (mm).
const PIECE_GAP_MM: f32 = 3.0;
/// Space between two plates laid side by side in the build (mm).
const PLATE_GAP_MM: f32 = 20.0;

/// Display colours of the parts (sRGB), in part order, repeated past the last.
const PART_COLOURS: [[u8; 4]; 6] = [
    [0xE0, 0x6C, 0x4F, 0xFF],
    [0x4F, 0x8F, 0xE0, 0xFF],
    [0x6C, 0xB8, 0x5A, 0xFF],
    [0xE0, 0xB8, 0x3F, 0xFF],
    [0x9B, 0x6C, 0xD0, 0xFF],
    [0x4F, 0xC0, 0xC0, 0xFF],
];

/// One build plate of `library.3mf`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plate {
    /// 1-based plate number.
    pub plate: usize,
    /// Where the plate's corner lies in the 3MF build (mm).
    pub origin_mm: [f32; 2],
    /// Plate size (mm).
    pub size_mm: [f64; 2],
    /// Piece IDs on it, in placement order.
    pub pieces: Vec<String>,
}

/// Where a piece goes: its plate (0-based) and build translation.
#[derive(Debug, Clone, Copy)]
struct Placed {
    plate: usize,
    translation: [f32; 3],
}

/// Lays the solids of `pieces` out on plates of `plate_mm` (width along x, depth along y).
/// Returns the plates and every solid piece's placement (same order as `pieces`; `None` for
/// pieces without a solid). A piece wider than a plate gets a plate of its own (listed, the
/// caller warns).
fn pack(pieces: &[Piece], plate_mm: [f64; 2]) -> (Vec<Plate>, Vec<Option<Placed>>) {
    let (w, d) = (plate_mm[0] as f32, plate_mm[1] as f32);
    let mut order: Vec<(usize, glam::Vec3, glam::Vec3)> = pieces
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let b = p.solid.as_ref()?.bbox();
            Some((i, b.min, b.max - b.min))
        })
        .collect();
    // Deepest first, then by ID: rows of similar depth, the same layout every run.
    order.sort_by(|a, b| {
        b.2.y
            .total_cmp(&a.2.y)
            .then_with(|| pieces[a.0].id.cmp(&pieces[b.0].id))
    });
    let mut plates: Vec<Plate> = Vec::new();
    let mut placed = vec![None; pieces.len()];
    // Cursor on the current plate: x in the row, the row's y and its depth.
    let (mut x, mut y, mut row) = (0.0f32, 0.0f32, 0.0f32);
    for (i, min, size) in order {
        let new_plate = |plates: &mut Vec<Plate>| {
            let k = plates.len();
            plates.push(Plate {
                plate: k + 1,
                origin_mm: [k as f32 * (w + PLATE_GAP_MM), 0.0],
                size_mm: plate_mm,
                pieces: Vec::new(),
            });
        };
        if plates.is_empty() {
            new_plate(&mut plates);
        }
        if x > 0.0 && x + size.x > w {
            // Next row.
            y += row + PIECE_GAP_MM;
            x = 0.0;
            row = 0.0;
        }
        if y > 0.0 && y + size.y > d {
            new_plate(&mut plates);
            x = 0.0;
            y = 0.0;
            row = 0.0;
        }
        let k = plates.len() - 1;
        let origin = plates[k].origin_mm;
        placed[i] = Some(Placed {
            plate: k,
            translation: [origin[0] + x - min.x, origin[1] + y - min.y, -min.z],
        });
        plates[k].pieces.push(pieces[i].id.clone());
        x += size.x + PIECE_GAP_MM;
        row = row.max(size.y);
    }
    (plates, placed)
}

/// The plates of `pieces` and the bytes of `library.3mf` (every solid piece an object named by
/// its ID, one colour per part), and the IDs of pieces larger than a plate.
///
/// # Errors
/// When the package cannot be encoded (a non-finite vertex).
pub(crate) fn library_3mf(
    pieces: &[Piece],
    part_names: &[String],
    plate_mm: [f64; 2],
) -> Result<(Vec<Plate>, Vec<u8>, Vec<String>)> {
    let (plates, placed) = pack(pieces, plate_mm);
    let materials = part_names
        .iter()
        .enumerate()
        .map(|(p, name)| tkio::threemf::BaseMaterial {
            name: name.clone(),
            color: PART_COLOURS[p % PART_COLOURS.len()],
        })
        .collect();
    let mut objects = Vec::new();
    let mut too_large = Vec::new();
    for (piece, at) in pieces.iter().zip(&placed) {
        let (Some(solid), Some(at)) = (&piece.solid, at) else {
            continue;
        };
        let e = solid.bbox();
        let size = e.max - e.min;
        if f64::from(size.x) > plate_mm[0] || f64::from(size.y) > plate_mm[1] {
            too_large.push(format!("{} (plate {})", piece.id, at.plate + 1));
        }
        objects.push(tkio::threemf::Object {
            name: &piece.id,
            mesh: solid as &Mesh,
            material: piece.part,
            translation: at.translation,
        });
    }
    let model = tkio::threemf::Model {
        materials,
        objects,
        title: "toonkit stop-motion replacement library".into(),
    };
    let bytes = tkio::threemf::encode(&model)
        .map_err(|e| Error::option_error("print_format", format!("library.3mf: {e}")))?;
    Ok((plates, bytes, too_large))
}
