//! `toonkit batch MANIFEST.toml -o OUT [--jobs N] [--shot NAME] [--openjd job.yaml]`: many
//! shots, in parallel on this machine, or as an Open Job Description template for a farm.
//!
//! A manifest lists shots:
//!
//! ```toml
//! [[shot]]
//! name = "robot_punch"                    # unique; [A-Za-z0-9_.-]
//! tool = "convert"                        # toonkit command words: "smear elongate", "loa animate", …
//! input = "characters/RobotExpressive.glb"  # relative to the manifest's folder
//! clip = "Punch"                          # optional: --clip
//! style = "styles/punchy.toml"            # optional: --style (relative to the manifest)
//! options = { fps = 24, mesh = ["Body"] } # optional: --fps 24 --mesh Body (true: a bare flag)
//! outputs = ["punch.abc", "punch.usdc", "punch.pc2"]  # relative to OUT; one run per output
//! ```
//!
//! Each output is made by running the equivalent `toonkit` command line in this process,
//! through the same parser and dispatcher as the `toonkit` binary, so every command and
//! option of the tools works in a manifest. A shot whose outputs exist and whose inputs and
//! options hash as recorded in `OUT/.toonkit-batch/<shot>.json` is skipped: the stamp is written
//! (atomically) only after all of the shot's outputs, so re-running after a crash or a kill
//! redoes only what is missing. A failing shot is reported and the others go on; the exit
//! code is the number of failed shots (capped at 100).

mod openjd;

use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{bail, Context as _, Result};
use clap::{Args, CommandFactory};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::json;

use super::Context;

/// Folder (inside OUT) of the per-shot stamps.
pub const STAMP_DIR: &str = ".toonkit-batch";

/// Arguments of `toonkit batch`.
#[derive(Debug, Args)]
pub struct BatchArgs {
    /// The manifest: `[[shot]]` tables with name, tool, input, clip, style, options, outputs.
    pub manifest: PathBuf,
    /// Output folder: shot outputs are written relative to it (default: the manifest's
    /// folder).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Shots run at the same time (default: one per core).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Only these shots (by name; repeat or comma-separate).
    #[arg(long, value_delimiter = ',')]
    pub shot: Vec<String>,
    /// Redo every shot, even those whose stamp matches.
    #[arg(long)]
    pub force: bool,
    /// Write an Open Job Description template (2023-09) running the shots on a farm instead
    /// of running them here.
    #[arg(long, value_name = "JOB.yaml")]
    pub openjd: Option<PathBuf>,
}

/// A manifest: the shots to make.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The shots, in order.
    #[serde(rename = "shot", default)]
    pub shots: Vec<Shot>,
}

/// One shot of a manifest.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shot {
    /// Unique name: stamp file name and OpenJD task value.
    pub name: String,
    /// The toonkit command words (`convert`, `smear elongate`, …).
    pub tool: String,
    /// Input file, relative to the manifest's folder.
    pub input: PathBuf,
    /// Clip to sample (`--clip`).
    #[serde(default)]
    pub clip: Option<String>,
    /// Style file (`--style`), relative to the manifest's folder.
    #[serde(default)]
    pub style: Option<PathBuf>,
    /// More options, `--name value` each (`true`: bare flag, `false`: left out, arrays
    /// comma-joined).
    #[serde(default)]
    pub options: BTreeMap<String, toml::Value>,
    /// Output files, relative to OUT; the command runs once per output.
    pub outputs: Vec<PathBuf>,
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
    /// The process exit code: the number of failed shots, at most 100.
    pub fn exit_code(&self) -> u8 {
        self.failed.min(100) as u8
    }
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

/// The stamp of a completed shot.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
struct Stamp {
    shot: String,
    hash: String,
    /// `(output, size in bytes)` of every declared output.
    outputs: Vec<(PathBuf, u64)>,
}

/// Runs `toonkit batch`.
pub fn run(ctx: &Context, args: BatchArgs) -> Result<()> {
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
        let text = openjd::template(&args.manifest, &out, &exe, &manifest, dir)?;
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

/// Reads and checks a manifest (unique, file-safe names; outputs listed).
pub fn read_manifest(path: &Path) -> Result<Manifest> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the manifest", path.display()))?;
    let manifest: Manifest = toml::from_str(&text).map_err(|e| {
        let msg = e.to_string().replace('\n', " ");
        anyhow::anyhow!("{}: invalid manifest: {}", path.display(), msg.trim())
    })?;
    if manifest.shots.is_empty() {
        bail!("{}: the manifest lists no [[shot]]", path.display());
    }
    let mut seen = std::collections::BTreeSet::new();
    for s in &manifest.shots {
        let ok = !s.name.is_empty()
            && s.name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_.-".contains(c))
            && !s.name.starts_with('.');
        if !ok {
            bail!(
                "{}: shot name '{}' must be letters, digits, '_', '.', '-'",
                path.display(),
                s.name
            );
        }
        if !seen.insert(&s.name) {
            bail!("{}: shot '{}' is listed twice", path.display(), s.name);
        }
        if s.outputs.is_empty() {
            bail!("{}: shot '{}' lists no outputs", path.display(), s.name);
        }
        if s.tool.split_whitespace().next() == Some("batch") {
            bail!("{}: shot '{}' cannot run a batch", path.display(), s.name);
        }
    }
    Ok(manifest)
}

/// The folder relative paths of a manifest start from.
fn manifest_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The `toonkit` argument vector making `output` of `shot`.
pub fn command_line(shot: &Shot, base: &Path, output: &Path) -> Result<Vec<String>> {
    let words: Vec<&str> = shot.tool.split_whitespace().collect();
    let mut command = crate::Cli::command();
    for w in &words {
        command = command
            .find_subcommand(w)
            .cloned()
            .ok_or_else(|| anyhow::anyhow!("shot '{}': unknown tool '{}'", shot.name, shot.tool))?;
    }
    let positional_output = command
        .get_arguments()
        .find(|a| a.get_id() == "output")
        .map(|a| a.is_positional())
        .ok_or_else(|| {
            anyhow::anyhow!(
                "shot '{}': '{}' writes no output file",
                shot.name,
                shot.tool
            )
        })?;
    let text = |p: &Path| p.to_string_lossy().into_owned();
    let mut argv = vec!["toonkit".to_string()];
    argv.extend(words.iter().map(|w| w.to_string()));
    argv.push(text(&base.join(&shot.input)));
    if positional_output {
        argv.push(text(output));
    }
    if let Some(clip) = &shot.clip {
        argv.extend(["--clip".to_string(), clip.clone()]);
    }
    if let Some(style) = &shot.style {
        argv.extend(["--style".to_string(), text(&base.join(style))]);
    }
    for (name, value) in &shot.options {
        let flag = format!("--{name}");
        match value {
            toml::Value::Boolean(true) => argv.push(flag),
            toml::Value::Boolean(false) => {}
            toml::Value::String(s) => argv.extend([flag, s.clone()]),
            toml::Value::Array(items) => {
                let items: Vec<String> = items.iter().map(scalar).collect();
                argv.extend([flag, items.join(",")]);
            }
            other => argv.extend([flag, scalar(other)]),
        }
    }
    if !positional_output {
        argv.extend(["-o".to_string(), text(output)]);
    }
    Ok(argv)
}

fn scalar(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The hash of everything that decides a shot's outputs: toonkit's version, the command
/// lines (with OUT left out, so a moved folder still matches), the input and style bytes.
fn shot_hash(shot: &Shot, base: &Path) -> Result<String> {
    let mut buf = Vec::new();
    buf.extend_from_slice(env!("CARGO_PKG_VERSION").as_bytes());
    for o in &shot.outputs {
        for a in command_line(shot, base, &Path::new("{OUT}").join(o))? {
            buf.extend_from_slice(a.as_bytes());
            buf.push(0);
        }
    }
    for file in std::iter::once(&shot.input).chain(shot.style.as_ref()) {
        let p = base.join(file);
        let bytes = std::fs::read(&p).with_context(|| format!("{}: cannot read", p.display()))?;
        buf.extend_from_slice(&twox_hash::XxHash3_128::oneshot(&bytes).to_le_bytes());
    }
    Ok(format!("{:032x}", twox_hash::XxHash3_128::oneshot(&buf)))
}

fn stamp_path(out: &Path, shot: &Shot) -> PathBuf {
    out.join(STAMP_DIR).join(format!("{}.json", shot.name))
}

/// The stamp of the shot's outputs as they are on disk, if they all exist.
fn current_stamp(shot: &Shot, out: &Path, hash: &str) -> Option<Stamp> {
    let outputs = shot
        .outputs
        .iter()
        .map(|o| Some((o.clone(), std::fs::metadata(out.join(o)).ok()?.len())))
        .collect::<Option<Vec<_>>>()?;
    Some(Stamp {
        shot: shot.name.clone(),
        hash: hash.to_string(),
        outputs,
    })
}

/// Makes one shot (or skips it when its stamp matches).
fn run_shot(shot: &Shot, base: &Path, out: &Path, force: bool, bar: &ProgressBar) -> ShotReport {
    let start = Instant::now();
    let outputs: Vec<PathBuf> = shot.outputs.iter().map(|o| out.join(o)).collect();
    let result = (|| -> Result<&'static str> {
        let hash = shot_hash(shot, base).with_context(|| format!("shot '{}'", shot.name))?;
        let stamp_file = stamp_path(out, shot);
        let recorded = std::fs::read(&stamp_file)
            .ok()
            .and_then(|b| serde_json::from_slice::<Stamp>(&b).ok());
        if !force && recorded.is_some() && recorded == current_stamp(shot, out, &hash) {
            return Ok("skipped");
        }
        for (k, o) in outputs.iter().enumerate() {
            tkio::remove_stale_temps(o);
            bar.set_message(format!("{} ({}/{})", o.display(), k + 1, outputs.len()));
            let argv = command_line(shot, base, o)?;
            crate::run_args(&argv[1..])
                .with_context(|| format!("shot '{}' ({})", shot.name, argv[1..].join(" ")))?;
        }
        let stamp = current_stamp(shot, out, &hash).ok_or_else(|| {
            anyhow::anyhow!("shot '{}': a declared output was not written", shot.name)
        })?;
        let text = serde_json::to_string_pretty(&stamp)?;
        tkio::save(&stamp_file, &tkio::Output::Text(&text))?;
        Ok("done")
    })();
    let (status, error) = match result {
        Ok(s) => (s, None),
        Err(e) => ("failed", Some(format!("{e:#}").replace('\n', " "))),
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
