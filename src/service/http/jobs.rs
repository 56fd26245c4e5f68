//! `/jobs`: the job list, one job's status, and dismissal.

use axum::extract::{Extension, Path, Query, State};
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::models::{JobList, Link, StatusInfo};
use crate::annotations::label_fault;
use crate::problem::Problem;
use crate::service::auth::Tenant;
use crate::service::queue::JobStatus;
use crate::service::queue::read::JobFilter;

/// Page size of `GET /jobs` when `limit` is not given.
pub const DEFAULT_LIMIT: u32 = 10;
/// Largest accepted `limit`.
pub const MAX_LIMIT: u32 = 1000;

/// Seconds a client should wait before polling a job that is not finished.
const RETRY_AFTER_SECONDS: &str = "1";

/// Parsed query of `GET /jobs`.
#[derive(Debug, Default)]
struct ListQuery {
    filter: JobFilter,
    limit: u32,
    cursor: Option<i64>,
}

/// Parses `status`, `processID`, `sweepID` (each repeatable and comma-separated),
/// `label` (repeatable, one label each: jobs with all of them), `inSweep` (`true` or
/// `false`), `limit`, `cursor`; `f` and `format` are the negotiator's
/// ([`super::negotiation`]); anything else is refused.
fn parse_list_query(pairs: &[(String, String)]) -> Result<ListQuery, Problem> {
    let mut query = ListQuery {
        limit: DEFAULT_LIMIT,
        ..ListQuery::default()
    };
    for (key, value) in pairs {
        match key.as_str() {
            "status" => {
                for text in value.split(',').filter(|s| !s.is_empty()) {
                    let status = JobStatus::parse(text).ok_or_else(|| {
                        Problem::invalid_query(format!(
                            "`status`: `{text}` is not one of accepted, running, successful, failed, dismissed"
                        ))
                    })?;
                    query.filter.statuses.push(status);
                }
            }
            "processID" => query
                .filter
                .process_ids
                .extend(value.split(',').filter(|s| !s.is_empty()).map(str::to_owned)),
            "sweepID" => query
                .filter
                .sweep_ids
                .extend(value.split(',').filter(|s| !s.is_empty()).map(str::to_owned)),
            "label" => {
                if let Some(fault) = label_fault(value) {
                    return Err(Problem::invalid_query(format!("`label` `{value}` {fault}")));
                }
                query.filter.labels.push(value.clone());
            }
            "inSweep" => {
                query.filter.in_sweep = Some(match value.as_str() {
                    "true" => true,
                    "false" => false,
                    other => {
                        return Err(Problem::invalid_query(format!(
                            "`inSweep` must be `true` (runs of sweeps only) or `false` (jobs submitted on \
                             their own only), not `{other}`"
                        )));
                    }
                });
            }
            "limit" => {
                query.limit = value
                    .parse()
                    .ok()
                    .filter(|n| (1..=MAX_LIMIT).contains(n))
                    .ok_or_else(|| {
                        Problem::invalid_query(format!("`limit` must be an integer from 1 to {MAX_LIMIT}"))
                    })?;
            }
            "cursor" => {
                query.cursor = Some(value.parse().map_err(|_| {
                    Problem::invalid_query("`cursor` must be the value given in a `next` link")
                })?);
            }
            "f" | "format" => {}
            other => {
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected status, processID, sweepID, label, inSweep, limit, cursor)"
                )));
            }
        }
    }
    Ok(query)
}

fn list_href(query: &ListQuery, cursor: Option<i64>) -> String {
    let mut href = format!("/jobs?limit={}", query.limit);
    if !query.filter.statuses.is_empty() {
        let statuses: Vec<&str> = query.filter.statuses.iter().map(|s| s.as_str()).collect();
        href.push_str(&format!("&status={}", statuses.join(",")));
    }
    if !query.filter.process_ids.is_empty() {
        href.push_str(&format!(
            "&processID={}",
            encode_component(&query.filter.process_ids.join(","))
        ));
    }
    if !query.filter.sweep_ids.is_empty() {
        href.push_str(&format!(
            "&sweepID={}",
            encode_component(&query.filter.sweep_ids.join(","))
        ));
    }
    for label in &query.filter.labels {
        href.push_str(&format!("&label={}", encode_component(label).replace(',', "%2C")));
    }
    if let Some(in_sweep) = query.filter.in_sweep {
        href.push_str(&format!("&inSweep={in_sweep}"));
    }
    if let Some(cursor) = cursor {
        href.push_str(&format!("&cursor={cursor}"));
    }
    href
}

/// Percent-encodes everything but unreserved characters and commas.
fn encode_component(text: &str) -> String {
    text.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' | b',' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// List jobs
///
/// Newest first. Filters: `status`, `processID` and `sweepID` (repeatable, or
/// comma-separated values), `label` (repeatable: only jobs that have every label named),
/// `inSweep` (`false`: only jobs submitted on their own, no sweep run; `true`: only
/// sweep runs). Each job says its `verdict` once successful. Paging: `limit` jobs per page; the `next` link (keyset `cursor`) gives the
/// following page, stable while new jobs arrive.
#[utoipa::path(get, path = "/jobs", operation_id = "getJobs", tag = "Jobs",
    params(
        ("status" = Option<String>, Query, description = "Only jobs in these statuses, e.g. `running,accepted`"),
        ("processID" = Option<String>, Query, description = "Only jobs of these processes"),
        ("sweepID" = Option<String>, Query, description = "Only runs of these sweeps"),
        ("label" = Option<Vec<String>>, Query, explode = true, description = "Only jobs that have this label; repeat it for jobs that have all of them (`label=a&label=b`)"),
        ("inSweep" = Option<bool>, Query, description = "`false`: only jobs submitted on their own (no sweep run); `true`: only runs of sweeps"),
        ("limit" = Option<u32>, Query, description = "Jobs per page, 1 to 1000 (default 10)", minimum = 1, maximum = 1000),
        ("cursor" = Option<i64>, Query, description = "Opaque position from a `next` link"),
    ),
    responses(
        (status = 200, description = "A page of jobs", body = JobList),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn list(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    query: Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>,
) -> Result<Response, ApiError> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let query = parse_list_query(&pairs)?;
    let mut jobs = state
        .queue
        .list(tenant.as_str(), &query.filter, query.limit + 1, query.cursor)
        .await?;
    let more = jobs.len() > query.limit as usize;
    jobs.truncate(query.limit as usize);
    let mut links = vec![Link::new(
        list_href(&query, query.cursor),
        "self",
        "application/json",
    )];
    if let (true, Some(last)) = (more, jobs.last()) {
        links.push(Link::new(
            list_href(&query, Some(last.seq)),
            "next",
            "application/json",
        ));
    }
    let list = JobList {
        jobs: jobs.iter().map(StatusInfo::from_record).collect(),
        links,
    };
    Ok(axum::Json(list).into_response())
}

/// A job's status
///
/// Carries a strong `ETag`: send it back in `If-None-Match` to get an empty `304` until
/// something changes. `Retry-After` (s) suggests a polling interval while the job is not
/// finished.
#[utoipa::path(get, path = "/jobs/{jobId}", operation_id = "getStatus", tag = "Jobs",
    params(("jobId" = String, Path, description = "Job id")),
    responses(
        (status = 200, description = "The job's status", body = StatusInfo,
            headers(("ETag" = String), ("Retry-After" = String, description = "s, while not finished"))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 404, description = "No such job (`no-such-job`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn status(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let job = state
        .queue
        .get(tenant.as_str(), &job_id)
        .await?
        .ok_or_else(|| Problem::no_such_job(&job_id))?;
    let body =
        serde_json::to_vec(&StatusInfo::from_record(&job)).map_err(|e| ApiError::Internal(e.to_string()))?;
    let mut extra = HeaderMap::new();
    if !job.status.is_finished() {
        extra.insert(header::RETRY_AFTER, HeaderValue::from_static(RETRY_AFTER_SECONDS));
    }
    Ok(tagged(&headers, "application/json", body, extra))
}

/// Dismiss a job
///
/// A queued job never runs; a running job stops within a second; a finished job's
/// results are deleted. The status becomes `dismissed`. Dismissing again is harmless.
#[utoipa::path(delete, path = "/jobs/{jobId}", operation_id = "dismiss", tag = "Jobs",
    params(("jobId" = String, Path, description = "Job id")),
    responses(
        (status = 200, description = "The dismissed job's status", body = StatusInfo),
        (status = 404, description = "No such job (`no-such-job`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn dismiss(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
) -> Result<Response, ApiError> {
    let job = state
        .queue
        .dismiss(tenant.as_str(), &job_id)
        .await?
        .ok_or_else(|| Problem::no_such_job(&job_id))?;
    if state.running.cancel(&job_id) {
        tracing::info!(job = %job_id, "dismissed while running: cancelling");
    }
    Ok(axum::Json(StatusInfo::from_record(&job)).into_response())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(items: &[(&str, &str)]) -> Vec<(String, String)> {
        items.iter().map(|(k, v)| ((*k).into(), (*v).into())).collect()
    }

    #[test]
    fn statuses_may_be_repeated_or_comma_separated() {
        let query =
            parse_list_query(&pairs(&[("status", "running,accepted"), ("status", "failed")])).unwrap();
        assert_eq!(
            query.filter.statuses,
            vec![JobStatus::Running, JobStatus::Accepted, JobStatus::Failed]
        );
    }

    #[test]
    fn unknown_parameters_and_bad_limits_are_refused() {
        assert!(parse_list_query(&pairs(&[("stauts", "running")])).is_err());
        assert!(parse_list_query(&pairs(&[("limit", "0")])).is_err());
        assert!(parse_list_query(&pairs(&[("limit", "1001")])).is_err());
        assert!(parse_list_query(&pairs(&[("status", "done")])).is_err());
    }

    #[test]
    fn in_sweep_is_a_boolean() {
        assert_eq!(
            parse_list_query(&pairs(&[("inSweep", "false")]))
                .unwrap()
                .filter
                .in_sweep,
            Some(false)
        );
        assert_eq!(
            parse_list_query(&pairs(&[("inSweep", "true")]))
                .unwrap()
                .filter
                .in_sweep,
            Some(true)
        );
        assert_eq!(parse_list_query(&[]).unwrap().filter.in_sweep, None);
        assert!(parse_list_query(&pairs(&[("inSweep", "no")])).is_err());
    }

    #[test]
    fn next_links_keep_the_filters() {
        let query = parse_list_query(&pairs(&[
            ("status", "running"),
            ("processID", "a b"),
            ("limit", "5"),
            ("inSweep", "false"),
        ]))
        .unwrap();
        assert_eq!(
            list_href(&query, Some(42)),
            "/jobs?limit=5&status=running&processID=a%20b&inSweep=false&cursor=42"
        );
    }
}
