//! `/jobs/{jobId}/results`: the results document, and each time history as CSV or JSON.

use axum::extract::{Extension, Path, State};
use std::io::Write;

use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::Response;

use super::AppState;
use super::conditional::{entity_tag_of_parts, tagged};
use super::error::ApiError;
use super::extract::ApiQuery;
use super::history_view::{Format, capped_max_points, require_finite, respond};
use super::models::{HistoryDocument, Results, Series};
use super::streamed::{Rendered, WriteBody};
use crate::problem::Problem;
use crate::processes::{Column, write_columns_csv_rows};
use crate::service::auth::Tenant;
use crate::service::queue::JobStatus;
use crate::service::queue::read::JobOutcome;
use crate::service::{store, thinning};

/// Query of `GET /jobs/{jobId}/results/{output}`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct HistoryQuery {
    /// Chosen by the service's negotiator (`f` is an alias): `csv` or `json`; without
    /// it, the one `Accept` prefers (q-values honoured), else JSON.
    #[param(pattern = "^(csv|json)$")]
    #[serde(alias = "f")]
    pub format: Option<String>,
    /// Start of the window (s), inclusive.
    pub t_start: Option<f64>,
    /// End of the window (s), inclusive.
    pub t_end: Option<f64>,
    /// Thin the window to at most this many rows (at least 2 per series), keeping each
    /// series' minimum and maximum of every bucket so that peaks survive. The service
    /// caps it (`--max-history-points`, default 500000): longer windows are always thinned.
    #[param(minimum = 2)]
    pub max_points: Option<usize>,
    /// Only these series, comma-separated and in this order (e.g. `c3,c17`); default: all.
    pub series: Option<String>,
    /// The CSV header: `short` (default), the column names (`time,c0,c1`), or `long`,
    /// each name followed by its unit and what it measures (`c12 [N] contact wall–p0 at
    /// 0.18 m`; the name is the cell's first word). The JSON form always has `columns`.
    #[param(pattern = "^(short|long)$")]
    pub header: Option<String>,
}

/// Why a finished-or-not job has no results to show; `Ok` carries the outcome of a successful one.
pub(super) fn successful(job_id: &str, outcome: Option<JobOutcome>) -> Result<JobOutcome, ApiError> {
    let outcome = outcome.ok_or_else(|| Problem::no_such_job(job_id))?;
    match outcome.record.status {
        JobStatus::Successful => Ok(outcome),
        JobStatus::Accepted | JobStatus::Running => {
            Err(Problem::result_not_ready(job_id, outcome.record.status.as_str()).into())
        }
        JobStatus::Dismissed => Err(Problem::job_dismissed(job_id).into()),
        JobStatus::Failed => {
            let problem = outcome
                .error
                .as_deref()
                .and_then(|text| serde_json::from_str::<Problem>(text).ok())
                .unwrap_or_else(|| Problem::job_failed("the job failed"));
            Err(problem.into())
        }
    }
}

/// Retry-After on "not ready" answers, so pollers back off.
pub(super) fn with_retry_after(result: Result<Response, ApiError>) -> Result<Response, ApiError> {
    match result {
        Err(ApiError::Problem(problem)) if problem.kind.ends_with("/result-not-ready") => {
            let mut response = axum::response::IntoResponse::into_response(ApiError::Problem(problem));
            response
                .headers_mut()
                .insert(header::RETRY_AFTER, HeaderValue::from_static("1"));
            Ok(response)
        }
        other => other,
    }
}

/// A job's results
///
/// The results document of a successful job, with `outputs` links to its histories.
/// Immutable once there: strong `ETag`, `304` on `If-None-Match`. A job not finished
/// yet: 404 `result-not-ready` (with `Retry-After`); a failed job: its error as a problem.
#[utoipa::path(get, path = "/jobs/{jobId}/results", operation_id = "getResult", tag = "Results",
    params(("jobId" = String, Path, description = "Job id")),
    responses(
        (status = 200, description = "Results document (fields per process, see its description)", body = Results,
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 404, description = "No such job, job not finished (`result-not-ready`), or dismissed",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 422, description = "The job failed (`job-failed`, e.g. divergence)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 500, description = "The job crashed or lost its worker too many times",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn results(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    with_retry_after(
        async {
            let outcome = successful(&job_id, state.queue.outcome(tenant.as_str(), &job_id).await?)?;
            let body = outcome.results.unwrap_or_else(|| "{}".into()).into_bytes();
            Ok(tagged(&headers, "application/json", body, HeaderMap::new()))
        }
        .await,
    )
}

/// One time history
///
/// CSV (`time,<series...>`, each number the shortest text that reads back exactly) or
/// JSON, optionally restricted to `t_start <= time <= t_end` (s), to the `series` named,
/// and thinned to `max_points` rows with min/max buckets. The JSON form's `columns` say
/// what each column is (unit, what it measures); `header=long` puts the same in the CSV
/// header (`c12 [N] contact wall–p0 at 0.18 m`). A window longer than the service's cap
/// (`--max-history-points`) is thinned to it: page through long histories with
/// `t_start` and `t_end` for full resolution. The output named `impacts` is the
/// per-impact table, with its own path and query (`/jobs/{jobId}/results/impacts`); the
/// JSON schema here covers both.
#[utoipa::path(get, path = "/jobs/{jobId}/results/{output}", operation_id = "getResultOutput", tag = "Results",
    params(
        ("jobId" = String, Path, description = "Job id"),
        ("output" = String, Path, description = "Output name, e.g. `tip_displacement` (`impacts`: see \
            `/jobs/{jobId}/results/impacts`)", example = "tip_displacement"),
        HistoryQuery,
    ),
    responses(
        (status = 200, description = "The history (time in s; values in the output's unit)",
            content(
                (super::openapi::ResultOutputSchema = "application/json"),
                (String = "text/csv")
            ),
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such job or output, or results not ready", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn output(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path((job_id, output)): Path<(String, String)>,
    ApiQuery(mut query): ApiQuery<HistoryQuery>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let long_header = match query.header.as_deref() {
        None | Some("short") => false,
        Some("long") => true,
        Some(other) => {
            return Err(
                Problem::invalid_query(format!("`header` must be `short` or `long`, not `{other}`")).into(),
            );
        }
    };
    require_finite([("t_start", query.t_start), ("t_end", query.t_end)], "s")?;
    let registry = state.registry.clone();
    // However long the history, a response holds at most the service's cap.
    query.max_points = Some(capped_max_points(query.max_points, state.max_history_points)?);
    respond(
        &state,
        &tenant,
        &job_id,
        &output,
        &headers,
        format,
        "rendering a history",
        move |stored, outcome| {
            let view = View {
                query: &query,
                format,
                long_header,
            };
            let etag = view.entity_tag(stored, outcome);
            render(stored, &columns_of(&registry, outcome), view, etag)
        },
    )
    .await
}

/// How a history is shown.
struct View<'a> {
    query: &'a HistoryQuery,
    format: Format,
    long_header: bool,
}

impl View<'_> {
    /// The tag of the bytes this view of `stored` writes: they are a function of the
    /// stored history, the job's results document (the columns' descriptions), the view
    /// and the code that renders them.
    fn entity_tag(&self, stored: &store::StoredHistory, outcome: &JobOutcome) -> HeaderValue {
        let query = self.query;
        let view = format!(
            "{:?} {} {:?} {:?} {:?} {:?} {} {}",
            self.format,
            self.long_header,
            query.t_start,
            query.t_end,
            query.max_points,
            query.series,
            stored.samples,
            stored.series.join(","),
        );
        entity_tag_of_parts(&[
            env!("CARGO_PKG_VERSION").as_bytes(),
            outcome.record.process_id.as_bytes(),
            outcome.results.as_deref().unwrap_or_default().as_bytes(),
            stored.name.as_bytes(),
            view.as_bytes(),
            &stored.data,
        ])
    }
}

/// What each column of a history of this job is: its process describes them from the
/// job's results document.
fn columns_of<'a>(
    registry: &'a crate::processes::Registry,
    outcome: &'a JobOutcome,
) -> impl Fn(&crate::processes::History) -> Vec<Column> + 'a {
    move |history| {
        let document: serde_json::Value = outcome
            .results
            .as_deref()
            .and_then(|text| serde_json::from_str(text).ok())
            .unwrap_or_default();
        let names: Vec<String> = history.series.iter().map(|(name, _)| name.clone()).collect();
        match registry.get(&outcome.record.process_id) {
            Some(process) => process.history_columns(&history.name, &names, &document),
            None => std::iter::once(Column::time())
                .chain(names.iter().map(Column::unknown))
                .collect(),
        }
    }
}

/// Decodes and selects now (a bad `series` is a 400 before anything is sent); the text,
/// JSON or CSV, is written as the client takes it.
fn render(
    stored: &store::StoredHistory,
    columns: &dyn Fn(&crate::processes::History) -> Vec<Column>,
    view: View<'_>,
    etag: HeaderValue,
) -> Result<Rendered, ApiError> {
    let query = view.query;
    let history = store::decode(stored).map_err(|e| ApiError::Internal(e.to_string()))?;
    let history = thinning::pick_series(history, query.series.as_deref()).map_err(Problem::invalid_query)?;
    let total_points = history.time.len();
    let in_window = thinning::count_in_window(&history.time, query.t_start, query.t_end);
    let selected = thinning::select_owned(history, query.t_start, query.t_end, query.max_points);
    let columns = columns(&selected);
    let write: WriteBody = if view.format == Format::Csv {
        let header: Vec<String> = if view.long_header {
            columns
                .iter()
                .map(|c| crate::csv_format::quote(&c.long_header()).into_owned())
                .collect()
        } else {
            std::iter::once("time".to_owned())
                .chain(selected.series.iter().map(|(name, _)| name.clone()))
                .collect()
        };
        Box::new(move |out: &mut dyn Write| {
            out.write_all(header.join(",").as_bytes())?;
            out.write_all(b"\n")?;
            write_columns_csv_rows(out, &selected.time, &selected.series)
        })
    } else {
        let document = HistoryDocument {
            columns,
            output: selected.name,
            points: selected.time.len(),
            total_points,
            thinned: selected.time.len() < in_window,
            time: selected.time,
            series: Series::from_columns(selected.series),
        };
        Box::new(move |out: &mut dyn Write| {
            serde_json::to_writer(out, &document).map_err(std::io::Error::other)
        })
    };
    Ok(Rendered::Stream { etag, write })
}
