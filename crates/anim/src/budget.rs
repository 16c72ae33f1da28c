//! Resource budgets: every size derived from an input file or an option is checked against
//! one of these limits before anything of that size is allocated, so a hostile or mistyped
//! value ends in a one-line error naming the option and the limit (exit 2 in the CLI, HTTP
//! 413 in the studio), never in an abort or a kill by the kernel.
//!
//! The limits sit far above what the tools are used for (a feature film's hero character is
//! about a million vertices over a few thousand frames) and far below what would exhaust a
//! workstation's memory. They are defined here once; the tool crates check them where the
//! size is known, before allocating.

use thiserror::Error;

/// Sampled positions, frames × vertices, of one job: 400 million points (4.8 GB of f32 xyz).
pub const DEFAULT_MAX_POINTS: u64 = 400_000_000;

/// Frames one clip may be sampled into (its length × `--fps`): 100,000 frames, over an hour
/// at 24 fps. Every frame costs a pose, a flipbook entry and per-frame output records however
/// small the mesh, so a clip keyed at 0 and 20,000 s is refused even on a triangle.
pub const DEFAULT_MAX_FRAMES: u64 = 100_000;

/// Temporal smoothing half-window N of SMEAR Eq. 2 (`--smooth`): a window wider than the
/// longest clip only repeats its end frames, and its weights are allocated.
pub const DEFAULT_MAX_SMOOTH: u64 = 100_000;

/// Motion-line vertices over all frames: lines × rings × sides × frames (`--count`,
/// `--samples`): 50 million vertices (about 2 GB of tube geometry with colours).
pub const DEFAULT_MAX_LINE_VERTICES: u64 = 50_000_000;

/// Pixels of one rendered picture or GIF, width × height × frames (`--size` and the clip):
/// 2^31 pixels (8 GB of RGBA), e.g. 48 frames of 6,688 × 6,688.
pub const DEFAULT_MAX_PIXELS: u64 = 1 << 31;

/// Nesting depth of an SVG keystroke file's elements (parsed recursively; thousands of nested
/// `<g>` would overflow the stack).
pub const DEFAULT_MAX_NESTING: u64 = 256;

/// Bytes of one stylization expression (`--length`, a style's functions).
pub const DEFAULT_MAX_EXPRESSION_LEN: u64 = 4096;

/// Unknowns of a line-of-action space-time solve: keystrokes × joints × nodes (LoA §4), whose
/// dense normal equations grow with its square.
pub const DEFAULT_MAX_SOLVER_UNKNOWNS: u64 = 8_000;

/// Keystrokes of one line of action.
pub const DEFAULT_MAX_KEYSTROKES: u64 = 1_000;

/// A size over its budget: what was asked for, the limit, and how to get under it.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{what} = {} is over the limit of {}{hint}", crate::human_number(*.asked as f64), crate::human_number(*.limit as f64))]
pub struct OverBudget {
    /// The option or the size measured (`--smooth`, `frames × vertices`).
    pub what: String,
    /// The size asked for.
    pub asked: u64,
    /// The budget.
    pub limit: u64,
    /// How to get under it, starting with "; " (or empty).
    pub hint: String,
}

/// `Ok` when `asked` ≤ `limit`, else [`OverBudget`] naming `what` with the `hint` (say what
/// to lower; the leading "; " is added).
///
/// # Errors
/// [`OverBudget`].
pub fn check_budget(what: &str, asked: u64, limit: u64, hint: &str) -> Result<(), OverBudget> {
    if asked <= limit {
        return Ok(());
    }
    Err(OverBudget {
        what: what.to_string(),
        asked,
        limit,
        hint: if hint.is_empty() {
            String::new()
        } else {
            format!("; {hint}")
        },
    })
}

/// `a × b × …` without overflow (saturating at `u64::MAX`, which is over every budget).
pub fn product(factors: &[u64]) -> u64 {
    factors.iter().fold(1u64, |p, &f| p.saturating_mul(f))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn over_budget_names_the_option_and_the_limit() {
        assert!(check_budget("--smooth", 10, DEFAULT_MAX_SMOOTH, "").is_ok());
        let e = check_budget("--smooth", 1_000_000_000, DEFAULT_MAX_SMOOTH, "lower it")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--smooth = "), "{e}");
        assert!(
            e.contains("over the limit of") && e.ends_with("; lower it"),
            "{e}"
        );
        assert_eq!(product(&[u64::MAX, 3]), u64::MAX);
    }
}
