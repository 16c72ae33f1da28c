//! Re-targeting a forward simulation onto the next keystroke (Section 3.2, LoA Eq. 2).

/// How the correction `Δγ = γ(t_k+1) − γ(t*)` is blended in over the frames before `t*`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Blend {
    /// Weight `u = t_i / t*`, as printed in the paper: lands exactly, but adds a constant
    /// angular velocity `Δγ / t*`, so the line's velocity jumps at the keystrokes.
    Linear,
    /// Weight `3u² − 2u³`: lands exactly and leaves the simulated velocity untouched at both
    /// ends, so the motion stays C1 through every keystroke. The default.
    #[default]
    Smoothstep,
}

impl Blend {
    /// The blend weight at normalized time `u ∈ [0, 1]` (0 at the start keystroke, 1 at `t*`).
    pub fn weight(self, u: f64) -> f64 {
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        match self {
            Blend::Linear => u,
            Blend::Smoothstep => u * u * (3.0 - 2.0 * u),
        }
    }

    /// `d weight / du` at `u`.
    pub fn slope(self, u: f64) -> f64 {
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        match self {
            Blend::Linear => 1.0,
            Blend::Smoothstep => 6.0 * u * (1.0 - u),
        }
    }
}

/// LoA Eq. 2: the simulated frame `t*_i = argmin_{t_i} Σ_j (γ_j(t_i) − γ_j(t_k+1))²`, searched over
/// frames `1..frames.len()` (frame 0 is the start keystroke itself). Ties go to the earliest
/// frame; NaN distances never win. Returns 1 when there is no frame after the start.
pub fn closest_frame(frames: &[Vec<f64>], target: &[f64]) -> usize {
    let mut best = (1, f64::INFINITY);
    for (i, angles) in frames.iter().enumerate().skip(1) {
        let d: f64 = angles
            .iter()
            .zip(target)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq2_picks_the_closest_simulated_frame() {
        let frames = vec![
            vec![1.0, 1.0],
            vec![0.5, 0.5],
            vec![0.1, -0.1],
            vec![-0.3, 0.2],
        ];
        assert_eq!(closest_frame(&frames, &[0.0, 0.0]), 2);
        // The start frame is never chosen, even when it matches.
        assert_eq!(closest_frame(&frames, &[1.0, 1.0]), 1);
    }

    #[test]
    fn blends_hit_zero_and_one() {
        for b in [Blend::Linear, Blend::Smoothstep] {
            assert_eq!(b.weight(0.0), 0.0);
            assert_eq!(b.weight(1.0), 1.0);
        }
        assert_eq!(Blend::Smoothstep.slope(1.0), 0.0);
    }
}
