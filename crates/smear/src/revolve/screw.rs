//! The rigid motion between two frames as a screw: a rotation by `angle` about the line
//! through `point` along `axis`, plus a slide along it (Chasles' theorem).

use glam::{DMat3, DQuat, DVec3, Quat, Vec3};

/// Below this rotation (radians per frame) a motion counts as a translation.
const MIN_ANGLE: f64 = 1e-6;

/// A screw motion (Chasles): `x ↦ point + R(angle·t)(x − point) + axis·slide·t` at fraction
/// `t` of the frame interval; a translation by `shift·t` when the rotation is negligible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Screw {
    /// A point on the rotation axis.
    pub point: Vec3,
    /// Unit rotation axis (zero for a translation).
    pub axis: Vec3,
    /// Rotation angle in radians over the whole interval, in [0, π].
    pub angle: f32,
    /// Translation along the axis over the whole interval.
    pub slide: f32,
    /// The whole translation (used when the rotation is negligible).
    pub shift: Vec3,
}

impl Screw {
    /// The motion that changes nothing.
    pub const IDENTITY: Screw = Screw {
        point: Vec3::ZERO,
        axis: Vec3::ZERO,
        angle: 0.0,
        slide: 0.0,
        shift: Vec3::ZERO,
    };

    /// Point `p` moved by fraction `t` of the screw (any real `t`: `t > 1` continues the
    /// rotation, `t < 0` runs it backwards). Points keep their distance to the axis.
    #[inline]
    pub fn apply(&self, p: Vec3, t: f32) -> Vec3 {
        if (self.angle as f64) < MIN_ANGLE {
            return p + self.shift * t;
        }
        let q = Quat::from_axis_angle(self.axis, self.angle * t);
        self.point + q * (p - self.point) + self.axis * (self.slide * t)
    }

    /// Angular speed in radians per frame interval (0 for translations).
    pub fn angle(&self) -> f32 {
        self.angle
    }
}

/// The best rigid motion taking points `a` to points `b` (least squares over the points,
/// centroids matched) as a [`Screw`], and its RMS residual.
///
/// The rotation is the rotational part of the cross-covariance `Σ (b − b̄)(a − ā)ᵀ`, found by
/// Müller et al.'s iteration ("A Robust Method to Extract the Rotational Part of
/// Deformations", MIG 2016), which also works for flat point sets (a propeller's blades) where
/// the covariance is singular.
pub fn fit_screw(a: &[Vec3], b: &[Vec3]) -> (Screw, f32) {
    let n = a.len().min(b.len());
    if n == 0 {
        return (Screw::IDENTITY, 0.0);
    }
    let mean = |p: &[Vec3]| p[..n].iter().map(|x| x.as_dvec3()).sum::<DVec3>() / n as f64;
    let (ca, cb) = (mean(a), mean(b));
    let mut cov = DMat3::ZERO;
    for (p, q) in a[..n].iter().zip(&b[..n]) {
        let (p, q) = (p.as_dvec3() - ca, q.as_dvec3() - cb);
        cov.x_axis += q * p.x;
        cov.y_axis += q * p.y;
        cov.z_axis += q * p.z;
    }
    let mut rot = DQuat::IDENTITY;
    for _ in 0..200 {
        let r = DMat3::from_quat(rot);
        let num =
            r.x_axis.cross(cov.x_axis) + r.y_axis.cross(cov.y_axis) + r.z_axis.cross(cov.z_axis);
        let den = (r.x_axis.dot(cov.x_axis) + r.y_axis.dot(cov.y_axis) + r.z_axis.dot(cov.z_axis))
            .abs()
            + 1e-12;
        let omega = num / den;
        let w = omega.length();
        if w < 1e-12 {
            break;
        }
        rot = (DQuat::from_axis_angle(omega / w, w) * rot).normalize();
    }
    let t = cb - rot * ca;
    let residual = (a[..n]
        .iter()
        .zip(&b[..n])
        .map(|(p, q)| (rot * p.as_dvec3() + t - q.as_dvec3()).length_squared())
        .sum::<f64>()
        / n as f64)
        .sqrt() as f32;
    let (mut axis, mut angle) = rot.to_axis_angle();
    if angle > std::f64::consts::PI {
        axis = -axis;
        angle = 2.0 * std::f64::consts::PI - angle;
    }
    if angle < MIN_ANGLE || !axis.is_finite() {
        let shift = t.as_vec3();
        return (
            Screw {
                shift,
                ..Screw::IDENTITY
            },
            residual,
        );
    }
    let axis = axis.normalize();
    let slide = t.dot(axis);
    let perp = t - axis * slide;
    // (I − R)c = t⊥ for c ⊥ axis: c = ½(t⊥ + cot(θ/2)·axis × t⊥).
    let point = 0.5 * (perp + axis.cross(perp) / (angle * 0.5).tan());
    (
        Screw {
            point: point.as_vec3(),
            axis: axis.as_vec3(),
            angle: angle as f32,
            slide: slide as f32,
            shift: t.as_vec3(),
        },
        residual,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_rotation_about_an_offset_axis() {
        let axis = Vec3::new(0.2, 1.0, 0.1).normalize();
        let centre = Vec3::new(1.0, -2.0, 0.5);
        let truth = Screw {
            point: centre,
            axis,
            angle: 1.1,
            slide: 0.3,
            shift: Vec3::ZERO,
        };
        // A flat (planar) set of points: the covariance is singular.
        let a: Vec<Vec3> = (0..12)
            .map(|k| {
                let u = axis.any_orthonormal_vector();
                let v = axis.cross(u);
                centre + u * (k as f32 * 0.3) + v * ((k % 3) as f32 - 1.0)
            })
            .collect();
        let b: Vec<Vec3> = a.iter().map(|p| truth.apply(*p, 1.0)).collect();
        let (s, res) = fit_screw(&a, &b);
        assert!(res < 1e-4, "residual {res}");
        assert!(
            (s.angle - 1.1).abs() < 1e-4 && s.axis.dot(axis) > 0.9999,
            "{s:?}"
        );
        assert!((s.slide - 0.3).abs() < 1e-4);
        for p in &a {
            assert!((s.apply(*p, 0.5) - truth.apply(*p, 0.5)).length() < 1e-4);
        }
        let (t, _) = fit_screw(&a, &a.iter().map(|p| *p + Vec3::X).collect::<Vec<_>>());
        assert_eq!(t.angle, 0.0);
        assert!((t.apply(Vec3::ZERO, 0.5) - Vec3::X * 0.5).length() < 1e-6);
    }
}
