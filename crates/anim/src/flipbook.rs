//! Flipbooks: several animated parts with the same frames, some with a topology that changes
//! per frame (e.g. motion lines) — what stylization results are, and what `tkio::save`
//! writes and `render` previews.

use crate::{Curves, Mesh, MeshAnimation};
use glam::Vec3;

/// One part of a [`Flipbook`].
// A flipbook has a handful of parts: the size of the inline point cache does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum FlipbookPart {
    /// A fixed-topology animation with optional per-frame RGBA vertex colours (frame-major,
    /// `frames × vertices`, linear RGB and alpha).
    Animation {
        /// The point cache.
        animation: MeshAnimation,
        /// Per-frame vertex colours.
        colors: Option<Vec<[f32; 4]>>,
    },
    /// One mesh per frame, whose topology may change from frame to frame; an empty mesh
    /// (no triangles) shows nothing at that frame.
    Frames {
        /// Name of the part.
        name: String,
        /// One mesh per frame.
        meshes: Vec<Mesh>,
        /// The same frames as curves when the meshes are tubes swept along them (motion
        /// lines): scene files that hold curves write these instead of the tubes.
        curves: Option<Vec<Curves>>,
        /// Velocity of every vertex of every frame's mesh (units per frame, one per vertex of
        /// that frame's mesh), for scene files that carry motion (USD `velocities`): a
        /// subdivided smear's vertices move along the smear although their count changes.
        velocities: Option<Vec<Vec<Vec3>>>,
    },
}

impl FlipbookPart {
    /// The part's name (the animation's mesh name, or the frames' name).
    pub fn name(&self) -> &str {
        match self {
            FlipbookPart::Animation { animation, .. } => &animation.mesh.name,
            FlipbookPart::Frames { name, .. } => name,
        }
    }
}

/// Parts that play together: `frames` frames at `fps`.
#[derive(Debug, Clone, Default)]
pub struct Flipbook {
    /// Frames per second.
    pub fps: f32,
    /// Number of frames.
    pub frames: usize,
    /// The parts, in drawing order.
    pub parts: Vec<FlipbookPart>,
}
