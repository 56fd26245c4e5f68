//! The API's one error type and its rendering as RFC 9457 problem details.
//!
//! Handlers return `Result<_, ApiError>`. Client errors carry their [`Problem`] as is;
//! server errors are logged with their cause and answered with a generic 500 problem
//! that reveals nothing of the internals.

use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use crate::problem::{CHOCMODAL_PROBLEMS, Problem};
use crate::service::db::fault::StorageFault;
use crate::service::storage_health::FAILURE_MEMORY;

/// Media type of problem documents.
pub const PROBLEM_JSON: &str = "application/problem+json";

/// Why a request failed.
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    /// The problem's own status (4xx): shown to the client as is.
    #[error("{}", .0.detail)]
    Problem(Box<Problem>),
    /// The problem's status (429, or 503 while shutting down): try again after
    /// `retry_after` seconds (`Retry-After`).
    #[error("{}", .problem.detail)]
    RetryLater { problem: Box<Problem>, retry_after: u64 },
    /// 507 (full disk) or 503 (I/O error) with `Retry-After` when the storage refused a
    /// write ([`StorageFault`]): nothing was stored, the problem names the cause. Any
    /// other database failure is a 500, logged and hidden from the client.
    #[error("database: {0}")]
    Database(#[from] sqlx::Error),
    /// 500: any other unexpected failure; logged, hidden from the client.
    #[error("internal: {0}")]
    Internal(String),
}

/// Seconds a tenant whose queue is full is asked to wait (`Retry-After`).
pub const QUEUE_FULL_RETRY_SECONDS: u64 = 10;

impl ApiError {
    /// 429: `queued` jobs are waiting and `adding` more would exceed `limit`.
    pub fn queue_full(queued: i64, adding: usize, limit: u64) -> Self {
        ApiError::RetryLater {
            problem: Box::new(Problem::too_many_queued_jobs(queued, adding, limit)),
            retry_after: QUEUE_FULL_RETRY_SECONDS,
        }
    }
}

impl From<Problem> for ApiError {
    fn from(problem: Problem) -> Self {
        ApiError::Problem(Box::new(problem))
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        match self {
            ApiError::Problem(problem) => problem_response(&problem),
            ApiError::RetryLater { problem, retry_after } => {
                let mut response = problem_response(&problem);
                response
                    .headers_mut()
                    .insert(header::RETRY_AFTER, HeaderValue::from(retry_after));
                response
            }
            ApiError::Database(error) => match StorageFault::of(&error) {
                Some(fault) => {
                    tracing::error!(%error, cause = fault.cause(), "the storage refused a write");
                    storage_fault_response(fault)
                }
                None => {
                    tracing::error!(%error, "database error while handling a request");
                    problem_response(&Problem::internal())
                }
            },
            ApiError::Internal(error) => {
                tracing::error!(%error, "internal error while handling a request");
                problem_response(&Problem::internal())
            }
        }
    }
}

/// Seconds a client whose write the storage refused is asked to wait (`Retry-After`).
pub const STORAGE_RETRY_SECONDS: u64 = FAILURE_MEMORY.as_secs();

/// 507 `storage-full` or 503 `storage-unavailable`, with `Retry-After` and the fault as
/// a response extension (the request tracker reports it to [`crate::service::storage_health`]).
pub fn storage_fault_response(fault: StorageFault) -> Response {
    let (slug, title) = match fault {
        StorageFault::Full(_) => ("storage-full", "Insufficient storage"),
        StorageFault::Io => ("storage-unavailable", "Storage unavailable"),
    };
    let problem = Problem::new(
        format!("{CHOCMODAL_PROBLEMS}/{slug}"),
        title,
        fault.status(),
        format!("{fault}: nothing was stored; retry in {STORAGE_RETRY_SECONDS} s (reads still work)"),
    );
    let mut response = problem_response(&problem);
    response
        .headers_mut()
        .insert(header::RETRY_AFTER, HeaderValue::from(STORAGE_RETRY_SECONDS));
    response.extensions_mut().insert(fault);
    response
}

/// A problem document with its status and `application/problem+json`.
pub fn problem_response(problem: &Problem) -> Response {
    let status = StatusCode::from_u16(problem.status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
    let body = serde_json::to_vec(problem).unwrap_or_default();
    (
        status,
        [(header::CONTENT_TYPE, HeaderValue::from_static(PROBLEM_JSON))],
        body,
    )
        .into_response()
}

impl IntoResponse for Problem {
    fn into_response(self) -> Response {
        problem_response(&self)
    }
}
