//! Part boundary smoothing (Section 3.1, "Part boundary smoothing", Fig. 5): per-triangle
//! part indicators χ_j become per-vertex votes by an animation-average-area-weighted average,
//! which are then mollified by Laplacian smoothing.

use super::topology::Csr;

/// Default number of Laplacian smoothing iterations of the votes.
pub const DEFAULT_SMOOTH_ITERATIONS: usize = 10;
/// Default step of one smoothing iteration (`0 < step ≤ 1`; 1 replaces a vote by the mean
/// of its neighbours).
pub const DEFAULT_SMOOTH_STEP: f64 = 0.5;

/// Per-vertex votes, vertex-major (`v * parts + j`), from per-triangle labels.
///
/// `vote_j(v) = Σ_{t ∋ v} A_t χ_j(t) / Σ_{t ∋ v} A_t` with `A_t` the animation-average area of
/// triangle t. Votes of a vertex sum to 1 (vertices on zero-area triangles only use uniform
/// weights; vertices on no triangle vote 1 for part 0).
pub(super) fn vertex_votes(
    parts: usize,
    vertex_triangles: &Csr,
    labels: &[u32],
    areas: &[f64],
) -> Vec<f64> {
    let n = vertex_triangles.len();
    let mut votes = vec![0.0; n * parts];
    for v in 0..n {
        let row = vertex_triangles.row(v);
        let total: f64 = row.iter().map(|&t| areas[t as usize]).sum();
        let out = &mut votes[v * parts..(v + 1) * parts];
        if row.is_empty() {
            out[0] = 1.0;
        } else if total > 0.0 {
            for &t in row {
                out[labels[t as usize] as usize] += areas[t as usize] / total;
            }
        } else {
            for &t in row {
                out[labels[t as usize] as usize] += 1.0 / row.len() as f64;
            }
        }
    }
    votes
}

/// Explicit umbrella-Laplacian smoothing of vertex-major votes:
/// `u ← (1 − step) u + step · mean_{w ∈ N(v)} u(w)`, `iterations` times.
///
/// Linear and constant-preserving, so votes keep summing to 1 (a partition of unity) and
/// stay in [0, 1]. Vertices with no neighbour keep their votes.
///
/// # Performance
/// O(iterations × (edges + vertices) × parts), one scratch buffer.
pub(super) fn smooth_votes(
    votes: &mut Vec<f64>,
    parts: usize,
    neighbors: &Csr,
    iterations: usize,
    step: f64,
) {
    let step = step.clamp(0.0, 1.0);
    let mut next = votes.clone();
    for _ in 0..iterations {
        for v in 0..neighbors.len() {
            let row = neighbors.row(v);
            if row.is_empty() {
                continue;
            }
            let inv = 1.0 / row.len() as f64;
            for j in 0..parts {
                let mean: f64 = row
                    .iter()
                    .map(|&w| votes[w as usize * parts + j])
                    .sum::<f64>()
                    * inv;
                next[v * parts + j] = (1.0 - step) * votes[v * parts + j] + step * mean;
            }
        }
        std::mem::swap(votes, &mut next);
    }
}
