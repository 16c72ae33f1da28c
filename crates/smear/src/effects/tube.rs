//! Tubes swept along polylines: the geometry of motion lines (Section 4.3, "thin tubular
//! meshes").

use anim::Mesh;
use glam::{Quat, Vec3};

/// One polyline sample: centre, radius and RGBA colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ring {
    pub center: Vec3,
    pub radius: f32,
    pub color: [f32; 4],
}

/// Any unit vector orthogonal to unit `t`.
fn orthogonal(t: Vec3) -> Vec3 {
    let a = if t.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    t.cross(a).normalize()
}

/// Appends a tube of `sides` sides through `rings` to `mesh` (positions, triangles and
/// colours), with rotation-minimizing frames (parallel transport) so it does not twist, closed
/// by a flat cap at each end (a fan around one centre vertex with the ring's colour) so the
/// tube is a closed, outward-oriented surface. Consecutive rings must be distinct; fewer than
/// 2 rings or fewer than 3 sides append nothing. Returns whether anything was appended.
pub(crate) fn sweep(rings: &[Ring], sides: usize, mesh: &mut Mesh) -> bool {
    if rings.len() < 2 || sides < 3 {
        return false;
    }
    let colors = mesh.colors.get_or_insert_with(Vec::new);
    let base = mesh.positions.len() as u32;
    let tangent = |j: usize| {
        let a = rings[j.saturating_sub(1)].center;
        let b = rings[(j + 1).min(rings.len() - 1)].center;
        (b - a).normalize_or_zero()
    };
    let mut t = tangent(0);
    if t == Vec3::ZERO {
        return false;
    }
    let mut normal = orthogonal(t);
    for (j, r) in rings.iter().enumerate() {
        let tj = tangent(j);
        if tj != Vec3::ZERO {
            normal = Quat::from_rotation_arc(t, tj) * normal;
            normal = (normal - tj * normal.dot(tj)).normalize_or(orthogonal(tj));
            t = tj;
        }
        let binormal = t.cross(normal);
        for k in 0..sides {
            let th = std::f32::consts::TAU * k as f32 / sides as f32;
            let radius = if r.radius.is_finite() {
                r.radius.max(0.0)
            } else {
                0.0
            };
            mesh.positions
                .push(r.center + radius * (th.cos() * normal + th.sin() * binormal));
            colors.push(r.color);
        }
    }
    let s = sides as u32;
    let last = rings.len() as u32 - 1;
    for j in 0..last {
        for k in 0..s {
            let a = base + j * s + k;
            let b = base + j * s + (k + 1) % s;
            let (c, d) = (a + s, b + s);
            mesh.triangles.push([a, b, c]);
            mesh.triangles.push([c, b, d]);
        }
    }
    // Caps: the start one faces back along the tangent, the end one forward.
    for (j, flip) in [(0, true), (last, false)] {
        let r = &rings[j as usize];
        let centre = mesh.positions.len() as u32;
        mesh.positions.push(r.center);
        colors.push(r.color);
        for k in 0..s {
            let a = base + j * s + k;
            let b = base + j * s + (k + 1) % s;
            mesh.triangles
                .push(if flip { [centre, b, a] } else { [centre, a, b] });
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tube_has_rings_of_constant_radius_around_the_curve() {
        let rings: Vec<Ring> = (0..10)
            .map(|j| {
                let a = j as f32 * 0.3;
                Ring {
                    center: Vec3::new(a.cos(), a.sin(), 0.1 * a) * 2.0,
                    radius: 0.05,
                    color: [1.0, 1.0, 1.0, 0.5],
                }
            })
            .collect();
        let mut mesh = Mesh::new("lines", Vec::new(), Vec::new());
        assert!(sweep(&rings, 6, &mut mesh));
        assert_eq!(mesh.positions.len(), 62);
        assert_eq!(mesh.triangles.len(), 9 * 6 * 2 + 2 * 6);
        assert_eq!(mesh.colors.as_ref().unwrap().len(), 62);
        // Closed and consistently oriented: every directed edge appears once and its reverse
        // once; the enclosed volume is positive (outward normals).
        let mut edges = std::collections::HashMap::new();
        for t in &mesh.triangles {
            for e in 0..3 {
                *edges.entry((t[e], t[(e + 1) % 3])).or_insert(0) += 1;
            }
        }
        assert!(edges
            .iter()
            .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1)));
        let volume: f32 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!(volume > 0.0, "volume {volume}");
        for (j, r) in rings.iter().enumerate() {
            for k in 0..6 {
                let d = (mesh.positions[j * 6 + k] - r.center).length();
                assert!((d - 0.05).abs() < 1e-5, "ring {j} vertex {k}: {d}");
            }
        }
        mesh.validate().unwrap();
        // A second tube is appended after the first.
        assert!(sweep(&rings[..2], 4, &mut mesh));
        assert_eq!(mesh.positions.len(), 62 + 10);
        assert!(!sweep(&rings[..1], 6, &mut mesh));
    }
}
