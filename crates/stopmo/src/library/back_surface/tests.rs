//! Unit tests of the shared back surface.

use super::*;

/// A 1 mm grid over a 20 × 20 mm saddle: corners where the boundary turns sharply.
fn saddle() -> (Mesh, Vec<Vec3>) {
    let k = 21;
    let positions: Vec<Vec3> = (0..k * k)
        .map(|i| {
            let (x, y) = ((i % k) as f32 - 10.0, (i / k) as f32 - 10.0);
            Vec3::new(x, y, 0.03 * (x * x - y * y))
        })
        .collect();
    let mut tris = Vec::new();
    for r in 0..k - 1 {
        for c in 0..k - 1 {
            let v = (r * k + c) as u32;
            let (right, up) = (v + 1, v + k as u32);
            tris.push([v, right, up + 1]);
            tris.push([v, up + 1, up]);
        }
    }
    (Mesh::new("saddle", positions.clone(), tris), positions)
}

#[test]
fn wall_rungs_lean_no_more_than_the_rung_slope_at_sharp_boundary_corners() {
    let (mesh, avg) = saddle();
    let lifted: Vec<Vec3> = avg.iter().map(|p| *p + Vec3::Z * 0.2).collect();
    let shell =
        PartShell::new(&mesh, &avg, &[&avg, &lifted], &ShellOptions::default()).expect("shell");
    let mut worst = 0.0f32;
    for &(a, _) in shell.boundary_edges() {
        let v = a as usize;
        let (d, e) = (
            shell.direction(v),
            shell.back()[v] - avg[shell.sources()[v] as usize],
        );
        let depth = -e.dot(d);
        assert!(depth > 0.0, "vertex {v}: back in front of the front");
        worst = worst.max((e + d * depth).length() / depth);
    }
    assert!(
        worst <= RUNG_SLOPE + 1e-3,
        "a rung leans {worst} mm per mm of depth"
    );
    assert_eq!(shell.stats.self_intersecting_triangles, 0);
    assert!(shell.stats.min_wall_mm >= ShellOptions::default().wall_mm * 0.99);
}

#[test]
fn a_piece_of_the_part_is_untangled_once_and_another_on_demand() {
    // The fronts are untangled when the part is laid out; `front` finds a piece's there
    // and must give exactly what untangling it again would.
    let (mesh, avg) = saddle();
    // Two different pieces: the saddle and one row of it pushed 2.5 mm sideways and down
    // (a lookup that returned the other piece's front would differ).
    let folded: Vec<Vec3> = avg
        .iter()
        .map(|p| {
            if p.y == 0.0 && p.x.abs() < 6.0 {
                *p + Vec3::new(0.0, 2.5, -0.6)
            } else {
                *p
            }
        })
        .collect();
    let shell =
        PartShell::new(&mesh, &avg, &[&avg, &folded], &ShellOptions::default()).expect("shell");
    let untangled_again = |piece: &[Vec3]| {
        let mut f = front_positions(&shell.source, &shell.caps, piece);
        untangle::untangle(
            &mut f,
            &shell.triangles,
            &shell.adjacency,
            &shell.on_boundary,
            shell.untangle_step_mm,
        );
        f.iter()
            .zip(&shell.nudge)
            .map(|(p, d)| *p + *d)
            .collect::<Vec<_>>()
    };
    let laid = |piece: &[Vec3]| front_positions(&shell.source, &shell.caps, piece);
    for piece in [&avg, &folded] {
        assert!(shell.fronts.find(&laid(piece)).is_some(), "not cached");
        assert_eq!(shell.front(piece), untangled_again(piece));
    }
    // A piece the part was not built with is untangled when it is asked for.
    let other: Vec<Vec3> = folded.iter().map(|p| *p + Vec3::Z * 0.01).collect();
    assert!(shell.fronts.find(&laid(&other)).is_none());
    assert_eq!(shell.front(&other), untangled_again(&other));
}

/// The crossings as the exact test finds them in each piece's whole solid: the shell
/// vertices of the crossing triangles and how many cross, summed over the pieces.
fn crossings_of_whole_solids(shell: &PartShell, pieces: &[&[Vec3]]) -> (Vec<u32>, usize) {
    let n = shell.back.len() as u32;
    let (mut vertices, mut count) = (Vec::new(), 0);
    for piece in pieces {
        let solid = shell.solid_unchecked(piece, "piece");
        let hits = crate::library::self_intersecting_triangles(&solid.positions, &solid.triangles)
            .expect("coordinates in range");
        count += hits.len();
        vertices.extend(
            hits.iter()
                .flat_map(|&t| solid.triangles[t as usize].map(|v| v % n)),
        );
    }
    vertices.sort_unstable();
    vertices.dedup();
    (vertices, count)
}

#[test]
fn crossings_with_the_fronts_found_once_are_those_of_the_whole_solids() {
    // Three pieces of the saddle (two agree on most vertices, one lifted everywhere), then a
    // back pushed through the front in a patch and a piece the shell was not built with:
    // the split test (front pairs found once, back pairs each time) must count exactly
    // what testing every solid whole counts.
    let (mesh, avg) = saddle();
    let lifted: Vec<Vec3> = avg.iter().map(|p| *p + Vec3::Z * 0.2).collect();
    let dented: Vec<Vec3> = avg
        .iter()
        .map(|p| {
            if p.x.abs() < 3.0 && p.y.abs() < 3.0 {
                *p - Vec3::Z * 0.3
            } else {
                *p
            }
        })
        .collect();
    let pieces: [&[Vec3]; 3] = [&avg, &lifted, &dented];
    let mut shell = PartShell::new(&mesh, &avg, &pieces, &ShellOptions::default()).expect("shell");
    assert_eq!(
        shell.crossings(&pieces),
        crossings_of_whole_solids(&shell, &pieces)
    );
    for v in 0..shell.back.len() {
        let p = shell.back[v];
        if p.x.abs() < 4.0 && p.y.abs() < 2.0 {
            shell.back[v] += shell.normals[v] * 4.0;
        }
    }
    let whole = crossings_of_whole_solids(&shell, &pieces);
    assert!(whole.1 > 0, "the pushed back crosses the front");
    assert_eq!(shell.crossings(&pieces), whole);
    for piece in pieces {
        let solid = shell.solid_unchecked(piece, "piece");
        let count = crate::library::self_intersecting_triangles(&solid.positions, &solid.triangles)
            .map(|t| t.len());
        assert_eq!(shell.solid_crossings(&solid), count);
    }
    let other: Vec<Vec3> = dented.iter().map(|p| *p + Vec3::Z * 0.01).collect();
    let others: [&[Vec3]; 2] = [&avg, &other];
    assert_eq!(
        shell.crossings(&others),
        crossings_of_whole_solids(&shell, &others)
    );
    let solid = shell.solid_unchecked(&other, "other");
    let count = crate::library::self_intersecting_triangles(&solid.positions, &solid.triangles)
        .map(|t| t.len());
    assert_eq!(shell.solid_crossings(&solid), count);
}
