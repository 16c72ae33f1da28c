//! Regression tests named after the figures and equations of Section 3 of the paper.

mod common;

use anim::VertexWeights;
use common::*;
use glam::{Mat4, Quat, Vec3};
use smear::{mesh_offsets, scene_offsets, smoothstep, OffsetOptions};

fn no_smoothing() -> OffsetOptions {
    OffsetOptions {
        smooth: 0,
        ..OffsetOptions::default()
    }
}

/// Fig. 3: a ball translating to the right: the leading hemisphere is positive, the trailing
/// one negative, the extremes ±1, and δ is the normalized signed distance to the plane.
#[test]
fn fig3_translating_ball() {
    let anim = translating(sphere(1.0), 6, |f| Vec3::new(0.5 * f as f32, 0.2, -0.1));
    let d = mesh_offsets(&anim, &OffsetOptions::default()).unwrap();
    for f in 0..6 {
        let c = Vec3::new(0.5 * f as f32, 0.2, -0.1);
        let (lo, hi) = d
            .frame(f)
            .iter()
            .fold((1.0f32, -1.0f32), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(
            (hi - 1.0).abs() < 1e-5 && (lo + 1.0).abs() < 1e-5,
            "frame {f}: [{lo}, {hi}]"
        );
        for (p, &x) in anim.frame(f).iter().zip(d.frame(f)) {
            let ahead = p.x - c.x;
            assert!((x - ahead).abs() < 1e-4, "δ {x} vs signed distance {ahead}");
            if ahead.abs() > 1e-3 {
                assert_eq!(x > 0.0, ahead > 0.0);
            }
        }
    }
}

/// Fig. 4: a peanut translating along its long axis. The plane-based offsets are monotonic
/// along the motion; the normal-based formula [Jones and Keyser 2005] is not (the trailing
/// lobe's front faces lead, the leading lobe's back faces trail).
#[test]
fn fig4_peanut_concavity() {
    let anim = translating(peanut(), 5, |f| Vec3::X * 0.3 * f as f32);
    let d = mesh_offsets(&anim, &OffsetOptions::default()).unwrap();
    let f = 2;
    let pos = anim.frame(f);
    let mut order: Vec<usize> = (0..pos.len()).collect();
    order.sort_by(|&a, &b| pos[a].x.total_cmp(&pos[b].x));
    let delta = d.frame(f);
    for w in order.windows(2) {
        assert!(
            delta[w[1]] >= delta[w[0]] - 1e-6,
            "not monotonic at x = {}",
            pos[w[1]].x
        );
    }
    // The normal-based formula: find a vertex behind another that has a larger value.
    let normals = anim.mesh.vertex_normals(pos);
    let by_normal: Vec<f32> = normals.iter().map(|n| n.x).collect();
    let mut worst = 0.0f32;
    for &a in &order {
        for &b in &order {
            if pos[a].x < pos[b].x - 0.2 {
                worst = worst.max(by_normal[a] - by_normal[b]);
            }
        }
    }
    assert!(
        worst > 0.3,
        "normal-based offsets should decrease across the waist, worst {worst}"
    );
    // The trailing lobe's front faces "lead" with the normal formula but trail with ours.
    let c = 0.3 * f as f32;
    let v = order
        .iter()
        .copied()
        .filter(|&v| pos[v].x < c - 0.3)
        .max_by(|&a, &b| by_normal[a].total_cmp(&by_normal[b]))
        .unwrap();
    assert!(
        by_normal[v] > 0.2 && delta[v] < -0.1,
        "normal {} vs δ {}",
        by_normal[v],
        delta[v]
    );
}

/// Capsule of two bones along world X (chain along local Y rotated by −90° about Z).
fn x_capsule(frames: usize, motion: Vec3) -> anim::SampledScene {
    let ys: Vec<f32> = (0..=20).map(|i| i as f32 * 0.1).collect();
    let mut mesh = tube(&ys, 24, |_| 0.25);
    let w = chain_weights(&mesh, 2, 1.0, 0.2);
    let rot = Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2);
    // The rest mesh lies in the bind pose: along world X like the bones.
    for p in &mut mesh.positions {
        *p = rot * *p;
    }
    let skel = chain(2, 1.0, rot);
    let locals0 = bind_locals(&skel);
    skinned_scene(mesh, skel, w, frames, move |f| {
        let mut l = locals0.clone();
        l[0] = Mat4::from_translation(motion * f as f32) * l[0];
        l
    })
}

/// Fig. 7: a two-bone capsule translating (almost) along its bones' axis. With the collinear
/// weight the offsets nearly vanish; without it they follow the height across the capsule,
/// which shears the elongated in-between.
#[test]
fn fig7_collinear_weight_removes_shear() {
    let scene = x_capsule(5, Vec3::new(1.0, 0.05, 0.0) * 0.2);
    let with = &scene_offsets(&scene, &no_smoothing()).unwrap()[0];
    let without = &scene_offsets(
        &scene,
        &OffsetOptions {
            collinear_weight: false,
            ..no_smoothing()
        },
    )
    .unwrap()[0];
    assert!(
        with.max_abs() < 0.01,
        "with collinear weights max |δ| = {}",
        with.max_abs()
    );
    assert!(without.max_abs() > 0.95);
    let f = 2;
    let pos = scene.objects[0].animation.frame(f);
    let y0 = 0.05 * 0.2 * f as f32;
    for (p, &x) in pos.iter().zip(without.frame(f)) {
        let h = (p.y - y0) / 0.25;
        assert!(
            (x - h).abs() < 0.05,
            "sheared offset {x} vs height {h} at {p}"
        );
    }
}

/// A tube along Y that is thin near the root and thick at the tip, two bones with hard
/// weights, the joint ring duplicated (one copy per bone) so both sides share positions.
fn thin_thick_capsule(
    frames: usize,
    locals: impl Fn(usize, &[Mat4]) -> Vec<Mat4>,
) -> anim::SampledScene {
    let mut ys: Vec<f32> = (0..=10).map(|i| i as f32 * 0.1).collect();
    ys.extend((10..=20).map(|i| i as f32 * 0.1));
    let seg = 16;
    let mesh = tube(&ys, seg, |y| 0.1 + 0.15 * y * y);
    let nv = mesh.vertex_count();
    let w = VertexWeights::from_influences((0..nv).map(|v| {
        let ring = if v == 0 { 0 } else { (v - 1) / seg };
        vec![(u32::from(ring > 10), 1.0)]
    }));
    let skel = chain(2, 1.0, Quat::IDENTITY);
    let l0 = bind_locals(&skel);
    skinned_scene(mesh, skel, w, frames, move |f| locals(f, &l0))
}

/// SMEAR Eq. 9 with SPEC.md's orientation is continuous across a joint: the two copies of the
/// joint ring (one on each bone) get the same offsets although the bones' parts have very
/// different thickness. The printed orientation would normalize each side by its own part.
#[test]
fn eq9_continuity_across_joint() {
    let scene = thin_thick_capsule(5, |f, l| {
        let mut l = l.to_vec();
        l[0] = Mat4::from_translation(Vec3::X * 0.1 * f as f32) * l[0];
        l
    });
    let d = &scene_offsets(&scene, &no_smoothing()).unwrap()[0];
    let seg = 16;
    let f = 2;
    let pos = scene.objects[0].animation.frame(f);
    let x0 = 0.1 * f as f32;
    let ring = |r: usize, s: usize| 1 + r * seg + s;
    let max_all = pos.iter().fold(0.0f32, |m, p| m.max((p.x - x0).abs()));
    let max_thin = (0..=10)
        .flat_map(|r| (0..seg).map(move |s| ring(r, s)))
        .fold(0.0f32, |m, v| m.max((pos[v].x - x0).abs()));
    let mut jump = 0.0f32;
    let mut printed_jump = 0.0f32;
    for s in 0..seg {
        let (a, b) = (ring(10, s), ring(11, s));
        assert!((pos[a] - pos[b]).length() < 1e-6);
        jump = jump.max((d.frame(f)[a] - d.frame(f)[b]).abs());
        // Both sides are normalized by the maximum over the whole neighbourhood.
        assert!((d.frame(f)[b] - (pos[b].x - x0) / max_all).abs() < 1e-4);
        printed_jump =
            printed_jump.max(((pos[a].x - x0) / max_thin - (pos[b].x - x0) / max_all).abs());
    }
    assert!(jump < 1e-5, "jump across the joint {jump}");
    assert!(
        printed_jump > 0.5,
        "printed SMEAR Eq. 9 would jump by {printed_jump}"
    );
}

/// Direct transcription of SMEAR Eqs. 3–9 for a two-bone chain, as an oracle.
fn oracle_two_bones(scene: &anim::SampledScene, f: usize) -> Vec<f32> {
    let frames = scene.frame_count;
    let (a, b, s) = match f {
        0 => (0, 1, 1.0),
        _ if f + 1 == frames => (f - 1, f, 1.0),
        _ => (f - 1, f + 1, 0.5),
    };
    let obj = &scene.objects[0];
    let pos = obj.animation.frame(f);
    let skin = obj.skin.as_ref().unwrap();
    let w = |v: usize, k: usize| skin.joint_weight(k, v);
    let eval = |k: usize, p: Vec3| -> (f32, f32, f32) {
        let bone = scene.bones_at(f)[k];
        let vr = (scene.bones_at(b)[k].root - scene.bones_at(a)[k].root) * s;
        let vt = (scene.bones_at(b)[k].tip - scene.bones_at(a)[k].tip) * s;
        let bv = bone.tip - bone.root;
        let bh = bv.normalize();
        let u = smoothstep((p - bone.root).dot(bh) / bv.length());
        let (r, t) = (vr.normalize(), vt.normalize());
        let om = r.dot(t).clamp(-1.0, 1.0).acos();
        let v = if om < 0.1 {
            ((1.0 - u) * r + u * t).normalize()
        } else {
            ((1.0 - u) * om).sin() / om.sin() * r + (u * om).sin() / om.sin() * t
        };
        let n = (v - v.dot(bh) * bh).normalize();
        ((p - bone.root).dot(n), 1.0 - v.dot(bh).powi(2), u)
    };
    let nv = pos.len();
    let in_r = |k: usize, v: usize| {
        if k == 0 {
            w(v, 0) > 0.0
        } else {
            w(v, 0) > 0.0 || w(v, 1) > 0.0
        }
    };
    let in_t = |k: usize, v: usize| {
        if k == 0 {
            w(v, 0) > 0.0 || w(v, 1) > 0.0
        } else {
            w(v, 1) > 0.0
        }
    };
    let maxima: Vec<(f32, f32)> = (0..2)
        .map(|k| {
            let (mut mr, mut mt) = (0.0f32, 0.0f32);
            for v in 0..nv {
                let x = eval(k, pos[v]).0.abs();
                if in_r(k, v) {
                    mr = mr.max(x);
                }
                if in_t(k, v) {
                    mt = mt.max(x);
                }
            }
            (mr, mt)
        })
        .collect();
    (0..nv)
        .map(|v| {
            (0..2)
                .filter(|&k| w(v, k) > 0.0)
                .map(|k| {
                    let (raw, coll, u) = eval(k, pos[v]);
                    let m = (1.0 - u) * maxima[k].0 + u * maxima[k].1;
                    w(v, k) * coll * raw / m
                })
                .sum()
        })
        .collect()
}

/// Fig. 5 / SMEAR Eqs. 3–9 on a bending, translating two-bone capsule with blended weights: the
/// crate's factored evaluation matches a literal transcription of the equations.
#[test]
fn fig5_bending_capsule_matches_the_equations() {
    let ys: Vec<f32> = (0..=20).map(|i| i as f32 * 0.1).collect();
    let mesh = tube(&ys, 20, |y| 0.2 + 0.05 * y);
    let w = chain_weights(&mesh, 2, 1.0, 0.25);
    let skel = chain(2, 1.0, Quat::IDENTITY);
    let l0 = bind_locals(&skel);
    let frames = 9;
    let scene = skinned_scene(mesh, skel, w, frames, move |f| {
        let t = f as f32;
        let mut l = l0.clone();
        l[0] = Mat4::from_translation(Vec3::new(0.15 * t, 0.02 * t * t, 0.0))
            * Mat4::from_rotation_z(0.05 * t);
        l[1] =
            l0[1] * Mat4::from_rotation_z(0.6 * (0.5 * t).sin()) * Mat4::from_rotation_x(0.2 * t);
        l
    });
    let d = &scene_offsets(&scene, &no_smoothing()).unwrap()[0];
    let mut worst = 0.0f32;
    for f in 0..frames {
        let o = oracle_two_bones(&scene, f);
        for (a, b) in d.frame(f).iter().zip(&o) {
            worst = worst.max((a - b).abs());
        }
    }
    assert!(worst < 2e-3, "max deviation from SMEAR Eqs. 3–9: {worst}");
    assert!(
        d.max_abs() > 0.5 && d.max_abs() < 1.5,
        "range {:?}",
        d.range()
    );
}
