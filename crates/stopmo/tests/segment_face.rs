//! The ICT face asset (1,800 frames at 30 fps, 9,409 vertices with UV-seam duplicates,
//! 18,460 triangles): the paper's two-part face split (forehead / chin seeds), Fig. 4 seed
//! robustness, seam homogenization, and Fig. 18 multi-part segmentations.

use std::sync::OnceLock;

use anim::{Aabb, MeshAnimation};
use glam::Vec3;
use stopmo::segment::{
    auto_parts, resolve_seeds, segment, segment_with, PartSpec, Seed, SegmentOptions, Segmentation,
    SegmentationProblem,
};

const FACE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/face/ict-face-talk.glb"
);

struct Face {
    anim: MeshAnimation,
    problem: SegmentationProblem,
    bbox: Aabb,
    /// RMS displacement from the average of every input vertex.
    motion: Vec<f32>,
}

fn face() -> &'static Face {
    static FACE_DATA: OnceLock<Face> = OnceLock::new();
    FACE_DATA.get_or_init(|| {
        let path = std::path::Path::new(FACE);
        let scene = tkio::gltf::read(path).unwrap_or_else(|e| panic!("cannot read {FACE}: {e}"));
        let opts = anim::SampleOptions {
            fps: 30.0,
            ..Default::default()
        };
        let sampled = anim::sample(&scene, &opts).unwrap_or_else(|e| panic!("{FACE}: {e}"));
        let anim = sampled
            .objects
            .into_iter()
            .next()
            .unwrap_or_else(|| panic!("{FACE}: no mesh"))
            .animation;
        let problem = SegmentationProblem::with_defaults(&anim).expect("face problem");
        let avg = problem.average_positions();
        let bbox = Aabb::from_points(avg);
        let n = anim.vertex_count();
        let mut acc = vec![0.0f64; n];
        for f in anim.frames() {
            for i in 0..n {
                acc[i] += f[i].distance_squared(avg[i]) as f64;
            }
        }
        let frames = anim.frame_count() as f64;
        let motion = acc.iter().map(|a| (a / frames).sqrt() as f32).collect();
        Face {
            anim,
            problem,
            bbox,
            motion,
        }
    })
}

/// Forehead and chin seeds, shifted by fractions of the box size.
fn seeds(dx: f32, dy_top: f32, dy_bottom: f32) -> Vec<PartSpec> {
    let b = face().bbox;
    let size = b.max - b.min;
    let mid = b.center();
    vec![
        PartSpec::new(
            "upper",
            vec![Seed::Point(Vec3::new(
                mid.x + dx * size.x,
                b.max.y - dy_top * size.y,
                b.max.z,
            ))],
        ),
        PartSpec::new(
            "lower",
            vec![Seed::Point(Vec3::new(
                mid.x - dx * size.x,
                b.min.y + dy_bottom * size.y,
                b.max.z,
            ))],
        ),
    ]
}

fn two_part_segmentation() -> &'static Segmentation {
    static SEG: OnceLock<Segmentation> = OnceLock::new();
    SEG.get_or_init(|| {
        let f = face();
        let parts = seeds(0.0, 0.0, 0.0);
        let s = resolve_seeds(&f.anim, &f.problem, &parts).expect("seeds");
        segment_with(
            &f.anim,
            &f.problem,
            vec!["upper".into(), "lower".into()],
            s,
            &SegmentOptions::default(),
        )
        .expect("segmentation")
    })
}

#[test]
fn face_cut_runs_below_the_eyes_where_motion_is_lowest() {
    let f = face();
    assert_eq!(f.anim.frame_count(), 1800);
    assert_eq!(f.anim.vertex_count(), 9409);
    let seg = two_part_segmentation();
    let avg = f.problem.average_positions();
    // Motion along the seam (input vertices next to it) versus the whole face.
    let seam_orig: Vec<usize> = seg
        .seam_vertices
        .iter()
        .filter(|&&v| (v as usize) < f.anim.vertex_count())
        .map(|&v| v as usize)
        .collect();
    let seam_motion =
        seam_orig.iter().map(|&i| f.motion[i]).sum::<f32>() / seam_orig.len().max(1) as f32;
    let face_motion = f.motion.iter().sum::<f32>() / f.motion.len() as f32;
    let ys: Vec<f32> = seg
        .seam_vertices
        .iter()
        .map(|&v| seg.cut.sources[v as usize].eval(avg).y)
        .collect();
    let mean_y = ys.iter().sum::<f32>() / ys.len() as f32;
    let (lo, hi) = (f.bbox.min.y, f.bbox.max.y);
    let rel = (mean_y - lo) / (hi - lo);
    eprintln!(
        "seam: {} vertices, mean height {rel:.3} of the face, motion {seam_motion:.5} vs face mean {face_motion:.5}, cut length {:.4}",
        seg.seam_vertices.len(),
        seg.cut_length
    );
    assert!(
        seam_motion < 0.5 * face_motion,
        "the seam must run where the face moves little"
    );
    // The seam must stay between the mouth and the eyes (below the blinks).
    let (mouth, eyes) = mouth_and_eye_heights(f);
    let (min_y, max_y) = ys.iter().fold((f32::MAX, f32::MIN), |(a, b), &y| {
        let r = (y - lo) / (hi - lo);
        (a.min(r), b.max(r))
    });
    eprintln!(
        "seam height {min_y:.3}..{max_y:.3} of the face; mouth band {mouth:.3}, eye band {eyes:.3}"
    );
    assert!(min_y > mouth, "seam dips to the mouth: {min_y} vs {mouth}");
    assert!(max_y < eyes, "seam rises to the eyes: {max_y} vs {eyes}");
    assert!(
        rel > 0.3 && rel < 0.8,
        "seam at {rel:.3} of the face height"
    );
}

#[test]
fn fig4_face_perturbed_seeds_give_the_same_cut() {
    // Fig. 4: the boundary stops depending on the seeds once γ is large enough.
    let f = face();
    let s0 = resolve_seeds(&f.anim, &f.problem, &seeds(0.0, 0.0, 0.0)).expect("seeds");
    for (dx, dt, db) in [(0.08, 0.05, 0.04), (-0.1, 0.1, 0.08)] {
        let s = resolve_seeds(&f.anim, &f.problem, &seeds(dx, dt, db)).expect("seeds");
        let mut changed = Vec::new();
        for gamma in [0.0, 100.0, 1000.0] {
            let a = f.problem.label(&s0, gamma);
            let b = f.problem.label(&s, gamma);
            changed.push(a.iter().zip(&b).filter(|(x, y)| x != y).count());
            // The large-γ cut is still a face split, not a small loop around a seed (the
            // shrinking bias that a literal sum over 1,800 frames would cause).
            let upper = a.iter().filter(|&&l| l == 0).count() as f32 / a.len() as f32;
            eprintln!(
                "γ = {gamma}: upper part {:.1}% of the triangles",
                100.0 * upper
            );
            assert!(
                (0.2..0.8).contains(&upper),
                "γ = {gamma}: upper part {upper}"
            );
        }
        eprintln!("seeds moved by ({dx}, {dt}, {db}): triangles changing part at γ = 0, 100, 1000: {changed:?}");
        // Measured: [885, 894, 93] and similar; the few left are around the moved seeds.
        assert!(
            changed[2] * 100 < f.anim.mesh.triangle_count(),
            "{changed:?}"
        );
        assert!(changed[0] > 5 * changed[2].max(1), "{changed:?}");
    }
}

#[test]
fn face_homogenized_seam_is_identical_in_every_frame() {
    let f = face();
    let seg = two_part_segmentation();
    let diag = f.anim.bbox().diagonal();
    let out = &seg.animation;
    let mut worst = 0.0f32;
    for &v in &seg.seam_vertices {
        let p0 = out.frame(0)[v as usize];
        for fr in out.frames() {
            worst = worst.max(fr[v as usize].distance(p0));
        }
    }
    assert!(worst <= 1e-5 * diag, "seam deviation {worst}");
    // Top of frame 100 + bottom of frame 1500: the shared boundary vertices coincide.
    let parts = seg.parts().expect("parts");
    let mut gap = 0.0f32;
    let mut shared = 0;
    for (lt, &v) in parts[0].vertices.iter().enumerate() {
        if let Ok(lb) = parts[1].vertices.binary_search(&v) {
            shared += 1;
            gap = gap.max(
                parts[0].animation.frame(100)[lt].distance(parts[1].animation.frame(1500)[lb]),
            );
        }
    }
    assert!(shared > 20, "{shared} shared vertices");
    assert_eq!(gap, 0.0);
    let h = seg.homogenization.expect("homogenized");
    eprintln!(
        "homogenization: mean change {:.2e} max {:.2e} (interior mean {:.2e} max {:.2e}) of diag {diag:.3}, max gradient {:.3}, factor {:.3} s, solve {:.3} s",
        h.mean_change, h.max_change, h.mean_free_change, h.max_free_change, h.max_displacement_gradient, h.factor_seconds, h.solve_seconds
    );
    assert!(h.max_change < 0.1 * diag as f64, "{h:?}");
    assert!(h.mean_free_change < 0.01 * diag as f64, "{h:?}");
}

#[test]
fn fig18_face_three_and_six_parts() {
    let f = face();
    for n in [3, 6] {
        let parts = auto_parts(&f.anim, n).expect("auto parts");
        let opts = SegmentOptions {
            homogenize: n == 3,
            ..SegmentOptions::default()
        };
        let seg = segment(&f.anim, &parts, &opts).expect("segmentation");
        let mut counts = vec![0usize; n];
        for &p in &seg.input_triangle_part {
            counts[p as usize] += 1;
        }
        eprintln!("{n} parts: {counts:?}, cut length {:.4}", seg.cut_length);
        assert!(counts.iter().all(|&c| c > 0), "{counts:?}");
        assert!(seg.seam_vertices.len() > 10);
    }
}

/// Heights (relative to the face box) of the most moving horizontal band (the mouth) and of
/// the most moving band in the upper third (the eyes, blinking).
fn mouth_and_eye_heights(f: &Face) -> (f32, f32) {
    let avg = f.problem.average_positions();
    let (lo, hi) = (f.bbox.min.y, f.bbox.max.y);
    let bins = 20;
    let mut band = vec![(0.0f32, 0usize); bins];
    for (p, m) in avg.iter().zip(&f.motion) {
        let b = (((p.y - lo) / (hi - lo)) * bins as f32) as usize;
        band[b.min(bins - 1)].0 += m;
        band[b.min(bins - 1)].1 += 1;
    }
    let mean = |b: usize| band[b].0 / band[b].1.max(1) as f32;
    let centre = |b: usize| (b as f32 + 0.5) / bins as f32;
    let mouth = (0..bins).fold(0, |a, b| if mean(b) > mean(a) { b } else { a });
    let eyes =
        (2 * bins / 3..bins).fold(2 * bins / 3, |a, b| if mean(b) > mean(a) { b } else { a });
    (centre(mouth), centre(eyes))
}

#[test]
fn fig4_large_gamma_cut_stays_between_mouth_and_eyes() {
    // The seed-independent cut of Fig. 4 (γ = 1,000 with StopShop Eq. 3 averaged over frames) is still
    // the paper's face split; far beyond (γ = 10,000) the graph cut's shrinking bias wins and
    // the cut collapses around a seed — reported, so the useful γ range is documented.
    let f = face();
    let s0 = resolve_seeds(&f.anim, &f.problem, &seeds(0.0, 0.0, 0.0)).expect("seeds");
    let avg = f.problem.average_positions();
    let tris = &f.anim.mesh.triangles;
    let (lo, hi) = (f.bbox.min.y, f.bbox.max.y);
    let (mouth, eyes) = mouth_and_eye_heights(f);
    let mut edges = Vec::new();
    for gamma in [100.0, 1000.0, 10000.0] {
        let l = f.problem.label(&s0, gamma);
        let ys: Vec<f32> = f
            .problem
            .motion_costs()
            .filter(|&(a, b, _)| l[a as usize] != l[b as usize])
            .map(|(a, _, _)| {
                let c = tris[a as usize].map(|v| avg[v as usize]);
                ((c[0].y + c[1].y + c[2].y) / 3.0 - lo) / (hi - lo)
            })
            .collect();
        let (mn, mx) = ys
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &y| (a.min(y), b.max(y)));
        eprintln!(
            "γ = {gamma}: {} cut edges at heights {mn:.3}..{mx:.3} (mouth {mouth:.3}, eyes {eyes:.3})",
            ys.len()
        );
        if gamma <= 1000.0 {
            assert!(mn > mouth && mx < eyes, "γ = {gamma}: cut {mn}..{mx}");
        }
        edges.push(ys.len());
    }
    assert!(edges[1] > 30, "γ = 1000 cut has {} edges", edges[1]);
    assert!(edges[2] < edges[1], "{edges:?}");
}
