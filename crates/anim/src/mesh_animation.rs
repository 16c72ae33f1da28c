//! Point caches: one topology, positions for every frame.

use glam::Vec3;
use rayon::prelude::*;

use crate::{Aabb, AnimError, Mesh, Result};

/// Default sampling rate in frames per second (SPEC.md).
pub const DEFAULT_FPS: f32 = 24.0;

/// A deforming mesh with fixed topology: `frames × vertices` positions, frame-major in one
/// contiguous buffer.
///
/// `mesh.positions` holds the rest (or first-frame) positions; the per-frame positions live in
/// the cache. Frame `k` is at time `start_time + k / fps`.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshAnimation {
    /// Topology, attributes and rest positions.
    pub mesh: Mesh,
    /// Frames per second.
    pub fps: f32,
    /// Time of frame 0 in seconds.
    pub start_time: f32,
    positions: Vec<Vec3>,
}

impl MeshAnimation {
    /// A cache from a frame-major position buffer.
    ///
    /// # Errors
    /// When the buffer length is not a multiple of the vertex count, when there are no frames,
    /// or when a position is not finite.
    pub fn new(mesh: Mesh, fps: f32, positions: Vec<Vec3>) -> Result<MeshAnimation> {
        let n = mesh.vertex_count();
        if n == 0 && !positions.is_empty() || n > 0 && !positions.len().is_multiple_of(n) {
            return Err(AnimError::LengthMismatch {
                what: format!("point cache of '{}'", mesh.name),
                expected: n * (positions.len() / n.max(1)),
                found: positions.len(),
            });
        }
        if !all_finite(&positions) {
            return Err(AnimError::NonFinite {
                what: format!("point cache of '{}'", mesh.name),
            });
        }
        if !(fps.is_finite() && fps > 0.0) {
            return Err(AnimError::Invalid(format!(
                "frame rate must be positive, got {fps}"
            )));
        }
        Ok(MeshAnimation {
            mesh,
            fps,
            start_time: 0.0,
            positions,
        })
    }

    /// [`MeshAnimation::new`] for a buffer its producer already checked: whole frames of
    /// finite positions, a positive frame rate (the sampler checks each frame while it is in
    /// cache, instead of a second pass over the whole buffer).
    pub(crate) fn from_finite(mesh: Mesh, fps: f32, positions: Vec<Vec3>) -> MeshAnimation {
        debug_assert!(
            positions.len().is_multiple_of(mesh.vertex_count().max(1))
                && fps.is_finite()
                && fps > 0.0
        );
        MeshAnimation {
            mesh,
            fps,
            start_time: 0.0,
            positions,
        }
    }

    /// A one-frame cache holding the mesh's own positions.
    pub fn still(mesh: Mesh) -> MeshAnimation {
        let positions = mesh.positions.clone();
        MeshAnimation {
            mesh,
            fps: DEFAULT_FPS,
            start_time: 0.0,
            positions,
        }
    }

    /// Number of vertices per frame.
    pub fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    /// Number of frames (a mesh with no vertex has 1 frame by convention when built by
    /// [`MeshAnimation::still`]).
    pub fn frame_count(&self) -> usize {
        match self.vertex_count() {
            0 => 1,
            n => self.positions.len() / n,
        }
    }

    /// Positions of frame `f`.
    ///
    /// # Panics
    /// If `f >= frame_count()`.
    pub fn frame(&self, f: usize) -> &[Vec3] {
        let n = self.vertex_count();
        &self.positions[f * n..(f + 1) * n]
    }

    /// Mutable positions of frame `f`.
    pub fn frame_mut(&mut self, f: usize) -> &mut [Vec3] {
        let n = self.vertex_count();
        &mut self.positions[f * n..(f + 1) * n]
    }

    /// Iterator over frames.
    pub fn frames(&self) -> impl ExactSizeIterator<Item = &[Vec3]> + '_ {
        self.positions.chunks_exact(self.vertex_count().max(1))
    }

    /// Parallel iterator over mutable frames, with their index.
    pub fn par_frames_mut(&mut self) -> impl IndexedParallelIterator<Item = (usize, &mut [Vec3])> {
        let n = self.vertex_count().max(1);
        self.positions.par_chunks_mut(n).enumerate()
    }

    /// The whole frame-major buffer.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The whole frame-major buffer, mutable.
    pub fn positions_mut(&mut self) -> &mut [Vec3] {
        &mut self.positions
    }

    /// Consumes the cache, returning the mesh and the buffer.
    pub fn into_parts(self) -> (Mesh, Vec<Vec3>) {
        (self.mesh, self.positions)
    }

    /// Time of frame `f` in seconds.
    pub fn time_of(&self, f: usize) -> f32 {
        self.start_time + f as f32 / self.fps
    }

    /// Duration from first to last frame in seconds.
    pub fn duration(&self) -> f32 {
        (self.frame_count().saturating_sub(1)) as f32 / self.fps
    }

    /// Bounding box over all frames.
    pub fn bbox(&self) -> Aabb {
        self.positions
            .par_chunks(4096)
            .map(Aabb::from_points)
            .reduce(|| Aabb::EMPTY, Aabb::union)
    }

    /// The mesh with the positions of frame `f`.
    pub fn mesh_at(&self, f: usize) -> Mesh {
        let mut m = self.mesh.clone();
        m.positions = self.frame(f).to_vec();
        m
    }

    /// Per-vertex average position over all frames (the "average mesh" of StopShop).
    pub fn average_positions(&self) -> Vec<Vec3> {
        let n = self.vertex_count();
        let frames = self.frame_count() as f64;
        (0..n)
            .into_par_iter()
            .map(|v| {
                let mut acc = glam::DVec3::ZERO;
                for f in self.frames() {
                    acc += f[v].as_dvec3();
                }
                (acc / frames).as_vec3()
            })
            .collect()
    }

    /// Concatenates several caches with the same frame count into one (vertex order = order
    /// of `parts`).
    ///
    /// # Errors
    /// When the frame counts differ.
    pub fn concat(name: &str, parts: &[MeshAnimation]) -> Result<MeshAnimation> {
        let Some(first) = parts.first() else {
            return Err(AnimError::Invalid("no mesh to combine".into()));
        };
        let frames = first.frame_count();
        let mut mesh = Mesh {
            name: name.to_string(),
            ..Mesh::default()
        };
        for p in parts {
            if p.frame_count() != frames {
                return Err(AnimError::LengthMismatch {
                    what: format!("frames of mesh '{}'", p.mesh.name),
                    expected: frames,
                    found: p.frame_count(),
                });
            }
            mesh.append(&p.mesh);
        }
        let n = mesh.vertex_count();
        let mut positions = Vec::with_capacity(n * frames);
        for f in 0..frames {
            for p in parts {
                positions.extend_from_slice(p.frame(f));
            }
        }
        Ok(MeshAnimation {
            mesh,
            fps: first.fps,
            start_time: first.start_time,
            positions,
        })
    }
}

/// Whether every coordinate of `positions` is finite: runs of coordinates tested without
/// stopping early (so the test vectorizes), the runs stopping at the first that is not.
fn all_finite(positions: &[Vec3]) -> bool {
    let x: &[f32] = bytemuck::cast_slice(positions);
    x.chunks(1024)
        .all(|run| run.iter().fold(true, |ok, c| ok & c.is_finite()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Mesh {
        Mesh::new("t", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
    }

    #[test]
    fn frames_are_contiguous() {
        let pos: Vec<Vec3> = (0..6).map(|i| Vec3::splat(i as f32)).collect();
        let a = MeshAnimation::new(tri(), 24.0, pos).unwrap();
        assert_eq!(a.frame_count(), 2);
        assert_eq!(a.frame(1)[0], Vec3::splat(3.0));
        assert_eq!(a.average_positions()[0], Vec3::splat(1.5));
    }

    #[test]
    fn wrong_length_and_nan_are_errors() {
        assert!(MeshAnimation::new(tri(), 24.0, vec![Vec3::ZERO; 4]).is_err());
        assert!(MeshAnimation::new(tri(), 24.0, vec![Vec3::NAN; 3]).is_err());
        // One coordinate anywhere in a long cache (past the first run tested at once).
        for (k, bad) in [
            (0, f32::INFINITY),
            (1000, f32::NAN),
            (3 * 999 + 2, f32::NEG_INFINITY),
        ] {
            let mut p = vec![Vec3::ONE; 3 * 1000];
            p[k / 3][k % 3] = bad;
            assert!(MeshAnimation::new(tri(), 24.0, p).is_err(), "{k}");
        }
        assert!(MeshAnimation::new(tri(), 24.0, vec![Vec3::ONE; 3 * 1000]).is_ok());
    }

    #[test]
    fn concat_interleaves_per_frame() {
        let a = MeshAnimation::new(tri(), 24.0, vec![Vec3::ZERO; 6]).unwrap();
        let b = MeshAnimation::new(tri(), 24.0, vec![Vec3::ONE; 6]).unwrap();
        let c = MeshAnimation::concat("ab", &[a, b]).unwrap();
        assert_eq!(c.vertex_count(), 6);
        assert_eq!(c.frame(1)[3], Vec3::ONE);
        assert_eq!(c.frame(1)[2], Vec3::ZERO);
    }
}
