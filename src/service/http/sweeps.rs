//! `/sweeps`: submit a sweep (validated whole before anything is queued), its status,
//! the sweep list, dismissal, and its results table with aggregates.

use axum::Json;
use axum::extract::{Extension, Path, Query, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::extract::{ApiQuery, JsonBody};
use super::history_view::Format;
use super::idempotency::{IdempotencyHeader, key_reused, mark_replayed};
use super::jobs::{DEFAULT_LIMIT, MAX_LIMIT};
use super::models::Link;
use super::sweep_models::{SweepList, SweepResults, SweepStatus};
use crate::annotations::{Annotations, label_fault};
use crate::problem::Problem;
use crate::processes::{InvalidInputs, Process, TooCostly};
use crate::service::auth::Tenant;
use crate::service::queue::idempotency::{KeyedRequest, Kind, RequestHash};
use crate::service::queue::sweep_create::{NewRun, NewSweep};
use crate::service::queue::sweep_read::SweepRun;
use crate::service::queue::{Admission, SweepRecord};
use crate::sweep::admission::{self, AdmissionLimits, Admitted, MAX_RUN_ERRORS, Refusal};
use crate::sweep::table::RunRecord;
use crate::sweep::{SweepDefinition, SweepError};

/// Submit a sweep
///
/// Expands the axes into runs (grid, Monte Carlo or Latin hypercube), validates every
/// run's inputs like an execution request, then queues them all as jobs of the sweep:
/// `201 Created`, `Location: /sweeps/{sweepId}`. Nothing is queued when anything is
/// invalid: 422 with `errors` pointing into the request (`/axes/0/linspace`) or, for a
/// generated run, `/runs/{run}/inputs/...` (the detail names the run's axis values).
/// Every run must also be within the service's cost ceilings (422 `too-costly`, with
/// the same run pointers), and the runs must fit in the tenant's queue (429). A retry
/// with the same `Idempotency-Key` and request gets the same sweep back.
#[utoipa::path(post, path = "/sweeps", operation_id = "createSweep", tag = "Sweeps",
    params(("Idempotency-Key" = Option<String>, Header, description = "Optional, 1 to 255 visible ASCII characters: a retry with the same key and the same request gets the same resource back (same id, `201`, same `Location`, plus `Idempotent-Replayed: true`) instead of creating another; the same key with another request is a 422 `idempotency-key-reused`. Keys are per tenant and kept as long as the resource they created.")),
    request_body(content = crate::sweep::SweepRequest, description = "The process, base inputs and axes; optionally `labels` (at most 20 texts of 1 to 64 characters) and a `note` (at most 2000 characters), as for a job: returned in the sweep's status, `GET /sweeps?label=` filters on them"),
    responses(
        (status = 201, description = "Sweep queued", body = SweepStatus,
            headers(("Location" = String, description = "`/sweeps/{sweepId}`"))),
        (status = 400, description = "Malformed JSON, or an invalid `Idempotency-Key` (`invalid-header`)", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such process", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 413, description = "Body over the size limit", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 415, description = "Body not declared as JSON", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 422, description = "Invalid sweep or run inputs (`invalid-inputs`), more runs than allowed (`sweep-too-large`), or a run above the cost ceilings (`too-costly`); or an `Idempotency-Key` first sent with another request (`idempotency-key-reused`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 429, description = "The runs would exceed the limit of queued jobs (`too-many-queued-jobs`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json",
            headers(("Retry-After" = String, description = "s"))),
        (status = 503, description = "The storage failed an I/O operation (`storage-unavailable`): nothing stored", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s"))),
        (status = 507, description = "The disk is full (`storage-full`, naming SQLITE_FULL, disk_full or ENOSPC): nothing stored", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s")))))]
pub async fn create(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    IdempotencyHeader(key): IdempotencyHeader,
    body: Result<JsonBody, ApiError>,
) -> Result<Response, ApiError> {
    let JsonBody(mut body) = body?;
    let keyed = key.map(|key| KeyedRequest {
        key,
        kind: Kind::Sweep,
        hash: RequestHash::of_json(Kind::Sweep, "", &body),
    });
    // Labels and a note are the sweep's, not part of its definition.
    let (labels, note) = match &mut body {
        serde_json::Value::Object(members) => (members.remove("labels"), members.remove("note")),
        _ => (None, None),
    };
    let annotations = Annotations::parse(labels.as_ref(), note.as_ref())
        .map_err(|errors| Problem::invalid_inputs(&InvalidInputs(errors)))?;
    // The tenant's stored signals the base inputs or an axis refer to.
    let signals = state.signals.library(tenant.as_str(), &body).await?;
    let registry = state.registry.clone();
    let limits = AdmissionLimits {
        max_runs: state.max_sweep_runs,
        cost: state.limits,
    };
    // Expanding and validating thousands of runs is CPU work: off the runtime.
    let Admitted { spec, runs } =
        tokio::task::spawn_blocking(move || admission::admit(&body, &registry, &limits, &signals))
            .await
            .map_err(|e| ApiError::Internal(format!("sweep admission panicked: {e}")))?
            .map_err(refusal)?;
    let definition =
        serde_json::to_value(spec.definition()).map_err(|e| ApiError::Internal(e.to_string()))?;
    let runs: Vec<NewRun> = runs
        .into_iter()
        .map(|run| NewRun {
            inputs: run.inputs,
            invalid: run.invalid.as_ref().map(Problem::invalid_inputs),
            warnings: run.warnings,
        })
        .collect();
    let admission = state
        .queue
        .create_sweep(
            &NewSweep {
                tenant: tenant.as_str(),
                process_id: &spec.process,
                definition: &definition,
                design: spec.design.as_str(),
                policy: spec.policy.as_str(),
                runs: &runs,
                annotations: &annotations,
            },
            state.max_queued_jobs,
            keyed.as_ref(),
        )
        .await?;
    let mut headers = HeaderMap::new();
    let record = match admission {
        Admission::Admitted(record) => {
            state.wake.notify_waiters();
            state.wake.notify_one();
            tracing::info!(sweep = %record.id, process = %record.process_id, runs = record.runs, %tenant, "sweep queued");
            record
        }
        Admission::Replayed(record) => {
            tracing::info!(sweep = %record.id, %tenant, "idempotent retry: the key's sweep, nothing queued");
            mark_replayed(&mut headers);
            record
        }
        Admission::KeyConflict(conflict) => return Err(key_reused(&conflict)),
        Admission::QueueFull { queued } => {
            let adding = runs.iter().filter(|run| run.invalid.is_none()).count();
            return Err(ApiError::queue_full(
                queued,
                adding,
                state.max_queued_jobs.unwrap_or(0),
            ));
        }
    };
    let status = sweep_status(&state, &tenant, &record).await?;
    headers.insert(
        header::LOCATION,
        HeaderValue::from_str(&format!("/sweeps/{}", record.id)).expect("uuid is a valid header value"),
    );
    Ok((StatusCode::CREATED, headers, Json(status)).into_response())
}

/// The problem document of a refused sweep.
fn refusal(refusal: Refusal) -> ApiError {
    let problem = match refusal {
        Refusal::Request(SweepError::Invalid(errors)) => Problem::invalid_inputs(&InvalidInputs(errors)),
        Refusal::Request(SweepError::TooLarge { runs, limit }) => Problem::sweep_too_large(runs, limit),
        Refusal::NoSuchProcess(id) => Problem::no_such_process(&id),
        Refusal::InvalidRuns(refused) => {
            let mut problem = Problem::invalid_inputs(&InvalidInputs(refused.errors));
            problem.detail = format!(
                "{} of {} runs have invalid inputs (first run {}); nothing was queued; see `errors` (at most {MAX_RUN_ERRORS})",
                refused.refused, refused.runs, refused.first
            );
            problem
        }
        Refusal::TooCostly { runs, exceeded } => {
            let mut problem = Problem::too_costly(&TooCostly {
                exceeded,
                errors: runs.errors,
            });
            problem.detail = format!(
                "{} of {} runs are above this service's cost ceilings (first run {}: {}); nothing was queued; \
                 see `errors` (at most {MAX_RUN_ERRORS})",
                runs.refused, runs.runs, runs.first, problem.detail
            );
            problem
        }
    };
    problem.into()
}

pub(super) async fn sweep_status(
    state: &AppState,
    tenant: &Tenant,
    record: &SweepRecord,
) -> Result<SweepStatus, ApiError> {
    let counts = state
        .queue
        .sweep_counts(tenant.as_str(), std::slice::from_ref(&record.id))
        .await?;
    Ok(SweepStatus::new(
        record,
        &counts.get(&record.id).cloned().unwrap_or_default(),
    ))
}

pub(super) async fn find(state: &AppState, tenant: &Tenant, sweep_id: &str) -> Result<SweepRecord, ApiError> {
    Ok(state
        .queue
        .get_sweep(tenant.as_str(), sweep_id)
        .await?
        .ok_or_else(|| Problem::no_such_sweep(sweep_id))?)
}

/// A sweep's status
///
/// Status, counts of runs per status, progress and links. Strong `ETag` (`304` on
/// `If-None-Match`), `Retry-After` (s) while runs are pending.
#[utoipa::path(get, path = "/sweeps/{sweepId}", operation_id = "getSweep", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id")),
    responses(
        (status = 200, description = "The sweep's status", body = SweepStatus, headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn status(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let record = find(&state, &tenant, &sweep_id).await?;
    let status = sweep_status(&state, &tenant, &record).await?;
    let mut extra = HeaderMap::new();
    if !status.is_finished() {
        extra.insert(header::RETRY_AFTER, HeaderValue::from_static("1"));
    }
    let body = serde_json::to_vec(&status).map_err(|e| ApiError::Internal(e.to_string()))?;
    Ok(tagged(&headers, "application/json", body, extra))
}

/// The query of `GET /sweeps`: `limit` (1 to 1000, default 10), `cursor`, `label`
/// (repeatable: sweeps with every label named); `f` and `format` are the negotiator's
/// ([`super::negotiation`]); anything else is refused.
#[derive(Debug, Default)]
struct SweepListQuery {
    limit: Option<u32>,
    cursor: Option<i64>,
    labels: Vec<String>,
}

fn parse_list_query(pairs: &[(String, String)]) -> Result<SweepListQuery, Problem> {
    let mut query = SweepListQuery::default();
    for (key, value) in pairs {
        match key.as_str() {
            "limit" => {
                query.limit = Some(
                    value
                        .parse()
                        .ok()
                        .filter(|n| (1..=MAX_LIMIT).contains(n))
                        .ok_or_else(|| {
                            Problem::invalid_query(format!(
                                "`limit` must be an integer from 1 to {MAX_LIMIT}"
                            ))
                        })?,
                )
            }
            "cursor" => {
                query.cursor = Some(value.parse().map_err(|_| {
                    Problem::invalid_query("`cursor` must be the value given in a `next` link")
                })?)
            }
            "label" => {
                if let Some(fault) = label_fault(value) {
                    return Err(Problem::invalid_query(format!("`label` `{value}` {fault}")));
                }
                query.labels.push(value.clone());
            }
            "f" | "format" => {}
            other => {
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected limit, cursor, label)"
                )));
            }
        }
    }
    Ok(query)
}

/// List sweeps
///
/// Newest first, `limit` per page; the `next` link gives older ones. `label`
/// (repeatable): only the sweeps that have every label named.
#[utoipa::path(get, path = "/sweeps", operation_id = "getSweeps", tag = "Sweeps",
    params(
        ("limit" = Option<u32>, Query, description = "Sweeps per page, 1 to 1000 (default 10)", minimum = 1, maximum = 1000),
        ("cursor" = Option<i64>, Query, description = "Opaque position from a `next` link"),
        ("label" = Option<Vec<String>>, Query, explode = true, description = "Only sweeps that have this label; repeat it for sweeps that have all of them"),
        ("f" = Option<String>, Query, description = "`json`, or `html` (the dashboard's page); `format` is an alias; default from `Accept`"),
    ),
    responses(
        (status = 200, description = "A page of sweeps", body = SweepList),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn list(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    query: Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>,
) -> Result<Response, ApiError> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let query = parse_list_query(&pairs)?;
    let limit = query.limit.unwrap_or(DEFAULT_LIMIT);
    let mut sweeps = state
        .queue
        .list_sweeps(tenant.as_str(), limit + 1, query.cursor, &query.labels)
        .await?;
    let more = sweeps.len() > limit as usize;
    sweeps.truncate(limit as usize);
    let ids: Vec<String> = sweeps.iter().map(|s| s.id.clone()).collect();
    let counts = state.queue.sweep_counts(tenant.as_str(), &ids).await?;
    let labels: String = query
        .labels
        .iter()
        .map(|label| format!("&label={}", percent_encoded(label)))
        .collect();
    let href = |cursor: Option<i64>| match cursor {
        Some(cursor) => format!("/sweeps?limit={limit}&cursor={cursor}{labels}"),
        None => format!("/sweeps?limit={limit}{labels}"),
    };
    let mut links = vec![Link::new(href(query.cursor), "self", "application/json")];
    if let (true, Some(last)) = (more, sweeps.last()) {
        links.push(Link::new(href(Some(last.seq)), "next", "application/json"));
    }
    let list = SweepList {
        sweeps: sweeps
            .iter()
            .map(|s| SweepStatus::new(s, &counts.get(&s.id).cloned().unwrap_or_default()))
            .collect(),
        links,
    };
    Ok(Json(list).into_response())
}

/// Every byte but unreserved characters percent-encoded (a query parameter's value).
pub(super) fn percent_encoded(text: &str) -> String {
    text.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// Dismiss a sweep
///
/// Every run still queued or running is dismissed (a running one stops within a
/// second); runs that ended keep their results. The sweep's status becomes `dismissed`.
#[utoipa::path(delete, path = "/sweeps/{sweepId}", operation_id = "dismissSweep", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id")),
    responses(
        (status = 200, description = "The dismissed sweep's status", body = SweepStatus),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn dismiss(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
) -> Result<Response, ApiError> {
    let (record, dismissed) = state
        .queue
        .dismiss_sweep(tenant.as_str(), &sweep_id)
        .await?
        .ok_or_else(|| Problem::no_such_sweep(&sweep_id))?;
    let cancelled = dismissed.iter().filter(|id| state.running.cancel(id)).count();
    tracing::info!(sweep = %sweep_id, dismissed = dismissed.len(), cancelled, "sweep dismissed");
    Ok(Json(sweep_status(&state, &tenant, &record).await?).into_response())
}

/// Query of `GET /sweeps/{sweepId}/results`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct SweepResultsQuery {
    /// Chosen by the service's negotiator (`f` is an alias): `csv` or `json`; without
    /// it, the one `Accept` prefers (q-values honoured), else JSON.
    #[param(pattern = "^(csv|json)$")]
    #[serde(alias = "f")]
    pub format: Option<String>,
}

/// A sweep's results
///
/// One row per run that ended (rows appear as runs finish): `run`, `job`, `status`, the
/// axis values (columns named by pointer), then the run's scalar results flattened with
/// dots (`quality.verdict` and the numeric quality fields among them). JSON adds the
/// aggregates, with the count of `poor` (and `doubtful`) runs in total and per axis
/// value; `format=csv`, or `Accept: text/csv` without a `format`, gives the table alone.
#[utoipa::path(get, path = "/sweeps/{sweepId}/results", operation_id = "getSweepResults", tag = "Sweeps",
    params(("sweepId" = String, Path, description = "Sweep id"), SweepResultsQuery),
    responses(
        (status = 200, description = "The results table (and aggregates in JSON)",
            content((SweepResults = "application/json"), (String = "text/csv")), headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such sweep (`no-such-sweep`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn results(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(sweep_id): Path<String>,
    // Checks the query; its `format` is the negotiator's (`format: Format`).
    ApiQuery(_): ApiQuery<SweepResultsQuery>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let csv = format == Format::Csv;
    let record = find(&state, &tenant, &sweep_id).await?;
    let status = sweep_status(&state, &tenant, &record).await?;
    let runs = state.queue.ended_sweep_runs(tenant.as_str(), &sweep_id).await?;
    let process = state.registry.get(&record.process_id);
    // Parsing thousands of results documents is CPU work: off the runtime.
    let body =
        tokio::task::spawn_blocking(move || render_results(&record, status, runs, process.as_deref(), csv))
            .await
            .map_err(|e| ApiError::Internal(format!("rendering sweep results panicked: {e}")))??;
    let mut extra = HeaderMap::new();
    extra.insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(tagged(&headers, format.content_type(), body, extra))
}

fn render_results(
    record: &SweepRecord,
    status: SweepStatus,
    runs: Vec<SweepRun>,
    process: Option<&dyn Process>,
    csv: bool,
) -> Result<Vec<u8>, ApiError> {
    let definition = SweepDefinition::from_stored(&record.definition)
        .map_err(|e| ApiError::Internal(format!("sweep {}: stored definition unreadable: {e}", record.id)))?;
    let records: Vec<RunRecord> = runs.into_iter().map(|run| run_record(run, process)).collect();
    let table = definition.table(&records);
    if csv {
        return Ok(table.to_csv().into_bytes());
    }
    let aggregates = definition.aggregates(&table);
    let href = format!("/sweeps/{}", record.id);
    let document = SweepResults {
        sweep_id: record.id.clone(),
        status: status.status,
        runs: record.runs,
        columns: table.columns,
        rows: table.rows,
        // Through a JSON value: its members sorted, as they always were.
        aggregates: serde_json::to_value(&aggregates).map_err(|e| ApiError::Internal(e.to_string()))?,
        links: vec![
            Link::new(format!("{href}/results"), "self", "application/json"),
            Link::new(format!("{href}/results?format=csv"), "alternate", "text/csv"),
            Link::new(&href, "up", "application/json").titled("Sweep status"),
        ],
    };
    serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))
}

/// What the results table needs of an ended run: its stored inputs, and the scalar
/// metrics of its stored results document (none when it has none).
pub(super) fn run_record(run: SweepRun, process: Option<&dyn Process>) -> RunRecord {
    let document: Option<serde_json::Value> = run
        .results
        .as_deref()
        .and_then(|text| serde_json::from_str(text).ok());
    let mut metrics = match (&document, process) {
        (Some(document), Some(process)) => process.summary_metrics(document),
        (Some(document), None) => crate::processes::metrics::flatten_scalars(document),
        (None, _) => Vec::new(),
    };
    // Where a run's result comes from is the sweep's (one solver, one build; the run's
    // inputs are its axis columns), not a metric to tabulate or aggregate.
    metrics.retain(|(name, _)| !name.starts_with("provenance."));
    RunRecord {
        run: usize::try_from(run.run).unwrap_or(0),
        job: run.job_id,
        status: run.status.as_str().to_owned(),
        inputs: serde_json::from_str(&run.inputs).unwrap_or(serde_json::Value::Null),
        metrics,
    }
}
