//! Errors: [`StudioError`] for starting the server, [`ApiError`] for one request (always a
//! JSON body `{"error": "..."}`, never a crash).

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;

/// Why the studio could not start.
#[derive(Debug, thiserror::Error)]
pub enum StudioError {
    /// An input file could not be read.
    #[error("{0}")]
    Open(String),
    /// The output folder could not be made.
    #[error("{path}: cannot use as output folder: {source}")]
    OutputFolder {
        /// The folder.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// Binding or serving failed.
    #[error("server: {0}")]
    Server(#[from] std::io::Error),
    /// Bad options.
    #[error("{0}")]
    Options(String),
}

/// A request that could not be served: an HTTP status and a one-line message, sent as JSON.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct ApiError {
    /// HTTP status.
    pub status: StatusCode,
    /// One line naming what is wrong.
    pub message: String,
}

impl ApiError {
    /// 400: the request is malformed or its values are invalid.
    pub fn bad(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::BAD_REQUEST,
            message: message.into(),
        }
    }

    /// 404: no such file, job or route.
    pub fn not_found(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::NOT_FOUND,
            message: message.into(),
        }
    }

    /// 403: refused (foreign host, a path outside the output folder).
    pub fn forbidden(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::FORBIDDEN,
            message: message.into(),
        }
    }

    /// 409: the request needs something done first (e.g. a line before exporting it).
    pub fn conflict(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::CONFLICT,
            message: message.into(),
        }
    }

    /// 413: a size the request asks for is over the studio's budget (the server stays up).
    pub fn too_large(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::PAYLOAD_TOO_LARGE,
            message: message.into(),
        }
    }

    /// 503: the jobs running now hold the memory this one needs (the studio's memory pool);
    /// the same request succeeds once they finish.
    pub fn busy(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::SERVICE_UNAVAILABLE,
            message: message.into(),
        }
    }

    /// A job's refusal: 413 when the request asked for more than a budget allows
    /// (`over_budget`, [`anim::budget`]), else 400.
    pub fn refused(message: impl Into<String>, over_budget: bool) -> ApiError {
        if over_budget {
            ApiError::too_large(message)
        } else {
            ApiError::bad(message)
        }
    }

    /// A file error of a job: 409 for an export that would replace a file the studio read,
    /// 413 for a size over budget, 500 otherwise (the disk, a bug).
    pub fn from_io(e: &tkio::IoError) -> ApiError {
        match e {
            tkio::IoError::WouldOverwriteInput { .. } => ApiError::conflict(e.to_string()),
            tkio::IoError::OverBudget { .. } => ApiError::too_large(e.to_string()),
            _ => ApiError::internal(e.to_string()),
        }
    }

    /// 500: the job failed.
    pub fn internal(message: impl Into<String>) -> ApiError {
        ApiError {
            status: StatusCode::INTERNAL_SERVER_ERROR,
            message: message.into(),
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = Json(serde_json::json!({ "error": self.message }));
        (self.status, body).into_response()
    }
}

/// The result type of API handlers.
pub type ApiResult<T> = Result<T, ApiError>;
