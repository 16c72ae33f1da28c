//! `toonkit.skin`: linear blend skinning of a whole clip from a host application's pose (its
//! bone matrices per frame), through `anim::skin_frames`.

use std::borrow::Cow;

use anim::glam::{Mat4, Vec3};
use anim::VertexWeights;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

use crate::arrays::{output, shape, values, ArrayIn};
use crate::errors::{anim_error, value_error};

/// Skins ``rest`` (float32 ``(vertices, 3)``) with ``matrices`` (float32 ``(frames, bones, 4,
/// 4)``, row-major, translation in column 3: each bone's skinning matrix, rest space to the
/// frame's space) and per-vertex influences ``indices`` (int ``(vertices, k)``, a bone index
/// or -1 for none) with ``weights`` (float32 ``(vertices, k)``). Weights are normalized to
/// sum 1 per vertex (non-positive ones dropped); a vertex without influence keeps its rest
/// position. Returns float32 ``(frames, vertices, 3)``, frame-major, ready for
/// ``Scene.from_arrays``. The GIL is released while skinning (parallel over frames).
///
/// >>> p = toonkit.skin(rest, indices, weights, matrices)
/// >>> p.shape == (len(matrices), len(rest), 3)
/// True
#[pyfunction]
#[pyo3(signature = (rest, indices, weights, matrices))]
pub(crate) fn skin<'py>(
    py: Python<'py>,
    rest: ArrayIn<'py, f32>,
    indices: ArrayIn<'py, i64>,
    weights: ArrayIn<'py, f32>,
    matrices: ArrayIn<'py, f32>,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let (data, frames, n) = skinned(py, &rest, &indices, &weights, &matrices)?;
    output(py, &[frames, n, 3], bytemuck::cast_vec::<Vec3, f32>(data))
}

/// The skinned clip of `toonkit.skin` (and of `Scene.from_arrays(skinning=...)`, which keeps
/// it as the scene's clip without a copy): frame-major points, the frame and vertex counts.
pub(crate) fn skinned(
    py: Python<'_>,
    rest: &ArrayIn<'_, f32>,
    indices: &ArrayIn<'_, i64>,
    weights: &ArrayIn<'_, f32>,
    matrices: &ArrayIn<'_, f32>,
) -> PyResult<(Vec<Vec3>, usize, usize)> {
    let n = shape(rest, "rest", &[None, Some(3)])?[0];
    let k = shape(indices, "indices", &[Some(n), None])?[1];
    shape(weights, "weights", &[Some(n), Some(k)])?;
    let m = shape(matrices, "matrices", &[None, None, Some(4), Some(4)])?;
    let (frames, bones) = (m[0], m[1]);
    check_clip(frames, n)?;
    let influences = influences(indices, weights, n, bones)?;
    let skinning = mat4s(matrices);
    let rest: Vec<Vec3> = values(rest).chunks_exact(3).map(Vec3::from_slice).collect();
    let mut data = zeroed_clip(frames, n);
    py.detach(|| anim::skin_frames(&influences, bones, &skinning, &rest, &mut data))
        .map_err(|e| anim_error("<arrays>", e))?;
    Ok((data, frames, n))
}

/// Checks a skinned clip of `frames` × `n` vertices against the job memory budget: the clip
/// is that size whatever the inputs' sizes, so it is checked before it is held.
pub(crate) fn check_clip(frames: usize, n: usize) -> PyResult<()> {
    anim::budget::JobMemory::new()
        .positions("skinned clip", frames, n, 1)
        .check("skin fewer frames or vertices")
        .map_err(|e| anim_error("<arrays>", e.into()))
}

/// A clip of `frames` × `n` points to skin into: zeroed f32s (fresh pages from the
/// allocator, mapped by the frames' writes, no pass over them) seen as points.
pub(crate) fn zeroed_clip(frames: usize, n: usize) -> Vec<Vec3> {
    bytemuck::cast_vec(vec![0.0f32; frames * n * 3])
}

/// The influences of `toonkit.skin` (``indices`` and ``weights``, ``(vertices, k)`` each, a
/// bone index or -1 per slot), checked against `n` vertices and `bones` matrices per frame.
pub(crate) fn influences(
    indices: &ArrayIn<'_, i64>,
    weights: &ArrayIn<'_, f32>,
    n: usize,
    bones: usize,
) -> PyResult<VertexWeights> {
    let (k, idx, w) = checked_influences(indices, weights, n, bones)?;
    Ok(weights_of(&idx, &w, k, n))
}

/// Slots per vertex, indices and weights of `toonkit.skin`'s influences.
pub(crate) type Influences<'a> = (usize, Cow<'a, [i64]>, Cow<'a, [f32]>);

/// The slots per vertex and the values of `influences`' inputs, checked, for
/// [`weights_of`] (on another thread, without the GIL).
pub(crate) fn checked_influences<'a>(
    indices: &'a ArrayIn<'_, i64>,
    weights: &'a ArrayIn<'_, f32>,
    n: usize,
    bones: usize,
) -> PyResult<Influences<'a>> {
    let k = shape(indices, "indices", &[Some(n), None])?[1];
    shape(weights, "weights", &[Some(n), Some(k)])?;
    let (idx, w) = (values(indices), values(weights));
    if let Some((i, &b)) = idx
        .iter()
        .enumerate()
        .find(|(_, &b)| b < -1 || b >= bones as i64)
    {
        return Err(value_error(format!(
            "indices[{}, {}] = {b}: a bone index must be -1 or below {bones}",
            i / k.max(1),
            i % k.max(1)
        )));
    }
    Ok((k, idx, w))
}

/// The influences of `n` vertices with `k` slots each (indices checked, -1 for none).
pub(crate) fn weights_of(idx: &[i64], w: &[f32], k: usize, n: usize) -> VertexWeights {
    VertexWeights::from_influences(idx.chunks(k.max(1)).zip(w.chunks(k.max(1))).take(n).map(
        |(i, w)| {
            i.iter()
                .zip(w)
                .filter(|(b, _)| **b >= 0)
                .map(|(b, x)| (*b as u32, *x))
        },
    ))
}

/// ``(..., 4, 4)`` row-major float32 matrices (translation in column 3) as glam's.
pub(crate) fn mat4s(matrices: &ArrayIn<'_, f32>) -> Vec<Mat4> {
    values(matrices)
        .chunks_exact(16)
        .map(|m| Mat4::from_cols_slice(m).transpose())
        .collect()
}
