//! Geometric interpolation (end of Section 3.1): Hermite cubic splines of the angles, lengths
//! and root, then forward kinematics, giving the dynamic line `x_dloa(s, t)`.

use glam::DVec2;

use crate::animation::{Animation, AnimationFrame};
use crate::chain::Chain;
use crate::keypose::KeyPose;

/// A C1 cubic Hermite spline through `(t_k, v_k)` with Bessel tangents (the slope of the
/// parabola through three neighbouring keys; one-sided slopes at the ends). Constant outside
/// the key range.
#[derive(Debug, Clone, PartialEq)]
pub struct HermiteTrack {
    times: Vec<f64>,
    values: Vec<f64>,
    tangents: Vec<f64>,
}

impl HermiteTrack {
    /// Builds a track; `times` must be strictly increasing and as long as `values` (extra
    /// entries of the longer slice are ignored).
    pub fn new(times: &[f64], values: &[f64]) -> Self {
        let n = times.len().min(values.len());
        let (t, v) = (&times[..n], &values[..n]);
        let mut tangents = vec![0.0; n];
        if n >= 2 {
            let slope = |k: usize| (v[k + 1] - v[k]) / (t[k + 1] - t[k]);
            tangents[0] = slope(0);
            tangents[n - 1] = slope(n - 2);
            for k in 1..n - 1 {
                let (h0, h1) = (t[k] - t[k - 1], t[k + 1] - t[k]);
                tangents[k] = (h1 * slope(k - 1) + h0 * slope(k)) / (h0 + h1);
            }
        }
        Self {
            times: t.to_vec(),
            values: v.to_vec(),
            tangents,
        }
    }

    fn segment(&self, t: f64) -> Option<(usize, f64, f64)> {
        let n = self.times.len();
        if n < 2 || t.is_nan() || t <= self.times[0] || t >= self.times[n - 1] {
            return None;
        }
        let k = self
            .times
            .partition_point(|&x| x <= t)
            .saturating_sub(1)
            .min(n - 2);
        let h = self.times[k + 1] - self.times[k];
        Some((k, (t - self.times[k]) / h, h))
    }

    /// Value at time `t`.
    pub fn value(&self, t: f64) -> f64 {
        self.value_with(self.basis(t), t)
    }

    /// The segment and Hermite basis weights at `t` (shared by tracks with the same times).
    fn basis(&self, t: f64) -> Option<(usize, [f64; 4])> {
        let (k, u, h) = self.segment(t)?;
        let (u2, u3) = (u * u, u * u * u);
        Some((
            k,
            [
                2.0 * u3 - 3.0 * u2 + 1.0,
                (u3 - 2.0 * u2 + u) * h,
                -2.0 * u3 + 3.0 * u2,
                (u3 - u2) * h,
            ],
        ))
    }

    fn value_with(&self, basis: Option<(usize, [f64; 4])>, t: f64) -> f64 {
        match basis {
            None => self.clamped(t),
            Some((k, w)) => {
                w[0] * self.values[k]
                    + w[1] * self.tangents[k]
                    + w[2] * self.values[k + 1]
                    + w[3] * self.tangents[k + 1]
            }
        }
    }

    /// Time derivative at `t` (the key tangent exactly at a key).
    pub fn derivative(&self, t: f64) -> f64 {
        if let Some(k) = self.times.iter().position(|&x| x == t) {
            return if self.times.len() >= 2 {
                self.tangents[k]
            } else {
                0.0
            };
        }
        match self.segment(t) {
            None => 0.0,
            Some((k, u, h)) => {
                let u2 = u * u;
                let d00 = 6.0 * u2 - 6.0 * u;
                let d10 = 3.0 * u2 - 4.0 * u + 1.0;
                let d01 = -6.0 * u2 + 6.0 * u;
                let d11 = 3.0 * u2 - 2.0 * u;
                (d00 * self.values[k] + d01 * self.values[k + 1]) / h
                    + d10 * self.tangents[k]
                    + d11 * self.tangents[k + 1]
            }
        }
    }

    fn clamped(&self, t: f64) -> f64 {
        match (self.values.first(), self.values.last()) {
            (Some(&a), Some(&b)) => {
                if t >= *self.times.last().unwrap_or(&0.0) {
                    b
                } else {
                    a
                }
            }
            _ => 0.0,
        }
    }
}

/// Hermite tracks for every degree of freedom of a line (angles, lengths, root x and y).
#[derive(Debug, Clone, PartialEq)]
pub struct HermiteLine {
    angles: Vec<HermiteTrack>,
    lengths: Vec<HermiteTrack>,
    root: [HermiteTrack; 2],
}

impl HermiteLine {
    /// Splines through the key poses (which must share one element count; see
    /// [`fit_keystrokes`](crate::fit_keystrokes)).
    pub fn new(keys: &[KeyPose]) -> Self {
        let times: Vec<f64> = keys.iter().map(|k| k.frame as f64).collect();
        let n = keys.first().map_or(0, |k| k.chain.elements());
        let track = |f: &dyn Fn(&KeyPose) -> f64| {
            HermiteTrack::new(&times, &keys.iter().map(f).collect::<Vec<_>>())
        };
        Self {
            angles: (0..n).map(|j| track(&|k| k.chain.angles()[j])).collect(),
            lengths: (0..n).map(|j| track(&|k| k.chain.lengths()[j])).collect(),
            root: [track(&|k| k.chain.root().x), track(&|k| k.chain.root().y)],
        }
    }

    /// The interpolated chain at (fractional) frame `t`.
    pub fn chain_at(&self, t: f64) -> Chain {
        let root = self.root_at(t);
        let angles = self.angles_at(t);
        let lengths = self.lengths_at(t);
        Chain::new(root, angles, lengths).unwrap_or_else(|_| {
            // Unreachable for valid keys; keep a defined result rather than panic.
            Chain::straight(root, 0.0, self.angles.len().max(2), 0.0)
                .unwrap_or_else(|_| unreachable!("2 elements are always valid"))
        })
    }

    /// Interpolated local angles at frame `t`.
    pub fn angles_at(&self, t: f64) -> Vec<f64> {
        let b = self.root[0].basis(t);
        self.angles.iter().map(|a| a.value_with(b, t)).collect()
    }

    /// Angular velocities (radians per frame) at frame `t`.
    pub fn angle_rates_at(&self, t: f64) -> Vec<f64> {
        self.angles.iter().map(|a| a.derivative(t)).collect()
    }

    /// Root position at frame `t`.
    pub fn root_at(&self, t: f64) -> DVec2 {
        let b = self.root[0].basis(t);
        DVec2::new(self.root[0].value_with(b, t), self.root[1].value_with(b, t))
    }

    /// Element lengths at frame `t`.
    pub fn lengths_at(&self, t: f64) -> Vec<f64> {
        let b = self.root[0].basis(t);
        self.lengths
            .iter()
            .map(|l| l.value_with(b, t).max(0.0))
            .collect()
    }
}

/// Geometric interpolation of the key poses: one chain per integer frame from the first key
/// to the last, inclusive.
pub fn interpolate_hermite(keys: &[KeyPose], fps: f64) -> Animation {
    let line = HermiteLine::new(keys);
    let (first, last) = match (keys.first(), keys.last()) {
        (Some(a), Some(b)) => (a.frame, b.frame),
        _ => (0, -1),
    };
    let frames = (first..=last)
        .map(|f| AnimationFrame {
            frame: f,
            chain: keys
                .iter()
                .find(|k| k.frame == f)
                .map_or_else(|| line.chain_at(f as f64), |k| k.chain.clone()),
        })
        .collect();
    Animation::new(fps, keys.iter().map(|k| k.frame).collect(), frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn track_interpolates_and_is_c1() {
        let t = [0.0, 3.0, 10.0, 12.0];
        let v = [0.0, 2.0, -1.0, 4.0];
        let tr = HermiteTrack::new(&t, &v);
        for (ti, vi) in t.iter().zip(v) {
            assert!((tr.value(*ti) - vi).abs() < 1e-12);
        }
        for &tk in &t[1..3] {
            let eps = 1e-6;
            let left = (tr.value(tk) - tr.value(tk - eps)) / eps;
            let right = (tr.value(tk + eps) - tr.value(tk)) / eps;
            assert!((left - right).abs() < 1e-4, "{left} vs {right}");
        }
    }
}
