//! `toonkit.smear.prepare` / `toonkit.smear.stylize`: the smear crate's whole job. `prepare`
//! solves the offsets once; every `stylize` reuses them (live tuning of a style).

use std::path::PathBuf;
use std::sync::Arc;
use std::thread::JoinHandle;

use anim::SampledScene;

use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use smear::{OffsetOptions, PrepareOptions, Style};

use crate::arrays::{frames_array, output, points_array, triangles};
use crate::errors::{at, io_error, smear_error, value_error};
use crate::progress::report;
use crate::scene::Scene;
use crate::smear_py::{offset_options, CameraArg};

/// Motion offsets solved once for any number of ``toonkit.smear.stylize`` calls.
///
/// >>> prepared = toonkit.smear.prepare(scene, smooth=2)
/// >>> prepared.offsets.shape == scene.positions.shape[:2]
/// True
#[pyclass(module = "toonkit.smear", name = "Prepared", frozen)]
pub(crate) struct Prepared {
    prepared: Arc<smear::Prepared>,
    source: String,
}

#[pymethods]
impl Prepared {
    /// float32 ``(frames, vertices)``: the prepared offsets, objects in ``scene.positions``'
    /// order (as ``toonkit.smear.offsets`` returns them).
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let p = &self.prepared;
        let mut values = Vec::new();
        let frames = p.scene().frame_count;
        let mut vertices = 0;
        for i in 0..p.object_count() {
            vertices += p.offsets(i).vertex_count();
        }
        values.reserve(frames * vertices);
        for f in 0..frames {
            for i in 0..p.object_count() {
                values.extend_from_slice(p.offsets(i).frame(f));
            }
        }
        output(py, &[frames, vertices], values)
    }

    /// What preparing did, as JSON text (per-object modes and ranges, timings).
    fn report_json(&self) -> PyResult<String> {
        serde_json::to_string(self.prepared.report()).map_err(|e| value_error(e.to_string()))
    }

    /// What preparing did, as a dict (per-object modes and ranges, timings).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_loads(py, &self.report_json()?)
    }

    fn __repr__(&self) -> String {
        let r = self.prepared.report();
        format!(
            "<toonkit.smear.Prepared {}: {} frames, {} vertices, {} object(s)>",
            self.source,
            r.frames,
            r.vertices,
            self.prepared.object_count()
        )
    }
}

/// What `toonkit.smear.prepare` runs: the scene (shared, not copied), the options and the
/// collider scenes, checked on the caller's thread.
struct PrepareJob {
    sampled: Arc<SampledScene>,
    options: PrepareOptions,
    colliders: Vec<Arc<SampledScene>>,
    source: String,
}

impl PrepareJob {
    fn new(
        scene: &Bound<'_, Scene>,
        smooth: usize,
        whole_body: bool,
        prune: Vec<String>,
        camera: Option<CameraArg>,
        options_json: Option<&str>,
        causal: bool,
        revolve: Vec<String>,
        collider_scenes: Vec<Bound<'_, Scene>>,
    ) -> PyResult<PrepareJob> {
        let scene = scene.get();
        scene.merged_check()?;
        let mut options: PrepareOptions = match options_json {
            Some(j) => {
                serde_json::from_str(j).map_err(|e| value_error(format!("prepare options: {e}")))?
            }
            None => PrepareOptions::default(),
        };
        options.offsets = offset_options(smooth, whole_body, prune, camera, (causal, revolve));
        let mut colliders = Vec::with_capacity(collider_scenes.len());
        for c in &collider_scenes {
            let c = c.get();
            if c.sampled.objects.is_empty() {
                return Err(value_error(format!(
                    "{}: the collider has no mesh",
                    c.source
                )));
            }
            colliders.push(c.sampled.clone());
        }
        Ok(PrepareJob {
            sampled: scene.sampled.clone(),
            options,
            colliders,
            source: scene.source.clone(),
        })
    }

    /// `smear::prepare`, every collider scene's objects added (no GIL needed).
    fn run(self) -> smear::Result<smear::Prepared> {
        // The clip is shared with the `Scene`, not copied.
        let mut p = smear::prepare(self.sampled, &self.options)?;
        for o in self.colliders.iter().flat_map(|c| &c.objects) {
            p.add_collider(smear::Collider::from_animation(&o.animation));
        }
        Ok(p)
    }
}

/// The native half of `toonkit.smear.prepare`; `options_json` holds the other
/// `PrepareOptions` fields (`weights`, `merge`, `colliders`) as JSON; every object of the
/// `collider_scenes` becomes a collider mesh (issue #22).
#[pyfunction(name = "smear_prepare")]
#[pyo3(signature = (scene, smooth=smear::DEFAULT_SMOOTH, whole_body=false, prune=Vec::new(), camera=None, options_json=None, progress=None, causal=false, revolve=Vec::new(), collider_scenes=Vec::new()))]
pub(crate) fn prepare(
    py: Python<'_>,
    scene: &Bound<'_, Scene>,
    smooth: usize,
    whole_body: bool,
    prune: Vec<String>,
    camera: Option<CameraArg>,
    options_json: Option<&str>,
    progress: Option<Py<PyAny>>,
    causal: bool,
    revolve: Vec<String>,
    collider_scenes: Vec<Bound<'_, Scene>>,
) -> PyResult<Prepared> {
    let job = PrepareJob::new(
        scene,
        smooth,
        whole_body,
        prune,
        camera,
        options_json,
        causal,
        revolve,
        collider_scenes,
    )?;
    report(py, progress.as_ref(), "prepare", 0.0)?;
    let source = job.source.clone();
    let prepared = py
        .detach(move || job.run())
        .map_err(|e| smear_error(&source, e))?;
    report(py, progress.as_ref(), "prepare", 1.0)?;
    Ok(Prepared {
        prepared: Arc::new(prepared),
        source,
    })
}

/// ``toonkit.smear.prepare`` running on a thread of its own (``toonkit.smear.start_prepare``):
/// the caller goes on (a host builds its result objects meanwhile, docs/blender.md "Speed")
/// and ``result()`` waits for the same ``Prepared`` ``prepare`` returns, or raises its error.
#[pyclass(module = "toonkit.smear", name = "Preparing")]
pub(crate) struct Preparing {
    handle: Option<JoinHandle<smear::Result<smear::Prepared>>>,
    source: String,
}

#[pymethods]
impl Preparing {
    /// Waits for the offsets: the ``Prepared`` (once), or ``prepare``'s error.
    fn result(&mut self, py: Python<'_>) -> PyResult<Prepared> {
        let handle = self.handle.take().ok_or_else(|| {
            value_error("the prepared offsets were already taken by an earlier result()")
        })?;
        let prepared = py
            .detach(|| handle.join())
            .map_err(|_| value_error("the prepare thread panicked"))?
            .map_err(|e| smear_error(&self.source, e))?;
        Ok(Prepared {
            prepared: Arc::new(prepared),
            source: self.source.clone(),
        })
    }
}

/// The native half of `toonkit.smear.start_prepare`: `smear_prepare`'s arguments (but
/// `progress`), checked here, the solve started on a thread of its own.
#[pyfunction(name = "smear_start_prepare")]
#[pyo3(signature = (scene, smooth=smear::DEFAULT_SMOOTH, whole_body=false, prune=Vec::new(), camera=None, options_json=None, causal=false, revolve=Vec::new(), collider_scenes=Vec::new()))]
pub(crate) fn start_prepare(
    scene: &Bound<'_, Scene>,
    smooth: usize,
    whole_body: bool,
    prune: Vec<String>,
    camera: Option<CameraArg>,
    options_json: Option<&str>,
    causal: bool,
    revolve: Vec<String>,
    collider_scenes: Vec<Bound<'_, Scene>>,
) -> PyResult<Preparing> {
    let job = PrepareJob::new(
        scene,
        smooth,
        whole_body,
        prune,
        camera,
        options_json,
        causal,
        revolve,
        collider_scenes,
    )?;
    let source = job.source.clone();
    Ok(Preparing {
        handle: Some(std::thread::spawn(move || job.run())),
        source,
    })
}

/// Reads a style: `style_json` (a dict's keys) or a TOML file at `path`, validated as the
/// CLI validates `--style`. A style that leaves `offsets` at their defaults takes the
/// prepared ones.
fn read_style(
    style_json: Option<&str>,
    path: Option<PathBuf>,
    prepared: &OffsetOptions,
) -> PyResult<Style> {
    let mut style = match (style_json, path) {
        (Some(j), _) => {
            let style: Style =
                serde_json::from_str(j).map_err(|e| value_error(format!("style: {e}")))?;
            style
                .validate()
                .map_err(|e| value_error(format!("style: {e}")))?;
            style
        }
        (None, Some(path)) => {
            let bytes = tkio::read_file(&path).map_err(io_error)?;
            let text = String::from_utf8(bytes).map_err(|_| {
                value_error(format!("{}: a style file is UTF-8 text", path.display()))
            })?;
            Style::from_toml_str(&text)
                .map_err(|e| value_error(at(&path.display().to_string(), e)))?
        }
        (None, None) => return Err(value_error("style: give a dict or a TOML file path")),
    };
    if style.offsets == OffsetOptions::default() {
        style.offsets = prepared.clone();
    }
    Ok(style)
}

/// The native half of `toonkit.smear.stylize`; `frames` = `(start, end)` stylizes clip
/// frames `start..end` only (`smear::stylize_frames`: a live restyle draws the frame on
/// screen, the others when the scene reaches them).
#[pyfunction(name = "smear_stylize")]
#[pyo3(signature = (prepared, style_json=None, style_path=None, progress=None, frames=None))]
pub(crate) fn stylize(
    py: Python<'_>,
    prepared: &Bound<'_, Prepared>,
    style_json: Option<&str>,
    style_path: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
    frames: Option<(usize, usize)>,
) -> PyResult<Stylized> {
    let p = prepared.get();
    let style = read_style(style_json, style_path, &p.prepared.options().offsets)?;
    let clip = p.prepared.report().frames;
    let (start, end) = frames.unwrap_or((0, clip));
    if start >= end || end > clip {
        return Err(value_error(format!(
            "frames ({start}, {end}): a non-empty range of the clip's {clip} frames"
        )));
    }
    report(py, progress.as_ref(), "stylize", 0.0)?;
    let shared = p.prepared.clone();
    let stylized = py
        .detach(move || smear::stylize_frames(&shared, &style, start..end))
        .map_err(|e| smear_error(&p.source, e))?;
    report(py, progress.as_ref(), "stylize", 1.0)?;
    Ok(Stylized {
        stylized,
        source: p.source.clone(),
    })
}

/// The result of a style: elongated positions, multiple in-betweens and motion lines.
#[pyclass(module = "toonkit.smear", name = "Stylized", frozen)]
pub(crate) struct Stylized {
    stylized: smear::Stylized,
    source: String,
}

impl Stylized {
    fn animation_part(&self, index: usize) -> Option<(&anim::MeshAnimation, Option<&[[f32; 4]]>)> {
        match self.stylized.flipbook.parts.get(index)? {
            anim::FlipbookPart::Animation { animation, colors } => {
                Some((animation, colors.as_deref()))
            }
            anim::FlipbookPart::Frames { .. } => None,
        }
    }
}

/// Parses JSON text into Python objects.
fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// A dict `{"name", "positions" (frames, v, 3), "triangles" (t, 3), "alpha" (frames, v)}`.
fn animation_dict<'py>(
    py: Python<'py>,
    animation: &anim::MeshAnimation,
    colors: Option<&[[f32; 4]]>,
) -> PyResult<Bound<'py, PyDict>> {
    let (f, v) = (animation.frame_count(), animation.vertex_count());
    let d = PyDict::new(py);
    d.set_item("name", &animation.mesh.name)?;
    d.set_item("positions", frames_array(py, animation)?)?;
    d.set_item("triangles", triangles(py, &animation.mesh)?)?;
    let alpha = match colors {
        Some(c) => c.iter().map(|c| c[3]).collect(),
        None => vec![1.0f32; f * v],
    };
    d.set_item("alpha", output(py, &[f, v], alpha)?)?;
    Ok(d)
}

#[pymethods]
impl Stylized {
    /// float32 ``(frames, vertices, 3)``: every object's elongated in-betweens (its input
    /// positions when the style does not elongate it), objects in ``scene.positions``' order.
    #[getter]
    fn elongated<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let bodies: Vec<&anim::MeshAnimation> = self
            .stylized
            .objects
            .iter()
            .filter_map(|o| self.animation_part(o.body).map(|(a, _)| a))
            .collect();
        let frames = self.stylized.flipbook.frames;
        let vertices: usize = bodies.iter().map(|a| a.vertex_count()).sum();
        // One copy into numpy's buffer, frame by frame (no array per frame).
        let mut data = Vec::with_capacity(frames * vertices * 3);
        for f in 0..frames {
            for a in &bodies {
                data.extend_from_slice(bytemuck::cast_slice::<glam::Vec3, f32>(a.frame(f)));
            }
        }
        output(py, &[frames, vertices, 3], data)
    }

    /// The multiple in-betweens: one dict per copy, ``{"name", "object" (index into
    /// ``scene.objects``), "positions" (frames, v, 3), "triangles" (t, 3), "alpha" (frames,
    /// v)}`` (per-vertex opacity, SMEAR Eq. 12).
    #[getter]
    fn multiples<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = Vec::new();
        for (k, o) in self.stylized.objects.iter().enumerate() {
            for i in o.copies.clone() {
                if let Some((a, c)) = self.animation_part(i) {
                    let d = animation_dict(py, a, c)?;
                    d.set_item("object", k)?;
                    out.push(d);
                }
            }
        }
        Ok(out)
    }

    /// The motion lines: one dict per object with lines, ``{"name", "object" (index into
    /// ``scene.objects``), "frames": [{"positions" (n, 3), "triangles" (t, 3), "alpha" (n,)},
    /// ...]}`` (one tube mesh per frame; empty where no line shows).
    #[getter]
    fn lines<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let mut out = Vec::new();
        for (k, o) in self.stylized.objects.iter().enumerate() {
            let Some(i) = o.lines else { continue };
            let Some(anim::FlipbookPart::Frames { name, meshes, .. }) =
                self.stylized.flipbook.parts.get(i)
            else {
                continue;
            };
            let frames = meshes
                .iter()
                .map(|m| {
                    let d = PyDict::new(py);
                    d.set_item("positions", points_array(py, &m.positions)?)?;
                    d.set_item("triangles", triangles(py, m)?)?;
                    let alpha: Vec<f32> = match &m.colors {
                        Some(c) => c.iter().map(|c| c[3]).collect(),
                        None => vec![1.0; m.vertex_count()],
                    };
                    d.set_item("alpha", output(py, &[m.vertex_count()], alpha)?)?;
                    Ok(d)
                })
                .collect::<PyResult<Vec<_>>>()?;
            let d = PyDict::new(py);
            d.set_item("name", name)?;
            d.set_item("object", k)?;
            d.set_item("frames", frames)?;
            out.push(d);
        }
        Ok(out)
    }

    /// The clip frame of the first frame held (0 unless ``stylize`` was given ``frames``).
    #[getter]
    fn first_frame(&self) -> usize {
        self.stylized.first_frame
    }

    /// What the style did, as JSON text (per-object elongation, copies, lines, timings).
    fn report_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.stylized.report).map_err(|e| value_error(e.to_string()))
    }

    /// What the style did, as a dict (per-object elongation, copies, lines, timings; the
    /// ``offset_solves`` counter shows that restyling never solved offsets again).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_loads(py, &self.report_json()?)
    }

    /// Writes every part as the CLI's ``toonkit smear IN --style S -o OUT`` does: ``.glb``
    /// (flipbooks) or a scene cache (``.usda``, ``.usdc``, ``.usdz``, ``.abc``: one mesh per
    /// part), atomically. Returns the path.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<PathBuf> {
        if !tkio::Format::from_extension(&path).is_some_and(tkio::Format::holds_scenes) {
            return Err(value_error(format!(
                "{}: a styled smear is written as .glb, .usda, .usdc, .usdz or .abc",
                path.display()
            )));
        }
        let p = path.clone();
        let book = &self.stylized.flipbook;
        py.detach(|| tkio::save(&p, &tkio::Output::Flipbook(book)))
            .map_err(io_error)?;
        Ok(path)
    }

    fn __repr__(&self) -> String {
        format!(
            "<toonkit.smear.Stylized {}: {} frames, {} parts>",
            self.source,
            self.stylized.flipbook.frames,
            self.stylized.flipbook.parts.len()
        )
    }
}
