//! Issue 19 acceptance on the ICT face (60 frames at 1 fps, the README's `upper`/`lower`
//! seeds): printable pieces are closed, oriented, single-shell solids with no
//! self-intersecting triangle (exact test) and the minimum wall, for 8, 20 and 50 pieces;
//! homogenization leaves the open borders where the input puts them; a saved segmentation
//! reused on another clip puts the seams at the same place.

use std::collections::HashMap;
use std::sync::OnceLock;

use anim::{MeshAnimation, SampleOptions};
use glam::Vec3;
use rayon::prelude::*;
use stopmo::library::{
    build_library, build_shells, check_solid, components, print_scale, self_intersecting_triangles,
    Bitmap, KeyOptions, LibraryOptions, LibrarySize, PartInput, PartSetup, PartShell, ShellInput,
    ShellOptions,
};
use stopmo::segment::{
    auto_parts, segment, segment_reusing, PartSpec, SavedSegmentation, Seed, SegmentOptions,
    Segmentation,
};

#[path = "../common/mod.rs"]
mod common;
mod diagnose;
mod open_borders;
mod printable;
mod seams;

/// The ICT face clip, relative to `assets/`.
const FACE: &str = "face/ict-face-talk.glb";

/// Print height of the acceptance (mm): the default one.
const HEIGHT_MM: f64 = stopmo::library::DEFAULT_PRINT_HEIGHT_MM;

/// The face clip at 1 fps (60 frames).
fn face() -> &'static MeshAnimation {
    static FACE_ANIM: OnceLock<MeshAnimation> = OnceLock::new();
    FACE_ANIM.get_or_init(|| {
        let scene = tkio::gltf::read(&common::asset(FACE))
            .unwrap_or_else(|e| panic!("cannot read {FACE}: {e}"));
        let opts = SampleOptions {
            fps: 1.0,
            ..SampleOptions::default()
        };
        anim::sample(&scene, &opts)
            .unwrap_or_else(|e| panic!("{FACE}: {e}"))
            .objects
            .into_iter()
            .next()
            .expect("face mesh")
            .animation
    })
}

/// The README's seeds (`--part upper=point:0,10,13 --part lower=point:0,-14,10`).
fn parts() -> Vec<PartSpec> {
    vec![
        PartSpec::new("upper", vec![Seed::Point(Vec3::new(0.0, 10.0, 13.0))]),
        PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -14.0, 10.0))]),
    ]
}

fn segmentation() -> &'static Segmentation {
    static SEG: OnceLock<Segmentation> = OnceLock::new();
    SEG.get_or_init(|| segment(face(), &parts(), &SegmentOptions::default()).expect("segment"))
}

fn part_animations(seg: &Segmentation) -> Vec<MeshAnimation> {
    seg.parts()
        .expect("parts")
        .into_iter()
        .map(|p| p.animation)
        .collect()
}

/// A 7×5 "ID" bitmap (a frame with a bar), standing in for rendered glyphs.
fn id_bitmap() -> Bitmap {
    let (w, h) = (7, 5);
    let pixels = (0..w * h)
        .map(|i| {
            let (c, r) = (i % w, i / w);
            r == 0 || r == h - 1 || c == 0 || c == w - 1 || r == 2
        })
        .collect();
    Bitmap {
        width: w,
        height: h,
        pixels,
    }
}

/// What [`close_pieces`] measured.
#[derive(Debug, Default)]
struct Measured {
    solids: usize,
    triangles: usize,
    crossing: usize,
    min_wall: f64,
    keys: usize,
    /// Fewest keys on one side of a seam.
    min_keys_per_seam: usize,
    /// Smallest distance between two keys of one seam side (mm).
    min_seam_key_spacing: f64,
    /// Smallest largest-triangle area over the keys of a part (mm², 0 when collinear).
    min_key_spread: f64,
}

/// Every piece of every part scaled to millimetres.
fn in_mm(lib: &stopmo::library::Library, mm: f32) -> Vec<Vec<Vec<Vec3>>> {
    lib.parts
        .iter()
        .map(|part| {
            part.solution
                .pieces
                .iter()
                .map(|piece| piece.iter().map(|x| *x * mm).collect())
                .collect()
        })
        .collect()
}

/// Every part's average surface in millimetres.
fn averages_mm(anims: &[MeshAnimation], mm: f32) -> Vec<Vec<Vec3>> {
    anims
        .iter()
        .map(|a| a.average_positions().iter().map(|x| *x * mm).collect())
        .collect()
}

/// [`build_shells`]'s input for every part (no printed back).
fn shell_inputs<'a>(
    anims: &'a [MeshAnimation],
    averages: &'a [Vec<Vec3>],
    pieces_mm: &'a [Vec<Vec<Vec3>>],
) -> Vec<ShellInput<'a>> {
    anims
        .iter()
        .zip(averages)
        .zip(pieces_mm)
        .map(|((a, average), pieces)| ShellInput {
            topology: &a.mesh,
            average,
            pieces: pieces.iter().map(Vec::as_slice).collect(),
            printed_back: None,
        })
        .collect()
}

/// The shells of every part ([`build_shells`]), with keys on every seam; checks that parts
/// meeting at a seam share its back points (their walls there are one surface).
fn shells(
    anims: &[MeshAnimation],
    pieces_mm: &[Vec<Vec<Vec3>>],
    mm: f32,
    height_mm: f64,
) -> Vec<(PartShell, Vec<stopmo::library::Key>, usize)> {
    let averages = averages_mm(anims, mm);
    let opts = ShellOptions {
        model_height_mm: height_mm,
        ..ShellOptions::default()
    };
    let built = build_shells(&shell_inputs(anims, &averages, pieces_mm), &opts).expect("shells");
    let boundaries: Vec<Vec<(Vec3, Vec3)>> = built
        .iter()
        .zip(&averages)
        .map(|(shell, avg)| shell.boundary_pairs(avg))
        .collect();
    let mut back_at: HashMap<[u32; 3], Vec3> = HashMap::new();
    for (average, back) in boundaries.iter().flatten() {
        let first = *back_at
            .entry(average.to_array().map(f32::to_bits))
            .or_insert(*back);
        assert_eq!(
            first, *back,
            "parts meeting at {average} disagree on the back point"
        );
    }
    // The fronts meet there too: a front point shifted to clear a wall moved in every part
    // (and piece) that shares it.
    let mut parts_at: HashMap<[u32; 3], std::collections::HashSet<usize>> = HashMap::new();
    for (p, b) in boundaries.iter().enumerate() {
        for (average, _) in b {
            parts_at
                .entry(average.to_array().map(f32::to_bits))
                .or_default()
                .insert(p);
        }
    }
    let mut front_at: HashMap<[u32; 3], Vec3> = HashMap::new();
    for ((shell, avg), pieces) in built.iter().zip(&averages).zip(pieces_mm) {
        let sources = shell.sources();
        for piece in pieces {
            let solid = shell.solid(piece, "x").expect("solid");
            for &(v, _) in shell.boundary_edges() {
                let key = avg[sources[v as usize] as usize]
                    .to_array()
                    .map(f32::to_bits);
                if parts_at.get(&key).is_none_or(|p| p.len() < 2) {
                    continue;
                }
                let p = solid.positions[v as usize];
                let first = *front_at.entry(key).or_insert(p);
                assert!(
                    first.distance(p) <= 1e-4,
                    "pieces meeting at a seam disagree on its front: {first} vs {p}"
                );
            }
        }
    }
    built
        .into_iter()
        .zip(&averages)
        .enumerate()
        .map(|(p, (mut shell, avg))| {
            let seams = shell.shared_seams(avg, &boundaries, p);
            let keys = shell
                .add_seam_keys(&KeyOptions::for_print_height(HEIGHT_MM), &seams)
                .expect("keys");
            (shell, keys, seams.len())
        })
        .collect()
}

/// Builds the library, closes every piece on its part's back surface with keys and an ID,
/// checks that each solid is a closed, oriented, single shell and counts self-intersecting
/// triangles with the exact test.
fn close_pieces(pieces: usize) -> Measured {
    close_pieces_of(segmentation(), pieces)
}

/// The library of the parts `anims` of one cut, `pieces` pieces per part, at the
/// acceptance's print height.
fn library_of(anims: &[MeshAnimation], pieces: usize) -> stopmo::library::Library {
    let inputs: Vec<PartInput<'_>> = anims
        .iter()
        .map(|a| PartInput {
            animation: a,
            setup: PartSetup::default(),
        })
        .collect();
    let opts = LibraryOptions {
        size: LibrarySize::Pieces(pieces),
        print_height_mm: HEIGHT_MM,
        ..LibraryOptions::default()
    };
    build_library(&inputs, &opts).expect("library")
}

/// [`close_pieces`] for any segmentation of the face.
fn close_pieces_of(seg: &Segmentation, pieces: usize) -> Measured {
    let anims = part_animations(seg);
    let refs: Vec<&MeshAnimation> = anims.iter().collect();
    let lib = library_of(&anims, pieces);
    let mm = print_scale(&refs, HEIGHT_MM) as f32;
    let pieces_mm = in_mm(&lib, mm);
    let mut m = Measured {
        min_wall: f64::INFINITY,
        min_keys_per_seam: usize::MAX,
        min_seam_key_spacing: f64::INFINITY,
        min_key_spread: f64::INFINITY,
        ..Measured::default()
    };
    for (p, (shell, keys, seams)) in shells(&anims, &pieces_mm, mm, HEIGHT_MM)
        .into_iter()
        .enumerate()
    {
        let a = &anims[p];
        m.keys += keys.len();
        assert!(seams >= 1, "part {}: no seam found", a.mesh.name);
        for seam in 0..seams {
            let on: Vec<Vec3> = keys
                .iter()
                .filter(|k| k.seam == Some(seam))
                .map(|k| Vec3::from_array(k.center))
                .collect();
            m.min_keys_per_seam = m.min_keys_per_seam.min(on.len());
            for (i, x) in on.iter().enumerate() {
                for y in &on[i + 1..] {
                    m.min_seam_key_spacing = m.min_seam_key_spacing.min(f64::from(x.distance(*y)));
                }
            }
        }
        let c: Vec<Vec3> = keys.iter().map(|k| Vec3::from_array(k.center)).collect();
        let mut spread = 0.0f64;
        for i in 0..c.len() {
            for j in i + 1..c.len() {
                for k in j + 1..c.len() {
                    let area = 0.5 * (c[j] - c[i]).cross(c[k] - c[i]).length();
                    spread = spread.max(f64::from(area));
                }
            }
        }
        m.min_key_spread = m.min_key_spread.min(spread);
        let results: Vec<(usize, usize, f64)> = pieces_mm[p]
            .par_iter()
            .enumerate()
            .map(|(k, piece)| {
                let name = format!("{}_{k:02}", a.mesh.name);
                let solid = shell
                    .solid_with_id(piece, &name, &id_bitmap(), 0.5, 0.4, &keys)
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                let check = check_solid(&solid);
                assert!(check.is_closed_manifold(), "{name}: {check:?}");
                assert_eq!(components(&solid).len(), 1, "{name}: not a single shell");
                assert!(
                    stopmo::library::volume(&solid) > 0.0,
                    "{name}: inward oriented"
                );
                let hits = self_intersecting_triangles(&solid.positions, &solid.triangles)
                    .expect("coordinates in range");
                (hits.len(), solid.triangles.len(), shell.min_wall(piece))
            })
            .collect();
        for (hits, tris, wall) in results {
            m.crossing += hits;
            m.triangles += tris;
            m.min_wall = m.min_wall.min(wall);
            m.solids += 1;
        }
    }
    eprintln!("{pieces} pieces per part: {m:?}");
    m
}

/// What holds today on every piece (run on every `cargo test`): every solid is closed,
/// oriented and one shell (checked in [`close_pieces`]), no front comes closer to the back
/// surface than the minimum wall, and registration keys sit on both sides of every seam (two,
/// a key diameter apart at least), not collinear within a part.
fn walls_and_keys(m: &Measured, pieces: usize) {
    assert_eq!(m.solids, 2 * pieces);
    keeps_the_wall(m);
    let key = KeyOptions::for_print_height(HEIGHT_MM);
    assert!(m.min_keys_per_seam >= 2, "{m:?}");
    assert!(m.min_seam_key_spacing >= 2.0 * key.radius_mm, "{m:?}");
    assert!(m.keys >= 6, "{m:?}");
    assert!(m.min_key_spread >= key.radius_mm * key.radius_mm, "{m:?}");
}

/// No front comes closer to the back surface than the minimum wall.
fn keeps_the_wall(m: &Measured) {
    assert!(
        m.min_wall >= ShellOptions::default().wall_mm * 0.99,
        "{m:?}"
    );
}
