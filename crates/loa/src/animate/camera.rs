//! The camera `P` the line is drawn through, the action plane, and the map from the
//! keystrokes' screen coordinates onto the camera's image plane.
//!
//! Orthographic (the paper's figures): a 3D point `x` projects to image coordinates
//! `P x = ((x − c)·r, (x − c)·u)` in world units, with `r`/`u` the camera's right/up axes.
//! Perspective (a scene camera, [`ActionCamera::from_scene_camera`]): the eye sits `D` behind
//! the focal plane through `c`, and `P x = D/z · ((x − c)·r, (x − c)·u)` with the depth
//! `z = D + (x − c)·f`, so image units are world units on the focal plane. The default is the
//! glTF front view (looking down −Z, +Y up) fitted to the character.

use glam::{DVec2, DVec3};

use super::error::AnimateError;

/// Fraction of the character's size added around it when fitting the camera.
pub const DEFAULT_CAMERA_MARGIN: f64 = 0.15;

/// An orthographic camera.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ActionCamera {
    /// Point the camera looks at (image origin).
    pub center: DVec3,
    /// Unit viewing direction (from the eye into the scene).
    pub forward: DVec3,
    /// Unit right axis of the image.
    pub right: DVec3,
    /// Unit up axis of the image.
    pub up: DVec3,
    /// Half height of the view volume (world units); the width follows the image aspect.
    pub half_height: f64,
    /// Perspective: distance `D` from the eye to the focal plane through `center` (`None` =
    /// orthographic).
    pub eye_distance: Option<f64>,
}

impl ActionCamera {
    /// The glTF front view (eye on +Z looking at −Z, +Y up) fitted to a bounding box.
    pub fn front_fitted(min: DVec3, max: DVec3) -> ActionCamera {
        Self::fitted(min, max, DVec3::NEG_Z, DVec3::Y)
    }

    /// A view along `forward` with `up` as close as possible to the image's up, fitted to a
    /// bounding box (falls back to +Z when `forward` is parallel to `up`).
    pub fn fitted(min: DVec3, max: DVec3, forward: DVec3, up: DVec3) -> ActionCamera {
        let forward = forward.try_normalize().unwrap_or(DVec3::NEG_Z);
        let right = forward
            .cross(up)
            .try_normalize()
            .unwrap_or_else(|| forward.any_orthonormal_vector());
        let up = right.cross(forward);
        let (min, max) = if min.is_finite() && max.is_finite() && min.cmple(max).all() {
            (min, max)
        } else {
            (DVec3::ZERO, DVec3::ONE)
        };
        let center = (min + max) * 0.5;
        let half = (max - min) * 0.5;
        let along = |a: DVec3| (half * a).abs().element_sum();
        let extent = along(up).max(along(right));
        ActionCamera {
            center,
            forward,
            right,
            up,
            half_height: (extent * (1.0 + DEFAULT_CAMERA_MARGIN)).max(1e-9),
            eye_distance: None,
        }
    }

    /// A scene camera (e.g. a glTF camera node) at its world matrix `world` (camera looks
    /// down its local −Z, +Y up), with its focal plane through the point of the view axis
    /// nearest `target` (the character's centre). Perspective cameras keep their
    /// perspective; orthographic ones their half height.
    pub fn from_scene_camera(
        projection: &anim::Projection,
        world: &glam::Mat4,
        target: DVec3,
    ) -> ActionCamera {
        let m = world.as_dmat4();
        let eye = m.w_axis.truncate();
        let forward = (-m.z_axis.truncate())
            .try_normalize()
            .unwrap_or(DVec3::NEG_Z);
        let right = forward
            .cross(m.y_axis.truncate())
            .try_normalize()
            .unwrap_or_else(|| forward.any_orthonormal_vector());
        let up = right.cross(forward);
        let depth = (target - eye).dot(forward).max(1e-6);
        let center = eye + forward * depth;
        match *projection {
            anim::Projection::Perspective { yfov, .. } => ActionCamera {
                center,
                forward,
                right,
                up,
                half_height: depth * (0.5 * yfov as f64).tan(),
                eye_distance: Some(depth),
            },
            anim::Projection::Orthographic { ymag, .. } => ActionCamera {
                center,
                forward,
                right,
                up,
                half_height: (ymag as f64).abs().max(1e-9),
                eye_distance: None,
            },
        }
    }

    /// `D / z` at `x`: image units per world unit across the view (1 for orthographic).
    #[inline]
    fn magnification(&self, x: DVec3) -> f64 {
        match self.eye_distance {
            None => 1.0,
            Some(d) => d / (d + (x - self.center).dot(self.forward)).max(1e-9 * d),
        }
    }

    /// The derivative of [`ActionCamera::project`] at `x` applied to a world-space direction
    /// `v` (for orthographic cameras simply `(v·r, v·u)`).
    #[inline]
    pub fn project_direction(&self, x: DVec3, v: DVec3) -> DVec2 {
        let flat = DVec2::new(v.dot(self.right), v.dot(self.up));
        match self.eye_distance {
            None => flat,
            Some(d) => {
                // p = s (a, b) with s = D / z: dp = s (v·r, v·u) − p (v·f) / z.
                let s = self.magnification(x);
                let z = d / s;
                s * flat - self.project(x) * (v.dot(self.forward) / z)
            }
        }
    }

    /// Image coordinates of a world point.
    #[inline]
    pub fn project(&self, x: DVec3) -> DVec2 {
        let d = x - self.center;
        self.magnification(x) * DVec2::new(d.dot(self.right), d.dot(self.up))
    }

    /// The world point on the plane through `center` facing the camera with image
    /// coordinates `p`.
    #[inline]
    pub fn unproject(&self, p: DVec2) -> DVec3 {
        self.center + self.right * p.x + self.up * p.y
    }
}

/// The plane the motion happens in: bones turn about its normal, the root moves in it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ActionPlane {
    /// Unit normal `n`.
    pub normal: DVec3,
    /// First in-plane axis `u`.
    pub u: DVec3,
    /// Second in-plane axis `v = n × u`.
    pub v: DVec3,
}

impl ActionPlane {
    /// The plane with normal `normal` (any length, not zero).
    pub fn new(normal: DVec3) -> Result<ActionPlane, AnimateError> {
        let n = normal
            .try_normalize()
            .ok_or(AnimateError::PlaneNormal([normal.x, normal.y, normal.z]))?;
        let u = n.any_orthonormal_vector();
        Ok(ActionPlane {
            normal: n,
            u,
            v: n.cross(u),
        })
    }
}

/// Maps the keystrokes' screen coordinates (x right, y down, any units) onto the camera's
/// image plane: `image = origin + scale · (x − anchor.x, anchor.y − y)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScreenMap {
    /// Screen point mapped onto `origin`.
    pub anchor: DVec2,
    /// Image-plane point (world units) the anchor lands on.
    pub origin: DVec2,
    /// World units per screen unit.
    pub scale: f64,
}

impl ScreenMap {
    /// Maps a screen point.
    #[inline]
    pub fn map(&self, p: DVec2) -> DVec2 {
        self.origin + self.scale * DVec2::new(p.x - self.anchor.x, self.anchor.y - p.y)
    }
}
