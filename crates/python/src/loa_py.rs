//! `toonkit.loa`: dynamic lines of action (LoA Section 3) from keystrokes, through the loa
//! crate's whole-job call.

use std::path::PathBuf;

use loa::{Keystrokes, LineOptions};
use numpy::PyArrayDyn;
use pyo3::prelude::*;

use crate::arrays::output;
use crate::errors::{at, io_error, value_error};
use crate::progress::report;

const SOURCE: &str = "<keystrokes>";

/// An animated line of action: one chain of joints per frame, first keystroke to last.
///
/// >>> line = toonkit.loa.line([{"frame": 0, "points": [[0, 0], [1, 1]]},
/// ...                          {"frame": 12, "points": [[0, 0], [1, -1]]}])
/// >>> line.points.shape[2]
/// 2
#[pyclass(module = "toonkit.loa", name = "Line", frozen)]
pub(crate) struct Line {
    /// The computed line.
    pub(crate) line: loa::Line,
    /// The keystrokes it was computed from.
    pub(crate) keys: Keystrokes,
}

#[pymethods]
impl Line {
    /// float64 ``(frames, joints, 2)``: the chain's joint positions in the keystrokes' screen
    /// coordinates.
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let frames = &self.line.animation.frames;
        let joints = frames.first().map_or(0, |f| f.chain.joints().len());
        let data = frames
            .iter()
            .flat_map(|f| f.chain.joints().into_iter().flat_map(|p| [p.x, p.y]))
            .collect();
        output(py, &[frames.len(), joints, 2], data)
    }

    /// float64 ``(frames, elements)``: local joint angles (radians), as the CLI's JSON.
    #[getter]
    fn angles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.per_element(py, |c| c.angles())
    }

    /// float64 ``(frames, elements)``: element lengths.
    #[getter]
    fn lengths<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        self.per_element(py, |c| c.lengths())
    }

    /// Frame numbers of the rows, first keystroke to last.
    #[getter]
    fn frames(&self) -> Vec<i64> {
        self.line.animation.frames.iter().map(|f| f.frame).collect()
    }

    /// Frames of the keystrokes.
    #[getter]
    fn keystroke_frames(&self) -> Vec<i64> {
        self.line.animation.keystroke_frames.clone()
    }

    /// Frames per second.
    #[getter]
    fn fps(&self) -> f64 {
        self.line.animation.fps
    }

    /// The CLI's JSON layout (``toonkit loa line ... -o OUT.json``).
    fn to_json(&self) -> String {
        self.line.animation.to_json_string()
    }

    /// Writes ``.json`` (the CLI's layout) or ``.svg`` (onion skin with the keystrokes),
    /// atomically. Returns the path.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<PathBuf> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let text = match ext.as_deref() {
            Some("json") => self.line.animation.to_json_string(),
            Some("svg") => loa::to_svg_string(&self.line.animation, Some(&self.keys)),
            _ => {
                return Err(value_error(format!(
                    "{}: a line is saved as .json or .svg",
                    path.display()
                )))
            }
        };
        let p = path.clone();
        py.detach(move || tkio::save(&p, &tkio::Output::Text(&text)))
            .map_err(io_error)?;
        Ok(path)
    }

    /// Warnings of the line (e.g. keystrokes drawn the other way round and reversed).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.line.warnings.clone()
    }

    fn __repr__(&self) -> String {
        let a = &self.line.animation;
        format!(
            "<toonkit.loa.Line: {} frames at {} fps, {} keystrokes>",
            a.frames.len(),
            a.fps,
            a.keystroke_frames.len()
        )
    }
}

impl Line {
    fn per_element<'py>(
        &self,
        py: Python<'py>,
        get: impl Fn(&loa::Chain) -> &[f64],
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let frames = &self.line.animation.frames;
        let n = frames.first().map_or(0, |f| get(&f.chain).len());
        let data = frames.iter().flat_map(|f| get(&f.chain).to_vec()).collect();
        output(py, &[frames.len(), n], data)
    }
}

/// The native half of `toonkit.loa.line`: keystrokes in the CLI's JSON layout and
/// `loa::LineOptions` as JSON (the keyword arguments).
#[pyfunction(name = "loa_line")]
#[pyo3(signature = (keystrokes_json, options_json, progress=None))]
pub(crate) fn line(
    py: Python<'_>,
    keystrokes_json: &str,
    options_json: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Line> {
    let options: LineOptions = serde_json::from_str(options_json)
        .map_err(|e| value_error(format!("line options: {e}")))?;
    let keys =
        Keystrokes::from_json_str(keystrokes_json).map_err(|e| value_error(at(SOURCE, e)))?;
    report(py, progress.as_ref(), "line", 0.0)?;
    let (line, keys) = py
        .detach(move || loa::line(&keys, &options).map(|l| (l, keys)))
        .map_err(|e| value_error(at(SOURCE, e)))?;
    report(py, progress.as_ref(), "line", 1.0)?;
    Ok(Line { line, keys })
}
