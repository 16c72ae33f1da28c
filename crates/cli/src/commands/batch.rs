//! `toonkit batch MANIFEST.toml -o OUT [--jobs N] [--shot NAME] [--openjd job.yaml]`: many
//! shots, in parallel on this machine, or as an Open Job Description template for a farm.
//! The manifest, command lines, stamps and template are the `batch` crate's; this command
//! runs each output's command line in this process, through the same parser and dispatcher
//! as the `toonkit` binary, so every command and option of the tools works in a manifest. A
//! failing shot is reported and the others go on; the exit code is the number of failed
//! shots (capped at 100).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use ::batch::{manifest_dir, read_manifest, Shot, Stamp, ToolOutput};
use anyhow::{bail, Context as _, Result};
use clap::{Args, CommandFactory};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::json;

use super::Context;

/// Arguments of `toonkit batch`.
#[derive(Debug, Args)]
pub(crate) struct BatchArgs {
    /// The manifest: `[[shot]]` tables with name, tool, input, clip, style, options, outputs.
    pub(crate) manifest: PathBuf,
    /// Output folder: shot outputs are written relative to it (default: the manifest's
    /// folder).
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Shots run at the same time (default: one per core).
    #[arg(long)]
    pub(crate) jobs: Option<usize>,
    /// Only these shots (by name; repeat or comma-separate).
    #[arg(long, value_delimiter = ',')]
    pub(crate) shot: Vec<String>,
    /// Redo every shot, even those whose stamp matches.
    #[arg(long)]
    pub(crate) force: bool,
    /// Write an Open Job Description template (2023-09) running the shots on a farm instead
    /// of running them here.
    #[arg(long, value_name = "JOB.yaml")]
    pub(crate) openjd: Option<PathBuf>,
}

/// The error of a batch in which some shots failed (the others were made).
#[derive(Debug, thiserror::Error)]
#[error("{failed} of {total} shots failed")]
pub(crate) struct ShotsFailed {
    /// Shots that failed.
    pub(crate) failed: usize,
    /// Shots in the batch.
    pub(crate) total: usize,
}

impl ShotsFailed {
    /// The process exit code: the number of failed shots, at most 100.
    pub(crate) fn exit_code(&self) -> u8 {
        self.failed.min(100) as u8
    }
}

/// What happened to one shot.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct ShotReport {
    /// Shot name.
    pub(crate) name: String,
    /// `done`, `skipped` or `failed`.
    pub(crate) status: &'static str,
    /// Files written (or found, when skipped).
    pub(crate) outputs: Vec<PathBuf>,
    /// Wall time.
    pub(crate) seconds: f64,
    /// Why it failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) error: Option<String>,
}

/// Runs `toonkit batch`.
pub(crate) fn run(ctx: &Context, args: BatchArgs) -> Result<()> {
    let start = Instant::now();
    let manifest = read_manifest(&args.manifest)?;
    let base = manifest_dir(&args.manifest);
    let out = args.output.clone().unwrap_or_else(|| base.clone());
    let shots: Vec<&Shot> = manifest
        .shots
        .iter()
        .filter(|s| args.shot.is_empty() || args.shot.contains(&s.name))
        .collect();
    if let Some(unknown) = args
        .shot
        .iter()
        .find(|n| !manifest.shots.iter().any(|s| &s.name == *n))
    {
        bail!("{}: no shot named '{unknown}'", args.manifest.display());
    }
    if let Some(job) = &args.openjd {
        let exe = std::env::current_exe().context("cannot locate the toonkit executable")?;
        let dir = job.parent().unwrap_or(Path::new(""));
        let text = ::batch::openjd_template(&args.manifest, &out, &exe, &manifest, dir)?;
        tkio::save(job, &tkio::Output::Text(&text))?;
        let summary = json!({"manifest": args.manifest, "openjd": job, "shots": shots.len()});
        ctx.report(&summary, || {
            format!("wrote {} ({} shots)", job.display(), manifest.shots.len())
        });
        return Ok(());
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .max(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the worker threads")?;
    let bars = Bars::new(ctx.json);
    let reports: Vec<ShotReport> = pool.install(|| {
        shots
            .par_iter()
            .map(|shot| {
                let bar = bars.add(&shot.name);
                let report = run_shot(shot, &base, &out, args.force, &bar);
                bars.finish(&bar, &report);
                report
            })
            .collect()
    });
    let failed = reports.iter().filter(|r| r.status == "failed").count();
    let count = |s: &str| reports.iter().filter(|r| r.status == s).count();
    let summary = json!({
        "manifest": args.manifest,
        "output": out,
        "jobs": jobs,
        "done": count("done"),
        "skipped": count("skipped"),
        "failed": failed,
        "shots": reports,
        "seconds": start.elapsed().as_secs_f64(),
    });
    ctx.report(&summary, || {
        let mut text = format!(
            "{} shots: {} done, {} skipped, {} failed in {:.1} s",
            reports.len(),
            count("done"),
            count("skipped"),
            failed,
            start.elapsed().as_secs_f64()
        );
        for r in reports.iter().filter(|r| r.status == "failed") {
            text.push_str(&format!(
                "\n  {}: {}",
                r.name,
                r.error.as_deref().unwrap_or("")
            ));
        }
        text
    });
    if failed > 0 {
        return Err(ShotsFailed {
            failed,
            total: reports.len(),
        }
        .into());
    }
    Ok(())
}

/// How a toonkit command (its words) takes its output file, from the parser itself.
pub(crate) fn tool_output(words: &[&str]) -> ToolOutput {
    let mut command = crate::Cli::command();
    for w in words {
        match command.find_subcommand(w) {
            Some(c) => command = c.clone(),
            None => return ToolOutput::Unknown,
        }
    }
    let output = command
        .get_arguments()
        .find(|a| a.get_id() == "output")
        .map(|a| a.is_positional());
    match output {
        Some(true) => ToolOutput::Positional,
        Some(false) => ToolOutput::Option,
        None => ToolOutput::NoOutput,
    }
}

/// Makes one shot (or skips it when its stamp matches).
fn run_shot(shot: &Shot, base: &Path, out: &Path, force: bool, bar: &ProgressBar) -> ShotReport {
    let start = Instant::now();
    let outputs: Vec<PathBuf> = shot.outputs.iter().map(|o| out.join(o)).collect();
    let result = (|| -> Result<&'static str> {
        let hash = Stamp::hash(shot, base, &tool_output)
            .with_context(|| format!("shot '{}'", shot.name))?;
        if !force && Stamp::is_done(shot, out, &hash) {
            return Ok("skipped");
        }
        for (k, o) in outputs.iter().enumerate() {
            tkio::remove_stale_temps(o);
            bar.set_message(format!("{} ({}/{})", o.display(), k + 1, outputs.len()));
            let argv = shot.command_line(base, o, tool_output)?;
            crate::run_args(&argv[1..])
                .with_context(|| format!("shot '{}' ({})", shot.name, argv[1..].join(" ")))?;
        }
        Stamp::write_done(shot, out, &hash)?;
        Ok("done")
    })();
    let (status, error) = match result {
        Ok(s) => (s, None),
        Err(e) => ("failed", Some(crate::one_line(&e))),
    };
    ShotReport {
        name: shot.name.clone(),
        status,
        outputs,
        seconds: start.elapsed().as_secs_f64(),
        error,
    }
}

/// One progress line per shot, shown on a terminal (never with `--json`).
struct Bars {
    multi: Option<MultiProgress>,
}

impl Bars {
    fn new(json: bool) -> Bars {
        let show = !json && std::io::stderr().is_terminal();
        Bars {
            multi: show.then(MultiProgress::new),
        }
    }

    fn add(&self, name: &str) -> ProgressBar {
        let Some(multi) = &self.multi else {
            return ProgressBar::hidden();
        };
        let bar = multi.add(ProgressBar::new_spinner());
        if let Ok(style) = ProgressStyle::with_template("{spinner} {prefix:>16} {elapsed:>4} {msg}")
        {
            bar.set_style(style);
        }
        bar.set_prefix(name.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        bar
    }

    fn finish(&self, bar: &ProgressBar, report: &ShotReport) {
        let msg = match &report.error {
            Some(e) => format!("FAILED: {e}"),
            None => format!("{} in {:.1} s", report.status, report.seconds),
        };
        bar.finish_with_message(msg);
    }
}
