//! `toonkit.smear`: motion offsets (SMEAR Section 3) on a [`Scene`], through the smear
//! crate's whole-job calls.

use numpy::PyArrayDyn;
use pyo3::prelude::*;
use smear::{CameraSelect, OffsetOptions};

use crate::arrays::output;
use crate::errors::smear_error;
use crate::progress::report;
use crate::scene::Scene;

/// A camera by name or index.
#[derive(FromPyObject)]
pub(crate) enum CameraArg {
    Index(usize),
    Name(String),
}

/// The offset options of the keyword arguments (the CLI's `smear offsets` flags).
pub(crate) fn offset_options(
    smooth: usize,
    whole_body: bool,
    prune: Vec<String>,
    camera: Option<CameraArg>,
    (causal, revolve): (bool, Vec<String>),
) -> OffsetOptions {
    OffsetOptions {
        causal,
        revolve,
        smooth,
        whole_body,
        prune,
        camera: camera.map(|c| match c {
            CameraArg::Index(i) => CameraSelect::Index(i),
            CameraArg::Name(n) => CameraSelect::Name(n),
        }),
        ..OffsetOptions::default()
    }
}

/// Motion offsets δ ∈ [-1, 1] per frame and vertex: leading parts > 0, trailing < 0
/// (SMEAR Eqs. 1-9), as ``toonkit smear offsets IN -o OUT.npy`` writes them: float32
/// ``(frames, vertices)`` in ``scene.positions``' vertex order.
///
/// ``smooth`` is the temporal half-window N of SMEAR Eq. 2 (0 = off); ``whole_body`` treats a
/// skinned character as one object (Fig. 14); ``prune`` lists joints whose vertices follow the
/// nearest kept ancestor; ``camera`` (name or index) computes offsets relative to a camera.
/// The GIL is released while computing; ``progress(stage, fraction)`` is called before and
/// after.
///
/// >>> scene = toonkit.load("assets/characters/RobotExpressive.glb", clip="Dance")
/// >>> delta = toonkit.smear.offsets(scene)
/// >>> delta.shape == scene.positions.shape[:2]
/// True
#[pyfunction(name = "smear_offsets")]
#[pyo3(signature = (scene, smooth=smear::DEFAULT_SMOOTH, whole_body=false, prune=Vec::new(), camera=None, progress=None, causal=false, revolve=Vec::new()))]
pub(crate) fn offsets<'py>(
    py: Python<'py>,
    scene: &Bound<'py, Scene>,
    smooth: usize,
    whole_body: bool,
    prune: Vec<String>,
    camera: Option<CameraArg>,
    progress: Option<Py<PyAny>>,
    causal: bool,
    revolve: Vec<String>,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let scene = scene.get();
    scene.merged_check()?;
    let options = offset_options(smooth, whole_body, prune, camera, (causal, revolve));
    report(py, progress.as_ref(), "offsets", 0.0)?;
    let sampled = scene.sampled.clone();
    let merged = py
        .detach(move || smear::offsets(&sampled, &options))
        .map_err(|e| smear_error(&scene.source, e))?
        .offsets;
    report(py, progress.as_ref(), "offsets", 1.0)?;
    let shape = [merged.frame_count(), merged.vertex_count()];
    output(py, &shape, merged.into_values())
}
