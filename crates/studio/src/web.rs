//! The page: our HTML/JS/CSS embedded at build time, three.js served from the npm install
//! in `crates/studio/web/node_modules` (`npm ci --prefix crates/studio/web`). When three.js
//! is missing the page still loads and says how to install it.

use std::path::{Component, Path};
use std::sync::Arc;

use axum::extract::{Path as UrlPath, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};

use crate::error::ApiError;
use crate::state::Studio;

/// Our page files: (URL name, content type, text).
pub const PAGE: &[(&str, &str, &str)] = &[
    (
        "index.html",
        "text/html; charset=utf-8",
        include_str!("../web/index.html"),
    ),
    (
        "style.css",
        "text/css; charset=utf-8",
        include_str!("../web/style.css"),
    ),
    ("app.js", JS, include_str!("../web/app.js")),
    ("api.js", JS, include_str!("../web/api.js")),
    ("viewport.js", JS, include_str!("../web/viewport.js")),
    ("smear.js", JS, include_str!("../web/smear.js")),
    ("smear_keys.js", JS, include_str!("../web/smear_keys.js")),
    (
        "smear_weights.js",
        JS,
        include_str!("../web/smear_weights.js"),
    ),
    ("loa.js", JS, include_str!("../web/loa.js")),
    ("stopmo.js", JS, include_str!("../web/stopmo.js")),
];

const JS: &str = "text/javascript; charset=utf-8";

/// The command that installs the page's npm packages.
pub const INSTALL_HINT: &str = "npm ci --prefix crates/studio/web";

/// The npm install folder of a source checkout.
pub fn default_node_modules() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("web/node_modules")
}

/// Whether three.js is installed under `node_modules`.
pub fn three_installed(node_modules: &Path) -> bool {
    node_modules.join("three/build/three.module.js").is_file()
}

/// `GET /`: the page.
pub async fn index() -> Response {
    file("index.html")
}

/// `GET /<page file>`.
pub async fn page(UrlPath(name): UrlPath<String>) -> Response {
    file(&name)
}

fn file(name: &str) -> Response {
    match PAGE.iter().find(|(n, _, _)| *n == name) {
        Some((_, kind, text)) => (
            [
                (header::CONTENT_TYPE, *kind),
                (header::CACHE_CONTROL, "no-cache"),
            ],
            *text,
        )
            .into_response(),
        None => ApiError::not_found(format!("/{name}: no such page file")).into_response(),
    }
}

/// `GET /vendor/three/<path>`: a `.js` file of the installed `three` package (`build/` and
/// `examples/jsm/` only).
pub async fn three(State(studio): State<Arc<Studio>>, UrlPath(path): UrlPath<String>) -> Response {
    let rel = Path::new(&path);
    let plain = rel.components().all(|c| matches!(c, Component::Normal(_)));
    let allowed = (path.starts_with("build/") || path.starts_with("examples/jsm/"))
        && path.ends_with(".js")
        && plain;
    if !allowed {
        return ApiError::forbidden(format!("/vendor/three/{path}: not served")).into_response();
    }
    let file = studio.node_modules.join("three").join(rel);
    match std::fs::read(&file) {
        Ok(bytes) => ([(header::CONTENT_TYPE, JS)], bytes).into_response(),
        Err(_) => (
            StatusCode::NOT_FOUND,
            [(header::CONTENT_TYPE, JS)],
            format!(
                "throw new Error('three.js is not installed: run `{INSTALL_HINT}` in the toonkit checkout, then restart the studio');"
            ),
        )
            .into_response(),
    }
}
