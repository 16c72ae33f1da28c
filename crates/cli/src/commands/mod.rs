//! One module per subcommand.

pub mod batch;
pub mod convert;
pub mod demo;
pub mod info;
pub mod loa;
pub mod render;
pub mod smear;
pub mod stopmo;
pub mod studio;

/// Options every command sees.
#[derive(Debug, Clone, Copy)]
pub struct Context {
    /// Print JSON on stdout instead of human text.
    pub json: bool,
    /// Print no summary at all (the caller reports: steps of `toonkit demo`, shots of
    /// `toonkit batch`).
    pub quiet: bool,
    /// How results are written (`--no-quantize`: float glTF geometry).
    pub save: tkio::SaveOptions,
}

impl Context {
    /// Prints a summary: the JSON value with `--json`, otherwise the human text.
    /// A closed stdout (`toonkit --json info X | head`) is not an error: the work is done.
    pub fn report(&self, value: &serde_json::Value, text: impl FnOnce() -> String) {
        use std::io::Write as _;
        if self.quiet {
            return;
        }
        let out = if self.json {
            serde_json::to_string_pretty(value).unwrap_or_default()
        } else {
            text()
        };
        let _ = writeln!(std::io::stdout().lock(), "{out}");
    }
}
