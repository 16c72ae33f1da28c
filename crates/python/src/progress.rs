//! The optional `progress` callable: `progress(stage: str, fraction: float)`, called with
//! the GIL held between the stages of a job (never while the GIL is released). An exception
//! it raises aborts the job and propagates.

use pyo3::prelude::*;

/// Reports `fraction` (0..=1) of `stage` to the callable, if there is one.
pub(crate) fn report(
    py: Python<'_>,
    progress: Option<&Py<PyAny>>,
    stage: &str,
    fraction: f64,
) -> PyResult<()> {
    if let Some(cb) = progress {
        cb.call1(py, (stage, fraction))?;
    }
    Ok(())
}
