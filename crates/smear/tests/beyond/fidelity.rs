//! How faithfully a smeared frame's surface follows the ideal smear (SMEAR §4.1): every point
//! of the input surface, not only its vertices, is displaced along its own trajectory by its
//! own offset. Ideal points are sampled on the input's triangles — a sample at barycentric
//! weights `w` has the interpolated offset `β = Σ wᵢ βᵢ` and the trajectory `Σ wᵢ Qᵢ` (SPEC's
//! Catmull-Rom is linear in its control points) — and measured against the output surface
//! (distance to its nearest triangle).

use glam::Vec3;
use smear::Trajectories;

/// Samples per input triangle: the points of a barycentric lattice of `LATTICE` steps
/// inside it (corners excluded, edges included).
const LATTICE: usize = 8;

/// The ideal smeared points of frame `h`: each input triangle's lattice points, displaced by
/// their own interpolated `beta` along their own trajectory.
pub(crate) fn ideal_points(
    tr: &Trajectories<'_>,
    tris: &[[u32; 3]],
    h: usize,
    beta: &[f32],
) -> Vec<Vec3> {
    let mut out = Vec::new();
    for t in tris {
        for i in 0..=LATTICE {
            for j in 0..=LATTICE - i {
                let k = LATTICE - i - j;
                if i == LATTICE || j == LATTICE || k == LATTICE {
                    continue;
                }
                let w = [i, j, k].map(|x| x as f32 / LATTICE as f32);
                let b: f32 = (0..3).map(|c| w[c] * beta[t[c] as usize]).sum();
                let p: Vec3 = (0..3)
                    .map(|c| tr.seen_from(h, t[c] as usize, h as f32 + b) * w[c])
                    .sum();
                out.push(p);
            }
        }
    }
    out
}

/// Distance from `p` to the triangle `a b c`.
pub(crate) fn point_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let segment = |a: Vec3, b: Vec3| {
        let ab = b - a;
        let s = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
        p.distance(a + ab * s)
    };
    let n = (b - a).cross(c - a);
    if n.length_squared() > 1e-12 {
        let n = n.normalize();
        let q = p - n * (p - a).dot(n);
        let inside = [(a, b), (b, c), (c, a)]
            .iter()
            .all(|(u, v)| (*v - *u).cross(q - *u).dot(n) >= 0.0);
        if inside {
            return (p - q).length();
        }
    }
    segment(a, b).min(segment(b, c)).min(segment(c, a))
}

/// Distances from every point to the nearest triangle of a surface, through a uniform grid
/// of the triangles' boxes (rings of cells searched outward until none can be nearer).
pub(crate) fn surface_distances(
    points: &[Vec3],
    positions: &[Vec3],
    tris: &[[u32; 3]],
) -> Vec<f32> {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in positions.iter().chain(points) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let cells = ((tris.len() as f32).cbrt().ceil() as usize).clamp(1, 64);
    let size = ((hi - lo).max_element() / cells as f32).max(1e-6);
    let cell = |p: Vec3| {
        ((p - lo) / size)
            .floor()
            .as_ivec3()
            .clamp(glam::IVec3::ZERO, glam::IVec3::splat(cells as i32 - 1))
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); cells * cells * cells];
    let index = |c: glam::IVec3| (c.x as usize * cells + c.y as usize) * cells + c.z as usize;
    for (k, t) in tris.iter().enumerate() {
        let v = t.map(|i| positions[i as usize]);
        let (a, b) = (
            cell(v[0].min(v[1]).min(v[2])),
            cell(v[0].max(v[1]).max(v[2])),
        );
        for x in a.x..=b.x {
            for y in a.y..=b.y {
                for z in a.z..=b.z {
                    grid[index(glam::IVec3::new(x, y, z))].push(k as u32);
                }
            }
        }
    }
    points
        .iter()
        .map(|&p| {
            let c = cell(p);
            let mut best = f32::INFINITY;
            for r in 0..cells as i32 {
                // Every triangle within distance r·size of p touches a cell of ring ≤ r.
                if best <= r as f32 * size - size {
                    break;
                }
                for x in c.x - r..=c.x + r {
                    for y in c.y - r..=c.y + r {
                        for z in c.z - r..=c.z + r {
                            let on_ring =
                                (x - c.x).abs().max((y - c.y).abs()).max((z - c.z).abs()) == r;
                            let inside = [x, y, z].iter().all(|&u| u >= 0 && u < cells as i32);
                            if !on_ring || !inside {
                                continue;
                            }
                            for &k in &grid[index(glam::IVec3::new(x, y, z))] {
                                let [a, b, d] = tris[k as usize].map(|i| positions[i as usize]);
                                best = best.min(point_triangle(p, a, b, d));
                            }
                        }
                    }
                }
            }
            best
        })
        .collect()
}

/// The `q`-quantile (0 … 1) of some values.
pub(crate) fn quantile(values: &mut [f32], q: f32) -> f32 {
    values.sort_by(f32::total_cmp);
    let k = ((values.len() as f32 - 1.0) * q).round() as usize;
    values.get(k).copied().unwrap_or(0.0)
}
