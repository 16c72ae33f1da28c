//! Segmentation and homogenization on a synthetic talking tube (see `segment_support`).

mod segment_support;

use glam::Vec3;
use segment_support::{area, diagonal, talking_tube, STILL_Y};
use stopmo::segment::{
    auto_parts, homogenize, resolve_seeds, segment, segment_with, PartSpec, Seed, SegmentOptions,
    SegmentationProblem,
};

fn point_seed(name: &str, angle: f32, y: f32) -> PartSpec {
    PartSpec::new(
        name,
        vec![Seed::Point(Vec3::new(angle.sin(), y, angle.cos()))],
    )
}

fn two_parts() -> Vec<PartSpec> {
    vec![
        point_seed("upper", 0.0, 0.95),
        point_seed("lower", 0.0, -0.95),
    ]
}

#[test]
fn jaw_cut_runs_along_the_still_ring() {
    let anim = talking_tube(32, 40, 48);
    let seg = segment(&anim, &two_parts(), &SegmentOptions::default()).unwrap();
    let avg = anim.average_positions();
    // Mean and spread of the seam's height on the cut mesh's average.
    let ys: Vec<f32> = seg
        .seam_vertices
        .iter()
        .map(|&v| seg.cut.sources[v as usize].eval(&avg).y)
        .collect();
    let mean = ys.iter().sum::<f32>() / ys.len() as f32;
    let spread = ys.iter().map(|y| (y - mean).abs()).fold(0.0f32, f32::max);
    let row = 2.0 / 40.0;
    assert!(
        (mean - STILL_Y).abs() < row,
        "seam at y = {mean}, still ring at {STILL_Y}"
    );
    assert!(spread < 1.5 * row, "seam spread {spread}");
    // The seam goes once around the tube (circumference 2π, welded across the UV seam).
    let tau = std::f64::consts::TAU;
    assert!(
        (seg.cut_length - tau).abs() < 0.1 * tau,
        "cut length {}",
        seg.cut_length
    );
}

#[test]
fn fig4_perturbed_seeds_give_the_same_cut() {
    let anim = talking_tube(32, 40, 48);
    let problem = SegmentationProblem::with_defaults(&anim).unwrap();
    let a = resolve_seeds(&anim, &problem, &two_parts()).unwrap();
    let b = resolve_seeds(
        &anim,
        &problem,
        &[
            point_seed("upper", 1.6, 0.7),
            point_seed("lower", 3.0, -0.6),
        ],
    )
    .unwrap();
    let la = problem.label(&a, 100.0);
    let lb = problem.label(&b, 100.0);
    let differ = la.iter().zip(&lb).filter(|(x, y)| x != y).count();
    assert_eq!(
        differ, 0,
        "{differ} triangles change part when the seeds move (γ = 100)"
    );
    // Without the binary term (first row of Fig. 4) the cut follows the seeds.
    let va = problem.label(&a, 0.0);
    let vb = problem.label(&b, 0.0);
    let differ0 = va.iter().zip(&vb).filter(|(x, y)| x != y).count();
    assert!(
        differ0 > 50,
        "γ = 0 should depend on the seeds, only {differ0} triangles differ"
    );
    assert!(problem.boundary_length(&la) < problem.boundary_length(&va));
}

#[test]
fn homogenized_seam_is_frame_invariant_and_parts_mix_without_gap() {
    let anim = talking_tube(32, 40, 48);
    let seg = segment(&anim, &two_parts(), &SegmentOptions::default()).unwrap();
    let diag = diagonal(&anim);
    let out = &seg.animation;
    let mut worst = 0.0f32;
    for &v in &seg.seam_vertices {
        let p0 = out.frame(0)[v as usize];
        for f in out.frames() {
            worst = worst.max(f[v as usize].distance(p0));
        }
    }
    assert!(worst <= 1e-5 * diag, "seam deviation {worst} (diag {diag})");
    // Mix the top of frame 7 with the bottom of frame 31: shared seam vertices coincide.
    let parts = seg.parts().unwrap();
    let (top, bottom) = (&parts[0], &parts[1]);
    let mut gap = 0.0f32;
    let mut shared = 0;
    for (lt, &vt) in top.vertices.iter().enumerate() {
        if let Ok(lb) = bottom.vertices.binary_search(&vt) {
            shared += 1;
            gap = gap.max(top.animation.frame(7)[lt].distance(bottom.animation.frame(31)[lb]));
        }
    }
    assert!(shared >= 32, "only {shared} shared seam vertices");
    assert_eq!(gap, 0.0, "gap between mixed parts");
    let stats = seg.homogenization.unwrap();
    eprintln!("homogenization: {stats:?}");
    assert!(
        stats.max_change > 0.0 && stats.max_change < 0.2 * diag as f64,
        "{stats:?}"
    );
    assert!(stats.mean_free_change < stats.max_free_change);
    // The interior deformation is smooth: displacement changes by less than 1 per unit
    // length between neighbours.
    assert!(stats.max_displacement_gradient < 1.0, "{stats:?}");
}

#[test]
fn cutting_keeps_the_surface_and_uv_duplicates() {
    let anim = talking_tube(24, 30, 20);
    let opts = SegmentOptions {
        homogenize: false,
        ..SegmentOptions::default()
    };
    let seg = segment(&anim, &two_parts(), &opts).unwrap();
    assert!(
        seg.animation.vertex_count() > anim.vertex_count(),
        "no vertex was added"
    );
    assert!(seg.animation.mesh.triangle_count() > anim.mesh.triangle_count());
    let mut worst = 0.0f64;
    for f in 0..anim.frame_count() {
        let a = area(&anim.mesh.triangles, anim.frame(f));
        let b = area(&seg.animation.mesh.triangles, seg.animation.frame(f));
        worst = worst.max((a - b).abs() / a);
    }
    assert!(worst < 1e-5, "surface area changed by {worst}");
    // The input vertices come first, unchanged.
    for f in [0, 7, 19] {
        assert_eq!(
            &seg.animation.frame(f)[..anim.vertex_count()],
            anim.frame(f)
        );
    }
    // The duplicated UV-seam column stays coincident with its twin in every frame.
    let w = 25;
    for r in 0..=30 {
        let (i, j) = (r * w, r * w + 24);
        for f in 0..anim.frame_count() {
            assert_eq!(seg.animation.frame(f)[i], seg.animation.frame(f)[j]);
        }
    }
    // Triangle labels of the cut mesh form two parts and smoothing moved no seed.
    assert!(seg.triangle_part.contains(&0) && seg.triangle_part.contains(&1));
    for (j, seeds) in seg.seeds.iter().enumerate() {
        for &t in seeds {
            assert_eq!(seg.input_triangle_part[t as usize], j as u32);
        }
    }
}

#[test]
fn homogenize_with_given_labels_pins_uv_duplicates_together() {
    let anim = talking_tube(24, 30, 30);
    // Label by height on the rest mesh: a straight cut at the second row above the middle.
    let labels: Vec<u32> = anim
        .mesh
        .triangles
        .iter()
        .map(|t| {
            let y: f32 = t
                .iter()
                .map(|&i| anim.mesh.positions[i as usize].y)
                .sum::<f32>()
                / 3.0;
            (y < 0.06) as u32
        })
        .collect();
    let (out, stats) = homogenize(&anim, &labels, 1e-6).unwrap();
    assert_eq!(stats.seam_vertices, 24);
    assert_eq!(stats.pinned_vertices, 72);
    let seam_row = 16; // y = -1 + 2·16/30 ≈ 0.067
    for c in 0..=24 {
        let v = seam_row * 25 + c;
        for f in out.frames() {
            assert_eq!(f[v], out.frame(0)[v], "vertex {v} moves");
        }
    }
    assert!(stats.max_free_change > 0.0);
}

#[test]
fn fig18_three_and_six_parts() {
    let anim = talking_tube(32, 40, 40);
    for n in [3, 6] {
        let parts = auto_parts(&anim, n).unwrap();
        assert_eq!(parts.len(), n);
        let seg = segment(&anim, &parts, &SegmentOptions::default()).unwrap();
        let mut counts = vec![0usize; n];
        for &p in &seg.input_triangle_part {
            counts[p as usize] += 1;
        }
        // The tube has two motion regions, so extra parts may be confined to their seed
        // patch by StopShop Eq. 1; every part must still exist and own its seeds.
        assert!(
            counts.iter().all(|&c| c > 0),
            "{n} parts: empty part in {counts:?}"
        );
        assert_eq!(counts.iter().sum::<usize>(), anim.mesh.triangle_count());
        let stats = seg.homogenization.unwrap();
        assert!(stats.seam_vertices > 0);
        let diag = diagonal(&anim);
        let mut worst = 0.0f32;
        for &v in &seg.seam_vertices {
            let p0 = seg.animation.frame(0)[v as usize];
            for f in seg.animation.frames() {
                worst = worst.max(f[v as usize].distance(p0));
            }
        }
        assert!(worst <= 1e-5 * diag, "{n} parts: seam deviation {worst}");
        let out_parts = seg.parts().unwrap();
        let tris: usize = out_parts
            .iter()
            .map(|p| p.animation.mesh.triangle_count())
            .sum();
        assert_eq!(tris, seg.animation.mesh.triangle_count());
        eprintln!(
            "{n} parts: triangles per part {counts:?}, cut length {:.3}",
            seg.cut_length
        );
    }
}

#[test]
fn still_animation_has_defined_results() {
    let mesh = segment_support::tube(16, 10);
    let one = anim::MeshAnimation::still(mesh);
    // Without motion StopShop Eq. 3 is the cut length; a moderate γ cuts across the tube.
    let opts = SegmentOptions {
        gamma: 10.0,
        ..SegmentOptions::default()
    };
    let seg = segment(&one, &two_parts(), &opts).unwrap();
    let stats = seg.homogenization.unwrap();
    assert_eq!(stats.max_change, 0.0, "a still mesh must not move");
    assert!(seg.cut_length > 0.0);
    let problem = SegmentationProblem::with_defaults(&one).unwrap();
    let seeds = resolve_seeds(&one, &problem, &two_parts()).unwrap();
    let again = segment_with(&one, &problem, vec!["a".into(), "b".into()], seeds, &opts).unwrap();
    assert_eq!(again.triangle_part, seg.triangle_part);
}

#[test]
fn bad_seeds_are_errors() {
    let anim = talking_tube(8, 6, 3);
    let o = SegmentOptions::default();
    assert!(segment(&anim, &two_parts()[..1], &o).is_err());
    let bad = vec![
        PartSpec::new("a", vec![Seed::Triangle(0)]),
        PartSpec::new("b", vec![Seed::Triangle(1_000_000)]),
    ];
    assert!(segment(&anim, &bad, &o).is_err());
    let same = vec![
        PartSpec::new("a", vec![Seed::Triangle(3)]),
        PartSpec::new("b", vec![Seed::Triangle(3)]),
    ];
    assert!(segment(&anim, &same, &o).is_err());
    let nan = vec![
        PartSpec::new("a", vec![Seed::Triangle(0)]),
        PartSpec::new("b", vec![Seed::Point(Vec3::NAN)]),
    ];
    assert!(segment(&anim, &nan, &o).is_err());
    let empty = vec![
        PartSpec::new("a", vec![Seed::Triangle(0)]),
        PartSpec::new("b", vec![]),
    ];
    assert!(segment(&anim, &empty, &o).is_err());
    assert!(segment(
        &anim,
        &two_parts(),
        &SegmentOptions {
            gamma: f64::NAN,
            ..o
        }
    )
    .is_err());
}
