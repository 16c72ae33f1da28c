//! `--subdivide`: acceptance of issue #22 on a low-poly run cycle.

use std::collections::HashMap;

use anim::FlipbookPart;
use glam::Vec3;
use smear::{stylize, subdivide_frame, Style, Trajectories};

use super::{elongation, fidelity, legged, prepared, swing};

/// Largest ratio of an edge's length in `output` to its length in `input`.
fn edge_ratio_max(input: &[glam::Vec3], output: &[glam::Vec3], tris: &[[u32; 3]]) -> f32 {
    let mut worst = 0.0f32;
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let rest = input[a].distance(input[b]);
            worst = worst.max(output[a].distance(output[b]) / rest);
        }
    }
    worst
}

#[test]
fn subdivide_2_keeps_every_edge_within_twice_its_rest_length() {
    let run = legged::gait(24, 0.35, 0.3);
    let p = prepared(&run, |_| {});
    let style = elongation(&p, 3.0);
    // Without subdivision the legs and body stretch into shards (edges > 2× their rest length).
    let plain = stylize(&p, &style).unwrap();
    let body = plain.animation(0).unwrap();
    let shards = (0..run.frame_count())
        .map(|f| edge_ratio_max(run.frame(f), body.frame(f), &run.mesh.triangles))
        .fold(0.0f32, f32::max);
    assert!(
        shards > 2.5,
        "the run does not stretch: worst ratio {shards}"
    );

    let sub = stylize(
        &p,
        &Style {
            subdivide: Some(2.0),
            ..style
        },
    )
    .unwrap();
    let stats = &sub.report.objects[0];
    let stretch = stats.subdivision_max_stretch.unwrap();
    assert!(stretch <= 2.0, "max stretch {stretch}");
    let FlipbookPart::Frames { meshes, .. } = &sub.flipbook.parts[0] else {
        panic!("a subdivided body has one mesh per frame");
    };
    assert_eq!(meshes.len(), run.frame_count());
    let n = run.vertex_count();
    let mut grew = false;
    for (f, m) in meshes.iter().enumerate() {
        // The input vertices keep their elongated places; new ones come after them.
        assert_eq!(&m.positions[..n], body.frame(f), "frame {f}");
        grew |= m.triangle_count() > run.mesh.triangle_count();
        // Independent bound: no output edge is longer than twice the longest input edge.
        let longest_in = run
            .mesh
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
            .map(|(a, b)| run.frame(f)[a].distance(run.frame(f)[b]))
            .fold(0.0, f32::max);
        // Crack-free: every edge of the closed input stays shared by exactly two triangles,
        // in opposite directions.
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let l = m.positions[a as usize].distance(m.positions[b as usize]);
                assert!(
                    l <= 2.0 * longest_in + 1e-5,
                    "frame {f}: edge {l} vs {longest_in}"
                );
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        assert!(
            edges.values().all(|&v| v == 0),
            "frame {f}: a crack or a flipped triangle"
        );
    }
    assert!(grew, "nothing was subdivided");
}

/// Distance from `p` to the nearest triangle of `mesh`.
fn point_mesh(p: Vec3, positions: &[Vec3], tris: &[[u32; 3]]) -> f32 {
    tris.iter()
        .map(|t| t.map(|v| positions[v as usize]))
        .map(|[a, b, c]| fidelity::point_triangle(p, a, b, c))
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn subdivision_follows_the_arc_of_a_swinging_leg() {
    // A low-poly animal whose legs and tail swing through arcs, smeared with β painted along
    // each limb (0 at its root, 3 frames at its tip): the smear of a limb edge is the curve
    // u ↦ S(u), the surface point at u along the edge taken at time h + β(u). The limbs are
    // rigid, so their edges barely stretch (the stretch test alone splits nothing), yet the
    // straight edges cut across the arc.
    let frames = 24;
    let run = swing::run(frames);
    let tr = Trajectories::of_animation(&run);
    let n = run.vertex_count();
    let beta: Vec<f32> = (0..n)
        .map(|v| if swing::is_tip(v) { 3.0 } else { 0.0 })
        .collect();
    let tris = &run.mesh.triangles;
    let (mut plain_worst, mut sub_worst, mut stretch) = (0.0f32, 0.0f32, 0.0f32);
    for h in 2..frames - 5 {
        let plain: Vec<Vec3> = (0..n).map(|v| tr.displaced(h, v, beta[v])).collect();
        let (sub, stats) = subdivide_frame(&tr, &run.mesh, h, &beta, None, 2.0);
        stretch = stretch.max(stats.max_stretch);
        assert_eq!(&sub.positions[..n], plain.as_slice(), "frame {h}");
        assert!(
            closed(&sub.triangles),
            "frame {h}: a crack or a flipped triangle"
        );
        // The true smear of every edge whose ends have different β, densely sampled.
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                if a > b || beta[a] == beta[b] {
                    continue;
                }
                for s in 0..=32 {
                    let u = s as f32 / 32.0;
                    let p = swing::pose(h as f32 + (1.0 - u) * beta[a] + u * beta[b]).0;
                    let truth = p[a] * (1.0 - u) + p[b] * u;
                    plain_worst = plain_worst.max(point_mesh(truth, &plain, tris));
                    sub_worst = sub_worst.max(point_mesh(truth, &sub.positions, &sub.triangles));
                }
            }
        }
    }
    assert!(stretch <= 2.0, "max stretch {stretch}");
    assert!(
        plain_worst > 0.1 * swing::LEG,
        "the straight edges should cut the arcs: {plain_worst}"
    );
    assert!(
        sub_worst <= 0.5 * plain_worst,
        "subdivided {sub_worst} vs straight {plain_worst} from the dense-sampled arcs"
    );
}

/// Whether every edge is shared by exactly two triangles in opposite directions.
fn closed(tris: &[[u32; 3]]) -> bool {
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
        }
    }
    edges.values().all(|&v| v == 0)
}

/// The p99 distance from the ideal smear to the output surface, as a fraction of the
/// first frame's bounding-box diagonal (the character's size), without and with `--subdivide tolerance`, over the frames
/// `every`-th frames, at β = β_max·δ (the linear preset); and the output's largest vertex
/// count.
pub(crate) fn p99_surface_errors(
    run: &anim::MeshAnimation,
    beta_max: f32,
    tolerance: f32,
    every: usize,
) -> (f32, f32, usize) {
    let p = prepared(run, |_| {});
    let style = elongation(&p, beta_max);
    let plain = stylize(&p, &style).unwrap();
    let body = plain.animation(0).unwrap();
    let sub = stylize(
        &p,
        &Style {
            subdivide: Some(tolerance),
            ..style
        },
    )
    .unwrap();
    let FlipbookPart::Frames { meshes, .. } = &sub.flipbook.parts[0] else {
        panic!("a subdivided body has one mesh per frame");
    };
    let tr = Trajectories::of_animation(run);
    let tris = &run.mesh.triangles;
    let diagonal = anim::Aabb::from_points(run.frame(0)).diagonal();
    let (mut plain_err, mut sub_err, mut most) = (Vec::new(), Vec::new(), 0);
    for h in (0..run.frame_count()).step_by(every) {
        let beta: Vec<f32> = p.offsets(0).frame(h).iter().map(|d| beta_max * d).collect();
        // The ideal at the vertices is exactly the plain output: the same β, trajectories.
        for (v, q) in body.frame(h).iter().enumerate() {
            let ideal = tr.displaced(h, v, beta[v]);
            assert!(
                ideal.distance(*q) <= 1e-4 * diagonal,
                "frame {h} vertex {v}"
            );
        }
        let ideal = fidelity::ideal_points(&tr, tris, h, &beta);
        plain_err.extend(fidelity::surface_distances(&ideal, body.frame(h), tris));
        let m = &meshes[h];
        sub_err.extend(fidelity::surface_distances(
            &ideal,
            &m.positions,
            &m.triangles,
        ));
        most = most.max(m.vertex_count());
    }
    let q = |e: &mut Vec<f32>| fidelity::quantile(e, 0.99) / diagonal;
    (q(&mut plain_err), q(&mut sub_err), most)
}

#[test]
fn subdivide_2_halves_the_p99_surface_error_of_low_poly_characters() {
    let characters = [
        ("run cycle", legged::gait(24, 0.35, 0.3)),
        ("swinging limbs", swing::run(24)),
    ];
    for (name, run) in characters {
        let (plain, sub, vertices) = p99_surface_errors(&run, 3.0, 2.0, 1);
        eprintln!(
            "{name}: p99 {plain:.2e} → {sub:.2e} of the diagonal ({:.2}×), {} → {vertices} vertices",
            plain / sub,
            run.vertex_count()
        );
        assert!(plain > 0.0, "{name}: the smear is flat");
        assert!(
            sub <= 0.5 * plain,
            "{name}: p99 {sub} vs {plain} without subdivision"
        );
    }
}
