//! How faithfully a smeared frame's surface follows the ideal smear (SMEAR §4.1): every point
//! of the input surface, not only its vertices, is displaced along its own trajectory by its
//! own offset. Ideal points are sampled on the input's triangles — a sample at barycentric
//! weights `w` has the interpolated offset `β = Σ wᵢ βᵢ` and the trajectory `Σ wᵢ Qᵢ` (SPEC's
//! Catmull-Rom is linear in its control points) — and measured against the output surface
//! (distance to its nearest triangle).

use glam::Vec3;
use rayon::prelude::*;
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
/// of the triangles' boxes (about one triangle per cell; rings of cells searched outward
/// until none can be nearer).
pub(crate) fn surface_distances(
    points: &[Vec3],
    positions: &[Vec3],
    tris: &[[u32; 3]],
) -> Vec<f32> {
    use glam::IVec3;
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in positions.iter().chain(points) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let span = (hi - lo).max(Vec3::splat(1e-6));
    // Cubic cells of about one triangle each, at most 96 along an axis.
    let volume = span.x * span.y * span.z;
    let size = (volume / tris.len().max(1) as f32)
        .cbrt()
        .max(span.max_element() / 96.0);
    let dims = (span / size).ceil().as_ivec3().max(IVec3::ONE);
    let cell = |p: Vec3| {
        ((p - lo) / size)
            .floor()
            .as_ivec3()
            .clamp(IVec3::ZERO, dims - 1)
    };
    let index = |c: IVec3| ((c.x * dims.y + c.y) * dims.z + c.z) as usize;
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); (dims.x * dims.y * dims.z) as usize];
    for (k, t) in tris.iter().enumerate() {
        let v = t.map(|i| positions[i as usize]);
        let (a, b) = (
            cell(v[0].min(v[1]).min(v[2])),
            cell(v[0].max(v[1]).max(v[2])),
        );
        for x in a.x..=b.x {
            for y in a.y..=b.y {
                for z in a.z..=b.z {
                    grid[index(IVec3::new(x, y, z))].push(k as u32);
                }
            }
        }
    }
    let rings = dims.max_element();
    points
        .par_iter()
        .map(|&p| {
            let c = cell(p);
            // Distance from p to the sides of its own cell: a triangle outside ring r − 1 is
            // at least (r − 1)·size + margin away.
            let corner = lo + c.as_vec3() * size;
            let margin = (p - corner)
                .min(corner + Vec3::splat(size) - p)
                .min_element()
                .max(0.0);
            let mut best = f32::INFINITY;
            for r in 0..rings {
                if r > 0 && best <= (r - 1) as f32 * size + margin {
                    break;
                }
                for x in c.x - r..=c.x + r {
                    for y in c.y - r..=c.y + r {
                        for z in c.z - r..=c.z + r {
                            let u = IVec3::new(x, y, z);
                            let on_ring = (u - c).abs().max_element() == r;
                            let inside = u.cmpge(IVec3::ZERO).all() && u.cmplt(dims).all();
                            if !on_ring || !inside {
                                continue;
                            }
                            for &k in &grid[index(u)] {
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
