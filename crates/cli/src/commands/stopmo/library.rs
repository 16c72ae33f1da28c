//! `toonkit stopmo library IN -o DIR`: replacement libraries (StopShop Sections 3.3–3.4, 5)
//! and everything an animator needs to print and shoot them, in the layout of SPEC.md
//! "Output layouts" (listed by `stopmo::LibraryResult::files`).

use std::path::{Path, PathBuf};

use anim::MeshFrames;
use anyhow::{bail, Result};
use clap::Args;

use super::{warn, LibraryOptionsArgs};
use crate::commands::Context;
use crate::flags::io::InputArgs;

/// Arguments of `toonkit stopmo library`.
#[derive(Debug, Args)]
pub(crate) struct LibraryArgs {
    /// Input animation; every mesh object is one part named after it (e.g. the .glb of
    /// `toonkit stopmo segment`), a single object is one part.
    pub(crate) input: PathBuf,
    /// Output directory.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) library: LibraryOptionsArgs,
    #[command(flatten)]
    pub(crate) input_args: InputArgs,
}

/// The parts of the input: one per mesh object, named after it (file-safe; the file stem
/// for an unnamed object), as morph weights when the clip only morphs still objects
/// (`tkio::open_frames`), else as positions.
fn parts(path: &Path, args: &InputArgs) -> Result<Vec<MeshFrames>> {
    let mut parts = tkio::open_frames(path, &args.options())?;
    if parts.is_empty() {
        bail!("{}: the file has no mesh", path.display());
    }
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("part");
    for p in &mut parts {
        let mesh = p.mesh_mut();
        mesh.name = stopmo::file_safe_name(if mesh.name.is_empty() {
            stem
        } else {
            &mesh.name
        });
    }
    Ok(parts)
}

/// Runs `toonkit stopmo library`.
pub(super) fn library(ctx: &Context, args: LibraryArgs) -> Result<()> {
    let anims = parts(&args.input, &args.input_args)?;
    let names: Vec<String> = anims.iter().map(|a| a.mesh().name.clone()).collect();
    let options = args.library.options(&names)?;
    let spinner = crate::progress::spinner("optimizing the library", ctx.json);
    let mut result = stopmo::library_frames(&anims, &options)
        .map_err(|e| args.library.context(e, &args.input))?;
    spinner.finish_and_clear();
    drop(anims);
    result.report.input = Some(args.input.display().to_string());
    tkio::save_files(&args.output, &result.files()?)?;
    warn(ctx, &result);
    let report = serde_json::to_value(&result.report)?;
    if let Some(p) = &args.library.report {
        tkio::save(p, &tkio::Output::Text(&result.report.to_json()))?;
    }
    ctx.report(&report, || describe(&result, &args.output));
    Ok(())
}

/// One line for people about a library written to `dir`.
pub(super) fn describe(result: &stopmo::LibraryResult, dir: &Path) -> String {
    let r = &result.report;
    let e = r.errors_mm;
    format!(
        "wrote {}: {} pieces over {} parts and {} frames; error mean {:.3} mm (max {:.3}), \
         velocity mean {:.3} mm (max {:.3}); {} shots, {} swaps (in sequence {}); {:.2} s",
        dir.display(),
        r.pieces,
        r.parts.len(),
        r.frames,
        e.position_mean,
        e.position_max,
        e.velocity_mean,
        e.velocity_max,
        r.shooting_order.shots,
        r.shooting_order.swaps,
        r.shooting_order.sequential_swaps,
        r.total_seconds
    )
}
