//! `--ground` and colliders: a walk with planted feet never goes through the floor or into a
//! collider mesh, offline and streamed.

use anim::{Mesh, MeshAnimation, SampledScene};
use glam::Vec3;
use smear::{
    prepare, stylize, Collider, ContactStyle, FunctionSpec, MultiplesStyle, Param, PrepareOptions,
    Stream, StreamOptions, Style,
};

use super::{elongation, legged, part_frames, prepared};

/// The lowest point of every part of a stylized result.
fn lowest(out: &smear::Stylized) -> f32 {
    out.flipbook
        .parts
        .iter()
        .flat_map(part_frames)
        .flatten()
        .fold(f32::INFINITY, |m, p| m.min(p.y))
}

#[test]
fn a_walk_with_planted_feet_stays_above_the_ground() {
    let walk = legged::gait(32, 0.1, 0.25);
    let input_low = walk
        .positions()
        .iter()
        .fold(f32::INFINITY, |m, p| m.min(p.y));
    assert!(input_low.abs() < 1e-6, "the feet touch y = 0: {input_low}");
    let p = prepared(&walk, |_| {});
    let style = Style {
        multiples: Some(MultiplesStyle {
            past: Param::Constant(2.0),
            future: Param::Constant(2.0),
            ..MultiplesStyle::default()
        }),
        ..elongation(&p, 2.0)
    };
    // Without contact, Catmull-Rom trajectories overshoot the landing and dive below.
    let free = stylize(&p, &style).unwrap();
    assert!(
        lowest(&free) < -1e-3,
        "nothing crossed the ground: {}",
        lowest(&free)
    );
    for squash in [0.0, 0.3] {
        for subdivide in [None, Some(2.0)] {
            let grounded = Style {
                contact: Some(ContactStyle {
                    ground: 0.0,
                    squash,
                    ..ContactStyle::default()
                }),
                subdivide,
                ..style.clone()
            };
            let out = stylize(&p, &grounded).unwrap();
            let low = lowest(&out);
            assert!(
                low >= 0.0,
                "squash {squash}, subdivide {subdivide:?}: lowest {low}"
            );
            // The smear is still there: grounding shortens, it does not cancel.
            let e = out.report.objects[0].elongation_max.unwrap();
            assert!(e > 0.1, "elongation {e}");
        }
    }
}

/// A walk with elongated and multiple in-betweens (β_max = 2, two copies each way).
fn walk_style(p: &smear::Prepared) -> Style {
    Style {
        multiples: Some(MultiplesStyle {
            past: Param::Constant(2.0),
            future: Param::Constant(2.0),
            ..MultiplesStyle::default()
        }),
        ..elongation(p, 2.0)
    }
}

/// An axis-aligned box, 12 outward-facing triangles on 24 corners (split at its edges, as
/// glTF writes flat-shaded boxes).
fn split_box(name: &str, min: Vec3, max: Vec3) -> Mesh {
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let corner = |a: f32, b: f32| {
                let mut u = [0.0f32; 3];
                u[axis] = side;
                u[(axis + 1) % 3] = a;
                u[(axis + 2) % 3] = b;
                min + (max - min) * Vec3::from(u)
            };
            let c = [
                corner(0., 0.),
                corner(1., 0.),
                corner(1., 1.),
                corner(0., 1.),
            ];
            let outward = Vec3::AXES[axis] * (2.0 * side - 1.0);
            let flip = (c[1] - c[0]).cross(c[2] - c[0]).dot(outward) < 0.0;
            let base = positions.len() as u32;
            positions.extend(c);
            for t in [[0, 1, 2], [0, 2, 3]] {
                let t: [u32; 3] = if flip { [t[0], t[2], t[1]] } else { t };
                triangles.push(t.map(|k| base + k));
            }
        }
    }
    Mesh::new(name, positions, triangles)
}

/// Output vertices strictly inside the box `[min, max]` (an independent test, not the
/// collider's own).
fn inside_box(out: &smear::Stylized, min: Vec3, max: Vec3) -> usize {
    let eps = Vec3::splat(1e-6);
    out.flipbook
        .parts
        .iter()
        .flat_map(part_frames)
        .flatten()
        .filter(|p| p.cmpgt(min + eps).all() && p.cmplt(max - eps).all())
        .count()
}

#[test]
fn a_floor_quad_collider_gives_the_ground_plane() {
    let walk = legged::gait(32, 0.1, 0.25);
    let floor = Mesh::new(
        "floor",
        vec![
            Vec3::new(-3.0, 0.0, -2.0),
            Vec3::new(-3.0, 0.0, 2.0),
            Vec3::new(7.0, 0.0, 2.0),
            Vec3::new(7.0, 0.0, -2.0),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    let mut with_floor = prepared(&walk, |_| {});
    with_floor.add_collider(Collider::from_mesh(&floor));
    let plain = prepared(&walk, |_| {});
    for subdivide in [None, Some(2.0)] {
        let style = Style {
            subdivide,
            ..walk_style(&plain)
        };
        let free = stylize(&plain, &style).unwrap();
        assert!(lowest(&free) < -1e-3, "nothing crossed: {}", lowest(&free));
        let grounded = Style {
            contact: Some(ContactStyle::default()),
            ..style.clone()
        };
        let by_plane = stylize(&plain, &grounded).unwrap();
        let by_quad = stylize(&with_floor, &style).unwrap();
        assert!(lowest(&by_quad) >= 0.0, "{}", lowest(&by_quad));
        assert_eq!(by_plane.flipbook.parts.len(), by_quad.flipbook.parts.len());
        let mut worst = 0.0f32;
        let n = walk.vertex_count();
        for (a, b) in by_plane.flipbook.parts.iter().zip(&by_quad.flipbook.parts) {
            for (fa, fb) in part_frames(a).iter().zip(part_frames(b)) {
                // Subdivided frames: the quad's skin moves points by ~1e-4, which may flip a
                // split whose deviation is at the threshold (relative to the frame's own
                // deviations); the input's vertices come first in both and must agree.
                let (fa, fb) = match subdivide {
                    None => {
                        assert_eq!(fa.len(), fb.len());
                        (&fa[..], &fb[..])
                    }
                    Some(_) => {
                        let (x, y) = (fa.len() as f32, fb.len() as f32);
                        assert!((x - y).abs() <= 0.02 * x.max(y), "{x} vs {y} vertices");
                        (&fa[..n], &fb[..n])
                    }
                };
                for (p, q) in fa.iter().zip(fb) {
                    worst = worst.max(p.distance(*q));
                }
            }
        }
        // The quad pushes out by a skin of 1e-5 × its diagonal (≈ 1.1e-4).
        assert!(worst < 5e-4, "subdivide {subdivide:?}: {worst}");
    }
}

#[test]
fn a_walk_onto_a_box_collider_never_enters_it() {
    // A platform the walk's feet plant on (top y = 0); a scene object named as collider.
    let walk = legged::gait(32, 0.1, 0.25);
    let (min, max) = (Vec3::new(-2.0, -0.6, -1.0), Vec3::new(6.0, 0.0, 1.0));
    let platform = split_box("Platform", min, max);
    let frames = walk.frame_count();
    let still: Vec<Vec3> = (0..frames)
        .flat_map(|_| platform.positions.iter().copied())
        .collect();
    let mut scene = SampledScene::from_animation(walk.clone());
    let mut object = scene.objects[0].clone();
    object.name = "Platform".into();
    object.animation = MeshAnimation::new(platform, walk.fps, still).unwrap();
    scene.objects.push(object);
    let options = PrepareOptions {
        colliders: vec!["Platform".into()],
        ..PrepareOptions::default()
    };
    let with_box = prepare(scene, &options).unwrap();
    assert_eq!(with_box.object_count(), 1, "the collider is not smeared");
    assert_eq!(with_box.colliders().len(), 1);
    let plain = prepared(&walk, |_| {});
    for subdivide in [None, Some(2.0)] {
        let style = Style {
            subdivide,
            ..walk_style(&plain)
        };
        let free = stylize(&plain, &style).unwrap();
        assert!(inside_box(&free, min, max) > 0, "nothing entered the box");
        let out = stylize(&with_box, &style).unwrap();
        assert_eq!(inside_box(&out, min, max), 0, "subdivide {subdivide:?}");
        let e = out.report.objects[0].elongation_max.unwrap();
        assert!(e > 0.1, "the smear is still there: {e}");
    }
    // An unknown collider name is one error naming the objects.
    let err = prepare(
        SampledScene::from_animation(walk),
        &PrepareOptions {
            colliders: vec!["Ramp".into()],
            ..PrepareOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("'Ramp'") && err.contains("critter"), "{err}");
}

#[test]
fn the_stream_keeps_out_of_a_moving_collider_like_the_causal_mode() {
    // A platform the walk's feet plant on, rising through them: frame f of the stream must
    // meet the platform's frame f although the stream keeps only its last few frames.
    let walk = legged::gait(32, 0.1, 0.25);
    let (min, max) = (Vec3::new(-2.0, -0.6, -1.0), Vec3::new(6.0, 0.0, 1.0));
    let platform = split_box("Platform", min, max);
    let slide = |f: usize| Vec3::Y * (0.02 * f as f32);
    let moving: Vec<Vec3> = (0..walk.frame_count())
        .flat_map(|f| platform.positions.iter().map(move |p| *p + slide(f)))
        .collect();
    let collider =
        Collider::from_animation(&MeshAnimation::new(platform, walk.fps, moving).unwrap());
    let mut offline = prepared(&walk, |o| o.offsets.causal = true);
    offline.add_collider(collider.clone());
    let expected = stylize(&offline, &elongation(&offline, 2.0)).unwrap();
    let body = expected.animation(0).unwrap();
    let options = StreamOptions {
        elongate: FunctionSpec::linear(2.0),
        ..StreamOptions::default()
    };
    let mut free = Stream::new(&walk.mesh, &options).unwrap();
    let mut stream = Stream::new(&walk.mesh, &options).unwrap();
    stream.add_collider(collider);
    let inside = |f: usize, p: &Vec3| {
        let (lo, hi) = (min + slide(f) + 1e-6, max + slide(f) - 1e-6);
        p.cmpgt(lo).all() && p.cmplt(hi).all()
    };
    let (mut entered, mut worst) = (0usize, 0.0f32);
    for f in 0..walk.frame_count() {
        entered += free
            .push(walk.frame(f))
            .unwrap()
            .iter()
            .filter(|p| inside(f, p))
            .count();
        let out = stream.push(walk.frame(f)).unwrap();
        assert_eq!(out.iter().filter(|p| inside(f, p)).count(), 0, "frame {f}");
        for (s, o) in out.iter().zip(body.frame(f)) {
            worst = worst.max(s.distance(*o));
        }
    }
    assert!(
        entered > 0,
        "nothing entered the platform without the collider"
    );
    assert!(
        worst < 1e-4,
        "the stream differs from the causal mode by {worst}"
    );
}
