//! `--revolve`: a spinning propeller keeps its blades on their circles.

use anim::{Mesh, MeshAnimation};
use glam::{Quat, Vec3};
use smear::{stylize, Trajectories};

use super::{elongation, part_frames, prepared};

/// Rotation per frame: 60°, fast enough for Catmull-Rom to cut the chord visibly.
const SPIN: f32 = std::f32::consts::FRAC_PI_3;

/// Two flat blades (separate pieces, radius 0.2 to 1) spinning about +Y.
fn propeller(frames: usize) -> MeshAnimation {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for blade in 0..2 {
        let base = p.len() as u32;
        let a0 = blade as f32 * std::f32::consts::PI;
        for k in 0..5 {
            let r = 0.2 + 0.2 * k as f32;
            for da in [-0.15f32, 0.15] {
                let a = a0 + da / r.max(0.5);
                p.push(Vec3::new(r * a.cos(), 0.0, -r * a.sin()));
            }
        }
        for k in 0..4u32 {
            let (i, j) = (base + 2 * k, base + 2 * k + 2);
            t.push([i, i + 1, j + 1]);
            t.push([i, j + 1, j]);
        }
    }
    let positions = (0..frames)
        .flat_map(|f| {
            let q = Quat::from_rotation_y(SPIN * f as f32);
            p.iter().map(move |x| q * *x).collect::<Vec<_>>()
        })
        .collect();
    MeshAnimation::new(Mesh::new("Propeller", p.clone(), t), 24.0, positions).unwrap()
}

fn radius(p: Vec3) -> f32 {
    (p.x * p.x + p.z * p.z).sqrt()
}

#[test]
fn elongated_blades_stay_on_their_circles() {
    let prop = propeller(16);
    for names in [vec!["Propeller".to_string()], vec!["auto".to_string()]] {
        let p = prepared(&prop, |o| o.offsets.revolve = names.clone());
        // Each blade has a leading (δ > 0) and a trailing (δ < 0) edge.
        let d = p.offsets(0).frame(8);
        let n = d.len() / 2;
        for blade in [&d[..n], &d[n..]] {
            assert!(
                blade.iter().any(|x| *x > 0.5) && blade.iter().any(|x| *x < -0.5),
                "{blade:?}"
            );
        }
        let out = stylize(&p, &elongation(&p, 1.0)).unwrap();
        let frames = part_frames(&out.flipbook.parts[0]);
        let mut moved = 0.0f32;
        for (f, frame) in frames.iter().enumerate() {
            for (q, r) in frame.iter().zip(prop.frame(f)) {
                let (a, b) = (radius(*q), radius(*r));
                assert!(
                    (a - b).abs() <= 0.01 * b,
                    "{names:?} frame {f}: radius {b} → {a}"
                );
                moved = moved.max(q.distance(*r));
            }
        }
        assert!(
            moved > 0.3,
            "{names:?}: the blades did not elongate ({moved})"
        );
    }
}

#[test]
fn linear_trajectories_cut_the_chord() {
    // The paper's Catmull-Rom trajectories through the same samples leave the circle by more
    // than 1 % half-way between frames; without --revolve the offsets are 0 (still centroid).
    let prop = propeller(16);
    let tr = Trajectories::of_animation(&prop);
    let tip = 8; // a vertex at radius 1
    let r = radius(prop.frame(8)[tip]);
    let mid = radius(tr.at(tip, 8.5));
    assert!((r - mid) / r > 0.02, "Catmull-Rom radius {mid} vs {r}");
    let plain = prepared(&prop, |_| {});
    assert_eq!(plain.offsets(0).max_abs(), 0.0);
}
