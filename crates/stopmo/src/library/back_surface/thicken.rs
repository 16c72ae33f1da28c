//! The back's last step: where a front point of some piece still lies closer to the back
//! than the wall — a nostril's floor dipping towards a back that its column did not reach,
//! between two columns on a tilted back — the back triangle nearest to that point moves
//! deeper along the direction field until the wall holds there. Boundary points stay (a
//! seam's back point is shared with the part across it, and the walls start there), so a
//! thin wall right at the boundary is left to the measurements. Crossings this makes are
//! what the written solids' regularization is for; the construction before it already keeps
//! the back clear of the fronts everywhere else.

use glam::Vec3;
use rayon::prelude::*;

use super::PartShell;
use crate::library::nearest::{closest_point_on_triangle, TriangleGrid};

/// Rounds at most (each one grid and one nearest-triangle query per front point).
const THICKEN_ROUNDS: usize = 24;
/// Pushes overshoot the wall by this factor, so the next measurement is not a hair under it.
const THICKEN_MARGIN: f64 = 1.002;
/// Least share of the nearest point's barycentric weight on non-boundary corners for a push:
/// below it the point sits on the boundary, which stays.
const MIN_FREE_WEIGHT: f32 = 0.2;

impl PartShell {
    /// Moves the back deeper where some piece's front is closer to it than `wall_mm`.
    ///
    /// # Returns
    /// The back vertices moved.
    ///
    /// # Performance
    /// Nothing but one measurement when every wall holds (the common case); otherwise a few
    /// rounds, each as costly as [`PartShell::thinnest_wall`].
    pub(super) fn thicken(&mut self, pieces: &[&[Vec3]], wall_mm: f64) -> usize {
        let n = self.back.len();
        let mut moved = vec![false; n];
        let mut last = f32::INFINITY;
        // Only the back moves: the pieces' fronts are laid out once.
        let fronts: Vec<Vec<Vec3>> = pieces.par_iter().map(|p| self.front(p)).collect();
        for _ in 0..THICKEN_ROUNDS {
            let grid = TriangleGrid::new(&self.back, &self.triangles);
            // Per back vertex, the deepest push any front point asks of it.
            let push = fronts
                .par_iter()
                .map(|front| {
                    let mut push = vec![0.0f32; n];
                    for &p in front {
                        let (d, Some(t)) = grid.nearest_below(p, wall_mm) else {
                            continue;
                        };
                        let need = (wall_mm * THICKEN_MARGIN - d) as f32;
                        let tri = self.triangles[t as usize];
                        let [a, b, c] = tri.map(|u| self.back[u as usize]);
                        let w = barycentric(closest_point_on_triangle(p, a, b, c), a, b, c);
                        // The nearest point moves with its free corners only: a point on a
                        // boundary vertex cannot be pushed, one next to it by its share.
                        let free: f32 = tri
                            .iter()
                            .zip(w)
                            .filter(|(&u, _)| !self.on_boundary[u as usize])
                            .map(|(_, w)| w)
                            .sum();
                        if free < MIN_FREE_WEIGHT {
                            continue;
                        }
                        for (&u, w) in tri.iter().zip(w) {
                            let u = u as usize;
                            if !self.on_boundary[u] && w > 0.0 {
                                push[u] = push[u].max(need / free);
                            }
                        }
                    }
                    push
                })
                .reduce(
                    || vec![0.0f32; n],
                    |mut a, b| {
                        for (x, y) in a.iter_mut().zip(b) {
                            *x = x.max(y);
                        }
                        a
                    },
                );
            // The largest push asked: done when none is, or when it stopped shrinking.
            let most = push.iter().fold(0.0f32, |a, &b| a.max(b));
            if most <= 0.0 || most >= last {
                break;
            }
            last = most;
            for (v, &d) in push.iter().enumerate() {
                if d > 0.0 {
                    self.back[v] -= self.normals[v] * d;
                    moved[v] = true;
                }
            }
        }
        moved.iter().filter(|&&m| m).count()
    }
}

/// Barycentric coordinates of `p` (in the plane of `a b c`) on the triangle; equal thirds for
/// a degenerate triangle.
fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (v0.dot(v0), v0.dot(v1), v1.dot(v1));
    let (d20, d21) = (v2.dot(v0), v2.dot(v1));
    let den = d00 * d11 - d01 * d01;
    if den.abs() <= f32::EPSILON * d00 * d11 || !den.is_finite() {
        return [1.0 / 3.0; 3];
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    [1.0 - v - w, v, w].map(|x| x.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_of_corners_and_centroid() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        assert_eq!(barycentric(a, a, b, c), [1.0, 0.0, 0.0]);
        assert_eq!(barycentric(b, a, b, c), [0.0, 1.0, 0.0]);
        let g = barycentric((a + b + c) / 3.0, a, b, c);
        assert!(g.iter().all(|x| (x - 1.0 / 3.0).abs() < 1e-6), "{g:?}");
        assert_eq!(barycentric(a, a, a, a), [1.0 / 3.0; 3]);
    }
}
