//! Motion reduction (Section 4, "Staging and solving for motion"): every degree of freedom's
//! trajectory is a Hermite spline with one node per keystroke and one between consecutive
//! keystrokes — `2N − 1` nodes for `N` keystrokes — and the optimization runs over the node
//! values. Tangents are Bessel's (the crate's [`HermiteTrack`]), so each frame's value is a
//! fixed linear combination of at most four node values: `θ(t_i) = Σ_m B_im θ_m`.

use crate::HermiteTrack;

/// Nodes and per-frame basis weights of the reduction.
#[derive(Debug, Clone, PartialEq)]
pub struct Reduction {
    /// Node times (frames; midpoints may be fractional).
    pub node_frames: Vec<f64>,
    /// Per frame: (node, weight) pairs with non-zero weight.
    pub weights: Vec<Vec<(usize, f64)>>,
}

impl Reduction {
    /// The `2N − 1` nodes of `key_frames` (strictly increasing) and the basis weights of the
    /// integer frames `first..=last`.
    pub fn new(key_frames: &[i64]) -> Reduction {
        let mut nodes = Vec::with_capacity(key_frames.len() * 2);
        for (i, &k) in key_frames.iter().enumerate() {
            if i > 0 {
                nodes.push((key_frames[i - 1] + k) as f64 * 0.5);
            }
            nodes.push(k as f64);
        }
        let first = key_frames.first().copied().unwrap_or(0);
        let last = key_frames.last().copied().unwrap_or(0);
        let frames = (last - first + 1).max(1) as usize;
        let mut weights = vec![Vec::new(); frames];
        let mut unit = vec![0.0; nodes.len()];
        for m in 0..nodes.len() {
            unit[m] = 1.0;
            let track = HermiteTrack::new(&nodes, &unit);
            for (f, w) in weights.iter_mut().enumerate() {
                let b = track.value((first + f as i64) as f64);
                if b.abs() > 1e-14 {
                    w.push((m, b));
                }
            }
            unit[m] = 0.0;
        }
        Reduction {
            node_frames: nodes,
            weights,
        }
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.node_frames.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_n_minus_one_nodes_and_partition_of_unity() {
        let r = Reduction::new(&[0, 10, 24]);
        assert_eq!(r.nodes(), 5);
        assert_eq!(r.node_frames, vec![0.0, 5.0, 10.0, 17.0, 24.0]);
        assert_eq!(r.weights.len(), 25);
        for w in &r.weights {
            let s: f64 = w.iter().map(|(_, b)| b).sum();
            assert!((s - 1.0).abs() < 1e-12);
            assert!(w.len() <= 4);
        }
        // Interpolating at nodes.
        assert_eq!(r.weights[10], vec![(2, 1.0)]);
    }
}
