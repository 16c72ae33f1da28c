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
