//! Replacement library on synthetic animations: Fig. 11 popping, baselines, size rules,
//! fixed libraries, saliency, cuts, fabrication, determinism and degenerate inputs.

use anim::{Mesh, MeshAnimation};
use glam::Vec3;
use stopmo::library::{
    allocate_budget, build_library, check_solid, solidify, volume, LibraryError, LibraryOptions,
    LibrarySize, Method, PartInput, PartProblem, PartSetup, SolveOptions, SubspaceOptions,
};

mod common;

/// A `k × k` grid in the XY plane, counter-clockwise seen from +Z.
fn grid(name: &str, k: usize) -> Mesh {
    let mut pos = Vec::new();
    for j in 0..k {
        for i in 0..k {
            pos.push(Vec3::new(
                i as f32 / (k - 1) as f32,
                j as f32 / (k - 1) as f32,
                0.0,
            ));
        }
    }
    Mesh::new(name, pos, common::grid_triangles(k))
}

/// A mouth: the lower half of the grid drops by `open(f)` (scaled by distance from the middle).
fn mouth(frames: usize, open: impl Fn(usize) -> f32) -> MeshAnimation {
    let mesh = grid("mouth", 6);
    let positions = (0..frames)
        .flat_map(|f| {
            let o = open(f);
            mesh.positions
                .iter()
                .map(move |p| {
                    let w = if p.y < 0.5 { 1.0 - p.y * 2.0 } else { 0.0 };
                    *p - Vec3::Y * (0.5 * o * w) + Vec3::Z * (0.2 * o * w * p.x)
                })
                .collect::<Vec<_>>()
        })
        .collect();
    MeshAnimation::new(mesh, 24.0, positions).unwrap()
}

/// Closed for 30 frames, a slow jittery opening over 60 frames, open for 30 frames.
fn slow_opening(f: usize) -> f32 {
    let ramp = ((f as f32 - 30.0) / 60.0).clamp(0.0, 1.0);
    let jitter = if (30..90).contains(&f) {
        0.12 * (f as f32 * 1.7).sin()
    } else {
        0.0
    };
    ramp + jitter
}

fn part(a: &MeshAnimation) -> PartInput<'_> {
    PartInput {
        animation: a,
        setup: PartSetup::default(),
    }
}

fn switches(labels: &[u32]) -> usize {
    labels.windows(2).filter(|w| w[0] != w[1]).count()
}

#[test]
fn fig11_velocity_term_removes_popping() {
    let anim = mouth(120, slow_opening);
    let run = |lambda: f64| {
        let opts = LibraryOptions {
            size: LibrarySize::Pieces(2),
            solve: SolveOptions {
                lambda,
                ..SolveOptions::default()
            },
            ..LibraryOptions::default()
        };
        build_library(&[part(&anim)], &opts).unwrap()
    };
    let (kmeans, ours) = (run(0.0), run(2.0));
    let (lk, lo) = (
        &kmeans.parts[0].solution.labels,
        &ours.parts[0].solution.labels,
    );
    // λ = 0 snaps back and forth between "closed" and "open" during the slow opening.
    assert!(
        switches(lk) >= 3,
        "k-means switches {} times: {lk:?}",
        switches(lk)
    );
    // λ > 0: one clean transition.
    assert_eq!(switches(lo), 1, "λ=2 labels {lo:?}");
    // The first snap to "open" comes earlier without the velocity term.
    let first_open = |l: &[u32]| l.iter().position(|&x| x != l[0]).unwrap();
    assert!(
        first_open(lk) < first_open(lo),
        "{} vs {}",
        first_open(lk),
        first_open(lo)
    );
    // And the popping shows in the velocity error.
    assert!(
        ours.errors_mm.velocity_mean < kmeans.errors_mm.velocity_mean,
        "velocity error λ=2 {} vs λ=0 {}",
        ours.errors_mm.velocity_mean,
        kmeans.errors_mm.velocity_mean
    );
}

#[test]
fn fig19_stopshop_beats_kmeans_and_uniform_on_velocity() {
    // Speech-like: several open/close cycles of different amplitude.
    let anim = mouth(300, |f| {
        let t = f as f32 / 300.0;
        0.5 + 0.45 * (t * 23.0).sin() * (t * 5.0).cos()
    });
    let run = |method: Method| {
        let opts = LibraryOptions {
            size: LibrarySize::Pieces(6),
            method,
            ..LibraryOptions::default()
        };
        build_library(&[part(&anim)], &opts).unwrap()
    };
    let (ours, km, uni) = (
        run(Method::StopShop),
        run(Method::KMeans),
        run(Method::Uniform),
    );
    assert!(ours.errors_mm.velocity_mean < km.errors_mm.velocity_mean);
    assert!(km.errors_mm.position_mean < uni.errors_mm.position_mean);
    assert!(ours.errors_mm.position_mean < uni.errors_mm.position_mean);
    // Uniform sampling holds each piece for 50 frames: a small mean velocity error (the input
    // velocity) but a large pop at every switch.
    assert!(ours.errors_mm.velocity_max < 0.5 * uni.errors_mm.velocity_max);
    // All three energies are StopShop Eq. 10 at the same λ: ours is the lowest.
    assert!(ours.energy < km.energy && ours.energy < uni.energy);
}

#[test]
fn lambda_zero_library_is_the_mean_of_its_frames() {
    let anim = mouth(80, |f| (f as f32 * 0.3).sin().abs());
    let setup = PartSetup::default();
    let p = PartProblem::new(&anim, &setup, &SubspaceOptions::default(), 1).unwrap();
    let s = p
        .solve(
            4,
            &SolveOptions {
                lambda: 0.0,
                ..SolveOptions::default()
            },
        )
        .unwrap();
    let mut worst = 0.0f32;
    for (k, piece) in s.pieces.iter().enumerate() {
        let frames: Vec<usize> = (0..80).filter(|&f| s.labels[f] == k as u32).collect();
        assert!(!frames.is_empty(), "piece {k} unused");
        for (i, r) in piece.iter().enumerate() {
            let mean = frames.iter().map(|&f| anim.frame(f)[i]).sum::<Vec3>() / frames.len() as f32;
            worst = worst.max((mean - *r).length());
        }
    }
    assert!(
        worst < 1e-5,
        "piece differs from its frames' mean by {worst}"
    );
    // Every energy after a label step is not above the first one.
    assert!(
        s.history.iter().all(|&e| e <= s.history[0] + 1e-9),
        "{:?}",
        s.history
    );
}

#[test]
fn fixed_library_only_labels_and_partial_library_keeps_fixed_pieces() {
    let anim = mouth(60, |f| f as f32 / 59.0);
    let closed = anim.frame(0).to_vec();
    let open = anim.frame(59).to_vec();
    let setup = PartSetup {
        fixed: vec![closed.clone(), open.clone()],
        ..PartSetup::default()
    };
    let p = PartProblem::new(&anim, &setup, &SubspaceOptions::default(), 1).unwrap();
    let s = p.label_fixed(2.0).unwrap();
    assert_eq!(s.pieces, vec![closed.clone(), open.clone()]);
    assert_eq!((s.labels[0], s.labels[59]), (0, 1));
    assert_eq!(switches(&s.labels), 1);
    // Partially fixed: 2 fixed + 2 free; the fixed ones are untouched, the free ones used.
    let s = p.solve(4, &SolveOptions::default()).unwrap();
    assert_eq!((&s.pieces[0], &s.pieces[1]), (&closed, &open));
    assert!(
        s.labels.iter().any(|&l| l >= 2),
        "free pieces unused: {:?}",
        s.labels
    );
    let free_only = PartProblem::new(&anim, &PartSetup::default(), &SubspaceOptions::default(), 1)
        .unwrap()
        .solve(2, &SolveOptions::default())
        .unwrap();
    assert!(
        s.energy < free_only.energy,
        "4 pieces {} vs 2 free {}",
        s.energy,
        free_only.energy
    );
}

#[test]
fn cuts_drop_the_velocity_link() {
    // A jump at frame 50 (scene change): with a cut, no velocity error is charged there.
    let anim = mouth(100, |f| if f < 50 { 0.0 } else { 1.0 });
    let setup = PartSetup {
        cuts: vec![50],
        ..PartSetup::default()
    };
    let p = PartProblem::new(&anim, &setup, &SubspaceOptions::default(), 1).unwrap();
    let s = p.solve(2, &SolveOptions::default()).unwrap();
    let (energy, errors) = p.evaluate(&s.pieces, &s.labels, 2.0).unwrap();
    assert!(!errors.has_velocity[50] && errors.has_velocity[51]);
    assert!(
        energy < 1e-8,
        "two exact pieces should give zero energy, got {energy}"
    );
    assert_eq!(p.chains(), &[0..50, 50..100]);
}

#[test]
fn max_error_search_finds_the_number_of_distinct_poses() {
    // Five distinct poses held for 12 frames each: five pieces reproduce it exactly.
    let anim = mouth(60, |f| (f / 12) as f32 * 0.25);
    let p = PartProblem::new(&anim, &PartSetup::default(), &SubspaceOptions::default(), 1).unwrap();
    let (s, curve) = p.solve_max_error(1e-4, &SolveOptions::default()).unwrap();
    assert_eq!(s.pieces.len(), 5, "curve {curve:?}");
    let at4 = curve
        .iter()
        .find(|c| c.pieces == 4)
        .expect("size 4 evaluated");
    assert!(at4.worst_frame_error > 1e-4);
    assert!(curve.windows(2).all(|w| w[0].pieces < w[1].pieces));
}

#[test]
fn budget_goes_to_the_part_that_moves_more() {
    let busy = mouth(60, |f| (f / 10) as f32 * 0.2); // 6 poses
    let mut calm = mouth(60, |f| if f < 30 { 0.0 } else { 0.3 }); // 2 poses
    calm.mesh.name = "calm".into();
    let opts = SolveOptions::default();
    let sub = SubspaceOptions::default();
    let parts = vec![
        PartProblem::new(&calm, &PartSetup::default(), &sub, 1).unwrap(),
        PartProblem::new(&busy, &PartSetup::default(), &sub, 2).unwrap(),
    ];
    let out = allocate_budget(&parts, 8, &opts).unwrap();
    let sizes: Vec<usize> = out.iter().map(|(s, _)| s.pieces.len()).collect();
    assert_eq!(sizes, vec![2, 6]);
    assert!(matches!(
        allocate_budget(&parts, 1, &opts),
        Err(LibraryError::BudgetTooSmall {
            budget: 1,
            minimum: 2
        })
    ));
}

#[test]
fn saliency_weights_trade_error_between_regions() {
    // Upper half moves independently of the lower half; few pieces cannot serve both.
    let mesh = grid("face", 6);
    let positions: Vec<Vec3> = (0..90)
        .flat_map(|f| {
            let (a, b) = ((f as f32 * 0.21).sin(), (f as f32 * 0.13).cos());
            mesh.positions
                .iter()
                .map(move |p| *p + Vec3::Z * if p.y < 0.5 { 0.3 * a } else { 0.3 * b })
                .collect::<Vec<_>>()
        })
        .collect();
    let anim = MeshAnimation::new(mesh.clone(), 24.0, positions).unwrap();
    let upper: Vec<bool> = mesh.positions.iter().map(|p| p.y >= 0.5).collect();
    let upper_error = |w: Option<Vec<f32>>| {
        let setup = PartSetup {
            saliency: w,
            ..PartSetup::default()
        };
        let p = PartProblem::new(&anim, &setup, &SubspaceOptions::default(), 1).unwrap();
        let s = p.solve(3, &SolveOptions::default()).unwrap();
        (0..90)
            .map(|f| {
                let r = &s.pieces[s.labels[f] as usize];
                (0..36)
                    .filter(|&i| upper[i])
                    .map(|i| (anim.frame(f)[i] - r[i]).length())
                    .sum::<f32>()
            })
            .sum::<f32>()
    };
    let plain = upper_error(None);
    let salient = upper_error(Some(
        upper.iter().map(|&u| if u { 20.0 } else { 1.0 }).collect(),
    ));
    assert!(
        salient < 0.7 * plain,
        "upper error salient {salient} vs plain {plain}"
    );
}

#[test]
fn same_seed_same_library() {
    let anim = mouth(150, |f| ((f as f32) * 0.11).sin().abs());
    let opts = LibraryOptions {
        size: LibrarySize::Pieces(5),
        ..LibraryOptions::default()
    };
    let a = build_library(&[part(&anim)], &opts).unwrap();
    let b = build_library(&[part(&anim)], &opts).unwrap();
    assert_eq!(a.parts[0].solution, b.parts[0].solution);
}

#[test]
fn fabricated_pieces_are_closed_oriented_manifolds() {
    let anim = mouth(40, |f| f as f32 / 39.0);
    let opts = LibraryOptions {
        size: LibrarySize::Pieces(3),
        ..LibraryOptions::default()
    };
    let lib = build_library(&[part(&anim)], &opts).unwrap();
    for k in 0..3 {
        let solid = lib.printable_piece(0, k, &anim.mesh, 1.5).unwrap();
        let check = check_solid(&solid);
        assert!(check.is_closed_manifold(), "piece {k}: {check:?}");
        assert!(volume(&solid) > 0.0, "piece {k} volume {}", volume(&solid));
    }
    // Flat square of side 25 mm (print height): volume = area × thickness.
    let flat = stopmo::library::scaled(&grid("flat", 5), 25.0);
    let solid = solidify(&flat, 1.5).unwrap();
    assert!(check_solid(&solid).is_closed_manifold());
    assert!(
        (volume(&solid) - 625.0 * 1.5).abs() < 1e-2,
        "volume {}",
        volume(&solid)
    );
    // A closed surface (tetrahedron) becomes a hollow shell: still a closed manifold.
    let tet = Mesh::new(
        "tet",
        vec![Vec3::ZERO, Vec3::X * 10.0, Vec3::Y * 10.0, Vec3::Z * 10.0],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let shell = solidify(&tet, 0.5).unwrap();
    assert!(check_solid(&shell).is_closed_manifold());
    assert!(volume(&shell) > 0.0 && volume(&shell) < volume(&tet));
    // Two squares touching at one corner (a bow-tie vertex) still give a closed manifold.
    let bowtie = Mesh::new(
        "bowtie",
        vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
        ],
        vec![[0, 1, 2], [2, 3, 4], [2, 4, 5]],
    );
    let solid = solidify(&bowtie, 0.1).unwrap();
    let check = check_solid(&solid);
    assert!(check.is_closed_manifold(), "{check:?}");
    assert!(
        (volume(&solid) - 1.5 * 0.1).abs() < 1e-4,
        "volume {}",
        volume(&solid)
    );
}

#[test]
fn degenerate_inputs_give_defined_results_or_errors() {
    // Still animation: zero error, no NaN.
    let still = mouth(10, |_| 0.0);
    let opts = LibraryOptions {
        size: LibrarySize::Pieces(3),
        ..LibraryOptions::default()
    };
    let lib = build_library(&[part(&still)], &opts).unwrap();
    assert!(
        lib.energy.abs() < 1e-9 && lib.errors_mm.position_max.abs() < 1e-6,
        "{}",
        lib.energy
    );
    // One frame, one piece.
    let one = mouth(1, |_| 0.5);
    let opts1 = LibraryOptions {
        size: LibrarySize::Pieces(1),
        ..LibraryOptions::default()
    };
    assert!(build_library(&[part(&one)], &opts1).unwrap().energy.abs() < 1e-9);
    // Errors.
    assert!(matches!(
        build_library(&[part(&one)], &opts),
        Err(LibraryError::TooManyPieces { .. })
    ));
    assert_eq!(
        build_library(&[], &opts).unwrap_err(),
        LibraryError::NoParts
    );
    let bad = PartInput {
        animation: &still,
        setup: PartSetup {
            saliency: Some(vec![1.0; 3]),
            ..PartSetup::default()
        },
    };
    assert!(matches!(
        build_library(&[bad], &opts),
        Err(LibraryError::BadSaliency { .. })
    ));
    let nan = LibraryOptions {
        solve: SolveOptions {
            lambda: f64::NAN,
            ..SolveOptions::default()
        },
        ..opts.clone()
    };
    assert!(matches!(
        build_library(&[part(&still)], &nan),
        Err(LibraryError::InvalidParameter(_))
    ));
    let other = mouth(11, |_| 0.0);
    assert!(matches!(
        build_library(&[part(&still), part(&other)], &opts),
        Err(LibraryError::FrameCountMismatch { .. })
    ));
}
