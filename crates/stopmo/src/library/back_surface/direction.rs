//! The direction field the back surface is offset along: the front's normals averaged over a
//! geodesic disc measured in millimetres, not over a number of mesh edges. Diffusing the
//! normals over edge rings smoothed ~3× less on the lips (edges 0.35–0.39 mm on the ICT
//! face) than on the chin (1.17 mm), so where a part ends at a lip (a seam through the mouth
//! corners) the direction there still leaned with the lip's curl and the back folded behind
//! it (two automatic parts, 8 pieces, before the local search: 1,032 and 1,360 back/back
//! crossing pairs; 96 and 64 averaged over σ = 14 mm along the surface).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::{DMat4, DVec3, DVec4, Vec3};
use rayon::prelude::*;

use super::PartShell;

/// Radius of the disc averaged over, in Gaussian widths (its edge weighs e⁻²).
const DISC_SIGMAS: f32 = 2.0;

/// A vertex `u` reached at geodesic distance `g` as one min-heap key: `g`'s bits above `u`.
/// Distances are never negative, and the bits of non-negative floats order as the floats
/// do, so the keys pop in the order of `(g, u)` — one integer comparison per heap step.
fn reached(g: f32, u: u32) -> Reverse<u64> {
    Reverse((u64::from(g.to_bits()) << 32) | u64::from(u))
}

/// Spacing of the vertices whose geodesic discs are summed exactly, in Gaussian widths: the
/// disc average changes over σ, so sums a fraction of σ apart, blended, stand for the sums
/// at every vertex (ICT face, σ = 17.5 mm: 1.5 mm apart, ~1,000 of ~10,000 vertices).
const DISC_SAMPLE_SPACING_SIGMAS: f32 = 1.0 / 12.0;

/// Radius of the blend of sample sums at a vertex, in sample spacings: every vertex has a
/// sample within one spacing, so at least one weighs in.
const DISC_BLEND_SPACINGS: f32 = 2.0;

/// Ridge on the slope of the blend's linear fit, per squared blend radius: keeps the fit
/// defined across the surface's normal (the samples lie on a surface) and where few
/// samples weigh in.
const BLEND_RIDGE: f32 = 0.01;

/// Edges of `adj` in one array with their lengths over `front` (CSR: the edges of `u` are
/// `edges[start[u]..start[u + 1]]`), the same f32 values a search would compute per visit.
fn edge_lengths(front: &[Vec3], adj: &[Vec<u32>]) -> (Vec<usize>, Vec<(u32, f32)>) {
    let mut start = Vec::with_capacity(front.len() + 1);
    let mut edges: Vec<(u32, f32)> = Vec::new();
    start.push(0);
    for (u, around) in adj.iter().enumerate().take(front.len()) {
        edges.extend(
            around
                .iter()
                .map(|&w| (w, front[u].distance(front[w as usize]))),
        );
        start.push(edges.len());
    }
    (start, edges)
}

/// Bounded Dijkstra searches over one edge array, reusing their buffers between searches.
struct DiscSearch<'a> {
    start: &'a [usize],
    edges: &'a [(u32, f32)],
    dist: Vec<f32>,
    touched: Vec<u32>,
    heap: BinaryHeap<Reverse<u64>>,
}

impl<'a> DiscSearch<'a> {
    fn new(start: &'a [usize], edges: &'a [(u32, f32)]) -> Self {
        DiscSearch {
            start,
            edges,
            dist: vec![f32::INFINITY; start.len().saturating_sub(1)],
            touched: Vec::new(),
            heap: BinaryHeap::new(),
        }
    }

    /// Calls `visit(u, g)` for every vertex `u` within `radius` of `v` along edge paths, in
    /// the order of `(g, u)`.
    fn run(&mut self, v: usize, radius: f32, mut visit: impl FnMut(usize, f32)) {
        let (dist, touched, heap) = (&mut self.dist, &mut self.touched, &mut self.heap);
        dist[v] = 0.0;
        touched.push(v as u32);
        heap.push(reached(0.0, v as u32));
        while let Some(Reverse(key)) = heap.pop() {
            let (g, u) = (f32::from_bits((key >> 32) as u32), key as u32 as usize);
            if g > dist[u] {
                continue;
            }
            visit(u, g);
            for &(w, length) in &self.edges[self.start[u]..self.start[u + 1]] {
                let w = w as usize;
                let gw = g + length;
                if gw <= radius && gw < dist[w] {
                    if dist[w] == f32::INFINITY {
                        touched.push(w as u32);
                    }
                    dist[w] = gw;
                    heap.push(reached(gw, w as u32));
                }
            }
        }
        for &u in touched.iter() {
            dist[u as usize] = f32::INFINITY;
        }
        touched.clear();
    }
}

/// Unit outward direction at every vertex of `front` (triangles `tris`, vertex adjacency
/// `adj`): the area-weighted normals of the vertices within `DISC_SIGMAS × sigma` mm along
/// the surface (shortest edge paths), weighted by a Gaussian of width `sigma` mm of that
/// distance. `sigma` 0 gives the (area-weighted) vertex normals.
///
/// The disc sums are exact at *samples*, vertices about `DISC_SAMPLE_SPACING_SIGMAS × sigma`
/// apart along the surface (greedily in vertex order: a vertex farther than that from every
/// earlier sample is one); every vertex fits a linear field to the sums of the samples within
/// `DISC_BLEND_SPACINGS` spacings (least squares weighted `(1 − (g/r)²)²`) and takes its
/// value at the vertex, normalized. On the ICT face at
/// σ = 17.5 mm this differs from the sum at every vertex by 0.18° on average, 1.8° at worst
/// (README, "What printing costs").
///
/// # Performance
/// One bounded Dijkstra search per sample (parallel) and a short one per sample for the
/// blend: ~10× fewer disc searches than one per vertex on the ICT face.
pub(super) fn smoothed_directions(
    front: &[Vec3],
    tris: &[[u32; 3]],
    adj: &[Vec<u32>],
    sigma: f32,
) -> Vec<Vec3> {
    let n = front.len();
    let area_normals = anim::area_normals(front, tris);
    let own = |v: usize| area_normals[v].try_normalize().unwrap_or(Vec3::Z);
    if !(sigma.is_finite() && sigma > 0.0) {
        return (0..n).map(own).collect();
    }
    let radius = DISC_SIGMAS * sigma;
    let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
    let (start, edges) = edge_lengths(front, adj);
    // Samples, and for every vertex the samples within the blend radius (index, distance).
    let spacing = DISC_SAMPLE_SPACING_SIGMAS * sigma;
    let blend = DISC_BLEND_SPACINGS * spacing;
    let mut search = DiscSearch::new(&start, &edges);
    let mut cover = vec![f32::INFINITY; n];
    let mut near: Vec<Vec<(u32, f32)>> = vec![Vec::new(); n];
    let mut samples: Vec<usize> = Vec::new();
    for v in 0..n {
        if cover[v] <= spacing {
            continue;
        }
        let s = samples.len() as u32;
        samples.push(v);
        search.run(v, blend, |u, g| {
            cover[u] = cover[u].min(g);
            near[u].push((s, g));
        });
    }
    let sums: Vec<Vec3> = samples
        .par_iter()
        .map_init(
            || DiscSearch::new(&start, &edges),
            |search, &v| {
                let mut sum = Vec3::ZERO;
                search.run(v, radius, |u, g| {
                    sum += area_normals[u] * (-g * g * inv_two_sigma2).exp();
                });
                sum
            },
        )
        .collect();
    let inv_blend2 = 1.0 / (blend * blend);
    let ridge = f64::from(BLEND_RIDGE * blend * blend);
    let out: Vec<Vec3> = (0..n)
        .into_par_iter()
        .map(|v| {
            // Weighted least squares of a linear field through the samples' sums, taken at
            // the vertex: a plain weighted mean would lean towards where the samples lie.
            let at = front[v].as_dvec3();
            let (mut a, mut b) = (DMat4::ZERO, [DVec3::ZERO; 4]);
            for &(s, g) in &near[v] {
                let t = 1.0 - g * g * inv_blend2;
                let w = f64::from(t * t);
                let d = front[samples[s as usize]].as_dvec3() - at;
                let x = DVec4::new(1.0, d.x, d.y, d.z);
                a += DMat4::from_cols(x * (w * x.x), x * (w * x.y), x * (w * x.z), x * (w * x.w));
                let sum = sums[s as usize].as_dvec3() * w;
                for k in 0..4 {
                    b[k] += sum * x[k];
                }
            }
            let weight = a.x_axis.x;
            for k in 1..4 {
                a.col_mut(k)[k] += ridge * weight;
            }
            let row =
                if a.determinant().abs() > f64::EPSILON * weight.powi(4).max(f64::MIN_POSITIVE) {
                    a.inverse().x_axis
                } else {
                    DVec4::new(1.0 / weight.max(f64::MIN_POSITIVE), 0.0, 0.0, 0.0)
                };
            let sum = (0..4).fold(DVec3::ZERO, |acc, k| acc + b[k] * row[k]);
            sum.as_vec3().try_normalize().unwrap_or_else(|| own(v))
        })
        .collect();
    out
}

/// [`smoothed_directions`] with the disc summed at every vertex (no samples).
#[cfg(test)]
fn exact_directions(front: &[Vec3], tris: &[[u32; 3]], adj: &[Vec<u32>], sigma: f32) -> Vec<Vec3> {
    let area_normals = anim::area_normals(front, tris);
    let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
    let (start, edges) = edge_lengths(front, adj);
    (0..front.len())
        .into_par_iter()
        .map_init(
            || DiscSearch::new(&start, &edges),
            |search, v| {
                let mut sum = Vec3::ZERO;
                search.run(v, DISC_SIGMAS * sigma, |u, g| {
                    sum += area_normals[u] * (-g * g * inv_two_sigma2).exp();
                });
                sum.try_normalize()
                    .unwrap_or_else(|| area_normals[v].try_normalize().unwrap_or(Vec3::Z))
            },
        )
        .collect()
}

/// Unit outward direction at every vertex of `front`: the vertex normals diffused over
/// `(radius_mm / mean edge)²` edge rings (at most 4,000), each step the normalized sum of a
/// vertex's and its neighbours' directions ([`super::DirectionField::EdgeRings`]).
///
/// # Performance
/// O(steps × edges), each step parallel over vertices into a second buffer.
pub(super) fn edge_ring_directions(
    front: &[Vec3],
    tris: &[[u32; 3]],
    adj: &[Vec<u32>],
    radius_mm: f64,
) -> Vec<Vec3> {
    let n = front.len();
    let mean_edge = {
        let (s, c) = tris.iter().fold((0.0f64, 0usize), |(s, c), t| {
            let l = (0..3)
                .map(|k| front[t[k] as usize].distance(front[t[(k + 1) % 3] as usize]) as f64)
                .sum::<f64>();
            (s + l, c + 3)
        });
        (s / c.max(1) as f64).max(1e-9)
    };
    let steps = ((radius_mm / mean_edge).powi(2)).ceil() as usize;
    let steps = steps.min(4000);
    let mut normals = anim::vertex_normals(front, tris);
    // Two buffers swapped per step (up to 4,000 steps): no allocation in the loop.
    let mut next = vec![Vec3::ZERO; n];
    for _ in 0..steps {
        next.par_iter_mut().enumerate().for_each(|(v, out)| {
            let s = adj[v]
                .iter()
                .fold(normals[v], |acc, &w| acc + normals[w as usize]);
            *out = s.try_normalize().unwrap_or(normals[v]);
        });
        std::mem::swap(&mut normals, &mut next);
    }
    normals
}

/// Of two backs of one part ([`DirectionField::Best`]), the one with fewer crossing
/// triangles, then the one whose wall holds `wall_mm`; a tie keeps `rings` (the edge rings).
pub(super) fn better(rings: PartShell, disc: PartShell, wall_mm: f64) -> PartShell {
    let key = |s: &PartShell| {
        (
            s.stats.self_intersecting_triangles,
            s.stats.min_wall_mm < wall_mm - 1e-6,
        )
    };
    if key(&disc) < key(&rings) {
        disc
    } else {
        rings
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sheet `z = 0.05 x²` over `x ∈ [-10, 10]`, `y ∈ [-6, 6]`, meshed with columns
    /// 0.25 mm apart for `x < 0` and 1 mm apart for `x ≥ 0` (rows 1 mm apart).
    fn two_densities() -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<Vec<u32>>) {
        let mut xs: Vec<f32> = (0..40).map(|i| -10.0 + 0.25 * i as f32).collect();
        xs.extend((0..=10).map(|i| i as f32));
        let rows = 13;
        let cols = xs.len();
        let positions: Vec<Vec3> = (0..rows * cols)
            .map(|i| {
                let (x, y) = (xs[i % cols], (i / cols) as f32 - 6.0);
                Vec3::new(x, y, 0.05 * x * x)
            })
            .collect();
        let mut tris = Vec::new();
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let v = (r * cols + c) as u32;
                let (right, up) = (v + 1, v + cols as u32);
                tris.push([v, right, up + 1]);
                tris.push([v, up + 1, up]);
            }
        }
        let adj = super::super::topology::neighbours(positions.len(), &tris);
        (positions, tris, adj)
    }

    fn at(positions: &[Vec3], x: f32) -> usize {
        (0..positions.len())
            .min_by(|&a, &b| {
                let d = |v: usize| positions[v].distance(Vec3::new(x, 0.0, 0.05 * x * x));
                d(a).total_cmp(&d(b))
            })
            .unwrap_or(0)
    }

    #[test]
    fn the_sampled_disc_directions_follow_the_disc_at_every_vertex() {
        let (positions, tris, adj) = two_densities();
        // σ = 12 mm: samples 1 mm apart, fewer than the vertices on the fine side.
        let sampled = smoothed_directions(&positions, &tris, &adj, 12.0);
        let exact = exact_directions(&positions, &tris, &adj, 12.0);
        let worst = sampled
            .iter()
            .zip(&exact)
            .map(|(a, b)| a.dot(*b).clamp(-1.0, 1.0).acos().to_degrees())
            .fold(0.0f32, f32::max);
        assert!(worst < 0.5, "worst {worst} degrees");
    }

    #[test]
    fn the_directions_are_smoothed_over_millimetres_not_over_edges() {
        let (positions, tris, adj) = two_densities();
        let (fine, coarse) = (at(&positions, -4.0), at(&positions, 4.0));
        let smooth = smoothed_directions(&positions, &tris, &adj, 3.0);
        // Mirror images of each other on a mirror-symmetric surface, whatever the meshing.
        assert!(
            (smooth[fine].x + smooth[coarse].x).abs() < 0.02,
            "fine side {} vs coarse side {}",
            smooth[fine],
            smooth[coarse]
        );
        // Averaged over the whole sheet, by area: the fine side has four times the vertices
        // of the coarse one but the same area, so the mean direction does not lean to it.
        let whole = smoothed_directions(&positions, &tris, &adj, 100.0);
        for v in [fine, coarse] {
            assert!(whole[v].x.abs() < 0.01, "{}", whole[v]);
            assert!((whole[v].length() - 1.0).abs() < 1e-4);
        }
    }
}
