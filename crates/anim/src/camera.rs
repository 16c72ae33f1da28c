//! Cameras: projection and per-frame world transform.

use glam::camera::rh::proj::opengl;
use glam::Mat4;

/// A camera projection (glTF conventions: the camera looks down its local −Z, +Y up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Perspective projection.
    Perspective {
        /// Vertical field of view in radians.
        yfov: f32,
        /// Width / height; `None` means the viewport's.
        aspect: Option<f32>,
        /// Near plane distance.
        znear: f32,
        /// Far plane distance; `None` means infinite.
        zfar: Option<f32>,
    },
    /// Orthographic projection.
    Orthographic {
        /// Half width of the view volume.
        xmag: f32,
        /// Half height of the view volume.
        ymag: f32,
        /// Near plane distance.
        znear: f32,
        /// Far plane distance.
        zfar: f32,
    },
}

impl Projection {
    /// The OpenGL-style clip matrix for a viewport of the given aspect ratio.
    pub fn matrix(&self, viewport_aspect: f32) -> Mat4 {
        match *self {
            Projection::Perspective {
                yfov,
                aspect,
                znear,
                zfar,
            } => {
                let a = aspect.unwrap_or(viewport_aspect);
                match zfar {
                    Some(f) => opengl::perspective(yfov, a, znear, f),
                    None => opengl::perspective(yfov, a, znear, znear * 1e6),
                }
            }
            Projection::Orthographic {
                xmag,
                ymag,
                znear,
                zfar,
            } => opengl::orthographic(-xmag, xmag, -ymag, ymag, znear, zfar),
        }
    }
}

/// A camera over a sampled clip: a projection and a world matrix per frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Camera (node) name.
    pub name: String,
    /// Projection.
    pub projection: Projection,
    /// World matrix per frame.
    pub world: Vec<Mat4>,
}

impl Camera {
    /// World-to-camera matrix of frame `f` (clamped to the last frame).
    pub fn view(&self, f: usize) -> Mat4 {
        let m = self
            .world
            .get(f)
            .or(self.world.last())
            .copied()
            .unwrap_or(Mat4::IDENTITY);
        m.inverse()
    }
}
