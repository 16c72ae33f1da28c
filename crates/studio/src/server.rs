//! Starting the server: [`serve`] for `toonkit studio`, [`router`] for tests.

use std::net::{Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;

use axum::extract::DefaultBodyLimit;
use axum::routing::get;
use axum::serve::ListenerExt;
use axum::Router;

use crate::error::{ApiError, StudioError};
use crate::files::{output_folder, OpenedFile};
use crate::guard::{self, Allowed};
use crate::state::Studio;
use crate::{api, web};

/// The default port.
pub const DEFAULT_PORT: u16 = 8765;

/// Largest request body accepted (keystrokes, styles, seeds are small).
pub const MAX_BODY_BYTES: usize = 2 * 1024 * 1024;

/// What `toonkit studio` was asked.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The files the studio may read (the first is shown first).
    pub files: Vec<PathBuf>,
    /// Port on 127.0.0.1 (0 = any free port).
    pub port: u16,
    /// Open the page in the default browser.
    pub open: bool,
    /// The only folder the studio writes into.
    pub out_dir: PathBuf,
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            files: Vec::new(),
            port: DEFAULT_PORT,
            open: false,
            out_dir: PathBuf::from("studio-out"),
        }
    }
}

/// The router of a studio answering as `127.0.0.1:port` / `localhost:port`.
pub fn router(studio: Arc<Studio>, port: u16) -> Router {
    let allowed = Allowed::local(port);
    Router::new()
        .route("/", get(web::index))
        .route("/{name}", get(web::page))
        .route("/vendor/three/{*path}", get(web::three))
        .merge(api::routes())
        .fallback(|| async { ApiError::not_found("no such route") })
        .layer(DefaultBodyLimit::max(MAX_BODY_BYTES))
        .layer(axum::middleware::from_fn_with_state(allowed, guard::check))
        .with_state(studio)
}

/// Opens the files, binds 127.0.0.1 and serves until the process ends.
///
/// # Errors
/// A file that cannot be read, an output folder that cannot be made, a port in use.
pub fn serve(options: &ServeOptions) -> Result<(), StudioError> {
    if options.files.is_empty() {
        return Err(StudioError::Options(
            "give at least one file to open".into(),
        ));
    }
    let files = options
        .files
        .iter()
        .map(|p| OpenedFile::open(p))
        .collect::<Result<Vec<_>, _>>()?;
    let out_dir = output_folder(&options.out_dir)?;
    let studio = Arc::new(Studio::new(files, out_dir));
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()?;
    runtime.block_on(async move {
        let addr = SocketAddr::from((Ipv4Addr::LOCALHOST, options.port));
        let listener = tokio::net::TcpListener::bind(addr).await?;
        let port = listener.local_addr()?.port();
        let url = format!("http://127.0.0.1:{port}/");
        println!(
            "toonkit studio on {url} (writes into {})",
            studio.out_dir.display()
        );
        if options.open {
            open_browser(&url);
        }
        // Answers go out as a header chunk then the buffers: without TCP_NODELAY the small
        // writes wait for the page's delayed acknowledgement (tens of milliseconds).
        let listener = listener.tap_io(|tcp| {
            let _ = tcp.set_nodelay(true);
        });
        axum::serve(listener, router(studio, port)).await
    })?;
    Ok(())
}

/// Opens `url` with the desktop's browser (best effort).
fn open_browser(url: &str) {
    let program = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(program).arg(url).spawn() {
        eprintln!("warning: could not open a browser ({program}: {e}); open {url}");
    }
}
