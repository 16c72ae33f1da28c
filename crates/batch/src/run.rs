//! Running a manifest's shots in parallel on this machine. The tool itself is the caller's
//! ([`Runner`]: `toonkit batch` runs each command line through the `toonkit` parser in its
//! own process); this module picks the shots, skips those whose stamp matches, runs the
//! others' outputs on a thread pool, writes their stamps and reports each shot. A failing
//! shot is reported and the others go on.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::{BatchError, Manifest, Shot, Stamp, ToolOutput};

/// How a batch runs: which shots, how many at once, and whether done shots are redone.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Only these shots (by name; all when empty).
    pub shots: Vec<String>,
    /// Shots run at the same time (default: one per core).
    pub jobs: Option<usize>,
    /// Redo every shot, even those whose stamp matches.
    pub force: bool,
}

/// Why a shot failed.
#[derive(Debug)]
pub enum ShotFailure<E> {
    /// The shot's inputs cannot be hashed for its stamp.
    Hash(BatchError),
    /// Its command line or its stamp cannot be made.
    Batch(BatchError),
    /// The tool failed on one output.
    Command {
        /// The command's words after the tool's name.
        command: String,
        /// The tool's error.
        error: E,
    },
}

/// The tool that makes the shots' outputs, and what the user sees while it works.
pub trait Runner: Sync {
    /// The tool's error.
    type Error;
    /// Runs one command line (the words after the tool's name).
    ///
    /// # Errors
    /// The tool's error.
    fn run(&self, argv: &[String]) -> Result<(), Self::Error>;
    /// How the tool takes its output file (see [`ToolOutput`]).
    fn tool_output(&self, words: &[&str]) -> ToolOutput;
    /// A failure as the one line of the shot's report.
    fn describe(&self, shot: &Shot, failure: ShotFailure<Self::Error>) -> String;
    /// A shot starts writing output `k` (0-based) of `n`.
    fn writing(&self, _shot: &Shot, _k: usize, _n: usize, _output: &Path) {}
    /// A shot is done, skipped or failed.
    fn finished(&self, _report: &ShotReport) {}
}

/// What happened to one shot.
#[derive(Debug, Clone, Serialize)]
pub struct ShotReport {
    /// Shot name.
    pub name: String,
    /// `done`, `skipped` or `failed`.
    pub status: &'static str,
    /// Files written (or found, when skipped).
    pub outputs: Vec<PathBuf>,
    /// Wall time.
    pub seconds: f64,
    /// Why it failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// What a batch did.
#[derive(Debug, Clone)]
pub struct BatchReport {
    /// Shots run at the same time.
    pub jobs: usize,
    /// One report per shot, in manifest order.
    pub shots: Vec<ShotReport>,
}

impl BatchReport {
    /// Shots with this status (`done`, `skipped`, `failed`).
    pub fn count(&self, status: &str) -> usize {
        self.shots.iter().filter(|r| r.status == status).count()
    }

    /// The batch in words: the counts and wall time, then one line per failed shot.
    pub fn summary(&self, seconds: f64) -> String {
        let mut text = format!(
            "{} shots: {} done, {} skipped, {} failed in {seconds:.1} s",
            self.shots.len(),
            self.count("done"),
            self.count("skipped"),
            self.count("failed"),
        );
        for r in self.shots.iter().filter(|r| r.status == "failed") {
            let error = r.error.as_deref().unwrap_or("");
            text.push_str(&format!("\n  {}: {error}", r.name));
        }
        text
    }
}

/// The error of a batch in which some shots failed (the others were made).
#[derive(Debug, thiserror::Error)]
#[error("{failed} of {total} shots failed")]
pub struct ShotsFailed {
    /// Shots that failed.
    pub failed: usize,
    /// Shots in the batch.
    pub total: usize,
}

impl ShotsFailed {
    /// The process exit code: 2, as for any bad input of a single command (a count of
    /// failed shots would wrap at 256 and read as success at 256 failures); how many failed
    /// and why is in the report, per shot.
    pub fn exit_code(&self) -> u8 {
        2
    }
}

/// The shots of `manifest` that `names` selects (all when empty), in manifest order.
///
/// # Errors
/// A name no shot has, naming the manifest file `path`.
pub fn select_shots<'m>(
    manifest: &'m Manifest,
    path: &Path,
    names: &[String],
) -> Result<Vec<&'m Shot>, BatchError> {
    if let Some(unknown) = names
        .iter()
        .find(|n| !manifest.shots.iter().any(|s| &s.name == *n))
    {
        return Err(BatchError::invalid(
            path,
            format!("no shot named '{unknown}'"),
        ));
    }
    Ok(manifest
        .shots
        .iter()
        .filter(|s| names.is_empty() || names.contains(&s.name))
        .collect())
}

/// Makes `shots` (paths relative to `base`, outputs under `out`) with `runner`, in parallel.
///
/// # Errors
/// The worker threads cannot start. Failing shots are not errors: see their reports.
pub fn run_shots<R: Runner>(
    shots: &[&Shot],
    base: &Path,
    out: &Path,
    options: &RunOptions,
    runner: &R,
) -> Result<BatchReport, BatchError> {
    let jobs = options
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| BatchError::Threads(e.to_string()))?;
    let shots = pool.install(|| {
        shots
            .par_iter()
            .map(|shot| {
                let report = match output_over_an_input(shot, shots, base, out) {
                    Some(error) => ShotReport {
                        name: shot.name.clone(),
                        status: "failed",
                        outputs: shot.outputs.iter().map(|o| out.join(o)).collect(),
                        seconds: 0.0,
                        error: Some(error),
                    },
                    None => run_shot(shot, base, out, options.force, runner),
                };
                runner.finished(&report);
                report
            })
            .collect()
    });
    Ok(BatchReport { jobs, shots })
}

/// Why `shot` may not run: one of its outputs is the input or style file of a shot of the
/// batch (its own, or another's that it would break), compared as files (device and inode,
/// so links and other spellings count) and, for outputs not written yet, by path.
fn output_over_an_input(shot: &Shot, all: &[&Shot], base: &Path, out: &Path) -> Option<String> {
    let lexical = |p: &Path| -> Option<PathBuf> {
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty());
        let dir = std::fs::canonicalize(dir.unwrap_or(Path::new("."))).ok()?;
        Some(dir.join(p.file_name()?))
    };
    for o in &shot.outputs {
        let output = out.join(o);
        for other in all {
            for file in std::iter::once(&other.input).chain(other.style.as_ref()) {
                let input = base.join(file);
                let same = tkio::same_file(&output, &input)
                    || matches!((lexical(&output), lexical(&input)), (Some(a), Some(b)) if a == b);
                if same {
                    let whose = if other.name == shot.name {
                        "its own input".to_string()
                    } else {
                        format!("the input of shot '{}'", other.name)
                    };
                    return Some(format!(
                        "output {} is {whose} ({}): refusing to write over it; name another output",
                        output.display(),
                        input.display()
                    ));
                }
            }
        }
    }
    None
}

/// Makes one shot (or skips it when its stamp matches).
fn run_shot<R: Runner>(
    shot: &Shot,
    base: &Path,
    out: &Path,
    force: bool,
    runner: &R,
) -> ShotReport {
    let start = Instant::now();
    let outputs: Vec<PathBuf> = shot.outputs.iter().map(|o| out.join(o)).collect();
    let tool = |words: &[&str]| runner.tool_output(words);
    let result = (|| -> Result<&'static str, ShotFailure<R::Error>> {
        let hash = Stamp::hash(shot, base, &tool).map_err(ShotFailure::Hash)?;
        if !force && Stamp::is_done(shot, out, &hash, base) {
            return Ok("skipped");
        }
        // Every file the shot reads is recorded for its stamp, and none may be written over.
        let reads = tkio::ReadScope::open();
        for (k, o) in outputs.iter().enumerate() {
            tkio::remove_stale_temps(o);
            runner.writing(shot, k, outputs.len(), o);
            let argv = shot
                .command_line(base, o, tool)
                .map_err(ShotFailure::Batch)?;
            runner
                .run(&argv[1..])
                .map_err(|error| ShotFailure::Command {
                    command: argv[1..].join(" "),
                    error,
                })?;
        }
        let read = reads.files();
        drop(reads);
        Stamp::write_done(shot, out, &hash, base, &read).map_err(ShotFailure::Batch)?;
        Ok("done")
    })();
    let (status, error) = match result {
        Ok(s) => (s, None),
        Err(f) => ("failed", Some(runner.describe(shot, f))),
    };
    ShotReport {
        name: shot.name.clone(),
        status,
        outputs,
        seconds: start.elapsed().as_secs_f64(),
        error,
    }
}
