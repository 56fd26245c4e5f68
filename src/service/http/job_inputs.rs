//! `/jobs/{jobId}/inputs`: the execution request a job was submitted with, ready to be
//! edited and submitted again.

use axum::extract::{Extension, Path, State};
use axum::http::HeaderMap;
use axum::response::Response;

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use crate::problem::Problem;
use crate::service::auth::Tenant;

/// A job's inputs
///
/// The body the job was submitted with, `{"inputs": {...}}` (for a sweep run, its
/// generated inputs): `POST` it to `/processes/{processID}/execution` to run it again.
/// Immutable: strong `ETag`, `304` on `If-None-Match`.
#[utoipa::path(get, path = "/jobs/{jobId}/inputs", operation_id = "getJobInputs", tag = "Jobs",
    params(("jobId" = String, Path, description = "Job id")),
    responses(
        (status = 200, description = "The execution request of the job", body = super::models::ExecuteRequest,
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 404, description = "No such job (`no-such-job`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn inputs(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let text = state
        .queue
        .inputs(tenant.as_str(), &job_id)
        .await?
        .ok_or_else(|| Problem::no_such_job(&job_id))?;
    // The stored text is JSON written by the service: wrapped as is, members in their order.
    let body = format!("{{\"inputs\":{text}}}").into_bytes();
    Ok(tagged(&headers, "application/json", body, HeaderMap::new()))
}
