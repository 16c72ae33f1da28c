//! Pieces closer to a sibling than the printer resolution: for every piece, its nearest
//! sibling under the largest vertex distance `max_v ‖p_v − q_v‖`.
//!
//! All pairs by brute force cost `pieces² · vertices` (a second at 200 pieces of 11,595
//! vertices). The distance at any subset of vertices is a lower bound of the pair's
//! distance, so each piece ranks its siblings by the bound on the vertices that vary most
//! across the library, measures them in that order and stops at the first whose bound is no
//! smaller than the nearest found; a measurement stops as soon as it exceeds that nearest.
//! The result is exact (the same `f32` distances and minima as the brute force).

use glam::Vec3;
use rayon::prelude::*;

use crate::library::piece_id;

/// Vertices of the lower bound (those varying most across the pieces).
const BOUND_VERTICES: usize = 16;

/// Pieces closer to a sibling than `resolution_mm` (largest vertex distance), and the
/// smallest such distance of the part (infinite for fewer than two pieces).
pub(super) fn below_resolution(
    name: &str,
    pieces_mm: &[Vec<Vec3>],
    resolution_mm: f64,
) -> (Vec<String>, f64) {
    let n = pieces_mm.len();
    let nearest: Vec<f64> = nearest_sibling_sq(pieces_mm)
        .into_iter()
        .map(|sq| f64::from(sq.sqrt()))
        .collect();
    let close = (0..n)
        .filter(|&k| nearest[k] < resolution_mm)
        .map(|k| piece_id(name, k, n))
        .collect();
    (close, nearest.iter().copied().fold(f64::INFINITY, f64::min))
}

/// Per piece, the squared largest vertex distance to its nearest sibling (`f32`; infinite
/// without a sibling). `sqrt` is monotone, so its root is the brute force's distance.
fn nearest_sibling_sq(pieces: &[Vec<Vec3>]) -> Vec<f32> {
    let n = pieces.len();
    let m = pieces.iter().map(Vec::len).min().unwrap_or(0);
    let order = spread_order(pieces, m);
    let bound_vertices = &order[..BOUND_VERTICES.min(m)];
    let sq = |a: Vec3, b: Vec3| (a - b).length_squared();
    // Lower bounds of every pair on the most varying vertices.
    let bounds: Vec<f32> = (0..n * n)
        .into_par_iter()
        .map(|ij| {
            let (a, b) = (&pieces[ij / n], &pieces[ij % n]);
            bound_vertices
                .iter()
                .map(|&v| sq(a[v], b[v]))
                .fold(0.0f32, f32::max)
        })
        .collect();
    (0..n)
        .into_par_iter()
        .map(|i| {
            let row = &bounds[i * n..(i + 1) * n];
            let mut siblings: Vec<usize> = (0..n).filter(|&j| j != i).collect();
            siblings.sort_by(|&a, &b| row[a].total_cmp(&row[b]).then(a.cmp(&b)));
            let mut best = f32::INFINITY;
            for j in siblings {
                if row[j] >= best {
                    break;
                }
                let (a, b) = (&pieces[i], &pieces[j]);
                let mut d = 0.0f32;
                for &v in &order {
                    d = d.max(sq(a[v], b[v]));
                    if d >= best {
                        break;
                    }
                }
                best = best.min(d);
            }
            best
        })
        .collect()
}

/// Vertices `0..m`, the ones whose positions vary most across the pieces first (the
/// diagonal of their box over the pieces), so that a distance grows fast.
fn spread_order(pieces: &[Vec<Vec3>], m: usize) -> Vec<usize> {
    let spread: Vec<f32> = (0..m)
        .into_par_iter()
        .map(|v| {
            let (lo, hi) = pieces
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p[v]), hi.max(p[v]))
                });
            (hi - lo).length_squared()
        })
        .collect();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| spread[b].total_cmp(&spread[a]).then(a.cmp(&b)));
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim::SplitMix64;

    /// Every pair measured over every vertex.
    fn brute_force(pieces: &[Vec<Vec3>]) -> Vec<f64> {
        let n = pieces.len();
        let mut nearest = vec![f64::INFINITY; n];
        for i in 0..n {
            for j in i + 1..n {
                let d = pieces[i]
                    .iter()
                    .zip(&pieces[j])
                    .map(|(x, y)| x.distance(*y))
                    .fold(0.0f32, f32::max) as f64;
                nearest[i] = nearest[i].min(d);
                nearest[j] = nearest[j].min(d);
            }
        }
        nearest
    }

    #[test]
    fn pruned_search_matches_every_pair() {
        let mut rng = SplitMix64::new(7, 0);
        let base: Vec<Vec3> = (0..300)
            .map(|_| {
                Vec3::new(
                    rng.normal() as f32,
                    rng.normal() as f32,
                    rng.normal() as f32,
                )
            })
            .collect();
        // Pieces near a few shapes (near-duplicates and far ones), two exact copies.
        let mut pieces: Vec<Vec<Vec3>> = (0..40)
            .map(|k| {
                let amp = [0.001f32, 0.05, 1.0][k % 3];
                base.iter()
                    .map(|&p| p + amp * Vec3::new(rng.normal() as f32, 0.0, rng.normal() as f32))
                    .collect()
            })
            .collect();
        pieces.push(pieces[5].clone());
        let expected = brute_force(&pieces);
        let found: Vec<f64> = nearest_sibling_sq(&pieces)
            .into_iter()
            .map(|sq| f64::from(sq.sqrt()))
            .collect();
        assert_eq!(found, expected);
        let (close, min) = below_resolution("jaw", &pieces, 0.01);
        assert_eq!(min, 0.0);
        assert!(close.len() >= 2, "{close:?}");
        assert_eq!(nearest_sibling_sq(&pieces[..1]), vec![f32::INFINITY]);
    }
}
