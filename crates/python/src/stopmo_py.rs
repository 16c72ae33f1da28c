//! `toonkit.stopmo`: segmentation and replacement libraries (StopShop) through the stopmo
//! crate's whole jobs; `.save(dir)` writes the CLI's output layout through `tkio::save`.

use std::path::PathBuf;

use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stopmo::{FileData, LibraryJobOptions, OutputFile, RunOptions, SegmentJobOptions};

use crate::arrays::{frames_array, output, points_array, triangles};
use crate::errors::{at, io_error, toonkit_error, value_error};
use crate::progress::report;
use crate::scene::Scene;

/// Parts of a segmented animation (StopShop Eqs. 1-9).
#[pyclass(module = "toonkit.stopmo", name = "Segmented", frozen)]
pub(crate) struct Segmented {
    segmented: stopmo::Segmented,
    source: String,
}

/// A part as `{"name", "positions" (frames, v, 3), "triangles" (t, 3), "vertices" (v,)}`.
fn part_dict<'py>(py: Python<'py>, part: &stopmo::segment::Part) -> PyResult<Bound<'py, PyDict>> {
    let a = &part.animation;
    let d = PyDict::new(py);
    d.set_item("name", &part.name)?;
    d.set_item("positions", frames_array(py, a)?)?;
    d.set_item("triangles", triangles(py, &a.mesh)?)?;
    let v: Vec<i64> = part.vertices.iter().map(|&v| v as i64).collect();
    d.set_item("vertices", output(py, &[v.len()], v)?)?;
    Ok(d)
}

/// Parses JSON text into Python objects.
fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl Segmented {
    /// Part names, in label order.
    #[getter]
    fn part_names(&self) -> Vec<String> {
        self.segmented
            .parts
            .iter()
            .map(|p| p.name.clone())
            .collect()
    }

    /// int32 ``(t,)``: the part of every input triangle.
    #[getter]
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<i32>>> {
        let l: Vec<i32> = self
            .segmented
            .segmentation
            .input_triangle_part
            .iter()
            .map(|&p| p as i32)
            .collect();
        output(py, &[l.len()], l)
    }

    /// The parts as dicts: ``{"name", "positions", "triangles", "vertices"}``.
    #[getter]
    fn parts<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.segmented
            .parts
            .iter()
            .map(|p| part_dict(py, p))
            .collect()
    }

    /// The CLI's ``--report`` JSON as a dict (parts, triangle_part, seam_vertices, gamma,
    /// cut_length).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_loads(py, &self.segmented.report_json())
    }

    /// Writes the parts as ``toonkit stopmo segment -o OUT.glb`` does (one node per part).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<PathBuf> {
        let parts = self.segmented.part_animations();
        let p = path.clone();
        py.detach(|| FileData::Parts(parts).save(&p))
            .map_err(io_error)?;
        Ok(path)
    }

    fn __repr__(&self) -> String {
        format!(
            "<toonkit.stopmo.Segmented {}: {} parts>",
            self.source,
            self.segmented.parts.len()
        )
    }
}

/// A replacement library: pieces, per-frame labels, assembly, report.
#[pyclass(module = "toonkit.stopmo", name = "Library", frozen)]
pub(crate) struct Library {
    result: stopmo::LibraryResult,
    source: String,
}

#[pymethods]
impl Library {
    /// Part names, in the order of ``labels``' columns.
    #[getter]
    fn part_names(&self) -> Vec<String> {
        self.result.part_names.clone()
    }

    /// int32 ``(frames, parts)``: the piece of every part at every frame (indices into that
    /// part's pieces).
    #[getter]
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<i32>>> {
        let per_part = self.result.labels();
        let frames = per_part.first().map_or(0, |l| l.len());
        let mut data = Vec::with_capacity(frames * per_part.len());
        for f in 0..frames {
            data.extend(per_part.iter().map(|l| l[f] as i32));
        }
        output(py, &[frames, per_part.len()], data)
    }

    /// The printable pieces: ``{"id", "part", "index", "positions", "triangles"}`` (the
    /// piece surface, model units).
    #[getter]
    fn pieces<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.result
            .pieces
            .iter()
            .map(|p| {
                let d = PyDict::new(py);
                d.set_item("id", &p.id)?;
                d.set_item("part", p.part)?;
                d.set_item("index", p.index)?;
                let m = &p.surface;
                d.set_item("positions", points_array(py, &m.positions)?)?;
                d.set_item("triangles", triangles(py, m)?)?;
                Ok(d)
            })
            .collect()
    }

    /// The stop-motion reconstruction, every part merged in part order (what
    /// ``reconstruction.pc2`` and ``rest.obj`` hold): ``{"positions" (frames, v, 3),
    /// "rest" (v, 3), "triangles" (t, 3)}``, model units.
    #[getter]
    fn reconstruction<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let err = |e| toonkit_error(at(&self.source, e));
        let frames = self.result.merged_reconstruction().map_err(err)?;
        let d = PyDict::new(py);
        d.set_item("positions", frames_array(py, &frames)?)?;
        let rest = &frames.mesh;
        d.set_item("rest", points_array(py, &rest.positions)?)?;
        d.set_item("triangles", triangles(py, rest)?)?;
        Ok(d)
    }

    /// Piece ids per frame (the rows of ``assembly.csv``).
    #[getter]
    fn assembly(&self) -> Vec<Vec<String>> {
        self.result.frame_ids()
    }

    /// ``report.json`` as a dict (energy, lambda, pieces, errors in mm, seconds, …).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_loads(py, &self.result.report.to_json())
    }

    /// Writes the CLI's output layout under ``dir`` (``pieces/``, ``assembly.csv``,
    /// ``shooting_order.csv``, ``report.json``, ``reconstruction.glb``/``.pc2``, …).
    /// Returns the relative paths written.
    fn save(&self, py: Python<'_>, dir: PathBuf) -> PyResult<Vec<String>> {
        let files: Vec<OutputFile<'_>> = self
            .result
            .files()
            .map_err(|e| toonkit_error(at(&self.source, e)))?;
        py.detach(|| tkio::save_files(&dir, &files))
            .map_err(io_error)?;
        Ok(files.into_iter().map(|f| f.path).collect())
    }

    fn __repr__(&self) -> String {
        format!(
            "<toonkit.stopmo.Library {}: {} parts, {} pieces>",
            self.source,
            self.result.part_names.len(),
            self.result.pieces.len()
        )
    }
}

/// The scene's objects merged (the animation the stopmo jobs take).
fn merged(scene: &Scene) -> PyResult<anim::MeshAnimation> {
    scene.merged_check()?;
    let name = std::path::Path::new(&scene.source)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("mesh");
    scene
        .sampled
        .merged(name)
        .map_err(|e| value_error(at(&scene.source, e)))
}

fn options<T: serde::de::DeserializeOwned>(what: &str, json: &str) -> PyResult<T> {
    serde_json::from_str(json).map_err(|e| value_error(format!("{what} options: {e}")))
}

/// The native half of `toonkit.stopmo.segment`.
#[pyfunction(name = "stopmo_segment")]
#[pyo3(signature = (scene, options_json, progress=None))]
pub(crate) fn segment(
    py: Python<'_>,
    scene: &Bound<'_, Scene>,
    options_json: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Segmented> {
    let scene = scene.get();
    let opts: SegmentJobOptions = options("segment", options_json)?;
    let anim = merged(scene)?;
    report(py, progress.as_ref(), "segment", 0.0)?;
    let segmented = py
        .detach(|| stopmo::segment(&anim, &opts))
        .map_err(|e| value_error(at(&scene.source, e)))?;
    report(py, progress.as_ref(), "segment", 1.0)?;
    Ok(Segmented {
        segmented,
        source: scene.source.clone(),
    })
}

/// The native half of `toonkit.stopmo.library`.
#[pyfunction(name = "stopmo_library")]
#[pyo3(signature = (segmented, options_json, progress=None))]
pub(crate) fn library(
    py: Python<'_>,
    segmented: &Bound<'_, Segmented>,
    options_json: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Library> {
    let seg = segmented.get();
    let opts: LibraryJobOptions = options("library", options_json)?;
    // Borrowed: each part's mesh is named after the part (no copy of the frames).
    let parts = seg.segmented.part_animations();
    report(py, progress.as_ref(), "library", 0.0)?;
    let result = py
        .detach(|| stopmo::library(&parts, &opts))
        .map_err(|e| value_error(at(&seg.source, e)))?;
    report(py, progress.as_ref(), "library", 1.0)?;
    Ok(Library {
        result,
        source: seg.source.clone(),
    })
}

/// The native half of `toonkit.stopmo.run`.
#[pyfunction(name = "stopmo_run")]
#[pyo3(signature = (scene, options_json, progress=None))]
pub(crate) fn run(
    py: Python<'_>,
    scene: &Bound<'_, Scene>,
    options_json: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Library> {
    let scene = scene.get();
    let opts: RunOptions = options("run", options_json)?;
    let anim = merged(scene)?;
    report(py, progress.as_ref(), "run", 0.0)?;
    let result = py
        .detach(|| stopmo::run(&anim, &opts))
        .map_err(|e| value_error(at(&scene.source, e)))?;
    report(py, progress.as_ref(), "run", 1.0)?;
    Ok(Library {
        result,
        source: scene.source.clone(),
    })
}
