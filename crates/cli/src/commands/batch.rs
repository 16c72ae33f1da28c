//! `toonkit batch MANIFEST.toml -o OUT [--jobs N] [--shot NAME] [--openjd job.yaml]`: many
//! shots, in parallel on this machine, or as an Open Job Description template for a farm.
//! The manifest, command lines, stamps, template and the parallel runner are the `batch`
//! crate's; this command gives the runner the tool: each output's command line runs in this
//! process, through the same parser and dispatcher as the `toonkit` binary, so every command
//! and option of the tools works in a manifest. A failing shot is reported and the others go
//! on; the exit code is 2 when any shot failed (as for any bad input), and the report (`--json`)
//! says which and why, per shot.

use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

pub(crate) use ::batch::ShotsFailed;
use ::batch::{
    manifest_dir, read_manifest, run_shots, select_shots, RunOptions, Runner, Shot, ShotFailure,
    ShotReport, ToolOutput,
};
use anyhow::{Context as _, Result};
use clap::{Args, CommandFactory};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use serde_json::json;

use super::Context;

/// Arguments of `toonkit batch`.
#[derive(Debug, Args)]
#[command(
    after_help = "Exit code: 0 when every shot was made or skipped, 2 when any shot \
failed (the others are still made; --json reports each shot's status and error)."
)]
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

/// Runs `toonkit batch`.
pub(crate) fn run(ctx: &Context, args: BatchArgs) -> Result<()> {
    let start = Instant::now();
    let manifest = read_manifest(&args.manifest)?;
    let base = manifest_dir(&args.manifest);
    let out = args.output.clone().unwrap_or_else(|| base.clone());
    let shots = select_shots(&manifest, &args.manifest, &args.shot)?;
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
    let options = RunOptions {
        shots: args.shot.clone(),
        jobs: args.jobs,
        force: args.force,
    };
    let report = run_shots(&shots, &base, &out, &options, &InProcess::new(ctx.json))?;
    let failed = report.count("failed");
    let summary = json!({
        "manifest": args.manifest,
        "output": out,
        "jobs": report.jobs,
        "done": report.count("done"),
        "skipped": report.count("skipped"),
        "failed": failed,
        "shots": report.shots,
        "seconds": start.elapsed().as_secs_f64(),
    });
    let seconds = start.elapsed().as_secs_f64();
    ctx.report(&summary, || report.summary(seconds));
    if failed > 0 {
        return Err(ShotsFailed {
            failed,
            total: report.shots.len(),
        }
        .into());
    }
    Ok(())
}

/// The shots' tool: `toonkit` itself, in this process, with one progress line per shot on a
/// terminal (never with `--json`).
struct InProcess {
    /// The `toonkit` parser: how each command takes its output.
    parser: clap::Command,
    multi: Option<MultiProgress>,
    bars: Mutex<HashMap<String, ProgressBar>>,
}

impl InProcess {
    fn new(json: bool) -> InProcess {
        let show = !json && std::io::stderr().is_terminal();
        InProcess {
            parser: crate::flags::built(crate::Cli::command()),
            multi: show.then(MultiProgress::new),
            bars: Mutex::default(),
        }
    }

    /// The progress line of a shot (made on its first output).
    fn bar(&self, name: &str) -> ProgressBar {
        let Some(multi) = &self.multi else {
            return ProgressBar::hidden();
        };
        let mut bars = self.bars.lock().unwrap_or_else(|e| e.into_inner());
        bars.entry(name.to_string())
            .or_insert_with(|| {
                let bar = multi.add(ProgressBar::new_spinner());
                if let Ok(style) =
                    ProgressStyle::with_template("{spinner} {prefix:>16} {elapsed:>4} {msg}")
                {
                    bar.set_style(style);
                }
                bar.set_prefix(name.to_string());
                bar.enable_steady_tick(Duration::from_millis(120));
                bar
            })
            .clone()
    }
}

impl Runner for InProcess {
    type Error = anyhow::Error;

    fn run(&self, argv: &[String]) -> Result<()> {
        crate::run_args(argv)
    }

    fn tool_output(&self, words: &[&str]) -> ToolOutput {
        ToolOutput::of(&self.parser, words)
    }

    fn describe(&self, shot: &Shot, failure: ShotFailure<anyhow::Error>) -> String {
        let e = match failure {
            ShotFailure::Hash(e) => anyhow::Error::new(e).context(format!("shot '{}'", shot.name)),
            ShotFailure::Batch(e) => e.into(),
            ShotFailure::Command { command, error } => {
                error.context(format!("shot '{}' ({command})", shot.name))
            }
        };
        crate::one_line(&e)
    }

    fn writing(&self, shot: &Shot, k: usize, n: usize, output: &Path) {
        let msg = format!("{} ({}/{})", output.display(), k + 1, n);
        self.bar(&shot.name).set_message(msg);
    }

    fn finished(&self, report: &ShotReport) {
        let msg = match &report.error {
            Some(e) => format!("FAILED: {e}"),
            None => format!("{} in {:.1} s", report.status, report.seconds),
        };
        self.bar(&report.name).finish_with_message(msg);
    }
}
