//! `toonkit studio FILE... [--port 8765] [--no-open] [--out DIR]`: the local web page
//! (`studio::serve`).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::Context;

#[derive(Debug, Args)]
pub(crate) struct StudioArgs {
    /// Files to open (the first is shown first; a second one, e.g. the face, feeds stopmo).
    /// The studio reads these files and no other.
    #[arg(required = true)]
    pub(crate) files: Vec<PathBuf>,
    /// Port on 127.0.0.1 (0 = any free port).
    #[arg(long, default_value_t = studio::DEFAULT_PORT)]
    pub(crate) port: u16,
    /// Do not open a browser.
    #[arg(long)]
    pub(crate) no_open: bool,
    /// The only folder the studio writes into.
    #[arg(short, long, default_value = "studio-out")]
    pub(crate) out: PathBuf,
}

pub(crate) fn run(_ctx: &Context, args: StudioArgs) -> Result<()> {
    let options = studio::ServeOptions {
        files: args.files,
        port: args.port,
        open: !args.no_open,
        out_dir: args.out,
    };
    studio::serve(&options)?;
    Ok(())
}
