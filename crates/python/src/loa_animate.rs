//! `toonkit.loa.animate`: 3D character motion that follows a line of action (LoA Section 4),
//! through the loa crate's whole-job call.

use std::path::PathBuf;
use std::sync::Arc;

use loa::animate::{AnimateOptions, Character, ContactKey, InitialPose, Motion as LoaMotion};
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
    motion: LoaMotion,
    scene: Arc<anim::Scene>,
    joint_names: Vec<String>,
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
        let m = &self.motion;
        let data = m.rotations.iter().flat_map(|q| q.to_array()).collect();
        output(py, &[m.frames(), m.joints, 4], data)
    }

    /// float64 ``(frames, joints, 3)``: world position of every joint per frame.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let m = &self.motion;
        let data = m.positions.iter().flat_map(|p| p.to_array()).collect();
        output(py, &[m.frames(), m.joints, 3], data)
    }

    /// Joint names, in the order of the arrays' joint axis.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.joint_names.clone()
    }

    /// Frames per second (the line's).
    #[getter]
    fn fps(&self) -> f64 {
        self.motion.fps
    }

    /// Frame number of the first frame (the first keystroke).
    #[getter]
    fn first_frame(&self) -> i64 {
        self.motion.first_frame
    }

    /// Measurements: distance to the line (fraction of its length), largest rotation step,
    /// contact error, body height.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.motion.report;
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
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let p = path.clone();
        let named = |e: &dyn std::fmt::Display| toonkit_error(at(&p.display().to_string(), e));
        let result = py.detach(|| -> Result<(), String> {
            match ext.as_deref() {
                Some("bvh") => {
                    let (skeleton, _) = self.scene.skeleton();
                    let skeletal = self
                        .motion
                        .skeletal_animation(&skeleton)
                        .map_err(|e| e.to_string())?;
                    let text = tkio::bvh::write(&skeleton, &skeletal).map_err(|e| e.to_string())?;
                    tkio::save(&p, &tkio::Output::Text(&text)).map_err(|e| e.to_string())?;
                }
                Some("glb") => {
                    let out = self.motion.to_scene(&self.scene);
                    let bytes = tkio::gltf::write_glb(&out).map_err(|e| e.to_string())?;
                    tkio::save(&p, &tkio::Output::Bytes(&bytes)).map_err(|e| e.to_string())?;
                }
                _ => return Err("a motion is saved as .glb or .bvh".to_string()),
            }
            Ok(())
        });
        result.map_err(|e| named(&e))?;
        Ok(path)
    }

    fn __repr__(&self) -> String {
        format!(
            "<toonkit.loa.Motion {}: {} frames × {} joints at {} fps>",
            self.source,
            self.motion.frames(),
            self.motion.joints,
            self.motion.fps
        )
    }
}

/// The native half of `toonkit.loa.animate`: bone sets, contacts and twists as the CLI's
/// `--bones`, `--contact`, `--twist` strings; the other `AnimateOptions` as JSON.
#[pyfunction(name = "loa_animate")]
#[pyo3(signature = (character, line, bones, contacts, twists, pose, options_json, progress=None))]
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
            let load = tkio::LoadOptions {
                fps: fps as f32,
                ..Default::default()
            };
            let source = path.display().to_string();
            let read = tkio::ReadScope::open();
            let loaded = py.detach(|| tkio::load(&path, &load)).map_err(io_error)?;
            read.freeze();
            inputs = Some(read);
            match loaded {
                tkio::Loaded::Scene(scene) => (Arc::from(scene), source),
                _ => {
                    return Err(value_error(format!(
                        "{source}: not a character (use a skinned glTF/GLB or a BVH file)"
                    )))
                }
            }
        }
    };
    report(py, progress.as_ref(), "animate", 0.0)?;
    let motion = py
        .detach(|| {
            let character = Character::from_scene(&scene, &pose, fps)?;
            let names = character.joint_names().to_vec();
            loa::animate(&character, &line.line, &options).map(|m| (m, names))
        })
        .map_err(|e| value_error(at(&source, e)))?;
    report(py, progress.as_ref(), "animate", 1.0)?;
    Ok(Motion {
        motion: motion.0,
        joint_names: motion.1,
        scene,
        source,
        _inputs: inputs,
    })
}
