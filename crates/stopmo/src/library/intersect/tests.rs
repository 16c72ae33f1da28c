//! Tests of the exact intersection test.

use super::*;

fn count(p: &[Vec3], t: &[[u32; 3]]) -> usize {
    self_intersecting_triangles(p, t).unwrap().len()
}

#[test]
fn crossing_and_separate_triangles() {
    let p = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.2, 0.2, -1.0),
        Vec3::new(0.2, 0.2, 1.0),
        Vec3::new(0.3, 0.9, 1.0),
    ];
    assert_eq!(count(&p, &[[0, 1, 2], [3, 4, 5]]), 2);
    let far: Vec<Vec3> = p
        .iter()
        .enumerate()
        .map(|(i, v)| if i >= 3 { *v + Vec3::X * 5.0 } else { *v })
        .collect();
    assert_eq!(count(&far, &[[0, 1, 2], [3, 4, 5]]), 0);
}

#[test]
fn neighbours_only_count_when_they_fold_or_cross() {
    // A flat quad: two triangles sharing an edge, no intersection.
    let p = vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::Y,
        Vec3::new(0.8, 0.2, 0.0),
    ];
    assert_eq!(count(&p, &[[0, 1, 2], [0, 2, 3]]), 0);
    // Folded onto each other (same side of the shared edge, coplanar).
    assert_eq!(count(&p, &[[0, 1, 2], [0, 2, 4]]), 2);
    // Sharing one vertex, coplanar and overlapping.
    assert_eq!(count(&p, &[[0, 1, 2], [0, 4, 3]]), 2);
    // Sharing one vertex, not overlapping.
    let q = vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::X, -Vec3::Y];
    assert_eq!(count(&q, &[[0, 1, 2], [0, 3, 4]]), 0);
    // Sharing one vertex and piercing: the second triangle dips through the first.
    let r = vec![
        Vec3::ZERO,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(1.0, 0.5, -1.0),
        Vec3::new(0.5, 1.0, 1.0),
    ];
    assert_eq!(count(&r, &[[0, 1, 2], [0, 3, 4]]), 2);
}

/// A crumpled random sheet (many crossing and touching pairs): the pairs touching the
/// marked triangles plus the pairs among the unmarked ones are exactly all the pairs.
#[test]
fn marked_and_unmarked_pairs_make_up_all_pairs() {
    let mut rng = anim::SplitMix64::new(7, 0);
    let k = 12;
    let p: Vec<Vec3> = (0..k * k)
        .map(|i| {
            let (x, y) = ((i % k) as f32, (i / k) as f32);
            Vec3::new(
                x + 1.5 * rng.next_f32(),
                y + 1.5 * rng.next_f32(),
                4.0 * rng.next_f32(),
            )
        })
        .collect();
    let mut t = Vec::new();
    for r in 0..k - 1 {
        for c in 0..k - 1 {
            let v = (r * k + c) as u32;
            t.push([v, v + 1, v + k as u32 + 1]);
            t.push([v, v + k as u32 + 1, v + k as u32]);
        }
    }
    t.push([3, 3, 40]); // degenerate
    let all = intersecting_pairs(&p, &t).unwrap();
    assert!(all.len() > 20, "{} pairs", all.len());
    let varying: Vec<bool> = (0..t.len()).map(|i| i % 3 == 0 || i > 150).collect();
    let kinds: Vec<u8> = varying.iter().map(|&v| u8::from(v)).collect();
    let unmarked: Vec<u32> = (0..t.len() as u32)
        .filter(|&i| !varying[i as usize])
        .collect();
    let sub: Vec<[u32; 3]> = unmarked.iter().map(|&i| t[i as usize]).collect();
    let mut parts: Vec<(u32, u32)> = intersecting_pairs(&p, &sub)
        .unwrap()
        .into_iter()
        .map(|(i, j)| (unmarked[i as usize], unmarked[j as usize]))
        .chain(intersecting_pairs_touching(&p, &t, &kinds, 1).unwrap())
        .collect();
    parts.sort_unstable();
    parts.dedup();
    assert_eq!(parts, all);
    assert!(intersecting_pairs_touching(&p, &t, &kinds[1..], 1).is_none());
}

/// The `f64` filters never change a sign: random points, points nudged a grid step off a
/// plane or line (the cases the filter must hand to `i128`), at the largest coordinates the
/// test accepts; and snapping rounds like `f64::round`.
#[test]
fn filtered_predicates_give_the_exact_signs() {
    let mut rng = anim::SplitMix64::new(19, 0);
    let big = (f64::from(MAX_EXACT_COORDINATE) * GRID) as i64;
    let mut coord = |scale: i64| (rng.next_f32() as f64 * 2.0 - 1.0) as f32 * scale as f32;
    let mut exact_2d = 0;
    for i in 0..20_000 {
        let scale = [big, 1 << 20, 1000][i % 3];
        let mut pt = || [0; 3].map(|_| coord(scale) as i64);
        let (a, b, c) = (pt(), pt(), pt());
        // d on the plane of a b c (exactly when the weights divide), then nudged.
        let d = if i % 2 == 0 {
            let d = [0, 1, 2].map(|k| (a[k] + b[k]) / 2 + (c[k] - a[k]) / 4);
            [d[0] + (i as i64 % 3) - 1, d[1], d[2]]
        } else {
            pt()
        };
        let exact = orient3d_exact(a, b, c, d);
        assert_eq!(orient3d(a, b, c, d), exact, "{a:?} {b:?} {c:?} {d:?}");
        let q = |p: P| [i128::from(p[0]), i128::from(p[1])];
        // c on the line a b (when the halves are exact), nudged by -1, 0 or 1 step.
        let (qa, qb) = (q(a), q(b));
        let nudge = i128::from(i as i64 % 3 - 1);
        let qc = if i % 2 == 0 {
            [(qa[0] + qb[0]) / 2 + nudge, (qa[1] + qb[1]) / 2]
        } else {
            q(d)
        };
        let exact = orient2d_exact(qa, qb, qc);
        exact_2d += usize::from(exact == 0);
        assert_eq!(orient2d(qa, qb, qc), exact);
    }
    assert!(exact_2d > 0, "no collinear case was tried");
    for x in [
        0.5f32,
        -0.5,
        1.5,
        -2.5,
        1e-30,
        -1e-30,
        4095.9998,
        0.1,
        -0.3,
        1.0 / 3.0,
    ] {
        let v = Vec3::splat(x / GRID as f32);
        assert_eq!(snap(v)[0], (f64::from(v.x) * GRID).round() as i64, "{x}");
        let w = Vec3::splat(x);
        assert_eq!(snap(w)[0], (f64::from(w.x) * GRID).round() as i64, "{x}");
    }
}

#[test]
fn closed_box_is_clean() {
    let (p, t) = crate::library::test_shapes::cuboid(Vec3::ZERO, Vec3::ONE);
    assert_eq!(count(&p, &t), 0);
}
