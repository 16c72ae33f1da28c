//! DNS-rebinding guard: every request must name the local server in `Host`, and a request
//! that carries an `Origin` must come from a page of the local server.
//!
//! A page of another site whose name was re-pointed at 127.0.0.1 sends its own name as
//! `Host` and `Origin`, so it is refused with 403 and a JSON error.

use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::header;
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::error::ApiError;

/// The hosts the server answers to: `127.0.0.1:PORT` and `localhost:PORT`.
#[derive(Debug, Clone)]
pub struct Allowed {
    hosts: Arc<Vec<String>>,
}

impl Allowed {
    /// The local names of a server on `port`.
    pub fn local(port: u16) -> Allowed {
        Allowed {
            hosts: Arc::new(vec![
                format!("127.0.0.1:{port}"),
                format!("localhost:{port}"),
            ]),
        }
    }

    /// Whether `host` (a `Host` header value) names the server.
    pub fn host(&self, host: &str) -> bool {
        let host = host.trim().to_ascii_lowercase();
        self.hosts.contains(&host)
    }

    /// Whether `origin` (an `Origin` header value) is a page of the server.
    pub fn origin(&self, origin: &str) -> bool {
        origin
            .trim()
            .strip_prefix("http://")
            .is_some_and(|rest| self.host(rest.trim_end_matches('/')))
    }
}

/// The middleware: refuses foreign `Host`/`Origin` with 403.
pub async fn check(State(allowed): State<Allowed>, request: Request, next: Next) -> Response {
    // Read the headers in a block: a borrow of the request (not `Sync`) must not live across
    // the `await` below.
    let (host, origin) = {
        let value = |name: header::HeaderName| {
            request
                .headers()
                .get(name)
                .map(|v| v.to_str().unwrap_or("\u{fffd}").to_string())
        };
        let host = value(header::HOST).or_else(|| request.uri().authority().map(|a| a.to_string()));
        (host, value(header::ORIGIN))
    };
    match host {
        Some(h) if allowed.host(&h) => {}
        Some(h) => {
            return ApiError::forbidden(format!("Host {h:?} is not this studio (refused)"))
                .into_response()
        }
        None => return ApiError::forbidden("a request without Host is refused").into_response(),
    }
    if let Some(origin) = origin {
        if !allowed.origin(&origin) {
            return ApiError::forbidden(format!("Origin {origin:?} is not this studio (refused)"))
                .into_response();
        }
    }
    next.run(request).await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_local_names_on_the_port_pass() {
        let a = Allowed::local(8765);
        assert!(a.host("127.0.0.1:8765") && a.host("LOCALHOST:8765"));
        assert!(!a.host("evil.example") && !a.host("127.0.0.1:80") && !a.host("evil.example:8765"));
        assert!(a.origin("http://127.0.0.1:8765") && a.origin("http://localhost:8765/"));
        assert!(!a.origin("http://evil.example:8765") && !a.origin("null"));
        assert!(!a.origin("https://127.0.0.1.evil.example:8765"));
    }
}
