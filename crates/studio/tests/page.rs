//! The page comes from the binary alone: every module the page imports — our scripts, the
//! workers they start and the vendored three.js — is embedded and served, with no npm
//! install or source tree.

use axum::http::{header, StatusCode};

mod common;
use common::{app, error_of, get, send, send_ok};

/// The module specifiers of `import ... from '...'` lines in a script.
fn imports(script: &str) -> Vec<String> {
    script
        .lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let rest = l
                .strip_prefix("import ")
                .or_else(|| l.strip_prefix("} from "))?;
            let from = if l.starts_with("} from ") {
                rest
            } else {
                rest.split(" from ").nth(1)?
            };
            let quote = from.chars().next()?;
            from[1..].split(quote).next().map(str::to_string)
        })
        .collect()
}

/// The script URLs of `new Worker('...')` in a script.
fn workers(script: &str) -> Vec<String> {
    script
        .split("new Worker(")
        .skip(1)
        .filter_map(|rest| {
            let quote = rest.chars().next()?;
            rest[1..].split(quote).next().map(str::to_string)
        })
        .collect()
}

/// The URL a specifier resolves to from `base` (an absolute URL path), with the page's
/// import map (`three`, `three/addons/`).
fn resolve(spec: &str, base: &str) -> String {
    if spec == "three" {
        return "/vendor/three/build/three.module.js".into();
    }
    if let Some(rest) = spec.strip_prefix("three/addons/") {
        return format!("/vendor/three/examples/jsm/{rest}");
    }
    if spec.starts_with('/') {
        return spec.into();
    }
    let dir = &base[..base.rfind('/').unwrap() + 1];
    let mut parts: Vec<&str> = dir.split('/').filter(|p| !p.is_empty()).collect();
    for p in spec.split('/') {
        match p {
            "." => {}
            ".." => {
                parts.pop();
            }
            p => parts.push(p),
        }
    }
    format!("/{}", parts.join("/"))
}

#[tokio::test]
async fn every_module_the_page_imports_is_served_from_the_binary() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let html = String::from_utf8(send_ok(&app, get("/")).await).unwrap();
    assert!(html.contains("\"three\": \"/vendor/three/build/three.module.js\""));
    let mut queue = vec!["/app.js".to_string()];
    let mut seen = std::collections::BTreeSet::new();
    while let Some(url) = queue.pop() {
        if !seen.insert(url.clone()) {
            continue;
        }
        let res = send(&app, get(&url)).await;
        assert_eq!(res.0, StatusCode::OK, "{url} is not served");
        let script = String::from_utf8(res.1).unwrap();
        for spec in imports(&script).into_iter().chain(workers(&script)) {
            queue.push(resolve(&spec, &url));
        }
    }
    for needed in [
        "/pack_worker.js",
        "/vendor/three/build/three.module.js",
        "/vendor/three/build/three.core.js",
        "/vendor/three/examples/jsm/controls/OrbitControls.js",
        "/report.js",
    ] {
        assert!(seen.contains(needed), "{needed} not reached from app.js");
    }
    let core =
        String::from_utf8(send_ok(&app, get("/vendor/three/build/three.core.js")).await).unwrap();
    assert!(
        core.contains(&format!(
            "const REVISION = '{}'",
            studio::web::THREE_VERSION.split('.').nth(1).unwrap()
        )),
        "the embedded three.js is not version {}",
        studio::web::THREE_VERSION
    );
}

#[tokio::test]
async fn the_three_modules_are_javascript_and_nothing_else_is_served_under_vendor() {
    let dir = tempfile::tempdir().unwrap();
    let app = app(dir.path());
    let res = tower::ServiceExt::oneshot(
        app.clone(),
        get("/vendor/three/examples/jsm/controls/OrbitControls.js"),
    )
    .await
    .unwrap();
    assert_eq!(res.status(), StatusCode::OK);
    assert!(res.headers()[header::CONTENT_TYPE]
        .to_str()
        .unwrap()
        .starts_with("text/javascript"));
    for path in [
        "/vendor/three/package.json",
        "/vendor/three/LICENSE",
        "/vendor/three/build/three.webgpu.js",
        "/vendor/three/../../Cargo.toml",
    ] {
        let (status, body) = send(&app, get(path)).await;
        assert!(
            status == StatusCode::NOT_FOUND || status == StatusCode::FORBIDDEN,
            "{path}: {status}"
        );
        if status == StatusCode::NOT_FOUND {
            assert!(!error_of(&body).is_empty());
        }
    }
}
