//! `/jobs/{jobId}/results/contacts`: the per-contact statistics table of a run
//! ([`ContactTable`]), as CSV or JSON: the table `chocmodal run --out` writes as
//! `contacts.csv`, by the same writer.

use axum::extract::{Extension, Path, State};
use axum::http::HeaderMap;
use axum::response::Response;

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::negotiation::Format;
use super::results::{successful, with_retry_after};
use crate::contact_table::ContactTable;
use crate::problem::Problem;
use crate::service::auth::Tenant;

/// Name of the table in problems (`no-such-output`).
const OUTPUT: &str = "contacts";

/// The per-contact statistics table
///
/// One row per contact of the run, in input order: `contact` (the index k of the
/// history column `c<k>`), then every scalar of the results' `contacts[k]`, dotted:
/// its bodies, `height`, `gap`, `max_force` (N), `max_force_time` (s), `impacts`,
/// `contact_time` (s), `impulse` (N·s), `impact_statistics.*`, a family's friction and
/// wear. CSV (`format=csv` or `Accept: text/csv`; a member a contact lacks is an empty
/// cell) or JSON (`columns` and one flat record per contact). A process without a
/// contact list (`cantilever-impact`): 404 `no-such-output`.
#[utoipa::path(get, path = "/jobs/{jobId}/results/contacts", operation_id = "getResultContacts", tag = "Results",
    params(("jobId" = String, Path, description = "Job id"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The per-contact statistics table",
            content((ContactTable = "application/json"), (String = "text/csv")),
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "A `format` this table has not (`invalid-query`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such job, results not ready, or a run without contacts",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn contacts(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    with_retry_after(
        async {
            let outcome = successful(&job_id, state.queue.outcome(tenant.as_str(), &job_id).await?)?;
            let results = outcome.results.unwrap_or_default();
            // A bundle's results document runs to megabytes: parse it off the runtime.
            let body = tokio::task::spawn_blocking(move || render(&results, format))
                .await
                .map_err(|e| ApiError::Internal(format!("rendering the contact table panicked: {e}")))??;
            let body = body.ok_or_else(|| Problem::no_such_output(&job_id, OUTPUT))?;
            Ok(tagged(&headers, format.content_type(), body, HeaderMap::new()))
        }
        .await,
    )
}

/// The table of a stored results document in `format`; `None` without contacts.
fn render(results: &str, format: Format) -> Result<Option<Vec<u8>>, ApiError> {
    let document: serde_json::Value = serde_json::from_str(results)
        .map_err(|e| ApiError::Internal(format!("stored results unreadable: {e}")))?;
    let Some(table) = ContactTable::of(&document) else {
        return Ok(None);
    };
    let body = if format == Format::Csv {
        table.to_csv().into_bytes()
    } else {
        serde_json::to_vec(&table).map_err(|e| ApiError::Internal(e.to_string()))?
    };
    Ok(Some(body))
}
