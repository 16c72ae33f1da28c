//! Farm batches of toonkit shots, as data: a [`Manifest`] of [`Shot`]s (read from TOML), the
//! `toonkit` command line that makes each output ([`Shot::command_line`]), the completion
//! [`Stamp`] that lets a re-run skip finished shots, and the Open Job Description template
//! ([`openjd_template`]) that runs the shots on a farm. Running the command lines is the
//! front end's part (`toonkit batch` runs them in-process through its own parser).
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
//! ```
//! let manifest = batch::Manifest::from_toml_str(
//!     "[[shot]]\nname = \"a\"\ntool = \"convert\"\ninput = \"in.glb\"\noutputs = [\"a.pc2\"]\n",
//! )
//! .unwrap();
//! let argv = manifest.shots[0]
//!     .command_line("shots".as_ref(), "out/a.pc2".as_ref(), |_| batch::ToolOutput::Positional)
//!     .unwrap();
//! assert_eq!(argv, ["toonkit", "convert", "shots/in.glb", "out/a.pc2"]);
//! ```
#![warn(missing_docs, unreachable_pub)]

pub mod demo;
mod error;
mod manifest;
mod openjd;
mod run;
mod stamp;

pub use error::BatchError;
pub use manifest::{manifest_dir, read_manifest, Manifest, Shot, ToolOutput};
pub use openjd::openjd_template;
pub use run::{
    run_shots, select_shots, BatchReport, RunOptions, Runner, ShotFailure, ShotReport, ShotsFailed,
};
pub use stamp::{Stamp, STAMP_DIR};
