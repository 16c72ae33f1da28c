//! `toonkit`: smear frames, stop-motion replacement libraries and dynamic lines of action for
//! 3D animation. The CLI is thin: it parses options, calls the library crates, and reports.
//! The binary (`src/main.rs`) calls [`main`]; the parser [`Cli`] is public so that tests can
//! walk every subcommand's options.

mod commands;
mod flags;
mod output;
mod progress;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Stylization tools for 3D animation: smear frames, 3D-printed stop-motion, lines of action.
#[derive(Debug, Parser)]
#[command(name = "toonkit", version, about, propagate_version = true)]
pub struct Cli {
    /// Print a machine-readable JSON summary (timings included) on stdout instead of text.
    #[arg(long, global = true)]
    json: bool,
    /// Write glTF flipbooks and morph outputs with float geometry instead of
    /// KHR_mesh_quantization (the default: about half the size, positions within 1e-5 of the
    /// bounding-box diagonal, seams shared by parts exact), for tools that cannot read it.
    #[arg(long, global = true)]
    no_quantize: bool,
    /// Quantized glTF output (the default; kept for scripts that pass it).
    #[arg(long, global = true, hide = true, conflicts_with = "no_quantize")]
    quantize: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Describe a file: meshes, vertices, triangles, joints, morph targets, clips, bounds.
    Info(flags::Deferred<commands::info::InfoArgs>),
    /// Convert any readable animation into any writable one.
    Convert(flags::Deferred<commands::convert::ConvertArgs>),
    /// Run the tools on the bundled sample and write the results.
    Demo(flags::Deferred<commands::demo::DemoArgs>),
    /// Dynamic lines of action: sketched keystrokes → animated line (Guay et al. 2015).
    Loa(flags::Deferred<commands::loa::LoaArgs>),
    /// Preview an animation as PNG (one frame, onion skins) or GIF, coloured by motion offsets.
    Render(flags::Deferred<commands::render::RenderArgs>),
    /// Smear frames: motion offsets (Basset et al. 2024).
    Smear(flags::Deferred<Box<commands::smear::SmearArgs>>),
    /// Replacement libraries for 3D-printed stop-motion (StopShop).
    Stopmo(flags::Deferred<Box<commands::stopmo::StopmoArgs>>),
    /// A local web page to tune smears, sketch lines of action and segment faces (127.0.0.1).
    Studio(flags::Deferred<commands::studio::StudioArgs>),
    /// Many shots from a manifest: in parallel here, or as an Open Job Description farm job.
    Batch(flags::Deferred<commands::batch::BatchArgs>),
}

/// Runs `toonkit ARGS…` in this process, quietly (no summary, no spinner): the demo's steps
/// and batch shots are exactly the command lines a user would type. A panic in a command is
/// an error of that command, not a crash of the caller.
pub(crate) fn run_args(args: &[String]) -> anyhow::Result<()> {
    let argv = std::iter::once("toonkit").chain(args.iter().map(String::as_str));
    let cli = Cli::try_parse_from(argv).map_err(|e| anyhow::anyhow!("{}", usage_error(&e)))?;
    let ctx = cli.context(true);
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(&ctx, cli.command)))
        .unwrap_or_else(|_| {
            Err(anyhow::anyhow!(
                "the command panicked (a bug: please report it)"
            ))
        })
}

/// Runs `toonkit` on the process's arguments: exit 0, or 2 on any error (one line on stderr)
/// and when any shot of `toonkit batch` failed.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            eprintln!("toonkit: error: {} (see --help)", usage_error(&e));
            return ExitCode::from(2);
        }
        Err(e) => e.exit(), // --help, --version
    };
    let ctx = cli.context(false);
    match run(&ctx, cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<commands::batch::ShotsFailed>() => {
            let failed = e.downcast_ref::<commands::batch::ShotsFailed>();
            eprintln!("toonkit: error: {e}");
            ExitCode::from(failed.map_or(2, |f| f.exit_code()))
        }
        Err(e) => {
            eprintln!("toonkit: error: {}", one_line(&e));
            ExitCode::from(2)
        }
    }
}

/// An error and its causes as one line, each text once: a cause already said by the message
/// before it (an OS error its wrapper described in the user's terms, a path the context
/// repeats) is left out.
pub(crate) fn one_line(e: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if msg.is_empty() || text.contains(msg.as_str()) {
            msg = text;
        } else if msg.contains(text.as_str()) || cause.is::<std::io::Error>() {
            continue;
        } else {
            msg.push_str(": ");
            msg.push_str(&text);
        }
    }
    msg.replace('\n', " ")
}

impl Cli {
    /// The options every command sees (`quiet`: in-process runs, which report as JSON).
    fn context(&self, quiet: bool) -> commands::Context {
        let save = tkio::SaveOptions {
            quantize: !self.no_quantize,
        };
        let json = self.json || quiet;
        commands::Context { json, quiet, save }
    }
}

/// The first line of a usage error, without clap's "error: " (its usage and hint follow).
fn usage_error(e: &clap::Error) -> String {
    let text = e.to_string();
    let first = text.lines().next().unwrap_or("invalid arguments");
    first.trim_start_matches("error: ").to_string()
}

/// Runs one parsed command (the binary's dispatcher; `toonkit batch` runs its shots through
/// it too). Each command (each batch shot, each demo step) is one job: no file it writes may
/// replace a file it reads ([`tkio::ReadScope`]). A batch is not one job itself (its shots
/// are), and the studio holds its scene for as long as it serves it.
fn run(ctx: &commands::Context, command: Command) -> anyhow::Result<()> {
    let _job = (!matches!(
        command,
        Command::Batch(_) | Command::Studio(_) | Command::Demo(_)
    ))
    .then(tkio::ReadScope::open);
    match command {
        Command::Info(a) => commands::info::run(ctx, a.0),
        Command::Convert(a) => commands::convert::run(ctx, a.0),
        Command::Demo(a) => commands::demo::run(ctx, a.0),
        Command::Loa(a) => commands::loa::run(ctx, a.0),
        Command::Render(a) => commands::render::run(ctx, a.0),
        Command::Smear(a) => commands::smear::run(ctx, *a.0),
        Command::Stopmo(a) => commands::stopmo::run(ctx, *a.0),
        Command::Batch(a) => commands::batch::run(ctx, a.0),
        Command::Studio(a) => commands::studio::run(ctx, a.0),
    }
}
