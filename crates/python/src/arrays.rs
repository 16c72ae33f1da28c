//! numpy in and out: inputs are read in place when they are C-contiguous with the right dtype
//! (numpy converts other layouts and dtypes once); outputs hand their Rust buffer to numpy
//! without copying.

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{
    AllowTypeChange, Element, IntoPyArray, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use crate::errors::value_error;

/// An input array of element type `T` (any array-like numpy can convert).
pub(crate) type ArrayIn<'py, T> = PyArrayLikeDyn<'py, T, AllowTypeChange>;

/// The shape of `a`, checked against `expected` (`None` = any extent) and naming `what` in
/// the error.
pub(crate) fn shape<T: Element>(
    a: &ArrayIn<'_, T>,
    what: &str,
    expected: &[Option<usize>],
) -> PyResult<Vec<usize>> {
    let s = a.shape().to_vec();
    let fits = s.len() == expected.len()
        && s.iter()
            .zip(expected)
            .all(|(n, e)| e.is_none_or(|e| e == *n));
    if !fits {
        let want: Vec<String> = expected
            .iter()
            .enumerate()
            .map(|(i, e)| e.map_or(format!("n{i}"), |e| e.to_string()))
            .collect();
        return Err(value_error(format!(
            "{what} must have shape ({}), got {s:?}",
            want.join(", ")
        )));
    }
    Ok(s)
}

/// The values of `a` in C order, borrowed when contiguous.
pub(crate) fn values<'a, T: Element + Copy>(a: &'a ArrayIn<'_, T>) -> std::borrow::Cow<'a, [T]> {
    match a.as_slice() {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => std::borrow::Cow::Owned(
            c_order_copy(a).unwrap_or_else(|| a.as_array().iter().copied().collect()),
        ),
    }
}

/// A strided array's values in C order through numpy's own copy: ~20× faster than
/// ndarray's iterator over dynamic dimensions (a broadcast `(15002, 10)` index array took
/// ~7 ms that way, docs/blender.md "Speed").
fn c_order_copy<T: Element + Copy>(a: &ArrayIn<'_, T>) -> Option<Vec<T>> {
    let copy = a
        .call_method0("copy")
        .ok()?
        .cast_into::<PyArrayDyn<T>>()
        .ok()?;
    let copy = copy.try_readonly().ok()?;
    copy.as_slice().ok().map(<[T]>::to_vec)
}

/// A numpy array of `shape` owning `data` (no copy).
pub(crate) fn output<'py, T: Element>(
    py: Python<'py>,
    shape: &[usize],
    data: Vec<T>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), data)
        .map_err(|e| value_error(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// [`output`], then marked read-only (arrays a result keeps and returns on every access).
pub(crate) fn frozen<'py, T: Element>(
    py: Python<'py>,
    shape: &[usize],
    data: Vec<T>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let a = output(py, shape, data)?;
    a.call_method1("setflags", (false,))?;
    Ok(a)
}

/// Flattens 3D points into `[x, y, z, …]` (one copy of their memory).
pub(crate) fn flat3(points: &[glam::Vec3]) -> Vec<f32> {
    bytemuck::cast_slice(points).to_vec()
}

/// int32 ``(t, 3)``: the triangles of `mesh`.
pub(crate) fn triangles<'py>(
    py: Python<'py>,
    mesh: &anim::Mesh,
) -> PyResult<Bound<'py, PyArrayDyn<i32>>> {
    let t: Vec<i32> = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(|i| i as i32))
        .collect();
    output(py, &[mesh.triangles.len(), 3], t)
}

/// float32 ``(v, 3)``: `points`.
pub(crate) fn points_array<'py>(
    py: Python<'py>,
    points: &[glam::Vec3],
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    output(py, &[points.len(), 3], flat3(points))
}

/// float32 ``(frames, v, 3)``: every frame's positions of `anim`.
pub(crate) fn frames_array<'py>(
    py: Python<'py>,
    anim: &anim::MeshAnimation,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    output(
        py,
        &[anim.frame_count(), anim.vertex_count(), 3],
        flat3(anim.positions()),
    )
}
