//! The size-versus-error curve (StopShop Fig. 8) as a job, the library of one of its points
//! built without solving again, and the seams of a segmentation, on a synthetic talking tube.

mod segment_support;

use anim::MeshAnimation;
use glam::Vec3;
use segment_support::talking_tube;
use stopmo::segment::{PartSpec, Seed};
use stopmo::{LibraryJobOptions, PieceCount, SegmentJobOptions, Segmented};

fn segmented() -> Segmented {
    stopmo::segment(
        &talking_tube(24, 30, 36),
        &SegmentJobOptions {
            parts: vec![
                PartSpec::new("upper", vec![Seed::Point(Vec3::new(0.0, 0.95, 1.0))]),
                PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -0.95, 1.0))]),
            ],
            ..Default::default()
        },
    )
    .unwrap()
}

#[test]
fn a_curve_point_builds_the_same_library_as_the_library_job_of_that_size() {
    let seg = segmented();
    let parts: Vec<MeshAnimation> = seg.parts.iter().map(|p| p.animation.clone()).collect();
    let opts = LibraryJobOptions::default();
    let mut calls = Vec::new();
    let curve = stopmo::size_curve(&parts, &opts, &[5, 1, 3, 3], &mut |done, total| {
        calls.push((done, total));
        true
    })
    .unwrap();
    assert_eq!(calls, [(0, 3), (1, 3), (2, 3), (3, 3)]);
    let sizes: Vec<usize> = curve.points.iter().map(|p| p.pieces).collect();
    assert_eq!(sizes, [1, 3, 5]);
    let totals: Vec<usize> = curve.points.iter().map(|p| p.total_pieces).collect();
    assert_eq!(totals, [2, 6, 10]);
    // More pieces, smaller error (Fig. 8's falling curve).
    let (first, last) = (curve.points[0], curve.points[2]);
    assert!(
        last.mean_error_mm < first.mean_error_mm && last.energy < first.energy,
        "{:?}",
        curve.points
    );
    assert!(first.max_error_mm >= first.mean_error_mm);

    let picked = stopmo::library_of(&parts, &opts, curve.library(3).unwrap()).unwrap();
    let direct = stopmo::library(
        &parts,
        &LibraryJobOptions {
            pieces: PieceCount::Each(3),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(picked.labels(), direct.labels());
    assert_eq!(picked.library.energy, direct.library.energy);
    assert_eq!(picked.library.energy, curve.points[1].energy);
    assert_eq!(picked.pieces.len(), 6);
    assert_eq!(picked.frame_ids(), direct.frame_ids());
    assert_eq!(
        picked.reconstruction_of(1).unwrap().positions(),
        direct.reconstruction_of(1).unwrap().positions()
    );
    let files: Vec<String> = picked
        .files()
        .unwrap()
        .iter()
        .map(|f| f.path.clone())
        .collect();
    assert!(
        files.iter().any(|f| f == "pieces/lower_02.stl"),
        "{files:?}"
    );
}

#[test]
fn a_stopped_curve_keeps_its_points_and_a_foreign_library_is_refused() {
    let seg = segmented();
    let parts: Vec<MeshAnimation> = seg.parts.iter().map(|p| p.animation.clone()).collect();
    let opts = LibraryJobOptions::default();
    let curve = stopmo::size_curve(&parts, &opts, &[1, 2, 4], &mut |done, _| done < 1).unwrap();
    assert_eq!(curve.points.len(), 1);
    assert!(curve.library(2).is_none());
    assert!(stopmo::size_curve(&parts, &opts, &[], &mut |_, _| true).is_err());
    assert!(stopmo::size_curve(&parts, &opts, &[0, 2], &mut |_, _| true).is_err());
    // The library of two parts is not a library of one.
    let e = stopmo::library_of(&parts[..1], &opts, curve.library(1).unwrap()).unwrap_err();
    assert!(e.to_string().starts_with("parts:"), "{e}");
}

#[test]
fn seams_are_the_edges_between_two_parts() {
    let seg = segmented();
    let s = &seg.segmentation;
    let edges = seg.seam_edges();
    assert!(edges.len() > 10, "{} seam edges", edges.len());
    // Every seam vertex is on a part boundary, and the seams go round the tube: about as
    // long as the cut.
    let mut length = 0.0;
    let average = s.animation.average_positions();
    for [a, b] in &edges {
        assert!(s.seam_vertices.binary_search(a).is_ok(), "{a}");
        assert!(s.seam_vertices.binary_search(b).is_ok(), "{b}");
        length += f64::from(average[*a as usize].distance(average[*b as usize]));
    }
    assert!(
        (length - s.cut_length).abs() < 0.05 * s.cut_length,
        "seams {length}, cut {}",
        s.cut_length
    );
}
