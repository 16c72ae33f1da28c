//! # toonkit-python
//!
//! The `toonkit` Python module: a thin PyO3 layer over the tool crates' whole-job calls on
//! numpy arrays. The compiled core is `toonkit._native`; the pure-Python package in
//! `python/toonkit` gives it its public shape (`toonkit.load`, `toonkit.Scene`,
//! `toonkit.smear`, `toonkit.stopmo`, `toonkit.loa`), keyword defaults and type stubs.
//!
//! Files are read through `tkio::load` and written through `tkio::save`, as the CLI does; no
//! algorithm lives here. The GIL is released during every computation. Errors are the CLI's
//! one-line messages as `FileNotFoundError`, `ValueError` or `toonkit.ToonkitError`.
//!
//! Built by maturin (`pip install ./crates/python`) as one `cp311-abi3` wheel.

mod arrays;
mod errors;
mod from_arrays;
mod loa_animate;
mod loa_character;
mod loa_py;
mod progress;
mod scene;
mod skin_py;
mod skin_stream;
mod smear_job;
mod smear_presets;
mod smear_py;
mod smear_stream;
mod stopmo_py;

use pyo3::prelude::*;

/// The compiled core of the ``toonkit`` package (import ``toonkit`` instead).
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ToonkitError", py.get_type::<errors::ToonkitError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<scene::Scene>()?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(skin_py::skin, m)?)?;
    m.add_class::<skin_stream::SkinStream>()?;
    m.add_function(wrap_pyfunction!(smear_py::offsets, m)?)?;
    m.add_class::<smear_job::Prepared>()?;
    m.add_class::<smear_job::Stylized>()?;
    m.add_class::<smear_stream::Stream>()?;
    m.add_function(wrap_pyfunction!(smear_job::prepare, m)?)?;
    m.add_class::<smear_job::Preparing>()?;
    m.add_function(wrap_pyfunction!(smear_job::start_prepare, m)?)?;
    m.add_function(wrap_pyfunction!(smear_job::stylize, m)?)?;
    m.add_function(wrap_pyfunction!(smear_presets::presets, m)?)?;
    m.add_function(wrap_pyfunction!(smear_presets::parameters, m)?)?;
    m.add_function(wrap_pyfunction!(smear_presets::preset_function, m)?)?;
    m.add_function(wrap_pyfunction!(smear_presets::save_style, m)?)?;
    m.add_function(wrap_pyfunction!(smear_presets::style_toml, m)?)?;
    m.add_class::<loa_py::Line>()?;
    // The documented slider ranges, defined once in the loa crate.
    let range = |r: std::ops::RangeInclusive<f64>| (*r.start(), *r.end());
    m.add("LOA_STIFFNESS_RANGE", range(loa::STIFFNESS_RANGE))?;
    m.add("LOA_DAMPING_RANGE", range(loa::DAMPING_RANGE))?;
    m.add_function(wrap_pyfunction!(loa_py::line, m)?)?;
    m.add_function(wrap_pyfunction!(loa_character::save_pose, m)?)?;
    m.add_function(wrap_pyfunction!(loa_character::bone_chain, m)?)?;
    m.add("LOA_BONE_SETS", loa_character::bone_set_presets())?;
    m.add_class::<stopmo_py::Segmented>()?;
    m.add_class::<stopmo_py::Library>()?;
    m.add_function(wrap_pyfunction!(stopmo_py::segment, m)?)?;
    m.add_function(wrap_pyfunction!(stopmo_py::library, m)?)?;
    m.add_function(wrap_pyfunction!(stopmo_py::run, m)?)?;
    m.add_class::<loa_animate::Motion>()?;
    m.add_function(wrap_pyfunction!(loa_animate::animate, m)?)?;
    Ok(())
}
