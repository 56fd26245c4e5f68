//! `/sweeps`: submit a sweep (validated whole before anything is queued), its status,
//! the sweep list, dismissal, and its results table with aggregates.

use std::sync::Arc;

use axum::Json;
use axum::extract::{Extension, Path, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use serde_json::{Value, json};

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::extract::{ApiQuery, JsonBody};
use super::jobs::{DEFAULT_LIMIT, MAX_LIMIT};
use super::models::Link;
use super::sweep_models::{SweepList, SweepResults, SweepStatus};
use crate::problem::Problem;
use crate::processes::{CostLimits, FieldError, InvalidInputs, Process, TooCostly};
use crate::service::auth::Tenant;
use crate::service::queue::sweep_create::{NewRun, NewSweep};
use crate::service::queue::{Admission, SweepRecord};
use crate::sweep::spec::{self, SweepError};
use crate::sweep::table::{self, RunRecord};
use crate::sweep::{Design, InvalidRuns, SweepSpec, aggregate};

/// At most this many field errors are reported for the runs of one sweep.
const MAX_RUN_ERRORS: usize = 100;

/// Submit a sweep
///
/// Expands the axes into runs (grid, Monte Carlo or Latin hypercube), validates every
/// run's inputs like an execution request, then queues them all as jobs of the sweep:
/// `201 Created`, `Location: /sweeps/{sweepId}`. Nothing is queued when anything is
/// invalid: 422 with `errors` pointing into the request (`/axes/0/linspace`) or, for a
/// generated run, `/runs/{run}/inputs/...` (the detail names the run's axis values).
/// Every run must also be within the service's cost ceilings (422 `too-costly`, with
/// the same run pointers), and the runs must fit in the tenant's queue (429).
#[utoipa::path(post, path = "/sweeps", operation_id = "createSweep", tag = "Sweeps",
    request_body(content = super::sweep_models::SweepRequestSchema, description = "The process, base inputs and axes"),
    responses(
        (status = 201, description = "Sweep queued", body = SweepStatus,
            headers(("Location" = String, description = "`/sweeps/{sweepId}`"))),
        (status = 400, description = "Malformed JSON", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such process", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 413, description = "Body over the size limit", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 415, description = "Body not declared as JSON", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 422, description = "Invalid sweep or run inputs (`invalid-inputs`), more runs than allowed (`sweep-too-large`), or a run above the cost ceilings (`too-costly`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 429, description = "The runs would exceed the limit of queued jobs (`too-many-queued-jobs`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json",
            headers(("Retry-After" = String, description = "s")))))]
pub async fn create(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    body: Result<JsonBody, ApiError>,
) -> Result<Response, ApiError> {
    let JsonBody(body) = body?;
    let spec = spec::parse(&body, state.max_sweep_runs).map_err(|error| match error {
        SweepError::Invalid(errors) => Problem::invalid_inputs(&InvalidInputs(errors)),
        SweepError::TooLarge { runs, limit } => Problem::sweep_too_large(runs, limit),
    })?;
    let process = state
        .registry
        .get(&spec.process)
        .ok_or_else(|| Problem::no_such_process(&spec.process))?;
    let spec = Arc::new(spec);
    // Expansion and validation of thousands of runs is CPU work: off the runtime.
    let runs = {
        let spec = spec.clone();
        let limits = state.limits;
        tokio::task::spawn_blocking(move || expand_and_validate(&spec, process.as_ref(), &limits))
            .await
            .map_err(|e| ApiError::Internal(format!("sweep validation panicked: {e}")))?
    }?;
    let definition = definition(&spec, &body);
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
            },
            state.max_queued_jobs,
        )
        .await?;
    let record = match admission {
        Admission::Admitted(record) => record,
        Admission::QueueFull { queued } => {
            let adding = runs.iter().filter(|run| run.invalid.is_none()).count();
            return Err(ApiError::queue_full(
                queued,
                adding,
                state.max_queued_jobs.unwrap_or(0),
            ));
        }
    };
    state.wake.notify_waiters();
    state.wake.notify_one();
    tracing::info!(sweep = %record.id, process = %record.process_id, runs = record.runs, %tenant, "sweep queued");
    let status = sweep_status(&state, &tenant, &record).await?;
    let mut headers = HeaderMap::new();
    headers.insert(
        header::LOCATION,
        HeaderValue::from_str(&format!("/sweeps/{}", record.id)).expect("uuid is a valid header value"),
    );
    Ok((StatusCode::CREATED, headers, Json(status)).into_response())
}

/// The normalized definition stored with the sweep: the request with its defaults made explicit.
fn definition(spec: &SweepSpec, body: &Value) -> Value {
    json!({
        "process": spec.process,
        "inputs": spec.inputs,
        "axes": body.get("axes").cloned().unwrap_or(Value::Null),
        "design": spec.design.as_str(),
        "samples": spec.samples,
        "seed": spec.seed,
        "policy": spec.policy.as_str(),
        "invalid_runs": spec.invalid_runs.as_str(),
    })
}

/// Why a generated run cannot be queued.
#[derive(Debug)]
enum Refusal {
    Invalid(InvalidInputs),
    TooCostly(TooCostly),
}

/// Every run, or the 422 naming the invalid runs (unless they are to be recorded) or
/// the runs above the cost ceilings (always refused). Runs are validated in parallel,
/// one chunk per core.
fn expand_and_validate(
    spec: &SweepSpec,
    process: &dyn Process,
    limits: &CostLimits,
) -> Result<Vec<NewRun>, ApiError> {
    let runs = spec.expand();
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(runs.len().max(1));
    let chunk = runs.len().div_ceil(threads).max(1);
    let refusals: Vec<(usize, Refusal)> = std::thread::scope(|scope| {
        let handles: Vec<_> = runs
            .chunks(chunk)
            .map(|runs| {
                scope.spawn(move || {
                    runs.iter()
                        .filter_map(|run| {
                            let refusal = match process.validate(&run.inputs) {
                                Err(invalid) => Refusal::Invalid(invalid),
                                Ok(estimate) => Refusal::TooCostly(limits.check(&estimate).err()?),
                            };
                            Some((run.index, refusal))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join())
            .collect::<Result<Vec<_>, _>>()
            .map(|chunks| chunks.into_iter().flatten().collect())
    })
    .map_err(|_| ApiError::Internal("a process's validation panicked".into()))?;
    let mut failures: Vec<(usize, InvalidInputs)> = Vec::new();
    let mut costly: Vec<(usize, TooCostly)> = Vec::new();
    for (index, refusal) in refusals {
        match refusal {
            Refusal::Invalid(invalid) => failures.push((index, invalid)),
            Refusal::TooCostly(refused) => costly.push((index, refused)),
        }
    }
    if !costly.is_empty() {
        costly.sort_by_key(|(index, _)| *index);
        let errors = run_errors(
            spec,
            &runs,
            costly
                .iter()
                .map(|(index, refused)| (*index, refused.errors.as_slice())),
        );
        let mut problem = Problem::too_costly(&TooCostly {
            exceeded: costly[0].1.exceeded.clone(),
            errors,
        });
        problem.detail = format!(
            "{} of {} runs are above this service's cost ceilings (first run {}: {}); nothing was queued; \
             see `errors` (at most {MAX_RUN_ERRORS})",
            costly.len(),
            runs.len(),
            costly[0].0,
            problem.detail
        );
        return Err(problem.into());
    }
    if failures.is_empty() || spec.invalid_runs == InvalidRuns::Record {
        let mut failures = failures.into_iter().collect::<std::collections::HashMap<_, _>>();
        return Ok(runs
            .into_iter()
            .map(|run| NewRun {
                invalid: failures
                    .remove(&run.index)
                    .map(|invalid| Problem::invalid_inputs(&invalid)),
                inputs: run.inputs,
            })
            .collect());
    }
    failures.sort_by_key(|(index, _)| *index);
    let invalid_runs = failures.len();
    let errors = run_errors(
        spec,
        &runs,
        failures
            .iter()
            .map(|(index, invalid)| (*index, invalid.0.as_slice())),
    );
    let mut problem = Problem::invalid_inputs(&InvalidInputs(errors));
    problem.detail = format!(
        "{invalid_runs} of {} runs have invalid inputs (first run {}); nothing was queued; see `errors` (at most {MAX_RUN_ERRORS})",
        runs.len(),
        failures[0].0
    );
    Err(problem.into())
}

/// The errors of generated runs, re-pointed into the sweep (`/runs/{run}/inputs/...`)
/// with each run's axis values in the detail; at most [`MAX_RUN_ERRORS`].
fn run_errors<'a>(
    spec: &SweepSpec,
    runs: &[crate::sweep::Run],
    refused: impl Iterator<Item = (usize, &'a [FieldError])>,
) -> Vec<FieldError> {
    refused
        .flat_map(|(index, errors)| {
            let values: Vec<String> = spec
                .axes
                .iter()
                .map(|axis| {
                    let value = runs[index]
                        .inputs
                        .pointer(&axis.pointer)
                        .cloned()
                        .unwrap_or(Value::Null);
                    format!("{} = {value}", axis.pointer)
                })
                .collect();
            errors.iter().map(move |error| {
                let within = error.pointer.strip_prefix("/inputs").unwrap_or(&error.pointer);
                FieldError::new(
                    format!("/runs/{index}/inputs{within}"),
                    format!("{} (run {index}: {})", error.detail, values.join(", ")),
                )
            })
        })
        .take(MAX_RUN_ERRORS)
        .collect()
}

async fn sweep_status(
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

async fn find(state: &AppState, tenant: &Tenant, sweep_id: &str) -> Result<SweepRecord, ApiError> {
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

/// Query of `GET /sweeps`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct SweepListQuery {
    /// Sweeps per page, 1 to 1000 (default 10).
    #[param(minimum = 1, maximum = 1000)]
    pub limit: Option<u32>,
    /// Opaque position from a `next` link.
    pub cursor: Option<i64>,
    /// Accepted and ignored (OGC format parameter).
    pub f: Option<String>,
}

/// List sweeps
///
/// Newest first, `limit` per page; the `next` link gives older ones.
#[utoipa::path(get, path = "/sweeps", operation_id = "getSweeps", tag = "Sweeps",
    params(SweepListQuery),
    responses(
        (status = 200, description = "A page of sweeps", body = SweepList),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn list(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    ApiQuery(query): ApiQuery<SweepListQuery>,
) -> Result<Response, ApiError> {
    let limit = query.limit.unwrap_or(DEFAULT_LIMIT);
    if !(1..=MAX_LIMIT).contains(&limit) {
        return Err(
            Problem::invalid_query(format!("`limit` must be an integer from 1 to {MAX_LIMIT}")).into(),
        );
    }
    let mut sweeps = state
        .queue
        .list_sweeps(tenant.as_str(), limit + 1, query.cursor)
        .await?;
    let more = sweeps.len() > limit as usize;
    sweeps.truncate(limit as usize);
    let ids: Vec<String> = sweeps.iter().map(|s| s.id.clone()).collect();
    let counts = state.queue.sweep_counts(tenant.as_str(), &ids).await?;
    let href = |cursor: Option<i64>| match cursor {
        Some(cursor) => format!("/sweeps?limit={limit}&cursor={cursor}"),
        None => format!("/sweeps?limit={limit}"),
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
    /// `json` (default: the table with aggregates) or `csv` (the table only).
    #[param(pattern = "^(csv|json)$")]
    pub format: Option<String>,
}

/// A sweep's results
///
/// One row per run that ended (rows appear as runs finish): `run`, `job`, `status`, the
/// axis values (columns named by pointer), then the run's scalar results flattened with
/// dots (`quality.verdict` and the numeric quality fields among them). JSON adds the
/// aggregates, with the count of `poor` (and `doubtful`) runs in total and per axis
/// value; `format=csv` gives the table alone.
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
    ApiQuery(query): ApiQuery<SweepResultsQuery>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let csv = match query.format.as_deref() {
        None | Some("json") => false,
        Some("csv") => true,
        Some(other) => {
            return Err(
                Problem::invalid_query(format!("`format` must be `csv` or `json`, not `{other}`")).into(),
            );
        }
    };
    let record = find(&state, &tenant, &sweep_id).await?;
    let status = sweep_status(&state, &tenant, &record).await?;
    let runs = state.queue.ended_sweep_runs(tenant.as_str(), &sweep_id).await?;
    let process = state.registry.get(&record.process_id);
    // Parsing thousands of results documents is CPU work: off the runtime.
    let body =
        tokio::task::spawn_blocking(move || render_results(&record, status, runs, process.as_deref(), csv))
            .await
            .map_err(|e| ApiError::Internal(format!("rendering sweep results panicked: {e}")))??;
    let content_type = if csv {
        "text/csv; charset=utf-8"
    } else {
        "application/json"
    };
    Ok(tagged(&headers, content_type, body, HeaderMap::new()))
}

fn render_results(
    record: &SweepRecord,
    status: SweepStatus,
    runs: Vec<crate::service::queue::sweep_read::SweepRun>,
    process: Option<&dyn Process>,
    csv: bool,
) -> Result<Vec<u8>, ApiError> {
    let definition: Value = serde_json::from_str(&record.definition).unwrap_or(Value::Null);
    let axes = definition["axes"].as_array().cloned().unwrap_or_default();
    let pointer = |axis: &Value| axis["pointer"].as_str().unwrap_or_default().to_owned();
    let is_list = |axis: &Value| {
        ["values", "linspace", "logspace"]
            .iter()
            .any(|k| axis.get(k).is_some())
    };
    let pointers: Vec<String> = axes.iter().map(pointer).collect();
    let records: Vec<RunRecord> = runs
        .into_iter()
        .map(|run| {
            let document: Option<Value> = run
                .results
                .as_deref()
                .and_then(|text| serde_json::from_str(text).ok());
            let metrics = match (&document, process) {
                (Some(document), Some(process)) => process.summary_metrics(document),
                (Some(document), None) => crate::processes::metrics::flatten_scalars(document),
                (None, _) => Vec::new(),
            };
            RunRecord {
                run: usize::try_from(run.run).unwrap_or(0),
                job: run.job_id,
                status: run.status.as_str().to_owned(),
                inputs: serde_json::from_str(&run.inputs).unwrap_or(Value::Null),
                metrics,
            }
        })
        .collect();
    let table = table::build(&pointers, &records);
    if csv {
        return Ok(table.to_csv().into_bytes());
    }
    let list_axes: Vec<String> = axes.iter().filter(|a| is_list(a)).map(pointer).collect();
    let mut aggregates = match Design::parse(&record.design) {
        Some(Design::Grid) => match aggregate::calibration(&table, &pointers) {
            Some(map) => json!({ "calibration": map }),
            None => json!({}),
        },
        _ => {
            let random_axes: Vec<String> = axes.iter().filter(|a| !is_list(a)).map(pointer).collect();
            json!({ "statistics": aggregate::cell_statistics(&table, &list_axes, &random_axes) })
        }
    };
    if let Some(quality) = aggregate::quality_counts(&table, &list_axes) {
        aggregates["quality"] = json!(quality);
    }
    let href = format!("/sweeps/{}", record.id);
    let document = SweepResults {
        sweep_id: record.id.clone(),
        status: status.status,
        runs: record.runs,
        columns: table.columns,
        rows: table.rows,
        aggregates,
        links: vec![
            Link::new(format!("{href}/results"), "self", "application/json"),
            Link::new(format!("{href}/results?format=csv"), "alternate", "text/csv"),
            Link::new(&href, "up", "application/json").titled("Sweep status"),
        ],
    };
    serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))
}
