//! A morph-target clip kept as its weights: frame `f` is `base + Σₖ w_fk · targetₖ`.
//!
//! A mesh whose only animation is its morph weights, on a node that does not move, is fully
//! described by its world-space rest positions, its K world-space target displacements and
//! `frames × K` weights: a 10,000-frame face of 9,409 vertices and 55 targets is 2 MiB of
//! weights instead of 1,077 MiB of positions (`docs/stopmo-scale.md`).

use glam::Vec3;

use crate::{AnimError, Mesh, MeshAnimation, Result};

/// A morph-target clip on a still node, as weights (see the module).
#[derive(Debug, Clone, PartialEq)]
pub struct MorphAnimation {
    /// Topology and attributes; `positions` holds frame 0 (as a sampled cache's mesh does).
    pub mesh: Mesh,
    /// Frames per second.
    pub fps: f32,
    /// Time of frame 0 in seconds.
    pub start_time: f32,
    base: Vec<Vec3>,
    targets: Vec<Vec3>,
    weights: Vec<f32>,
}

impl MorphAnimation {
    /// A clip from world-space rest positions `base` (one per vertex of `mesh`), world-space
    /// displacements `targets` (target-major, `K × vertices`) and frame-major weights
    /// (`frames × K`). `mesh.positions` becomes frame 0.
    ///
    /// # Errors
    /// Lengths that disagree, no frame, a value that is not finite, or a frame rate that is
    /// not positive.
    pub fn new(
        mut mesh: Mesh,
        fps: f32,
        base: Vec<Vec3>,
        targets: Vec<Vec3>,
        weights: Vec<f32>,
    ) -> Result<MorphAnimation> {
        let m = mesh.vertex_count();
        let what = || format!("morph weights of '{}'", mesh.name);
        if base.len() != m || !targets.len().is_multiple_of(m.max(1)) {
            return Err(AnimError::LengthMismatch {
                what: what(),
                expected: m,
                found: base.len(),
            });
        }
        let k = targets.len().checked_div(m).unwrap_or(0);
        if weights.is_empty() || k > 0 && !weights.len().is_multiple_of(k) {
            return Err(AnimError::LengthMismatch {
                what: what(),
                expected: k.max(1),
                found: weights.len(),
            });
        }
        let finite = base.iter().chain(&targets).all(|p| p.is_finite())
            && weights.iter().all(|w| w.is_finite());
        if !finite {
            return Err(AnimError::NonFinite { what: what() });
        }
        if !(fps.is_finite() && fps > 0.0) {
            return Err(AnimError::Invalid(format!(
                "frame rate must be positive, got {fps}"
            )));
        }
        let mut a = MorphAnimation {
            mesh: Mesh::default(),
            fps,
            start_time: 0.0,
            base,
            targets,
            weights,
        };
        mesh.positions = vec![Vec3::ZERO; m];
        a.frame_into(0, &mut mesh.positions);
        a.mesh = mesh;
        Ok(a)
    }

    /// Number of vertices per frame.
    pub fn vertex_count(&self) -> usize {
        self.base.len()
    }

    /// Number of morph targets K.
    pub fn target_count(&self) -> usize {
        self.targets
            .len()
            .checked_div(self.vertex_count())
            .unwrap_or(0)
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        // Without targets every frame is the base: the weights hold one 0 per frame.
        match self.target_count() {
            0 => self.weights.len(),
            k => self.weights.len() / k,
        }
    }

    /// World-space rest positions.
    pub fn base(&self) -> &[Vec3] {
        &self.base
    }

    /// World-space displacements, target-major (`K × vertices`).
    pub fn targets(&self) -> &[Vec3] {
        &self.targets
    }

    /// Frame-major weights (`frames × K`).
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// Weights of frame `f` (K values).
    pub fn frame_weights(&self, f: usize) -> &[f32] {
        let k = self.target_count();
        &self.weights[f * k..(f + 1) * k]
    }

    /// Positions of frame `f` into `out` (one per vertex): the base plus every active target
    /// in target order, as the sampler adds them.
    pub fn frame_into(&self, f: usize, out: &mut [Vec3]) {
        out.copy_from_slice(&self.base);
        let m = self.vertex_count();
        for (t, &w) in self.frame_weights(f).iter().enumerate() {
            if w != 0.0 {
                for (o, d) in out.iter_mut().zip(&self.targets[t * m..(t + 1) * m]) {
                    *o += w * *d;
                }
            }
        }
    }

    /// The weights averaged over the frames, `w̄` (summed in f64, then divided).
    pub fn mean_weights(&self) -> Vec<f64> {
        let (n, k) = (self.frame_count(), self.target_count());
        let mut wbar = vec![0.0f64; k];
        for f in 0..n {
            for (a, &w) in wbar.iter_mut().zip(self.frame_weights(f)) {
                *a += f64::from(w);
            }
        }
        wbar.iter_mut().for_each(|v| *v /= n as f64);
        wbar
    }

    /// The average frame `b + T w̄` as a one-frame animation with the clip's topology and
    /// timing (positions summed in f64).
    ///
    /// # Errors
    /// [`AnimError`] when the average is not finite.
    pub fn average_frame(&self) -> Result<MeshAnimation> {
        let m = self.vertex_count();
        let wbar = self.mean_weights();
        let average: Vec<Vec3> = (0..m)
            .map(|v| {
                let mut p = self.base[v].as_dvec3();
                for (j, &w) in wbar.iter().enumerate() {
                    p += self.targets[j * m + v].as_dvec3() * w;
                }
                p.as_vec3()
            })
            .collect();
        let mut a = MeshAnimation::new(self.mesh.clone(), self.fps, average)?;
        a.start_time = self.start_time;
        Ok(a)
    }

    /// The clip expanded into positions (every frame by [`MorphAnimation::frame_into`]).
    pub fn to_positions(&self) -> MeshAnimation {
        let m = self.vertex_count();
        let mut positions = vec![Vec3::ZERO; self.frame_count() * m];
        for (f, out) in positions.chunks_exact_mut(m.max(1)).enumerate() {
            self.frame_into(f, out);
        }
        let mut a = MeshAnimation::from_finite(self.mesh.clone(), self.fps, positions);
        a.start_time = self.start_time;
        a
    }
}

/// A mesh's frames as positions or, for a morph-only clip on a still node, as weights.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshFrames {
    /// Positions of every frame.
    Positions(MeshAnimation),
    /// Morph weights (see [`MorphAnimation`]).
    Morph(MorphAnimation),
}

impl MeshFrames {
    /// Topology, attributes and first-frame (or rest) positions.
    pub fn mesh(&self) -> &Mesh {
        match self {
            MeshFrames::Positions(a) => &a.mesh,
            MeshFrames::Morph(a) => &a.mesh,
        }
    }

    /// The mesh, mutable (to rename it).
    pub fn mesh_mut(&mut self) -> &mut Mesh {
        match self {
            MeshFrames::Positions(a) => &mut a.mesh,
            MeshFrames::Morph(a) => &mut a.mesh,
        }
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        match self {
            MeshFrames::Positions(a) => a.frame_count(),
            MeshFrames::Morph(a) => a.frame_count(),
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        match self {
            MeshFrames::Positions(a) => a.vertex_count(),
            MeshFrames::Morph(a) => a.vertex_count(),
        }
    }
}
