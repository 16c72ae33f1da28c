//! Progress bars for long work, hidden when stderr is not a terminal or output is JSON.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::ProgressBar;

/// A spinner for work of unknown length.
pub(crate) fn spinner(message: &str, json: bool) -> ProgressBar {
    if json || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new_spinner();
    pb.set_message(message.to_string());
    pb.enable_steady_tick(Duration::from_millis(100));
    pb
}
