//! The acceptance: closed, oriented, single-shell solids with the wall and keys, and no self-intersecting triangle (README parts at 8, 20, 50 pieces; three automatic parts).

use super::*;

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
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn twenty_pieces_are_printable() {
    printable(20);
}

#[test]
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn fifty_pieces_are_printable() {
    printable(50);
}

/// Two automatic parts put the seam through the mouth corners, so the lip edges are walled
/// boundaries of a part. Offset along directions diffused over edge rings (which smooth ~3×
/// less on the fine lip mesh than on the chin), the back hooked behind the lips: 1,032 and
/// 1,360 back/back crossing pairs over 8 pieces before the local search; averaged over
/// millimetres along the surface, 80 and 80. (The walls at the lip edges still cross as
/// built; the written solids are regularized: see the last test.)
#[test]
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn two_automatic_parts_keep_the_back_unfolded_behind_the_lips() {
    let parts = auto_parts(face(), 2).expect("auto parts");
    // The construction alone (no local search): what the direction field decides.
    let opts = ShellOptions {
        resolve_rounds: 0,
        ..ShellOptions::default()
    };
    let (built, pieces_mm) = bare_shells(&parts, 8, &opts);
    for (shell, pieces) in built.iter().zip(&pieces_mm) {
        let t = shell.triangles().len() as u32;
        let is_back = |x: u32| (t..2 * t).contains(&x);
        let back_back: usize = pieces
            .par_iter()
            .map(|piece| {
                let solid = shell.solid(piece, "x").expect("solid");
                stopmo::library::intersecting_pairs(&solid.positions, &solid.triangles)
                    .expect("coordinates in range")
                    .iter()
                    .filter(|&&(i, j)| is_back(i) && is_back(j))
                    .count()
            })
            .sum();
        assert!(back_back <= 200, "{back_back} back/back crossing pairs");
    }
}

/// The shells of a cut of the face into `parts`, `pieces` per part, built with `opts`, and the
/// pieces in millimetres (no keys, no IDs).
fn bare_shells(
    parts: &[PartSpec],
    pieces: usize,
    opts: &ShellOptions,
) -> (Vec<PartShell>, Vec<Vec<Vec<Vec3>>>) {
    let anims =
        part_animations(&segment(face(), parts, &SegmentOptions::default()).expect("segment"));
    let refs: Vec<&MeshAnimation> = anims.iter().collect();
    let lib = library_of(&anims, pieces);
    let mm = print_scale(&refs, HEIGHT_MM) as f32;
    let pieces_mm = in_mm(&lib, mm);
    let averages = averages_mm(&anims, mm);
    let built = build_shells(&shell_inputs(&anims, &averages, &pieces_mm), opts).expect("shells");
    (built, pieces_mm)
}

/// A cut the README does not show — one seed far to the side of the face, one under the
/// mouth — prints without a crossing at 8 pieces with the default direction field. Each
/// field alone fails on some cut: the geodesic disc leaves 376 crossing triangles here (the
/// edge rings 0), the edge rings fold the back behind the lips with two automatic parts
/// (the test above); `DirectionField::Best` keeps, per part, the back that crosses less.
#[test]
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn a_seed_beside_the_face_prints_without_crossings() {
    let parts = vec![
        PartSpec::new("side", vec![Seed::Point(Vec3::new(30.0, 0.0, 0.0))]),
        PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -14.0, 10.0))]),
    ];
    let (built, _) = bare_shells(&parts, 8, &ShellOptions::default());
    let crossing: Vec<usize> = built
        .iter()
        .map(|s| s.stats.self_intersecting_triangles)
        .collect();
    assert_eq!(crossing, vec![0, 0], "crossing triangles per part");
    for s in &built {
        assert!(s.stats.min_wall_mm >= 1.5 - 1e-3, "{:?}", s.stats);
    }
}

/// The README cut printed at other sizes and walls (`--print-height`, `--thickness`), as the
/// issue tried them: the direction field and the envelope's column follow the face, so they
/// scale with the print height, not with the wall. With a column set in walls and fields in
/// fixed millimetres (`stopmo run`, 8 pieces): 150 mm left a 0.00 mm wall and 82 crossing
/// triangles at the nose tip, 100 mm a 0.87 mm wall, a 2.5 mm wall 816 crossing triangles and
/// a 1 mm wall 0.56 mm under the nose.
#[test]
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn other_print_heights_and_walls_print_clean() {
    let parts = part_animations(segmentation());
    for (height, wall) in [
        (150.0, 1.5),
        (100.0, 1.5),
        (60.0, 2.5),
        (60.0, 1.0),
        (40.0, 1.5),
    ] {
        let opts = stopmo::LibraryJobOptions {
            pieces: stopmo::PieceCount::Each(8),
            print_height_mm: height,
            thickness_mm: wall,
            ..Default::default()
        };
        let result = stopmo::library(&parts, &opts).expect("library");
        for part in &result.report.printing.as_ref().expect("printed").parts {
            let s = &part.shell;
            eprintln!("{height} mm, wall {wall} mm, {}: {s:?}", part.name);
            assert_eq!(
                s.self_intersecting_triangles, 0,
                "{height} mm, wall {wall}: {s:?}"
            );
            assert!(
                s.min_wall_mm >= wall * 0.99,
                "{height} mm, wall {wall}: {s:?}"
            );
        }
    }
}

/// The README cut printed small (25 mm, the first print height), 20 pieces: the
/// lower lip's corners press through each other in some pieces of the input's own shapes,
/// which the shells untangle. Retracting by the 60 mm step (0.02 mm a round) pushed a lip
/// 2.4 times thinner than at 60 mm through its other side and left crossing solids (here
/// 82 triangles; `stopmo run … --pieces 20 --print-height 25`: 40 in `lower_07`); the step
/// scaled to the print leaves none. Not asserted: the upper part's back collapses under the
/// nose at this size with a 1.5 mm wall in this test's 1 fps sampling (540 triangles, none
/// from the 24 fps clip of `stopmo run`), and the lower wall is 1.44 mm at the cheek.
#[test]
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn a_25_mm_print_untangles_the_lip_corners() {
    let parts = part_animations(segmentation());
    let opts = stopmo::LibraryJobOptions {
        pieces: stopmo::PieceCount::Each(20),
        print_height_mm: 25.0,
        ..Default::default()
    };
    let result = stopmo::library(&parts, &opts).expect("library");
    // The input's own surface crosses itself in some lower piece (what is untangled).
    let pressed = result
        .pieces
        .par_iter()
        .filter(|p| {
            self_intersecting_triangles(&p.surface.positions, &p.surface.triangles)
                .is_some_and(|t| !t.is_empty())
        })
        .count();
    assert!(
        pressed > 0,
        "no piece surface crosses itself: the test tests nothing"
    );
    for part in &result.report.printing.as_ref().expect("printed").parts {
        eprintln!("25 mm, 20 pieces, {}: {:?}", part.name, part.shell);
    }
    let lower = &result.report.printing.as_ref().expect("printed").parts[1];
    assert_eq!(lower.name, "lower");
    assert_eq!(
        lower.shell.self_intersecting_triangles, 0,
        "{:?}",
        lower.shell
    );
}

/// Cuts the back surface was not tuned on: seeds on the forehead and the chin put the seam
/// through both eyes, two automatic parts put it along the upper lip's rim. As built, their
/// solids cross themselves where no single-point move helps (the front folds over the wall
/// where the seam meets an eye opening; the lip rims' walls cross the curled lips; 118 + 254
/// and 990 + 1,019 triangles over 8 pieces per part at 2 fps): every one of those is
/// regularized, so every written solid is a closed, oriented single shell without a
/// crossing triangle, and regularizing trims next to nothing (chips and cavities under 0.1 %
/// of the material). The wall holds too: where a front point came closer to the back than
/// the wall, the back is thickened.
#[test]
#[ignore = "minutes each (CI runs them in its print phase): cargo test --workspace --test print_face -- --include-ignored"]
fn cuts_through_the_eyes_and_along_the_lips_print_regularized() {
    let through_eyes = vec![
        PartSpec::new("upper", vec![Seed::Point(Vec3::new(0.0, 15.0, 8.0))]),
        PartSpec::new("lower", vec![Seed::Point(Vec3::new(0.0, -8.0, 12.0))]),
    ];
    let along_lips = auto_parts(face(), 2).expect("auto parts");
    for (cut, parts) in [
        ("through the eyes", through_eyes),
        ("two automatic parts", along_lips),
    ] {
        let seg = segment(face(), &parts, &SegmentOptions::default()).expect("segment");
        let opts = stopmo::LibraryJobOptions {
            pieces: stopmo::PieceCount::Each(8),
            ..Default::default()
        };
        let result = stopmo::library(&part_animations(&seg), &opts).expect("library");
        let printing = result.report.printing.as_ref().expect("printed");
        let regularized: usize = printing
            .parts
            .iter()
            .map(|p| p.regularized_pieces.len())
            .sum();
        eprintln!(
            "{cut}: {:?}",
            printing
                .parts
                .iter()
                .map(|p| (
                    p.built_self_intersecting_triangles,
                    p.regularized_pieces.len()
                ))
                .collect::<Vec<_>>()
        );
        assert!(
            regularized > 0,
            "{cut}: nothing to regularize, the test tests nothing"
        );
        for part in &printing.parts {
            assert_eq!(part.shell.self_intersecting_triangles, 0, "{cut}: {part:?}");
            // Two automatic parts left a 1.26 mm wall under the 1.5 mm one at a nostril's
            // floor before the back was thickened there.
            assert!(part.shell.min_wall_mm >= 1.5 * 0.99, "{cut}: {part:?}");
            assert_eq!(
                part.built_self_intersecting_triangles > 0,
                !part.regularized_pieces.is_empty(),
                "{cut}: {part:?}"
            );
        }
        let dropped: f64 = printing.parts.iter().map(|p| p.dropped_volume_mm3).sum();
        assert!(
            dropped < 1e-3 * printing.material.volume_mm3,
            "{cut}: {dropped} mm³ dropped of {}",
            printing.material.volume_mm3
        );
        let bad: Vec<String> = result
            .pieces
            .par_iter()
            .filter_map(|p| {
                let s = p.solid.as_ref().expect("solid");
                let crossing = self_intersecting_triangles(&s.positions, &s.triangles)
                    .map_or(usize::MAX, |t| t.len());
                let shells = components(s).len();
                let closed = check_solid(s).is_closed_manifold();
                (crossing > 0 || shells != 1 || !closed).then(|| {
                    format!(
                        "{}: {crossing} crossing, {shells} shells, closed {closed}",
                        p.id
                    )
                })
            })
            .collect();
        assert!(bad.is_empty(), "{cut}: {bad:?}");
    }
}
