//! One module per subcommand.

pub(crate) mod batch;
pub(crate) mod convert;
pub(crate) mod demo;
pub(crate) mod info;
pub(crate) mod loa;
pub(crate) mod render;
pub(crate) mod smear;
pub(crate) mod stopmo;
pub(crate) mod studio;

/// Options every command sees.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Context {
    /// Print JSON on stdout instead of human text.
    pub(crate) json: bool,
    /// Print no summary at all (the caller reports: steps of `toonkit demo`, shots of
    /// `toonkit batch`).
    pub(crate) quiet: bool,
    /// How results are written (`--no-quantize`: float glTF geometry).
    pub(crate) save: tkio::SaveOptions,
}

impl Context {
    /// Prints a summary: the JSON value with `--json`, otherwise the human text.
    /// A closed stdout (`toonkit --json info X | head`) is not an error: the work is done.
    pub(crate) fn report(&self, value: &serde_json::Value, text: impl FnOnce() -> String) {
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
