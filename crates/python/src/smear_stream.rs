//! `toonkit.smear.Stream`: the crate's streaming smear (push a frame, get its elongated
//! in-between; past-only, issue #22).

use numpy::PyArrayDyn;
use pyo3::prelude::*;

use crate::arrays::{output, shape, values, ArrayIn};
use crate::errors::value_error;

/// A streaming smear over one mesh topology: ``push(positions)`` returns the elongated
/// in-between of that frame at once, using only the frames pushed so far.
///
/// ``triangles`` is an int array ``(T, 3)``, ``vertices`` the number of points per frame;
/// ``options_json`` holds ``smear::StreamOptions`` as JSON (``smooth``, ``elongate``,
/// ``history``, ``ground``).
#[pyclass(module = "toonkit.smear", name = "Stream")]
pub(crate) struct Stream {
    inner: smear::Stream,
    vertices: usize,
}

#[pymethods]
impl Stream {
    #[new]
    #[pyo3(signature = (triangles, vertices, options_json=None))]
    fn new(
        triangles: ArrayIn<'_, i64>,
        vertices: usize,
        options_json: Option<&str>,
    ) -> PyResult<Self> {
        shape(&triangles, "triangles", &[None, Some(3)])?;
        let flat = values(&triangles);
        let mut tris = Vec::with_capacity(flat.len() / 3);
        for t in flat.chunks_exact(3) {
            if t.iter().any(|&v| v < 0 || v as usize >= vertices) {
                return Err(value_error(format!(
                    "triangles: vertex index {t:?} out of range for {vertices} vertices"
                )));
            }
            tris.push([t[0] as u32, t[1] as u32, t[2] as u32]);
        }
        let options: smear::StreamOptions = match options_json {
            Some(j) => {
                serde_json::from_str(j).map_err(|e| value_error(format!("stream options: {e}")))?
            }
            None => smear::StreamOptions::default(),
        };
        let mesh = anim::Mesh::new("stream", vec![glam::Vec3::ZERO; vertices], tris);
        let inner = smear::Stream::new(&mesh, &options).map_err(|e| value_error(e.to_string()))?;
        Ok(Stream { inner, vertices })
    }

    /// Pushes one frame (float32 ``(vertices, 3)``) and returns its elongated in-between
    /// (float32 ``(vertices, 3)``). The GIL is released while computing.
    fn push<'py>(
        &mut self,
        py: Python<'py>,
        positions: ArrayIn<'py, f32>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        shape(&positions, "positions", &[Some(self.vertices), Some(3)])?;
        let flat = values(&positions);
        let points: Vec<glam::Vec3> = flat.chunks_exact(3).map(glam::Vec3::from_slice).collect();
        let inner = &mut self.inner;
        let out = py
            .detach(move || inner.push(&points).map(crate::arrays::flat3))
            .map_err(|e| value_error(e.to_string()))?;
        output(py, &[self.vertices, 3], out)
    }

    /// Smoothed motion offsets of the last pushed frame (float32 ``(vertices,)``).
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        output(py, &[self.vertices], self.inner.offsets().to_vec())
    }

    /// Frames pushed so far.
    #[getter]
    fn frames_pushed(&self) -> usize {
        self.inner.frames_pushed()
    }

    fn __repr__(&self) -> String {
        format!(
            "toonkit.smear.Stream({} vertices, {} frames pushed)",
            self.vertices,
            self.inner.frames_pushed()
        )
    }
}
