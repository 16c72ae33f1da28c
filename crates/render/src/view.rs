//! Views: world → camera → clip transforms, auto-fitted or from a scene camera.

use anim::{Aabb, Camera};
use glam::{Mat4, Vec3, Vec4Swizzles};

/// Fraction of the fitted extent added as a margin on every side by [`View::fit`].
pub const DEFAULT_FIT_MARGIN: f32 = 0.06;

/// Where an auto-fitted orthographic view looks from (Y-up world, glTF conventions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViewDirection {
    /// From +Z towards −Z (the glTF "front").
    Front,
    /// From −Z towards +Z.
    Back,
    /// From +X towards −X.
    Side,
    /// From +Y looking down, −Z up on screen.
    Top,
    /// From the front-right and slightly above (azimuth 45°, elevation 25°).
    ThreeQuarter,
    /// From the given direction (pointing from the subject towards the eye).
    Direction(Vec3),
}

impl ViewDirection {
    /// Unit vector from the subject towards the eye.
    pub fn eye_direction(self) -> Vec3 {
        let d = match self {
            ViewDirection::Front => Vec3::Z,
            ViewDirection::Back => Vec3::NEG_Z,
            ViewDirection::Side => Vec3::X,
            ViewDirection::Top => Vec3::Y,
            ViewDirection::ThreeQuarter => {
                let (az, el) = (45f32.to_radians(), 25f32.to_radians());
                Vec3::new(az.sin() * el.cos(), el.sin(), az.cos() * el.cos())
            }
            ViewDirection::Direction(d) => d,
        };
        d.try_normalize().unwrap_or(Vec3::Z)
    }
}

/// A view: the world → camera matrix and an OpenGL-style camera → clip matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// World → camera (the camera looks down its −Z, +Y up).
    pub view: Mat4,
    /// Camera → clip space (OpenGL conventions, depth in `[−w, w]`).
    pub projection: Mat4,
    /// True for a perspective projection (headlight from the eye point rather than along −Z).
    pub perspective: bool,
}

impl View {
    /// A view from explicit matrices; the projection kind is read from the matrix.
    pub fn new(view: Mat4, projection: Mat4) -> View {
        View {
            view,
            projection,
            perspective: projection.w_axis.w.abs() < 1e-6,
        }
    }

    /// An orthographic view from `direction` that frames `bbox` with [`DEFAULT_FIT_MARGIN`]
    /// for an image of aspect `aspect` (width / height).
    ///
    /// An empty box frames the unit cube around the origin; a box reduced to a point frames
    /// a unit square around it.
    pub fn fit(bbox: Aabb, direction: ViewDirection, aspect: f32) -> View {
        let bbox = if bbox.is_empty() || !bbox.min.is_finite() || !bbox.max.is_finite() {
            Aabb {
                min: Vec3::splat(-0.5),
                max: Vec3::splat(0.5),
            }
        } else {
            bbox
        };
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let d = direction.eye_direction();
        let up = if d.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::NEG_Z * d.y.signum()
        } else {
            Vec3::Y
        };
        let center = bbox.center();
        let radius = bbox.diagonal().max(1e-6);
        let view = glam::camera::rh::view::look_at_mat4(center + d * radius, center, up);
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { bbox.min.x } else { bbox.max.x },
                if i & 2 == 0 { bbox.min.y } else { bbox.max.y },
                if i & 4 == 0 { bbox.min.z } else { bbox.max.z },
            );
            let p = view.transform_point3(c);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let mid = ((lo + hi) * 0.5).truncate();
        let mut half_w = (hi.x - lo.x) * 0.5;
        let mut half_h = (hi.y - lo.y) * 0.5;
        if half_w.max(half_h) <= 1e-9 * radius.max(1.0) {
            (half_w, half_h) = (0.5, 0.5);
        }
        let margin = 1.0 + 2.0 * DEFAULT_FIT_MARGIN;
        half_w *= margin;
        half_h *= margin;
        if half_w < half_h * aspect {
            half_w = half_h * aspect;
        } else {
            half_h = half_w / aspect;
        }
        let depth_pad = (hi.z - lo.z) * 0.05 + 1e-4 * radius;
        let projection = glam::camera::rh::proj::opengl::orthographic(
            mid.x - half_w,
            mid.x + half_w,
            mid.y - half_h,
            mid.y + half_h,
            -hi.z - depth_pad,
            -lo.z + depth_pad,
        );
        View {
            view,
            projection,
            perspective: false,
        }
    }

    /// The view of a scene camera at frame `frame` (clamped to its last frame) for an image
    /// of aspect `aspect` (width / height).
    pub fn camera(camera: &Camera, frame: usize, aspect: f32) -> View {
        View::new(camera.view(frame), camera.projection.matrix(aspect))
    }

    /// World → clip matrix.
    pub fn world_to_clip(&self) -> Mat4 {
        self.projection * self.view
    }

    /// Pixel coordinates (x right, y down, pixel centres at `k + 0.5`) and depth in
    /// `[0, 1]` of a world point on a `width × height` image; `None` behind the eye.
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> Option<Vec3> {
        let c = self.world_to_clip() * p.extend(1.0);
        if c.w <= 1e-12 {
            return None;
        }
        let n = c.xyz() / c.w;
        Some(Vec3::new(
            (n.x * 0.5 + 0.5) * width as f32,
            (0.5 - n.y * 0.5) * height as f32,
            n.z * 0.5 + 0.5,
        ))
    }
}

/// Bounding box of every frame of a point cache (for a view that holds the whole motion).
pub fn animation_bbox(animation: &anim::MeshAnimation) -> Aabb {
    Aabb::from_points(animation.positions())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Aabb {
        Aabb {
            min: Vec3::new(-1.0, -2.0, -0.5),
            max: Vec3::new(1.0, 2.0, 0.5),
        }
    }

    #[test]
    fn front_fit_frames_the_box_with_margin() {
        let v = View::fit(unit(), ViewDirection::Front, 1.0);
        let top = v.project(Vec3::new(0.0, 2.0, 0.0), 100, 100).unwrap();
        let bottom = v.project(Vec3::new(0.0, -2.0, 0.0), 100, 100).unwrap();
        let right = v.project(Vec3::new(1.0, 0.0, 0.0), 100, 100).unwrap();
        // Height 4 spans 100 / 1.12 pixels; the centre is the image centre.
        assert!(
            (bottom.y - top.y - 100.0 / 1.12).abs() < 1e-3,
            "{top} {bottom}"
        );
        assert!((right.x - 50.0 - 25.0 / 1.12).abs() < 1e-3, "{right}");
        // Nearer points have smaller depth, and all of the box is inside [0, 1].
        let near = v.project(Vec3::new(0.0, 0.0, 0.5), 100, 100).unwrap();
        let far = v.project(Vec3::new(0.0, 0.0, -0.5), 100, 100).unwrap();
        assert!(
            0.0 < near.z && near.z < far.z && far.z < 1.0,
            "{near} {far}"
        );
    }

    #[test]
    fn top_view_puts_front_at_the_bottom() {
        let v = View::fit(unit(), ViewDirection::Top, 1.0);
        let front = v.project(Vec3::new(0.0, 0.0, 0.5), 64, 64).unwrap();
        let back = v.project(Vec3::new(0.0, 0.0, -0.5), 64, 64).unwrap();
        assert!(front.y > back.y);
    }

    #[test]
    fn degenerate_boxes_give_finite_views() {
        for b in [
            Aabb::EMPTY,
            Aabb {
                min: Vec3::ONE,
                max: Vec3::ONE,
            },
        ] {
            let v = View::fit(b, ViewDirection::ThreeQuarter, 2.0);
            assert!(v.world_to_clip().is_finite());
            assert!(!v.perspective);
        }
    }

    #[test]
    fn camera_view_is_inverse_world() {
        let cam = Camera {
            name: "c".into(),
            projection: anim::Projection::Perspective {
                yfov: 1.0,
                aspect: None,
                znear: 0.1,
                zfar: Some(100.0),
            },
            world: vec![Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0))],
        };
        let v = View::camera(&cam, 3, 1.0);
        assert!(v.perspective);
        let p = v.project(Vec3::ZERO, 10, 10).unwrap();
        assert!((p.x - 5.0).abs() < 1e-4 && (p.y - 5.0).abs() < 1e-4);
        assert!(v.project(Vec3::new(0.0, 0.0, 10.0), 10, 10).is_none());
    }
}
