//! `toonkit.SkinStream`: `toonkit.skin` fed a few frames at a time, skinning on a worker
//! thread while the host reads the next frames (docs/blender.md, "Speed": Blender's frame
//! loop runs on one core, the skinning on the other).

use std::sync::mpsc::{channel, Sender};
use std::thread::JoinHandle;

use anim::glam::{Mat4, Vec3};
use anim::AnimError;
use pyo3::prelude::*;

use crate::arrays::{shape, values, ArrayIn};
use crate::errors::{anim_error, value_error};
use crate::skin_py::{check_clip, checked_influences, mat4s, weights_of, zeroed_clip};

/// What the worker returns: the skinned clip, frame-major.
type Skinned = Result<Vec<Vec3>, AnimError>;

/// The worker skinning the frames pushed so far.
struct Worker {
    /// Matrices of the next frames (frame-major, `bones` per frame); dropped to finish.
    frames: Sender<Vec<Mat4>>,
    handle: JoinHandle<Skinned>,
}

/// Skins a clip (the arguments of ``toonkit.skin`` but the matrices) as its frames' matrices
/// arrive: ``push`` hands over the next frames' ``(k, bones, 4, 4)`` float32 matrices and
/// returns at once, a worker thread skins them (``anim::skin_frames``, the same values as
/// ``toonkit.skin``) while the caller goes on; ``Scene.from_arrays(None, ...,
/// skinning=stream)`` waits for the last frame and keeps the clip without a copy. The clip
/// (``frames × vertices``) is checked against the job memory budget when the stream is made.
///
/// >>> s = toonkit.SkinStream(rest, indices, weights, frames=len(m), bones=m.shape[1])
/// >>> s.push(m[:8]); s.push(m[8:])
/// >>> scene = toonkit.Scene.from_arrays(None, triangles, skinning=s)
#[pyclass(module = "toonkit", name = "SkinStream")]
pub(crate) struct SkinStream {
    worker: Option<Worker>,
    frames: usize,
    vertices: usize,
    bones: usize,
    pushed: usize,
}

#[pymethods]
impl SkinStream {
    #[new]
    #[pyo3(signature = (rest, indices, weights, frames, bones))]
    fn new(
        rest: ArrayIn<'_, f32>,
        indices: ArrayIn<'_, i64>,
        weights: ArrayIn<'_, f32>,
        frames: usize,
        bones: usize,
    ) -> PyResult<SkinStream> {
        let n = shape(&rest, "rest", &[None, Some(3)])?[0];
        check_clip(frames, n)?;
        let (k, idx, w) = checked_influences(&indices, &weights, n, bones)?;
        let (idx, w, rest) = (idx.into_owned(), w.into_owned(), values(&rest).into_owned());
        let (frames_in, received) = channel::<Vec<Mat4>>();
        // The influences are built on the worker too: the caller goes on reading frames.
        let handle = std::thread::spawn(move || -> Skinned {
            let weights = weights_of(&idx, &w, k, n);
            let rest: Vec<Vec3> = rest.chunks_exact(3).map(Vec3::from_slice).collect();
            let mut clip = zeroed_clip(frames, n);
            let mut done = 0;
            for m in received {
                let k = m.len() / bones.max(1);
                let out = &mut clip[done * n..(done + k) * n];
                anim::skin_frames(&weights, bones, &m, &rest, out)?;
                done += k;
            }
            Ok(clip)
        });
        Ok(SkinStream {
            worker: Some(Worker {
                frames: frames_in,
                handle,
            }),
            frames,
            vertices: n,
            bones,
            pushed: 0,
        })
    }

    /// Skins the next frames: ``matrices`` float32 ``(k, bones, 4, 4)``, row-major (as
    /// ``toonkit.skin``'s). Returns before they are skinned.
    fn push(&mut self, matrices: ArrayIn<'_, f32>) -> PyResult<()> {
        let k = shape(
            &matrices,
            "matrices",
            &[None, Some(self.bones), Some(4), Some(4)],
        )?[0];
        if self.pushed + k > self.frames {
            return Err(value_error(format!(
                "the skin stream takes {} frames; {} were pushed, {k} more is too many",
                self.frames, self.pushed
            )));
        }
        let worker = self.worker.as_ref().ok_or_else(used)?;
        // A send fails only when the worker stopped on an error, which `finish` reports.
        let _ = worker.frames.send(mat4s(&matrices));
        self.pushed += k;
        Ok(())
    }
}

impl SkinStream {
    /// Waits for the worker and takes the skinned clip: frame-major points, the frame and
    /// vertex counts. A stream takes its clip once.
    pub(crate) fn finish(&mut self, py: Python<'_>) -> PyResult<(Vec<Vec3>, usize, usize)> {
        if self.worker.is_some() && self.pushed != self.frames {
            return Err(value_error(format!(
                "the skin stream got {} of its {} frames; push the others first",
                self.pushed, self.frames
            )));
        }
        let Worker { frames, handle } = self.worker.take().ok_or_else(used)?;
        drop(frames);
        let clip = py
            .detach(|| handle.join())
            .map_err(|_| value_error("the skinning worker panicked"))?
            .map_err(|e| anim_error("<arrays>", e))?;
        Ok((clip, self.frames, self.vertices))
    }
}

/// The error of a stream whose clip `Scene.from_arrays` already took.
fn used() -> PyErr {
    value_error("the skin stream was already used by Scene.from_arrays")
}
