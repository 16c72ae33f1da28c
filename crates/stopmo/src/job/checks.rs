//! The one positivity check of the stopmo options' lengths, made by the jobs and by any
//! front end that checks its flags before reading the input.

use super::error::{Error, Result};
use super::options::{LibraryJobOptions, PieceCount};

/// Refuses a length option (named `option`, as the options struct names it) that is not a
/// positive, finite number of millimetres.
///
/// # Errors
/// [`Error::Option`] naming `option` and the value.
pub fn check_positive_mm(option: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        return Ok(());
    }
    Err(Error::option_error(
        option,
        format!("must be a positive number of millimetres, got {value}"),
    ))
}

impl LibraryJobOptions {
    /// Checks the lengths that must be positive (`max_error_mm`, `thickness_mm`) before any
    /// work: what [`library`](crate::library()) refuses, for front ends to refuse early.
    ///
    /// # Errors
    /// As [`check_positive_mm`].
    pub fn check_lengths(&self) -> Result<()> {
        if let PieceCount::MaxErrorMm(e) = self.pieces {
            check_positive_mm("max_error_mm", e)?;
        }
        check_positive_mm("thickness_mm", self.thickness_mm)
    }
}
