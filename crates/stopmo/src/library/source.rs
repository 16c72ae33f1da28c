//! A part's frames as the solver reads them: positions, or morph weights expanded on demand.
//!
//! A morph-target clip on a still node is `x_f = b + T w_f` ([`MorphAnimation`]); the solver
//! reduces it exactly from the K × K Gram matrix of the targets (the `problem` module) and
//! expands frames only where a quantity is not a quadratic form: the reported per-frame
//! vertex distances and the bounding box, in streamed blocks (one GEMM of weights by targets
//! each), so the clip is never held as positions (`docs/stopmo-scale.md`).

use std::borrow::Cow;

use anim::{Aabb, Mesh, MeshAnimation, MeshFrames, MorphAnimation};
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use glam::Vec3;
use rayon::prelude::*;

/// Bytes of one expanded block of morph frames (small in unit tests, so that they cross
/// blocks).
const EXPAND_BYTES: usize = if cfg!(test) { 4096 } else { 16 << 20 };

/// A part's frames, borrowed.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Source<'a> {
    /// Positions of every frame.
    Positions(&'a MeshAnimation),
    /// Morph weights on a still node.
    Morph(&'a MorphAnimation),
}

impl<'a> Source<'a> {
    /// The source of `frames`.
    pub(crate) fn of(frames: &'a MeshFrames) -> Source<'a> {
        match frames {
            MeshFrames::Positions(a) => Source::Positions(a),
            MeshFrames::Morph(a) => Source::Morph(a),
        }
    }

    /// Topology and first-frame positions.
    pub(crate) fn mesh(&self) -> &'a Mesh {
        match self {
            Source::Positions(a) => &a.mesh,
            Source::Morph(a) => &a.mesh,
        }
    }

    pub(crate) fn frame_count(&self) -> usize {
        match self {
            Source::Positions(a) => a.frame_count(),
            Source::Morph(a) => a.frame_count(),
        }
    }

    pub(crate) fn vertex_count(&self) -> usize {
        match self {
            Source::Positions(a) => a.vertex_count(),
            Source::Morph(a) => a.vertex_count(),
        }
    }

    /// Positions of frame `f` (borrowed, or expanded).
    pub(crate) fn frame(&self, f: usize) -> Cow<'a, [Vec3]> {
        match self {
            Source::Positions(a) => Cow::Borrowed(a.frame(f)),
            Source::Morph(a) => {
                let mut out = vec![Vec3::ZERO; a.vertex_count()];
                a.frame_into(f, &mut out);
                Cow::Owned(out)
            }
        }
    }

    /// Calls `each(f0, frames)` for consecutive blocks of frames (frame-major positions,
    /// `frames.len() / vertices` frames from `f0`): the whole clip at once for positions,
    /// expanded blocks of a few MiB for morph weights.
    pub(crate) fn blocks(&self, mut each: impl FnMut(usize, &[Vec3])) {
        match self {
            Source::Positions(a) => each(0, a.positions()),
            Source::Morph(a) => {
                let (n, m) = (a.frame_count(), a.vertex_count().max(1));
                let step = (EXPAND_BYTES / (12 * m)).clamp(1, n.max(1));
                let mut buf = vec![Vec3::ZERO; step * m];
                for f0 in (0..n).step_by(step) {
                    let k = step.min(n - f0);
                    expand(a, f0, &mut buf[..k * m]);
                    each(f0, &buf[..k * m]);
                }
            }
        }
    }

    /// Bounding box over all frames.
    pub(crate) fn bbox(&self) -> Aabb {
        match self {
            Source::Positions(a) => a.bbox(),
            Source::Morph(_) => {
                let mut b = Aabb::EMPTY;
                self.blocks(|_, x| {
                    let part = x
                        .par_chunks(4096)
                        .map(Aabb::from_points)
                        .reduce(|| Aabb::EMPTY, Aabb::union);
                    b = b.union(part);
                });
                b
            }
        }
    }
}

/// Frames `f0..` of `a` into `out` (whole frames): `b + T w_f` as one f32 GEMM of the
/// block's weights by the targets.
pub(crate) fn expand(a: &MorphAnimation, f0: usize, out: &mut [Vec3]) {
    let (m, k) = (a.vertex_count(), a.target_count());
    let rows = out.len() / m.max(1);
    out.par_chunks_mut(m.max(1))
        .for_each(|o| o.copy_from_slice(a.base()));
    if k == 0 || m == 0 || rows == 0 {
        return;
    }
    let t: &[f32] = bytemuck::cast_slice(a.targets());
    let o: &mut [f32] = bytemuck::cast_slice_mut(out);
    let par = match rayon::current_num_threads() {
        0 | 1 => Par::Seq,
        n => Par::rayon(n),
    };
    matmul(
        MatMut::from_row_major_slice_mut(o, rows, 3 * m),
        Accum::Add,
        MatRef::from_row_major_slice(&a.weights()[f0 * k..(f0 + rows) * k], rows, k),
        MatRef::from_row_major_slice(t, k, 3 * m),
        1.0f32,
        par,
    );
}
