//! Resource budgets: every size derived from an input file or an option is checked against
//! one of these limits before anything of that size is allocated, so a hostile or mistyped
//! value ends in a one-line error naming the option and the limit (exit 2 in the CLI, HTTP
//! 413 in the studio), never in an abort or a kill by the kernel.
//!
//! One budget bounds the memory of a job, [`DEFAULT_MAX_JOB_BYTES`] (or the environment's
//! [`MAX_JOB_BYTES_ENV`]): a job estimates what it
//! will hold ([`JobMemory`]: frames × vertices × the copies it makes, motion lines, pictures)
//! before its heavy allocations, and the size limits below that grow with memory are derived
//! from it. The others bound what is not memory (frames of a clip, nesting, solver size).
//! They are defined here once; the tool crates check them where the size is known, before
//! allocating.

use std::fmt::Display;

use thiserror::Error;

/// Bytes one job may hold at once (its samples and every copy it makes: velocities,
/// offsets, stylized frames, encoded files, pictures): 6 GB, a quarter of a 24 GB
/// workstation, so that a job under it does not run the machine out of memory beside the
/// others running there (a studio's requests, a batch's parallel shots).
pub const DEFAULT_MAX_JOB_BYTES: u64 = 6_000_000_000;

/// The environment variable that sets the job budget in bytes instead of
/// [`DEFAULT_MAX_JOB_BYTES`] (e.g. `TOONKIT_MAX_JOB_BYTES=2e9` on a small machine or in a
/// container, higher on a large workstation); a value that is not a positive number is
/// ignored.
pub const MAX_JOB_BYTES_ENV: &str = "TOONKIT_MAX_JOB_BYTES";

/// The job budget in bytes: [`MAX_JOB_BYTES_ENV`] when set to a positive number, else
/// [`DEFAULT_MAX_JOB_BYTES`], and never more than half the process's address-space limit
/// (`ulimit -v`) when one is set — the rest is for the runtime, its threads' reserved arenas
/// and the copies a job makes while writing (read once per process).
pub fn max_job_bytes() -> u64 {
    static LIMIT: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *LIMIT.get_or_init(|| {
        let configured = std::env::var(MAX_JOB_BYTES_ENV)
            .ok()
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite() && *v >= 1.0)
            .map_or(DEFAULT_MAX_JOB_BYTES, |v| v as u64);
        address_space_limit().map_or(configured, |l| configured.min(l / 2))
    })
}

/// The soft address-space limit of this process in bytes (`ulimit -v`), from
/// `/proc/self/limits`; `None` when unlimited or not on Linux.
fn address_space_limit() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    let soft = line["Max address space".len()..]
        .split_whitespace()
        .next()?;
    soft.parse::<u64>().ok()
}

/// Bytes of one sampled position (f32 x, y, z).
pub const POSITION_BYTES: u64 = 12;

/// Sampled positions, frames × vertices, of one job: half the job budget in f32 xyz (250
/// million points, 3 GB), since every job holds at least one copy of them beside the
/// samples (a merge, offsets, an encoded file).
pub const DEFAULT_MAX_POINTS: u64 = DEFAULT_MAX_JOB_BYTES / POSITION_BYTES / 2;

/// Sampled positions one job may hold: [`DEFAULT_MAX_POINTS`], or half the budget set by
/// [`MAX_JOB_BYTES_ENV`] in f32 xyz.
pub fn max_points() -> u64 {
    max_job_bytes() / POSITION_BYTES / 2
}

// The limits derived from the job budget stay within it.
const _: () = assert!(DEFAULT_MAX_POINTS * POSITION_BYTES * 2 <= DEFAULT_MAX_JOB_BYTES);
const _: () = assert!(DEFAULT_MAX_PIXELS * PIXEL_BYTES <= DEFAULT_MAX_JOB_BYTES);

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

/// Pixels of one rendered picture or GIF, width × height × frames (`--size` and the clip),
/// kept together until encoded: the job budget at 5 bytes a pixel (RGBA and the GIF's palette
/// index), 1.2 billion pixels, e.g. 48 frames of 5,000 × 5,000.
pub const DEFAULT_MAX_PIXELS: u64 = DEFAULT_MAX_JOB_BYTES / PIXEL_BYTES;

/// Bytes of one pixel of a picture kept until encoded: RGBA and the GIF's palette index.
pub const PIXEL_BYTES: u64 = 5;

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

/// What a job will hold, summed from its parts before it allocates them, checked against
/// the job budget ([`max_job_bytes`], by default [`DEFAULT_MAX_JOB_BYTES`]).
///
/// # Examples
/// ```
/// use anim::budget::JobMemory;
/// // A clip sampled at 100,000 frames of a 50,000-vertex mesh, with three copies.
/// let job = JobMemory::new().positions("copies of the clip", 100_000, 50_000, 3);
/// let e = job.check("lower --fps").unwrap_err().to_string();
/// assert!(e.starts_with("memory of the job (3 copies of the clip, 100000 frames × 50000 vertices)"));
/// ```
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct JobMemory {
    bytes: u64,
    parts: Vec<String>,
}

impl JobMemory {
    /// Nothing held yet.
    pub fn new() -> JobMemory {
        JobMemory::default()
    }

    /// Adds `copies` copies of `frames × vertices` positions (f32 xyz), described as `what`.
    pub fn positions(self, what: &str, frames: usize, vertices: usize, copies: u64) -> JobMemory {
        let bytes = product(&[frames as u64, vertices as u64, POSITION_BYTES, copies]);
        self.bytes(
            format!("{copies} {what}, {frames} frames × {vertices} vertices"),
            bytes,
        )
    }

    /// Adds `bytes` bytes, described as `what`.
    pub fn bytes(mut self, what: impl Display, bytes: u64) -> JobMemory {
        self.bytes = self.bytes.saturating_add(bytes);
        self.parts.push(what.to_string());
        self
    }

    /// The bytes estimated.
    pub fn total(&self) -> u64 {
        self.bytes
    }

    /// `Ok` when the estimate is within the job budget ([`max_job_bytes`]), else
    /// [`OverBudget`] naming its parts, in bytes, with `hint` (what to lower; the variable
    /// that raises the budget is named after it).
    ///
    /// # Errors
    /// [`OverBudget`].
    pub fn check(&self, hint: &str) -> Result<(), OverBudget> {
        self.check_within(max_job_bytes(), hint)
    }

    /// `Ok` when the estimate is within `limit` bytes (a share of the job budget, e.g. what a
    /// server has left for one more job), else [`OverBudget`] as [`JobMemory::check`] says it.
    ///
    /// # Errors
    /// [`OverBudget`].
    pub fn check_within(&self, limit: u64, hint: &str) -> Result<(), OverBudget> {
        let hint = if hint.is_empty() {
            format!("or raise {MAX_JOB_BYTES_ENV}")
        } else {
            format!("{hint} (or raise {MAX_JOB_BYTES_ENV})")
        };
        check_budget(
            &format!("memory of the job ({}) in bytes", self.parts.join(" + ")),
            self.bytes,
            limit,
            &hint,
        )
    }
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

    #[test]
    fn a_job_over_the_memory_budget_names_its_parts_and_the_limit() {
        let small = JobMemory::new()
            .positions("copies of the clip", 100, 1000, 3)
            .bytes("motion lines", 1000);
        assert_eq!(small.total(), 100 * 1000 * 12 * 3 + 1000);
        assert!(small.check("").is_ok());
        let e = JobMemory::new()
            .positions("copies of the clip", 480_001, 3_000, 3)
            .check("lower --fps")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "memory of the job (3 copies of the clip, 480001 frames × 3000 vertices) in bytes \
             = 5.1840108e10 is over the limit of 6e9; lower --fps (or raise TOONKIT_MAX_JOB_BYTES)"
        );
    }
}
