//! The command-line flags of the tool crates' jobs: clap lives in the CLI only, the tool crates
//! keep the serde option structs, presets, defaults and ranges the flags fill and show.

mod deferred;
pub(crate) mod io;
pub(crate) mod loa;
pub(crate) mod render;
pub(crate) mod smear;
pub(crate) mod stopmo;

pub(crate) use deferred::{built, Deferred};

/// A flag whose value (or a file it names) cannot be used, in the user's terms
/// (`--settle x: …`, `--step must be ≥ 1 …`).
#[derive(Debug, thiserror::Error)]
pub(crate) enum FlagError {
    /// A flag's value is wrong; the text names the flag.
    #[error("{0}")]
    Flag(String),
    /// A flag and value, or a file a flag names (`at`), and what is wrong with it.
    #[error("{at}")]
    At {
        /// The flag and its value, or the file.
        at: String,
        /// What is wrong.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The smear library refused the options the flags describe.
    #[error(transparent)]
    Smear(#[from] ::smear::SmearError),
    /// A file a flag names cannot be read.
    #[error(transparent)]
    Io(#[from] tkio::IoError),
}
