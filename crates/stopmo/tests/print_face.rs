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

mod common;

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

/// The shells of every part ([`build_shells`]), with keys on every seam; checks that parts
/// meeting at a seam share its back points (their walls there are one surface).
fn shells(
    anims: &[MeshAnimation],
    pieces_mm: &[Vec<Vec<Vec3>>],
    mm: f32,
) -> Vec<(PartShell, Vec<stopmo::library::Key>, usize)> {
    let averages: Vec<Vec<Vec3>> = anims
        .iter()
        .map(|a| a.average_positions().iter().map(|x| *x * mm).collect())
        .collect();
    let inputs: Vec<ShellInput<'_>> = anims
        .iter()
        .zip(&averages)
        .zip(pieces_mm)
        .map(|((a, average), pieces)| ShellInput {
            topology: &a.mesh,
            average,
            pieces: pieces.iter().map(Vec::as_slice).collect(),
            printed_back: None,
        })
        .collect();
    let built = build_shells(&inputs, &ShellOptions::default()).expect("shells");
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

/// [`close_pieces`] for any segmentation of the face.
fn close_pieces_of(seg: &Segmentation, pieces: usize) -> Measured {
    let anims = part_animations(seg);
    let refs: Vec<&MeshAnimation> = anims.iter().collect();
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
    let lib = build_library(&inputs, &opts).expect("library");
    let mm = print_scale(&refs, HEIGHT_MM) as f32;
    let pieces_mm = in_mm(&lib, mm);
    let mut m = Measured {
        min_wall: f64::INFINITY,
        min_keys_per_seam: usize::MAX,
        min_seam_key_spacing: f64::INFINITY,
        min_key_spread: f64::INFINITY,
        ..Measured::default()
    };
    for (p, (shell, keys, seams)) in shells(&anims, &pieces_mm, mm).into_iter().enumerate() {
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

/// A segmentation the back surface was not tuned on (three automatic parts): where a later
/// part's surface lies deeper at a seam than the earlier part's back point there, taking
/// that point as is left 1.29 and 0.90 mm walls under the 1.5 mm minimum; the shared seam
/// points now move deeper in every part that meets there (and [`shells`] checks that the
/// parts still agree on them). Every seam gets two keys on each side there too.
#[test]
fn auto_parts_keep_the_wall_where_a_later_part_is_deeper_at_the_seam() {
    let parts = auto_parts(face(), 3).expect("auto parts");
    let seg = segment(face(), &parts, &SegmentOptions::default()).expect("segment");
    let m = close_pieces_of(&seg, 5);
    keeps_the_wall(&m);
    // Every seam keyed twice on each side, the short one between parts 2 and 3 (15 mm) too:
    // its strict band had room for one key.
    let key = KeyOptions::for_print_height(HEIGHT_MM);
    assert!(m.min_keys_per_seam >= 2, "{m:?}");
    assert!(m.min_seam_key_spacing >= 2.0 * key.radius_mm, "{m:?}");
    assert!(m.min_key_spread >= key.radius_mm * key.radius_mm, "{m:?}");
}

/// The acceptance: no self-intersecting triangle either.
fn printable(pieces: usize) {
    let m = close_pieces(pieces);
    walls_and_keys(&m, pieces);
    assert_eq!(m.crossing, 0, "{m:?}");
}

#[test]
fn eight_pieces_are_printable() {
    printable(8);
}

#[test]
#[ignore = "slow in a debug build (minutes): cargo test --release -p toonkit-stopmo --test print_face -- --include-ignored"]
fn twenty_pieces_are_printable() {
    printable(20);
}

#[test]
#[ignore = "slow in a debug build (minutes): cargo test --release -p toonkit-stopmo --test print_face -- --include-ignored"]
fn fifty_pieces_are_printable() {
    printable(50);
}

/// Boundary vertices of every part that lie neither on the input's open border nor on
/// another part's boundary at the same point, and the seam vertices (on another part's
/// boundary), over all parts.
fn unshared_seam_points(seg: &Segmentation) -> (usize, usize) {
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let boundary = |tris: &[[u32; 3]], at: &dyn Fn(u32) -> [u32; 3]| {
        let mut uses: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (at(t[k]), at(t[(k + 1) % 3]));
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        uses.into_iter()
            .filter(|(_, n)| *n == 1)
            .flat_map(|((a, b), _)| [a, b])
            .collect::<std::collections::HashSet<[u32; 3]>>()
    };
    let avg_in = face().average_positions();
    let open = boundary(&face().mesh.triangles, &|v| key(avg_in[v as usize]));
    let parts: Vec<std::collections::HashSet<[u32; 3]>> = part_animations(seg)
        .iter()
        .map(|a| {
            let avg = a.average_positions();
            boundary(&a.mesh.triangles, &|v| key(avg[v as usize]))
        })
        .collect();
    let (mut unshared, mut seam) = (0, 0);
    for (p, points) in parts.iter().enumerate() {
        for k in points {
            if parts
                .iter()
                .enumerate()
                .any(|(q, o)| q != p && o.contains(k))
            {
                seam += 1;
            } else if !open.contains(k) {
                unshared += 1;
            }
        }
    }
    (unshared, seam)
}

/// The seams of the parts are one curve: every point where a part ends is on another part
/// or on the face's own open border. The cut left T-junctions (a crossing kept on one side
/// of an input edge, dropped on the other) and, at a three-part corner, a hole: 7 points of
/// one part missing from the other on the README's cut, 1 with three automatic parts, and
/// the printed walls crossed there (the nose wing, the lips).
#[test]
fn seams_of_the_parts_are_one_curve() {
    let (unshared, seam) = unshared_seam_points(segmentation());
    assert_eq!(
        unshared, 0,
        "README cut: {unshared} unshared of {seam} seam points"
    );
    assert!(seam >= 2 * 150, "README cut: {seam} seam points");
    let parts = auto_parts(face(), 3).expect("auto parts");
    let seg = segment(face(), &parts, &SegmentOptions::default()).expect("segment");
    let (unshared, seam) = unshared_seam_points(&seg);
    assert_eq!(
        unshared, 0,
        "three parts: {unshared} unshared of {seam} seam points"
    );
}

/// Welded open-border vertices of the cut mesh that are not on the seam.
fn open_border_vertices(seg: &Segmentation) -> Vec<u32> {
    let mesh = &seg.animation.mesh;
    let class = &seg.cut.weld_class;
    let mut count = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (class[t[k] as usize], class[t[(k + 1) % 3] as usize]);
            *count.entry((a.min(b), a.max(b))).or_insert(0u32) += 1;
        }
    }
    let mut border = vec![false; seg.cut.welded_count];
    for (&(a, b), &c) in &count {
        if c == 1 {
            border[a as usize] = true;
            border[b as usize] = true;
        }
    }
    let seam: std::collections::HashSet<u32> = seg.seam_vertices.iter().copied().collect();
    (0..class.len() as u32)
        .filter(|&v| border[class[v as usize] as usize] && !seam.contains(&v))
        .collect()
}

#[test]
fn homogenization_keeps_open_borders_and_pieces_agree_there() {
    let seg = segmentation();
    let input = face();
    let mm = {
        let a = part_animations(seg);
        let refs: Vec<&MeshAnimation> = a.iter().collect();
        print_scale(&refs, HEIGHT_MM)
    };
    let border = open_border_vertices(seg);
    assert!(border.len() > 100, "{} open-border vertices", border.len());
    let mut worst = 0.0f64;
    for (f, (out, x)) in seg.animation.frames().zip(input.frames()).enumerate() {
        for &v in &border {
            let y = seg.cut.sources[v as usize].eval(x);
            let d = f64::from(out[v as usize].distance(y)) * mm;
            worst = worst.max(d);
            assert!(d <= 0.02, "frame {f}: border vertex {v} moved {d:.4} mm");
        }
    }
    let h = seg.homogenization.expect("homogenized");
    eprintln!(
        "open borders: {} vertices, max change {worst:.2e} mm; mean change {:.4} mm, max {:.4} mm",
        border.len(),
        h.mean_change * mm,
        h.max_change * mm
    );
    // Pieces of a part differ on the open borders by no more than the input moves there.
    let anims = part_animations(seg);
    let parts = seg.parts().expect("parts");
    let inputs: Vec<PartInput<'_>> = anims
        .iter()
        .map(|a| PartInput {
            animation: a,
            setup: PartSetup::default(),
        })
        .collect();
    let lib = build_library(
        &inputs,
        &LibraryOptions {
            size: LibrarySize::Pieces(20),
            print_height_mm: HEIGHT_MM,
            ..LibraryOptions::default()
        },
    )
    .expect("library");
    let border_set: std::collections::HashSet<u32> = border.iter().copied().collect();
    let mut worst_excess = 0.0f64;
    for (p, part) in parts.iter().enumerate() {
        for (local, &v) in part.vertices.iter().enumerate() {
            if !border_set.contains(&v) {
                continue;
            }
            let inputs: Vec<Vec3> = input
                .frames()
                .map(|x| seg.cut.sources[v as usize].eval(x))
                .collect();
            let spread = |pts: &[Vec3]| {
                pts.iter()
                    .flat_map(|a| pts.iter().map(move |b| a.distance(*b)))
                    .fold(0.0f32, f32::max)
            };
            let own = spread(&inputs);
            let pieces: Vec<Vec3> = lib.parts[p]
                .solution
                .pieces
                .iter()
                .map(|q| q[local])
                .collect();
            let between = spread(&pieces);
            let excess = f64::from(between - own) * mm;
            worst_excess = worst_excess.max(excess);
            // Pieces are confined where a part ends (library::BORDER_RINGS: a mean of frames
            // never leaves their hull; without it the inner lip edge spread 0.135 mm more
            // than the input's 5.8 mm); 0.01 mm is a fifth of a 0.05 mm printer resolution.
            assert!(
                excess <= 0.01,
                "part {}: border vertex {v}: pieces differ by {:.4} mm, input moves {:.4} mm",
                part.name,
                f64::from(between) * mm,
                f64::from(own) * mm
            );
        }
    }
    eprintln!("pieces' border spread minus input spread: at most {worst_excess:.2e} mm");
}

#[test]
fn reused_segmentation_puts_seams_of_two_clips_together() {
    let full = face();
    let m = full.vertex_count();
    let clip = |range: std::ops::Range<usize>| {
        let pos: Vec<Vec3> = range.flat_map(|f| full.frame(f).to_vec()).collect();
        MeshAnimation::new(full.mesh.clone(), full.fps, pos).expect("clip")
    };
    let (a, b) = (clip(0..30), clip(30..60));
    let seg_a = segment(&a, &parts(), &SegmentOptions::default()).expect("segment clip A");
    let saved = seg_a.saved(m, full.mesh.triangle_count());
    // Through JSON, as `--segmentation segmentation.json` reads it.
    let json = serde_json::to_string(&saved).expect("serialize");
    let saved: SavedSegmentation = serde_json::from_str(&json).expect("deserialize");
    let seg_b = segment_reusing(&b, &saved, &SegmentOptions::default()).expect("reuse on B");
    let diag = full.bbox().diagonal();
    let mut worst = 0.0f32;
    for (seg, clip) in [(&seg_a, &a), (&seg_b, &b)] {
        let anims = part_animations(seg);
        let inputs: Vec<PartInput<'_>> = anims
            .iter()
            .map(|x| PartInput {
                animation: x,
                setup: PartSetup::default(),
            })
            .collect();
        let lib = build_library(
            &inputs,
            &LibraryOptions {
                size: LibrarySize::Pieces(8),
                ..LibraryOptions::default()
            },
        )
        .expect("library");
        assert_eq!(clip.vertex_count(), m);
        for (p, part) in seg.parts().expect("parts").iter().enumerate() {
            for (local, &v) in part.vertices.iter().enumerate() {
                if seg_a.seam_vertices.binary_search(&v).is_err() {
                    continue;
                }
                let target = Vec3::from_array(saved.reference[v as usize]);
                for piece in &lib.parts[p].solution.pieces {
                    worst = worst.max(piece[local].distance(target));
                }
            }
        }
    }
    assert_eq!(seg_a.seam_vertices, seg_b.seam_vertices);
    eprintln!(
        "seam vertices of both clips' pieces within {:.2e} of the diagonal",
        worst / diag
    );
    assert!(
        worst <= 1e-5 * diag,
        "seams differ by {worst} (diag {diag})"
    );
}

/// Diagnostics: which parts of the solids cross (run with `--ignored --nocapture`;
/// `STOPMO_PIECES` sets the library size, default 8).
#[test]
#[ignore]
fn diagnose_crossings() {
    let pieces: usize = std::env::var("STOPMO_PIECES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(8);
    // STOPMO_AUTO_PARTS=N: N automatic parts instead of the README's seeds.
    let auto: Option<usize> = std::env::var("STOPMO_AUTO_PARTS")
        .ok()
        .and_then(|s| s.parse().ok());
    let anims = match auto {
        Some(n) => {
            let parts = auto_parts(face(), n).expect("auto parts");
            part_animations(&segment(face(), &parts, &SegmentOptions::default()).expect("segment"))
        }
        None => part_animations(segmentation()),
    };
    let refs: Vec<&MeshAnimation> = anims.iter().collect();
    let inputs: Vec<PartInput<'_>> = anims
        .iter()
        .map(|a| PartInput {
            animation: a,
            setup: PartSetup::default(),
        })
        .collect();
    let lib = build_library(
        &inputs,
        &LibraryOptions {
            size: LibrarySize::Pieces(pieces),
            print_height_mm: HEIGHT_MM,
            ..LibraryOptions::default()
        },
    )
    .expect("library");
    let mm = print_scale(&refs, HEIGHT_MM) as f32;
    let all_mm = in_mm(&lib, mm);
    for (p, (shell, keys, _)) in shells(&anims, &all_mm, mm).into_iter().enumerate() {
        let a = &anims[p];
        let pieces_mm = &all_mm[p];
        let avg: Vec<Vec3> = a.average_positions().iter().map(|x| *x * mm).collect();
        let avg_hits = self_intersecting_triangles(&avg, &a.mesh.triangles).unwrap();
        let input_hits: usize = (0..a.frame_count())
            .map(|f| {
                let x: Vec<Vec3> = a.frame(f).iter().map(|v| *v * mm).collect();
                self_intersecting_triangles(&x, &a.mesh.triangles)
                    .unwrap()
                    .len()
            })
            .max()
            .unwrap_or(0);
        eprintln!(
            "part {}: {} triangles; average crosses {}, worst input frame {}",
            a.mesh.name,
            a.mesh.triangles.len(),
            avg_hits.len(),
            input_hits
        );
        eprintln!("  shell {:?}, {} keys", shell.stats, keys.len());
        let t = shell.triangles().len() as u32;
        let caps = shell.cap_triangle_count() as u32;
        let kind = |x: u32| -> &'static str {
            if x < t - caps {
                "front"
            } else if x < t {
                "front-cap"
            } else if x < 2 * t - caps {
                "back"
            } else if x < 2 * t {
                "back-cap"
            } else {
                "wall"
            }
        };
        for (k, piece) in pieces_mm.iter().enumerate() {
            let front = self_intersecting_triangles(piece, &a.mesh.triangles).unwrap();
            let solid = shell
                .solid_with_id(piece, "x", &id_bitmap(), 0.5, 0.4, &keys)
                .unwrap();
            let pairs =
                stopmo::library::intersecting_pairs(&solid.positions, &solid.triangles).unwrap();
            let mut tally: std::collections::BTreeMap<(&str, &str), usize> = Default::default();
            for &(i, j) in &pairs {
                *tally.entry((kind(i), kind(j))).or_default() += 1;
            }
            let centre = |x: u32| {
                solid.triangles[x as usize]
                    .iter()
                    .map(|&v| solid.positions[v as usize])
                    .sum::<Vec3>()
                    / 3.0
            };
            let samples: Vec<String> = pairs
                .iter()
                .step_by((pairs.len() / 6).max(1))
                .map(|&(i, j)| {
                    let c = centre(i);
                    format!("{}/{}@({:.1},{:.1},{:.1})", kind(i), kind(j), c.x, c.y, c.z)
                })
                .collect();
            eprintln!(
                "  piece {k}: front alone {}, solid pairs {} {:?}; wall {:.3} mm; e.g. {}",
                front.len(),
                pairs.len(),
                tally,
                shell.min_wall(piece),
                samples.join(" ")
            );
        }
    }
}
