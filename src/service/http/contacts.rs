//! The tables of a run, as CSV or JSON, by the writer `chocmodal run --out` writes them
//! with (`crate::contact_table`): `/jobs/{jobId}/results/contacts` (the per-contact
//! statistics, [`ContactTable`]), `/jobs/{jobId}/results/pins` (per pin, [`PinTable`]) and
//! `/jobs/{jobId}/results/resultants` (per pin and contact height, [`ResultantTable`]).

use axum::extract::{Extension, Path, State};
use axum::http::HeaderMap;
use axum::response::Response;

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::negotiation::Format;
use super::results::{successful, with_retry_after};
use crate::contact_table::{ContactTable, PinTable, ResultantTable};
use crate::problem::Problem;
use crate::service::auth::Tenant;

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
    serve(state, tenant, job_id, headers, format, TABLES[0]).await
}

/// The per-pin table
///
/// One row per pin: every scalar of the results' `pins[p]`, dotted: `pin`, its largest
/// deflections (`max_abs_deflection`, `x.*`/`y.*` and `deflection.*` in the hexagonal
/// bundle), its largest bending (`bending.moment` N·m, `bending.stress` Pa,
/// `bending.strain`, where and when), its utilisations, and its largest resultant contact
/// force (`max_resultant_force.*`). CSV or JSON (`columns` and one flat record per pin).
/// A process without pins (`cantilever-impact`): 404 `no-such-output`.
#[utoipa::path(get, path = "/jobs/{jobId}/results/pins", operation_id = "getResultPins", tag = "Results",
    params(("jobId" = String, Path, description = "Job id"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The per-pin table",
            content((PinTable = "application/json"), (String = "text/csv")),
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "A `format` this table has not (`invalid-query`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such job, results not ready, or a run without pins",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn pins(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    serve(state, tenant, job_id, headers, format, TABLES[1]).await
}

/// The resultant contact forces per pin and contact height
///
/// One row per pin and height where a contact acts on it, by pin then height: `pin`,
/// `height` (m), `contacts` (how many act on it there), `max_force` (N: the largest
/// magnitude of the vector sum of their forces on the pin, over every step) and `time`
/// (s). CSV or JSON (`columns` and one flat record per row). A process without pins
/// (`cantilever-impact`): 404 `no-such-output`.
#[utoipa::path(get, path = "/jobs/{jobId}/results/resultants", operation_id = "getResultResultants", tag = "Results",
    params(("jobId" = String, Path, description = "Job id"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON); `f` is an alias")),
    responses(
        (status = 200, description = "The resultant contact forces",
            content((ResultantTable = "application/json"), (String = "text/csv")),
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "A `format` this table has not (`invalid-query`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such job, results not ready, or a run without pins",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes both JSON and CSV (`not-acceptable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn resultants(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    serve(state, tenant, job_id, headers, format, TABLES[2]).await
}

/// A table: its name in problems (`no-such-output`) and how a results document gives
/// it, as CSV or JSON (`None`: the document has no such table).
type Render = fn(&serde_json::Value, Format) -> Option<Result<Vec<u8>, serde_json::Error>>;

/// The three tables.
const TABLES: [(&str, Render); 3] = [
    ("contacts", |document, format| {
        ContactTable::of(document).map(|t| encode(&t, t.to_csv(), format))
    }),
    ("pins", |document, format| {
        PinTable::of(document).map(|t| encode(&t, t.to_csv(), format))
    }),
    ("resultants", |document, format| {
        ResultantTable::of(document).map(|t| encode(&t, t.to_csv(), format))
    }),
];

/// `table` as CSV (`csv`) or JSON.
fn encode(table: &impl serde::Serialize, csv: String, format: Format) -> Result<Vec<u8>, serde_json::Error> {
    match format {
        Format::Csv => Ok(csv.into_bytes()),
        _ => serde_json::to_vec(table),
    }
}

/// The table `(name, render)` of a job's results in `format`.
async fn serve(
    state: AppState,
    tenant: Tenant,
    job_id: String,
    headers: HeaderMap,
    format: Format,
    (name, render): (&'static str, Render),
) -> Result<Response, ApiError> {
    with_retry_after(
        async {
            let outcome = successful(&job_id, state.queue.outcome(tenant.as_str(), &job_id).await?)?;
            let results = outcome.results.unwrap_or_default();
            // A bundle's results document runs to megabytes: parse it off the runtime.
            let body = tokio::task::spawn_blocking(move || rendered(&results, format, render))
                .await
                .map_err(|e| ApiError::Internal(format!("rendering the {name} table panicked: {e}")))??;
            let body = body.ok_or_else(|| Problem::no_such_output(&job_id, name))?;
            Ok(tagged(&headers, format.content_type(), body, HeaderMap::new()))
        }
        .await,
    )
}

/// The table `render` gives of a stored results document, in `format`; `None` without.
fn rendered(results: &str, format: Format, render: Render) -> Result<Option<Vec<u8>>, ApiError> {
    let document: serde_json::Value = serde_json::from_str(results)
        .map_err(|e| ApiError::Internal(format!("stored results unreadable: {e}")))?;
    render(&document, format)
        .transpose()
        .map_err(|e| ApiError::Internal(e.to_string()))
}
