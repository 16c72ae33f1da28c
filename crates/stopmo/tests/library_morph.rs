//! The library job on morph weights (`docs/stopmo-scale.md`): a morph-only clip on a still
//! node is solved from its weights, never expanded into positions, and gives the library of
//! its positions.

use std::collections::BTreeMap;

use anim::glam::Vec3;
use anim::{Mesh, MeshFrames, MorphAnimation};
use stopmo::{FramesForm, LibraryJobOptions, PieceCount};

mod common;

fn options(pieces: usize) -> LibraryJobOptions {
    LibraryJobOptions {
        pieces: PieceCount::Each(pieces),
        print: false,
        ..LibraryJobOptions::default()
    }
}

/// A `side × side` grid with `targets` morph targets and `frames` frames whose sums are exact
/// in f32: positions and displacements are multiples of 1/16, weights multiples of 1/8 (so a
/// frame's position is a multiple of 1/128 below 64, whatever order it is summed in).
fn dyadic_grid(side: usize, targets: usize, frames: usize) -> MorphAnimation {
    let mut rng = anim::SplitMix64::new(52, 0);
    let mut small = |range: u64| rng.below(range as usize) as f32;
    let mut base = Vec::new();
    for y in 0..side {
        for x in 0..side {
            base.push(Vec3::new(x as f32, y as f32, 0.0) * 0.5);
        }
    }
    let triangles = common::grid_triangles(side);
    let m = base.len();
    // Each target bulges a patch of the grid (the rest stays still).
    let mut deltas = vec![Vec3::ZERO; targets * m];
    for t in 0..targets {
        let (cx, cy) = (small(side as u64), small(side as u64));
        for (v, p) in base.iter().enumerate() {
            let near = (p.x * 2.0 - cx).abs() + (p.y * 2.0 - cy).abs() < side as f32 / 3.0;
            if near {
                deltas[t * m + v] =
                    Vec3::new(small(9) - 4.0, small(9) - 4.0, small(17) - 8.0) / 16.0;
            }
        }
    }
    // Speech-like: weights drift by ±1/8 per frame within [0, 1].
    let mut w = vec![0u64; targets];
    let mut weights = Vec::with_capacity(frames * targets);
    for _ in 0..frames {
        for wt in w.iter_mut() {
            *wt = match small(3) as u64 {
                0 => wt.saturating_sub(1),
                1 => (*wt + 1).min(8),
                _ => *wt,
            };
            weights.push(*wt as f32 / 8.0);
        }
    }
    MorphAnimation::new(
        Mesh::new("grid", base.clone(), triangles),
        24.0,
        base,
        deltas,
        weights,
    )
    .expect("morph clip")
}

/// Exact sums: the weight form and its expanded positions give the same pieces, labels and
/// energy (λ = 2, so the border confinement and the signed combinations are exercised), with
/// and without a fixed piece, and the report says which form was used.
#[test]
fn morph_weights_give_the_library_of_their_positions_when_sums_are_exact() {
    let morph = dyadic_grid(14, 6, 300);
    let dense = morph.to_positions();
    for fixed in [false, true] {
        let mut opts = options(7);
        if fixed {
            opts.fixed = BTreeMap::from([("grid".to_string(), vec![dense.frame(40).to_vec()])]);
        }
        let a = stopmo::library(std::slice::from_ref(&dense), &opts).expect("positions");
        let b =
            stopmo::library_frames(&[MeshFrames::Morph(morph.clone())], &opts).expect("weights");
        assert_eq!(a.report.frames_form, FramesForm::Positions);
        assert_eq!(b.report.frames_form, FramesForm::MorphWeights);
        let (pa, pb) = (&a.library.parts[0].solution, &b.library.parts[0].solution);
        assert_eq!(pa.labels, pb.labels, "fixed {fixed}");
        assert_eq!(pa.pieces, pb.pieces, "fixed {fixed}");
        let (ea, eb) = (a.report.energy, b.report.energy);
        assert!(
            (ea - eb).abs() <= 1e-9 * ea.abs(),
            "fixed {fixed}: energy {ea} (positions) vs {eb} (weights)"
        );
        assert_eq!(a.library.parts[0].errors, b.library.parts[0].errors);
        assert_eq!(a.report.mm_per_unit, b.report.mm_per_unit);
        if fixed {
            assert_eq!(pb.pieces[0], dense.frame(40));
        }
    }
}

/// The bundled talking face is morph-only on a still node: read as weights, it is solved
/// without its positions and gives the library of its positions up to their f32 rounding.
#[test]
fn bundled_face_is_read_as_weights_and_solves_as_its_positions() {
    let path = testdata::asset("face/ict-face-talk.glb");
    let open = tkio::OpenOptions {
        fps: Some(30.0),
        ..tkio::OpenOptions::default()
    };
    let frames = tkio::open_frames(&path, &open).expect("open as frames");
    assert_eq!(frames.len(), 1);
    let MeshFrames::Morph(morph) = &frames[0] else {
        panic!("the talking face is read as positions");
    };
    assert_eq!((morph.frame_count(), morph.vertex_count()), (1800, 9409));
    let dense = tkio::open(&path, &open)
        .expect("open")
        .objects
        .remove(0)
        .animation;
    // The same frames up to f32 rounding.
    let expanded = morph.to_positions();
    let diag = dense.bbox().diagonal();
    let worst = dense
        .positions()
        .iter()
        .zip(expanded.positions())
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    assert!(worst <= 1e-5 * diag, "frames differ by {worst} of {diag}");
    let opts = options(12);
    let a = stopmo::library(std::slice::from_ref(&dense), &opts).expect("positions");
    let b = stopmo::library_frames(&frames, &opts).expect("weights");
    assert_eq!(b.report.frames_form, FramesForm::MorphWeights);
    let (ea, eb) = (a.report.energy, b.report.energy);
    assert!(
        (ea - eb).abs() <= 1e-4 * ea,
        "energy {ea} (positions) vs {eb} (weights)"
    );
    let same = a.library.parts[0]
        .solution
        .labels
        .iter()
        .zip(&b.library.parts[0].solution.labels)
        .filter(|(x, y)| x == y)
        .count();
    assert!(same * 100 >= 99 * 1800, "{same} of 1800 labels agree");
    assert!((a.report.mm_per_unit / b.report.mm_per_unit - 1.0).abs() < 1e-6);
}

/// A skinned character is not morph-only: it is read as positions (and solved as before), and
/// the report says so.
#[test]
fn skinned_character_is_read_as_positions() {
    let path = testdata::asset("characters/CesiumMan.glb");
    let open = tkio::OpenOptions {
        fps: Some(12.0),
        ..tkio::OpenOptions::default()
    };
    let frames = tkio::open_frames(&path, &open).expect("open as frames");
    assert!(!frames.is_empty());
    assert!(
        frames.iter().all(|f| matches!(f, MeshFrames::Positions(_))),
        "a skinned mesh was read as morph weights"
    );
    let result = stopmo::library_frames(&frames, &options(3)).expect("library");
    assert_eq!(result.report.frames_form, FramesForm::Positions);
}

/// A clip with at least as many morph targets as frames (what `stopmo segment` writes: one
/// target per frame) is read as positions: the weight form would hold as much and cost
/// more. The bundled face has 55 targets: 30 frames are read as positions, 60 as weights.
#[test]
fn as_many_targets_as_frames_are_read_as_positions() {
    let path = testdata::asset("face/ict-face-talk.glb");
    let read = |fps: f32| {
        let open = tkio::OpenOptions {
            fps: Some(fps),
            ..tkio::OpenOptions::default()
        };
        tkio::open_frames(&path, &open).expect("open as frames")
    };
    let few = read(0.5);
    assert_eq!(few.len(), 1);
    let MeshFrames::Positions(a) = &few[0] else {
        panic!("55 targets over 30 frames are read as weights");
    };
    assert_eq!(a.frame_count(), 30);
    let MeshFrames::Morph(m) = &read(1.0)[0] else {
        panic!("55 targets over 60 frames are read as positions");
    };
    assert_eq!(m.frame_count(), 60);
}
