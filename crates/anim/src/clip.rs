//! Keyframed animation clips (glTF semantics: LINEAR, STEP, CUBICSPLINE; quaternion slerp).

use glam::{Quat, Vec3};

use crate::Transform;

/// How values between keys are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Linear (slerp for rotations).
    Linear,
    /// Hold the previous key.
    Step,
    /// Cubic Hermite with per-key in/out tangents (values stored as in-tangent, value,
    /// out-tangent per key).
    CubicSpline,
}

/// The animated property of a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Property {
    /// Translation (3 components).
    Translation,
    /// Rotation quaternion x, y, z, w (4 components).
    Rotation,
    /// Scale (3 components).
    Scale,
    /// Morph-target weights (as many components as targets).
    Weights(usize),
}

impl Property {
    /// Number of floats per key value.
    pub fn components(self) -> usize {
        match self {
            Property::Translation | Property::Scale => 3,
            Property::Rotation => 4,
            Property::Weights(n) => n,
        }
    }
}

/// One animated property of one node.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Target node index in the scene.
    pub node: usize,
    /// Which property.
    pub property: Property,
    /// Interpolation mode.
    pub interpolation: Interpolation,
    /// Key times in seconds, strictly increasing.
    pub times: Vec<f32>,
    /// Key values, flat: `times.len() × components` (× 3 for cubic splines).
    pub values: Vec<f32>,
}

impl Channel {
    /// The STEP scale channel of frame `f` of a flipbook (one node per frame): scale 1 from
    /// `times[f]`, 0 before (from `times[0]`) and from `times[f + 1]` on.
    ///
    /// Returns `None` for a one-frame flipbook (its node is simply always visible) or when
    /// `f` is out of `times`.
    pub fn flipbook_visibility(node: usize, f: usize, times: &[f32]) -> Option<Channel> {
        if times.len() < 2 || f >= times.len() {
            return None;
        }
        let (mut t, mut v) = (Vec::with_capacity(3), Vec::with_capacity(9));
        if f > 0 {
            t.push(times[0]);
            v.extend([0.0; 3]);
        }
        t.push(times[f]);
        v.extend([1.0; 3]);
        if f + 1 < times.len() {
            t.push(times[f + 1]);
            v.extend([0.0; 3]);
        }
        Some(Channel {
            node,
            property: Property::Scale,
            interpolation: Interpolation::Step,
            times: t,
            values: v,
        })
    }

    /// Number of floats stored per key (3× the components for cubic splines).
    pub fn stride(&self) -> usize {
        match self.interpolation {
            Interpolation::CubicSpline => 3 * self.property.components(),
            _ => self.property.components(),
        }
    }

    /// Checks that values match times, times increase and everything is finite.
    pub fn validate(&self) -> Result<(), String> {
        if self.times.is_empty() {
            return Err("animation channel has no keys".into());
        }
        if self.values.len() != self.times.len() * self.stride() {
            return Err(format!(
                "animation channel has {} keys but {} values (expected {})",
                self.times.len(),
                self.values.len(),
                self.times.len() * self.stride()
            ));
        }
        if !self.times.iter().chain(&self.values).all(|v| v.is_finite()) {
            return Err("animation channel has non-finite keys".into());
        }
        if self.times.windows(2).any(|w| w[1] < w[0]) {
            return Err("animation channel key times decrease".into());
        }
        Ok(())
    }

    /// The value of key `k` (the middle element for cubic splines).
    fn key(&self, k: usize) -> &[f32] {
        let c = self.property.components();
        let s = self.stride();
        let off = if self.interpolation == Interpolation::CubicSpline {
            c
        } else {
            0
        };
        &self.values[k * s + off..k * s + off + c]
    }

    /// Evaluates the channel at time `t` into `out` (length = components). Times before the
    /// first key or after the last hold the end values.
    pub fn sample(&self, t: f32, out: &mut [f32]) {
        let n = self.times.len();
        let c = self.property.components();
        if n == 0 {
            return;
        }
        let k = self.times.partition_point(|&x| x <= t);
        if k == 0 {
            out.copy_from_slice(self.key(0));
            return;
        }
        if k >= n {
            out.copy_from_slice(self.key(n - 1));
            return;
        }
        let (i, j) = (k - 1, k);
        let dt = self.times[j] - self.times[i];
        let s = if dt > 0.0 {
            ((t - self.times[i]) / dt).clamp(0.0, 1.0)
        } else {
            0.0
        };
        match self.interpolation {
            Interpolation::Step => out.copy_from_slice(self.key(i)),
            Interpolation::Linear => {
                if self.property == Property::Rotation {
                    let a = quat(self.key(i));
                    let b = quat(self.key(j));
                    out.copy_from_slice(&a.slerp(b, s).normalize().to_array());
                } else {
                    let (a, b) = (self.key(i), self.key(j));
                    for m in 0..c {
                        out[m] = a[m] + (b[m] - a[m]) * s;
                    }
                }
            }
            Interpolation::CubicSpline => {
                let st = self.stride();
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                for m in 0..c {
                    let v0 = self.values[i * st + c + m];
                    let b0 = self.values[i * st + 2 * c + m];
                    let v1 = self.values[j * st + c + m];
                    let a1 = self.values[j * st + m];
                    out[m] = h00 * v0 + h10 * dt * b0 + h01 * v1 + h11 * dt * a1;
                }
                if self.property == Property::Rotation {
                    let q = quat(out).normalize();
                    out.copy_from_slice(&q.to_array());
                }
            }
        }
    }

    /// Applies the sampled value to a node's transform or weights.
    pub fn apply(&self, t: f32, transform: &mut Transform, weights: &mut [f32]) {
        let mut buf = [0.0f32; 4];
        match self.property {
            Property::Translation => {
                self.sample(t, &mut buf[..3]);
                transform.translation = Vec3::from_slice(&buf);
            }
            Property::Scale => {
                self.sample(t, &mut buf[..3]);
                transform.scale = Vec3::from_slice(&buf);
            }
            Property::Rotation => {
                self.sample(t, &mut buf);
                let q = quat(&buf);
                transform.rotation = if q.length_squared() > 0.0 {
                    q
                } else {
                    Quat::IDENTITY
                };
            }
            Property::Weights(n) => {
                if weights.len() == n {
                    self.sample(t, weights);
                }
            }
        }
    }
}

fn quat(v: &[f32]) -> Quat {
    Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize()
}

/// A named set of channels played together.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Clip {
    /// Clip name (glTF animation name, or `clip<N>` when unnamed).
    pub name: String,
    /// Animated properties.
    pub channels: Vec<Channel>,
}

impl Clip {
    /// Time of the first key over all channels (0 for an empty clip).
    pub fn start(&self) -> f32 {
        let t = self
            .channels
            .iter()
            .filter_map(|c| c.times.first())
            .fold(f32::INFINITY, |a, &b| a.min(b));
        if t.is_finite() {
            t
        } else {
            0.0
        }
    }

    /// Time of the last key over all channels (0 for an empty clip).
    pub fn end(&self) -> f32 {
        let t = self
            .channels
            .iter()
            .filter_map(|c| c.times.last())
            .fold(f32::NEG_INFINITY, |a, &b| a.max(b));
        if t.is_finite() {
            t
        } else {
            0.0
        }
    }

    /// Duration in seconds.
    pub fn duration(&self) -> f32 {
        (self.end() - self.start()).max(0.0)
    }

    /// Number of frames sampled at `fps` from first to last key, inclusive (SPEC.md).
    pub fn frame_count(&self, fps: f32) -> usize {
        frame_count(self.duration(), fps)
    }

    /// The key rate when every channel's keys are evenly spaced at one common rate.
    pub fn key_rate(&self) -> Option<f32> {
        let mut rate: Option<f32> = None;
        for c in &self.channels {
            if c.times.len() < 2 {
                continue;
            }
            let dt = (c.times[c.times.len() - 1] - c.times[0]) / (c.times.len() - 1) as f32;
            let even = c
                .times
                .windows(2)
                .all(|w| ((w[1] - w[0]) - dt).abs() < 1e-3 * dt.max(1e-6));
            if !even || dt <= 0.0 {
                return None;
            }
            let r = 1.0 / dt;
            match rate {
                Some(q) if (q - r).abs() > 1e-2 * q => return None,
                _ => rate = Some(r),
            }
        }
        rate.map(|r| (r * 1000.0).round() / 1000.0)
    }
}

/// Frames covering `duration` seconds at `fps`, both ends included.
pub fn frame_count(duration: f32, fps: f32) -> usize {
    if !(duration.is_finite() && fps.is_finite() && duration > 0.0 && fps > 0.0) {
        return 1;
    }
    // Exact for any f32 duration × fps (saturating far past every budget): callers check it
    // against [`MAX_FRAMES`] before allocating, and the message states the true count.
    let n = (duration as f64 * fps as f64 + 1e-3).floor();
    (n as usize).saturating_add(1)
}

/// The most frames a clip may be sampled into ([`crate::budget::DEFAULT_MAX_FRAMES`]); longer
/// requests are an error (lower the fps or pick a shorter clip) rather than an allocation
/// that cannot succeed.
pub const MAX_FRAMES: usize = crate::budget::DEFAULT_MAX_FRAMES as usize;

#[cfg(test)]
mod tests {
    use super::*;

    fn chan(
        property: Property,
        interpolation: Interpolation,
        times: Vec<f32>,
        values: Vec<f32>,
    ) -> Channel {
        Channel {
            node: 0,
            property,
            interpolation,
            times,
            values,
        }
    }

    #[test]
    fn linear_and_step_and_clamp() {
        let c = chan(
            Property::Translation,
            Interpolation::Linear,
            vec![0.0, 1.0],
            vec![0., 0., 0., 2., 4., 6.],
        );
        let mut o = [0.0; 3];
        c.sample(0.5, &mut o);
        assert_eq!(o, [1.0, 2.0, 3.0]);
        c.sample(-1.0, &mut o);
        assert_eq!(o, [0.0; 3]);
        c.sample(9.0, &mut o);
        assert_eq!(o, [2.0, 4.0, 6.0]);
        let s = Channel {
            interpolation: Interpolation::Step,
            ..c
        };
        s.sample(0.99, &mut o);
        assert_eq!(o, [0.0; 3]);
    }

    #[test]
    fn slerp_keeps_unit_length() {
        let q1 = Quat::from_rotation_y(1.5);
        let mut v = Quat::IDENTITY.to_array().to_vec();
        v.extend(q1.to_array());
        let c = chan(Property::Rotation, Interpolation::Linear, vec![0.0, 2.0], v);
        let mut o = [0.0; 4];
        c.sample(1.0, &mut o);
        let q = Quat::from_array(o);
        assert!((q.length() - 1.0).abs() < 1e-6);
        assert!(q.abs_diff_eq(Quat::from_rotation_y(0.75), 1e-5));
    }

    #[test]
    fn cubic_spline_hits_keys_and_uses_tangents() {
        // Scalar weight 0 -> 1 with zero tangents: smoothstep.
        let v = vec![0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let c = chan(
            Property::Weights(1),
            Interpolation::CubicSpline,
            vec![0.0, 1.0],
            v,
        );
        let mut o = [0.0];
        c.sample(0.5, &mut o);
        assert!((o[0] - 0.5).abs() < 1e-6);
        c.sample(0.25, &mut o);
        assert!((o[0] - (3.0 * 0.0625 - 2.0 * 0.015625)).abs() < 1e-6);
    }

    #[test]
    fn frame_count_inclusive() {
        assert_eq!(frame_count(2.0, 24.0), 49);
        assert_eq!(frame_count(0.0, 24.0), 1);
        assert_eq!(frame_count(59.966_667, 30.0), 1800);
        assert_eq!(frame_count(20_000.0, 24.0), 480_001);
        assert_eq!(frame_count(f32::MAX, f32::MAX), usize::MAX);
    }
}
