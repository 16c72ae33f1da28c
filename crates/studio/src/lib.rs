//! toonkit studio: a local web page over the three tools' whole-job calls.
//!
//! `toonkit studio FILE... [--port 8765] [--no-open]` serves one page (three.js vendored and embedded for the
//! viewport) and a small API on `127.0.0.1`:
//!
//! * smear — [`smear::prepare`] once per opened file and clip (offsets solved once), then
//!   [`smear::stylize`] on every slider change; the geometry goes back as float32 buffers.
//! * loa — keystrokes drawn over the viewport ([`loa::Keystrokes`] from the page's JSON),
//!   [`loa::line`] then [`loa::animate()`]: the dynamic line (LoA Section 3) and the character
//!   that follows it (LoA Section 4).
//! * stopmo — part seeds clicked on the mesh, [`stopmo::segment()`] on a worker thread with
//!   progress polling and cancel (StopShop Section 4).
//!
//! Safety: the server binds 127.0.0.1 only, refuses requests whose `Host`/`Origin` is not the
//! local server (DNS rebinding, [`guard`]), reads only the files it was opened with (the API
//! names them by index, never by path), writes only inside its output folder
//! ([`files::output_path`]), limits request bodies ([`MAX_BODY_BYTES`]) and answers every bad
//! request with a JSON error (`{"error": "..."}`). Requests running at once share one memory
//! pool the size of the job budget ([`memory`]): a request that does not fit waits briefly,
//! then is answered 503.
//!
//! ```no_run
//! let options = studio::ServeOptions {
//!     files: vec!["assets/characters/RobotExpressive.glb".into()],
//!     ..Default::default()
//! };
//! studio::serve(&options)?;
//! # Ok::<(), studio::StudioError>(())
//! ```

#![warn(missing_docs, unreachable_pub)]

pub mod api;
pub mod error;
pub mod files;
pub mod guard;
pub mod jobs;
mod loa_skin;
mod lock;
pub mod memory;
pub mod pack;
pub mod server;
pub mod state;
pub mod web;

pub use error::{ApiError, StudioError};
pub use server::{router, serve, ServeOptions, DEFAULT_PORT, MAX_BODY_BYTES};
pub use state::Studio;
