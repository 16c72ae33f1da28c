//! The command-line flags of the tool crates' jobs: clap lives in the CLI only, the tool crates
//! keep the serde option structs, presets, defaults and ranges the flags fill and show.

pub(crate) mod loa;
pub(crate) mod render;
