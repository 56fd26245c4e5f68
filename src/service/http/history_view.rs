//! The path shared by the views of one stored history of a job, the history itself
//! (`/jobs/{jobId}/results/{output}`) and its spectrum (`.../spectrum`): the query checks
//! both make, and [`respond`], which finds the history of a successful job, renders it
//! off the runtime and sends it with an entity tag.

use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::conditional::{entity_tag, if_none_match};
use super::error::ApiError;
pub(super) use super::negotiation::Format;
use super::results::{successful, with_retry_after};
use super::streamed::{Rendered, WriteBody, held_bytes, streamed, working_bytes};
use crate::problem::Problem;
use crate::service::auth::Tenant;
use crate::service::queue::read::JobOutcome;
use crate::service::store::StoredHistory;

/// 400 unless each bound of a window that is given is finite; `unit` goes in the reason.
pub(super) fn require_finite(bounds: [(&str, Option<f64>); 2], unit: &str) -> Result<(), ApiError> {
    for (name, value) in bounds {
        if value.is_some_and(|v| !v.is_finite()) {
            return Err(Problem::invalid_query(format!("`{name}` must be a finite number ({unit})")).into());
        }
    }
    Ok(())
}

/// The rows one response may hold: `max_points` when given (400 below 2), never more than
/// the service's `cap` however long the history.
pub(super) fn capped_max_points(requested: Option<usize>, cap: usize) -> Result<usize, ApiError> {
    if requested.is_some_and(|n| n < 2) {
        return Err(Problem::invalid_query("`max_points` must be at least 2").into());
    }
    Ok(requested.map_or(cap, |n| n.min(cap)))
}

/// `output` of the job `job_id`, rendered by `render` in `format` (with the job's outcome:
/// its process and results document): 404 (with `Retry-After` while the job is not
/// finished) unless the job succeeded and recorded that output. Decompressing, thinning
/// and transforming a long history is CPU work, so `render` runs on the blocking pool;
/// `work` names it in the error should it panic. The response's working memory comes
/// out of the server's budget (503 `server-busy` when it is spent) until its body is
/// sent; a [`Rendered::Stream`] body is written as the client takes it.
pub(super) async fn respond<F, R>(
    state: &AppState,
    tenant: &Tenant,
    job_id: &str,
    output: &str,
    headers: &HeaderMap,
    format: Format,
    work: &'static str,
    render: F,
) -> Result<Response, ApiError>
where
    F: FnOnce(&StoredHistory, &JobOutcome) -> Result<R, ApiError> + Send + 'static,
    R: Into<Rendered>,
{
    let render = move |stored: &StoredHistory, outcome: &JobOutcome| {
        render(stored, outcome).map(|body| (body, HeaderMap::new()))
    };
    respond_with_headers(state, tenant, job_id, output, headers, format, work, render).await
}

/// [`respond`], with headers that `render` adds to the response (on a 304 too: they
/// describe the representation, as its tag does).
pub(super) async fn respond_with_headers<F, R>(
    state: &AppState,
    tenant: &Tenant,
    job_id: &str,
    output: &str,
    headers: &HeaderMap,
    format: Format,
    work: &'static str,
    render: F,
) -> Result<Response, ApiError>
where
    F: FnOnce(&StoredHistory, &JobOutcome) -> Result<(R, HeaderMap), ApiError> + Send + 'static,
    R: Into<Rendered>,
{
    with_retry_after(
        async {
            let outcome = successful(job_id, state.queue.outcome(tenant.as_str(), job_id).await?)?;
            let stored = state
                .queue
                .history(tenant.as_str(), job_id, output)
                .await?
                .ok_or_else(|| Problem::no_such_output(job_id, output))?;
            let permit = state.response_memory.admit(working_bytes(&stored))?;
            let (rendered, extra) = tokio::task::spawn_blocking(move || {
                render(&stored, &outcome)
                    .map(|(body, extra)| -> (Rendered, HeaderMap) { (body.into(), extra) })
            })
            .await
            .map_err(|e| ApiError::Internal(format!("{work} panicked: {e}")))??;
            let (etag, body) = match rendered {
                Rendered::Bytes(bytes) => (entity_tag(&bytes), Either::Bytes(bytes)),
                Rendered::Stream { etag, write } => (etag, Either::Stream(write)),
            };
            let mut response_headers = extra;
            response_headers.insert(header::ETAG, etag.clone());
            response_headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
            if if_none_match(headers, &etag) {
                return Ok((StatusCode::NOT_MODIFIED, response_headers).into_response());
            }
            response_headers.insert(
                header::CONTENT_TYPE,
                HeaderValue::from_static(format.content_type()),
            );
            let body = match body {
                Either::Bytes(bytes) => held_bytes(permit, bytes),
                Either::Stream(write) => streamed(permit, write),
            };
            Ok((StatusCode::OK, response_headers, body).into_response())
        }
        .await,
    )
}

/// A rendered body without its tag.
enum Either {
    Bytes(Vec<u8>),
    Stream(WriteBody),
}
