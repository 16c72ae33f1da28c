//! One module per subcommand.

pub mod convert;
pub mod demo;
pub mod info;
pub mod loa;
mod loa_animate;
mod loa_render;
pub mod render;
pub mod smear;
pub mod smear_effects;
mod smear_prepare;
pub mod smear_style;
pub mod stopmo;
mod stopmo_curve;
mod stopmo_library;
mod stopmo_print;
mod stopmo_run;

/// Options every command sees.
#[derive(Debug, Clone, Copy)]
pub struct Context {
    /// Print JSON on stdout instead of human text.
    pub json: bool,
}

impl Context {
    /// Prints a summary: the JSON value with `--json`, otherwise the human text.
    /// A closed stdout (`toonkit --json info X | head`) is not an error: the work is done.
    pub fn report(&self, value: &serde_json::Value, text: impl FnOnce() -> String) {
        use std::io::Write as _;
        let out = if self.json {
            serde_json::to_string_pretty(value).unwrap_or_default()
        } else {
            text()
        };
        let _ = writeln!(std::io::stdout().lock(), "{out}");
    }
}
