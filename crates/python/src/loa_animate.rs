//! `toonkit.loa.animate`: 3D character motion that follows a line of action (LoA Section 4),
//! through the loa crate's whole-job call.

use std::path::PathBuf;
use std::sync::Arc;

use loa::animate::{AnimateOptions, ContactKey, InitialPose};
use loa::job::{self, SceneMotion};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::output;
use crate::errors::{at, io_error, toonkit_error, value_error};
use crate::loa_py::Line;
use crate::progress::report;
use crate::scene::Scene;

/// A character: a file path, or a `toonkit.Scene` loaded from a glTF/BVH file.
#[derive(FromPyObject)]
pub(crate) enum CharacterArg<'py> {
    Scene(Bound<'py, Scene>),
    Path(PathBuf),
}

/// Joint motion synthesized from a line of action.
#[pyclass(module = "toonkit.loa", name = "Motion", frozen)]
pub(crate) struct Motion {
    done: SceneMotion,
    source: String,
    /// The character file read (when given by path): no save of the motion may replace it.
    _inputs: Option<tkio::ReadScope>,
}

#[pymethods]
impl Motion {
    /// float64 ``(frames, joints, 4)``: world rotation of every joint per frame, quaternions
    /// ``(x, y, z, w)``.
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let m = &self.done.motion;
        let data = m.rotations.iter().flat_map(|q| q.to_array()).collect();
        output(py, &[m.frames(), m.joints, 4], data)
    }

    /// float64 ``(frames, joints, 3)``: world position of every joint per frame.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let m = &self.done.motion;
        let data = m.positions.iter().flat_map(|p| p.to_array()).collect();
        output(py, &[m.frames(), m.joints, 3], data)
    }

    /// Joint names, in the order of the arrays' joint axis.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.done.joint_names.clone()
    }

    /// Frames per second (the line's).
    #[getter]
    fn fps(&self) -> f64 {
        self.done.motion.fps
    }

    /// Frame number of the first frame (the first keystroke).
    #[getter]
    fn first_frame(&self) -> i64 {
        self.done.motion.first_frame
    }

    /// Measurements: distance to the line (fraction of its length), largest rotation step,
    /// contact error, body height.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.done.motion.report;
        let d = PyDict::new(py);
        d.set_item("line_distance_mean", r.line_distance_mean)?;
        d.set_item("line_distance_p95", r.line_distance_p95)?;
        let worst = PyDict::new(py);
        worst.set_item("distance", r.line_distance_worst.distance)?;
        worst.set_item("joint", &r.line_distance_worst.joint)?;
        worst.set_item("frame", r.line_distance_worst.frame)?;
        d.set_item("line_distance_worst", worst)?;
        d.set_item("measured_joints", &r.measured_joints)?;
        d.set_item("unmeasured_frames", &r.unmeasured_frames)?;
        d.set_item("max_rotation_step", r.max_rotation_step)?;
        d.set_item("contact_error_max", r.contact_error_max)?;
        d.set_item("height", r.height)?;
        Ok(d)
    }

    /// Writes the character with the synthesized clip as ``.glb`` or the motion as ``.bvh``,
    /// as ``toonkit loa animate`` does, atomically. Returns the path.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<PathBuf> {
        py.detach(|| self.done.save(&path))
            .map_err(|e| toonkit_error(e.to_string()))?;
        Ok(path)
    }

    fn __repr__(&self) -> String {
        format!(
            "<toonkit.loa.Motion {}: {} frames × {} joints at {} fps>",
            self.source,
            self.done.motion.frames(),
            self.done.motion.joints,
            self.done.motion.fps
        )
    }
}

/// A character file that cannot be read (`FileNotFoundError` / `ToonkitError`) or holds no
/// character (`ValueError`).
pub(crate) fn open_error(e: job::SceneJobError) -> PyErr {
    match e {
        job::SceneJobError::Read(e) => io_error(e),
        e => value_error(e.to_string()),
    }
}

/// The native half of `toonkit.loa.animate`: bone sets, contacts and twists as the CLI's
/// `--bones`, `--contact`, `--twist` strings; the other `AnimateOptions` as JSON; `canvas`
/// the `(width, height)` in pixels of a canvas the keystrokes were drawn on through the
/// default camera (as the studio's page draws them).
#[pyfunction(name = "loa_animate")]
#[pyo3(signature = (character, line, bones, contacts, twists, pose, options_json, progress=None, canvas=None))]
pub(crate) fn animate(
    py: Python<'_>,
    character: CharacterArg<'_>,
    line: &Bound<'_, Line>,
    bones: Vec<String>,
    contacts: Vec<String>,
    twists: Vec<String>,
    pose: &str,
    options_json: &str,
    progress: Option<Py<PyAny>>,
    canvas: Option<[f64; 2]>,
) -> PyResult<Motion> {
    let mut options: AnimateOptions = serde_json::from_str(options_json)
        .map_err(|e| value_error(format!("animate options: {e}")))?;
    let bad = |flag: &str, v: &str, e: loa::animate::AnimateError| {
        value_error(format!("{flag} {v}: {e}"))
    };
    for b in &bones {
        options
            .bone_sets
            .push(b.parse().map_err(|e| bad("bones", b, e))?);
    }
    for c in &contacts {
        options
            .contacts
            .extend(ContactKey::parse_all(c).map_err(|e| bad("contacts", c, e))?);
    }
    for t in &twists {
        options
            .twists
            .push(t.parse().map_err(|e| bad("twists", t, e))?);
    }
    let pose: InitialPose = pose.parse().map_err(|e| bad("pose", pose, e))?;
    let line = line.get();
    let fps = line.line.animation.fps;
    let mut inputs = None;
    let (scene, source) = match character {
        CharacterArg::Scene(s) => {
            let s = s.get();
            let scene = s.file_scene.clone().ok_or_else(|| {
                value_error(format!(
                    "{}: not a character (load a skinned glTF/GLB or a BVH file)",
                    s.source
                ))
            })?;
            (scene, s.source.clone())
        }
        CharacterArg::Path(path) => {
            let source = path.display().to_string();
            let read = tkio::ReadScope::open();
            let scene = py
                .detach(|| job::open_character(&path, fps))
                .map_err(open_error)?;
            read.freeze();
            inputs = Some(read);
            (Arc::new(scene), source)
        }
    };
    let options = job::SceneOptions {
        motion: options,
        pose,
        canvas,
        ..Default::default()
    };
    report(py, progress.as_ref(), "animate", 0.0)?;
    let done = py
        .detach(|| job::animate_line(&scene, line.line.clone(), &options))
        .map_err(|e| value_error(at(&source, e)))?;
    report(py, progress.as_ref(), "animate", 1.0)?;
    Ok(Motion {
        done,
        source,
        _inputs: inputs,
    })
}
