//! The page: our HTML/JS/CSS and the three.js modules it imports (vendored in
//! `web/vendor/three`), all embedded at build time, so the binary serves the page from any
//! folder with no npm install or network.

use axum::extract::Path as UrlPath;
use axum::http::header;
use axum::response::{IntoResponse, Response};

use crate::error::ApiError;

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
    ("pack_worker.js", JS, include_str!("../web/pack_worker.js")),
    ("viewport.js", JS, include_str!("../web/viewport.js")),
    ("normals.js", JS, include_str!("../web/normals.js")),
    ("smear.js", JS, include_str!("../web/smear.js")),
    ("smear_clip.js", JS, include_str!("../web/smear_clip.js")),
    ("smear_keys.js", JS, include_str!("../web/smear_keys.js")),
    (
        "smear_weights.js",
        JS,
        include_str!("../web/smear_weights.js"),
    ),
    ("loa.js", JS, include_str!("../web/loa.js")),
    ("stopmo.js", JS, include_str!("../web/stopmo.js")),
    ("report.js", JS, include_str!("../web/report.js")),
];

const JS: &str = "text/javascript; charset=utf-8";

/// The vendored three.js version (`web/vendor/three/README.md`).
pub const THREE_VERSION: &str = "0.187.0";

/// The three.js modules the page imports (`web/vendor/three`, npm's `three` package at
/// [`THREE_VERSION`]), embedded so the binary alone serves the page: (path under
/// `/vendor/three/`, text).
pub const THREE: &[(&str, &str)] = &[
    (
        "build/three.module.js",
        include_str!("../web/vendor/three/build/three.module.js"),
    ),
    (
        "build/three.core.js",
        include_str!("../web/vendor/three/build/three.core.js"),
    ),
    (
        "examples/jsm/controls/OrbitControls.js",
        include_str!("../web/vendor/three/examples/jsm/controls/OrbitControls.js"),
    ),
];

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
        Some((_, kind, text)) => text_response(kind, "no-cache", text),
        None => ApiError::not_found(format!("/{name}: no such page file")).into_response(),
    }
}

/// `GET /vendor/three/<path>`: one of the embedded three.js modules ([`THREE`]); they never
/// change within a build, so the browser may keep them for a day.
pub async fn three(UrlPath(path): UrlPath<String>) -> Response {
    match THREE.iter().find(|(n, _)| *n == path) {
        Some((_, text)) => text_response(JS, "max-age=86400", text),
        None => ApiError::not_found(format!(
            "/vendor/three/{path}: not one of the page's three.js {THREE_VERSION} modules"
        ))
        .into_response(),
    }
}

fn text_response(kind: &'static str, cache: &'static str, text: &'static str) -> Response {
    (
        [(header::CONTENT_TYPE, kind), (header::CACHE_CONTROL, cache)],
        text,
    )
        .into_response()
}
