//! Python exceptions with the CLI's one-line messages: `FileNotFoundError` for a missing
//! file, `ValueError` for a bad argument or option, [`ToonkitError`] for everything else
//! (malformed files, failed computations). Never a panic, never a silent NaN.

use std::fmt::Display;

use pyo3::exceptions::{PyException, PyFileNotFoundError, PyValueError};
use pyo3::{create_exception, PyErr};

create_exception!(
    toonkit,
    ToonkitError,
    PyException,
    "A toonkit file or computation failed; the message is the CLI's one-line error."
);

/// `"{source}: {error}"` on one line, as `toonkit` prints it after `toonkit: error: `.
pub(crate) fn at(source: &str, e: impl Display) -> String {
    one_line(&format!("{source}: {e}"))
}

/// Joins a multi-line message into one line.
pub(crate) fn one_line(msg: &str) -> String {
    msg.replace('\n', " ")
}

/// A `ValueError` with a one-line message.
pub(crate) fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(one_line(&msg.into()))
}

/// A [`ToonkitError`] with a one-line message.
pub(crate) fn toonkit_error(msg: impl Into<String>) -> PyErr {
    ToonkitError::new_err(one_line(&msg.into()))
}

/// A file error: `FileNotFoundError` when the file does not exist, else [`ToonkitError`]
/// (the message names the file already).
pub(crate) fn io_error(e: tkio::IoError) -> PyErr {
    let msg = one_line(&e.to_string());
    match &e {
        tkio::IoError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(msg)
        }
        _ => ToonkitError::new_err(msg),
    }
}

/// A data-model error on `source` (bad arrays, unknown clip or mesh): a `ValueError`.
pub(crate) fn anim_error(source: &str, e: anim::AnimError) -> PyErr {
    value_error(at(source, e))
}

/// A smear error on `source`: options naming things that do not exist are `ValueError`s,
/// the rest [`ToonkitError`].
pub(crate) fn smear_error(source: &str, e: smear::SmearError) -> PyErr {
    use smear::SmearError as E;
    let msg = at(source, &e);
    match e {
        E::UnknownJoint { .. }
        | E::PruneWithoutAncestor { .. }
        | E::UnknownAttribute { .. }
        | E::UnknownCamera { .. }
        | E::UnknownObject { .. }
        | E::InvalidParameter {
            name: "revolve", ..
        } => value_error(msg),
        _ => toonkit_error(msg),
    }
}
