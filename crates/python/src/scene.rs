//! `toonkit.Scene`: a sampled clip (every mesh object's positions per frame, skeleton, skin,
//! cameras) from `toonkit.load` (through `tkio::load`, as the CLI reads files) or from arrays
//! of a host application (`Scene.from_arrays`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anim::{MeshAnimation, SampleOptions, SampledScene};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyList, PyRange};
use tkio::{LoadOptions, Loaded};

use crate::arrays::frozen;
use crate::errors::{anim_error, io_error, value_error};

/// A clip sampled at a fixed frame rate.
///
/// ``positions`` is float32 ``(frames, vertices, 3)`` with the vertices of all mesh objects
/// merged in object order (the order ``toonkit convert IN rest.obj`` writes), ``triangles``
/// int32 ``(t, 3)`` indexes them. Arrays are read-only views kept by the scene.
///
/// >>> import toonkit
/// >>> scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
/// >>> scene.positions.shape[2], scene.fps
/// (3, 24.0)
#[pyclass(module = "toonkit", name = "Scene", frozen)]
pub(crate) struct Scene {
    /// The sampled clip every tool works on.
    pub(crate) sampled: Arc<SampledScene>,
    /// The file path, or `<arrays>`, for one-line error messages.
    pub(crate) source: String,
    /// The scene as read (hierarchy, skins, clips) when it came from a glTF/BVH file: what
    /// `toonkit.loa.animate` poses.
    pub(crate) file_scene: Option<Arc<anim::Scene>>,
    /// Every object's positions merged per frame, made on first read: a host that hands
    /// its arrays to `from_arrays` and prepares at once never pays a copy of the clip it
    /// already holds (docs/blender.md, "Speed").
    positions: PyOnceLock<Py<PyArrayDyn<f32>>>,
    triangles: Py<PyArrayDyn<i32>>,
    /// The files the load read: while the scene lives, no save may replace them.
    _inputs: Option<tkio::ReadScope>,
}

impl Scene {
    /// Wraps a sampled scene; its merged positions array is made on first use.
    pub(crate) fn new(
        py: Python<'_>,
        sampled: SampledScene,
        source: String,
        file_scene: Option<Arc<anim::Scene>>,
        inputs: Option<tkio::ReadScope>,
    ) -> PyResult<Scene> {
        let mut triangles = Vec::new();
        let mut base = 0i32;
        for o in &sampled.objects {
            for t in &o.animation.mesh.triangles {
                triangles.extend(t.map(|i| i as i32 + base));
            }
            base += o.animation.vertex_count() as i32;
        }
        let nt = triangles.len() / 3;
        Ok(Scene {
            positions: PyOnceLock::new(),
            triangles: frozen(py, &[nt, 3], triangles)?.unbind(),
            sampled: Arc::new(sampled),
            source,
            file_scene,
            _inputs: inputs,
        })
    }

    /// `ValueError` naming the source when the scene has no mesh (as the CLI says it).
    pub(crate) fn merged_check(&self) -> PyResult<()> {
        if self.sampled.objects.is_empty() {
            return Err(value_error(format!(
                "{}: the file has no mesh",
                self.source
            )));
        }
        Ok(())
    }
}

/// Reads and samples a file as the CLI does (`tkio::load`, then the clip at `fps`).
fn load_sampled(
    path: &Path,
    clip: Option<&str>,
    fps: f32,
) -> Result<(SampledScene, Option<Arc<anim::Scene>>), PyErrLater> {
    let loaded = tkio::load(
        path,
        &LoadOptions {
            fps,
            ..Default::default()
        },
    )
    .map_err(PyErrLater::Io)?;
    let at = |e| PyErrLater::Anim(path.display().to_string(), e);
    match loaded {
        Loaded::Scene(scene) => {
            let clip = match clip {
                Some(name) => Some(scene.find_clip(name).map_err(at)?),
                None => None,
            };
            let options = SampleOptions {
                fps,
                clip,
                meshes: Vec::new(),
            };
            let sampled = anim::sample(&scene, &options).map_err(at)?;
            Ok((sampled, Some(Arc::from(scene))))
        }
        Loaded::Cache(cache) => Ok((SampledScene::from_animation(cache), None)),
        Loaded::Mesh(mesh) => Ok((
            SampledScene::from_animation(MeshAnimation::still(mesh)),
            None,
        )),
    }
}

/// An error made without the GIL, turned into a Python exception after.
pub(crate) enum PyErrLater {
    Io(tkio::IoError),
    Anim(String, anim::AnimError),
}

impl From<PyErrLater> for PyErr {
    fn from(e: PyErrLater) -> PyErr {
        match e {
            PyErrLater::Io(e) => io_error(e),
            PyErrLater::Anim(source, e) => anim_error(&source, e),
        }
    }
}

/// `Scene.from_arrays`' ``skinning``: a `toonkit.SkinStream` fed every frame, or the
/// arguments of `toonkit.skin`.
#[derive(FromPyObject)]
pub(crate) enum Skinning<'py> {
    Stream(Bound<'py, crate::skin_stream::SkinStream>),
    Arrays(
        (
            crate::arrays::ArrayIn<'py, f32>,
            crate::arrays::ArrayIn<'py, i64>,
            crate::arrays::ArrayIn<'py, f32>,
            crate::arrays::ArrayIn<'py, f32>,
        ),
    ),
}

/// A clip name or index.
#[derive(FromPyObject)]
pub(crate) enum ClipArg {
    Index(usize),
    Name(String),
}

/// Reads an animation file (glTF/GLB, OBJ sequence, PC2/MDD + rest OBJ, BVH, OBJ/STL) and
/// samples a clip (by name or index; default the first) at ``fps`` frames per second, exactly
/// as the ``toonkit`` CLI reads its inputs. The GIL is released while reading.
///
/// Raises ``FileNotFoundError`` for a missing file, ``ValueError`` for a bad ``fps`` or an
/// unknown clip, ``toonkit.ToonkitError`` for a malformed file.
///
/// >>> scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
/// >>> scene.frame_count > 0
/// True
#[pyfunction]
#[pyo3(signature = (path, clip=None, fps=anim::DEFAULT_FPS))]
pub(crate) fn load(
    py: Python<'_>,
    path: PathBuf,
    clip: Option<ClipArg>,
    fps: f32,
) -> PyResult<Scene> {
    if !(fps.is_finite() && fps > 0.0) {
        return Err(value_error(format!(
            "fps must be a positive number, got {fps}"
        )));
    }
    let clip = clip.map(|c| match c {
        ClipArg::Index(i) => i.to_string(),
        ClipArg::Name(n) => n,
    });
    let p = path.clone();
    let inputs = tkio::ReadScope::open();
    let (sampled, file_scene) = py.detach(|| load_sampled(&p, clip.as_deref(), fps))?;
    inputs.freeze();
    Scene::new(
        py,
        sampled,
        path.display().to_string(),
        file_scene,
        Some(inputs),
    )
}

#[pymethods]
impl Scene {
    /// A scene from a host application's arrays: ``positions`` ``(frames, vertices, 3)``,
    /// ``triangles`` ``(t, 3)`` vertex indices, and optionally ``skin``, a dict with
    /// ``"parents"`` (``(joints,)`` int, -1 for a root; parents before children),
    /// ``"matrices"`` (``(frames, joints, 4, 4)`` joint world matrices, translation in column 3),
    /// ``"weights"`` (``(vertices, joints)`` skin weights) and optionally ``"joint_names"``,
    /// so that articulated offsets (SMEAR Eqs. 3-9) work on data from Blender too.
    /// ``Scene.skin`` returns the same dict for a loaded scene.
    ///
    /// ``objects`` (``[(name, range(start, stop)), ...]`` tiling the vertices, as
    /// ``Scene.objects`` returns them) splits the mesh into objects: an object without skin
    /// weights is a simple object (SMEAR Eq. 1), carried by ``skin["object_parents"][i]``.
    ///
    /// ``attributes`` (``{name: (vertices,) float32}``) are scalar per-vertex attributes, e.g.
    /// painted weights for a style's ``weights = { attribute = "name" }``.
    ///
    /// ``rest`` (``(vertices, 3)`` world-space positions) is the character at its rest pose,
    /// the mesh as modelled (bind pose, no shape key): its bounding-box diagonal is one size
    /// unit of a smear style (docs/smear-units.md). Default: the first frame.
    ///
    /// Arrays are read in place when they are C-contiguous float32 (int for indices).
    ///
    /// ``skinning`` (``(rest, indices, weights, matrices)``, the arguments of ``toonkit.skin``,
    /// or a ``toonkit.SkinStream`` every frame was pushed to) replaces ``positions`` (pass
    /// ``None``): the clip is skinned straight into the scene, with no copy of it
    /// (docs/blender.md, "Speed"); ``positions`` then reads (a copy, made on first read) the
    /// values ``toonkit.skin`` returns.
    ///
    /// >>> s = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
    /// >>> t = toonkit.Scene.from_arrays(s.positions, s.triangles, fps=s.fps, skin=s.skin)
    /// >>> t.positions.shape == s.positions.shape
    /// True
    #[staticmethod]
    #[pyo3(signature = (positions, triangles, fps=anim::DEFAULT_FPS, skin=None, objects=None, attributes=None, rest=None, skinning=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays<'py>(
        py: Python<'py>,
        positions: Option<crate::arrays::ArrayIn<'py, f32>>,
        triangles: crate::arrays::ArrayIn<'_, i64>,
        fps: f32,
        skin: Option<&Bound<'_, PyDict>>,
        objects: Option<Vec<(String, Bound<'_, PyAny>)>>,
        attributes: Option<std::collections::BTreeMap<String, crate::arrays::ArrayIn<'_, f32>>>,
        rest: Option<crate::arrays::ArrayIn<'_, f32>>,
        skinning: Option<Skinning<'py>>,
    ) -> PyResult<Scene> {
        let clip = match (positions, skinning) {
            (Some(p), None) => crate::from_arrays::Clip::copied(&p)?,
            (None, Some(skinning)) => {
                let (points, frames, vertices) = match skinning {
                    Skinning::Arrays((r, i, w, m)) => crate::skin_py::skinned(py, &r, &i, &w, &m)?,
                    Skinning::Stream(s) => s.borrow_mut().finish(py)?,
                };
                crate::from_arrays::Clip {
                    points,
                    frames,
                    vertices,
                }
            }
            _ => {
                return Err(value_error(
                    "give the clip as positions or as skinning (positions=None), not both",
                ))
            }
        };
        let attributes = attributes
            .unwrap_or_default()
            .into_iter()
            .map(|(name, a)| {
                crate::arrays::shape(&a, &format!("attributes[{name:?}]"), &[None])?;
                Ok((name, crate::arrays::values(&a).into_owned()))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let objects = objects
            .map(|list| {
                list.into_iter()
                    .map(|(name, r)| {
                        let start: usize = r.getattr("start")?.extract()?;
                        let stop: usize = r.getattr("stop")?.extract()?;
                        Ok((name, start, stop))
                    })
                    .collect::<PyResult<Vec<_>>>()
            })
            .transpose()?;
        let sampled = crate::from_arrays::sampled(
            clip,
            &triangles,
            fps,
            skin,
            objects,
            attributes,
            rest.as_ref(),
        )?;
        Scene::new(py, sampled, "<arrays>".to_string(), None, None)
    }

    /// float32 ``(frames, vertices, 3)``: world-space positions, objects merged in order.
    #[getter]
    fn positions(&self, py: Python<'_>) -> PyResult<Py<PyArrayDyn<f32>>> {
        let p = self.positions.get_or_try_init(py, || {
            let (frames, vertices) = (self.sampled.frame_count, self.sampled.vertex_count());
            let mut positions = Vec::with_capacity(frames * vertices * 3);
            for f in 0..frames {
                for o in &self.sampled.objects {
                    positions.extend_from_slice(bytemuck::cast_slice(o.animation.frame(f)));
                }
            }
            frozen(py, &[frames, vertices, 3], positions).map(Bound::unbind)
        })?;
        Ok(p.clone_ref(py))
    }

    /// int32 ``(t, 3)``: triangles indexing ``positions``' vertices.
    #[getter]
    fn triangles(&self, py: Python<'_>) -> Py<PyArrayDyn<i32>> {
        self.triangles.clone_ref(py)
    }

    /// Frames per second.
    #[getter]
    fn fps(&self) -> f32 {
        self.sampled.fps
    }

    /// Number of frames.
    #[getter]
    fn frame_count(&self) -> usize {
        self.sampled.frame_count
    }

    /// Number of vertices (all objects).
    #[getter]
    fn vertex_count(&self) -> usize {
        self.sampled.vertex_count()
    }

    /// The character's size: the bounding-box diagonal of every object at its rest pose (the
    /// mesh as modelled, see ``from_arrays``' ``rest``), one size unit of a smear style in
    /// scene units (docs/smear-units.md).
    #[getter]
    fn size(&self) -> f32 {
        self.sampled.rest_diagonal()
    }

    /// Names of the skeleton's joints (empty when nothing is skinned).
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.sampled
            .skeleton
            .joints
            .iter()
            .map(|j| j.name.clone())
            .collect()
    }

    /// Names of the scene's cameras (for ``toonkit.smear.offsets(camera=...)``).
    #[getter]
    fn cameras(&self) -> Vec<String> {
        self.sampled
            .cameras
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }

    /// ``[(name, range(start, stop)), ...]``: each mesh object and its vertices in
    /// ``positions``.
    #[getter]
    fn objects<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let mut base = 0isize;
        let mut items = Vec::new();
        for o in &self.sampled.objects {
            let n = o.animation.vertex_count() as isize;
            items.push((o.name.clone(), PyRange::new(py, base, base + n)?));
            base += n;
        }
        PyList::new(py, items)
    }

    /// The skin as ``Scene.from_arrays`` takes it (``None`` when nothing is skinned):
    /// ``{"joint_names", "parents", "matrices", "weights"}``. Vertices of unskinned objects
    /// have zero weights.
    #[getter]
    fn skin<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        crate::from_arrays::skin_dict(py, &self.sampled)
    }

    fn __repr__(&self) -> String {
        format!(
            "<toonkit.Scene {}: {} frames at {} fps, {} vertices, {} object(s), {} joints>",
            self.source,
            self.sampled.frame_count,
            self.sampled.fps,
            self.sampled.vertex_count(),
            self.sampled.objects.len(),
            self.sampled.skeleton.len()
        )
    }
}
