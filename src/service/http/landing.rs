//! Capabilities and operations: landing page, conformance, health, metrics, OpenAPI.

use axum::Json;
use axum::extract::State;
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::error::ApiError;
use super::models::{Conformance, Health, LandingPage, Link, Readiness};
use super::openapi;

/// The classes claimed. Not `oas30`: the API definition is OpenAPI 3.1 (utoipa's), and
/// a client of the 3.0 class (OWSLib's `api()`) looks for a 3.0 document.
const OGC_CONFORMANCE: &[&str] = &[
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/core",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/ogc-process-description",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/json",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/html",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/job-list",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/dismiss",
];

fn landing_links() -> Vec<Link> {
    vec![
        Link::new("/", "self", "application/json").titled("This document"),
        Link::new(
            "/openapi.json",
            "service-desc",
            "application/vnd.oai.openapi+json;version=3.1",
        )
        .titled("The API definition"),
        Link::new(
            "/conformance",
            "http://www.opengis.net/def/rel/ogc/1.0/conformance",
            "application/json",
        )
        .titled("Conformance classes"),
        Link::new(
            "/processes",
            "http://www.opengis.net/def/rel/ogc/1.0/processes",
            "application/json",
        )
        .titled("Processes"),
        Link::new(
            "/jobs",
            "http://www.opengis.net/def/rel/ogc/1.0/job-list",
            "application/json",
        )
        .titled("Jobs"),
        Link::new("/sweeps", "https://chocmodal.dev/rel/sweeps", "application/json")
            .titled("Sweeps: many runs of a process with aggregated results"),
        Link::new(
            "/signals",
            "https://chocmodal.dev/rel/signals",
            "application/json",
        )
        .titled("Signals: accelerograms stored once, referenced by jobs and sweeps"),
        Link::new("/healthz", "status", "application/json").titled("Liveness"),
        Link::new("/metrics", "monitor", "text/plain").titled("Prometheus metrics"),
    ]
}

/// Landing page
///
/// Links to everything else. JSON, or the dashboard's home page (HTML) when the client
/// prefers `text/html` to `application/json` (a browser) or asks `?f=html`.
#[utoipa::path(get, path = "/", operation_id = "getLandingPage", tag = "Capabilities",
    responses((status = 200, description = "Links to the API's resources",
        content((LandingPage = "application/json"), (String = "text/html")))))]
pub async fn landing() -> Response {
    let page = LandingPage {
        title: "chocmodal",
        description: "Modal multi-contact dynamics of slender beam bundles, as OGC API – Processes jobs",
        links: landing_links(),
    };
    Json(page).into_response()
}

/// Conformance classes
#[utoipa::path(get, path = "/conformance", operation_id = "getConformance", tag = "Capabilities",
    responses((status = 200, description = "The OGC conformance classes this service implements", body = Conformance)))]
pub async fn conformance() -> Json<Conformance> {
    Json(Conformance {
        conforms_to: OGC_CONFORMANCE.to_vec(),
    })
}

/// Liveness
///
/// 200 while the service answers and its database responds (`writable` says whether the
/// storage takes writes: a full disk does not make the service dead), 503 otherwise.
#[utoipa::path(get, path = "/healthz", operation_id = "getHealth", tag = "Operations",
    responses(
        (status = 200, description = "Alive", body = Health),
        (status = 503, description = "The database does not respond", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn healthz(State(state): State<AppState>) -> Response {
    match state.queue.database().ping().await {
        Ok(()) => {
            let fault = state
                .metrics
                .storage()
                .current()
                .map(|cannot| cannot.fault.cause());
            Json(Health {
                status: "ok",
                writable: fault.is_none(),
                storage_fault: fault,
            })
            .into_response()
        }
        Err(error) => {
            tracing::error!(%error, "health check: database unavailable");
            crate::problem::Problem::from_status(503, "Service Unavailable", "the database does not respond")
                .into_response()
        }
    }
}

/// Readiness
///
/// 200 `{"status": "ready"}` when the database takes a write: a probe write (one row,
/// in a transaction) commits, and no write was refused by the storage in the last 5 s. Otherwise 507 `storage-full` (full disk: `SQLITE_FULL`,
/// PostgreSQL `53100` `disk_full`, `ENOSPC`) or 503 `storage-unavailable` (I/O error,
/// or a database that does not answer), with `Retry-After`; reads keep working
/// meanwhile, and readiness comes back on its own once space is freed.
#[utoipa::path(get, path = "/readyz", operation_id = "getReadiness", tag = "Operations",
    responses(
        (status = 200, description = "Ready: the database takes writes", body = Readiness),
        (status = 503, description = "The storage failed an I/O operation or the database does not respond (`storage-unavailable`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json",
            headers(("Retry-After" = u64, description = "Seconds to wait"))),
        (status = 507, description = "The disk is full (`storage-full`), naming the cause",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json",
            headers(("Retry-After" = u64, description = "Seconds to wait")))))]
pub async fn readyz(State(state): State<AppState>) -> Response {
    let storage = state.metrics.storage();
    let now = state.queue.clock().now_ms();
    match state.queue.database().probe_write(now).await {
        Ok(()) => match storage.current() {
            // The probe fits where a larger write did not (free pages, the WAL's
            // reused space): a recent refusal still counts.
            Some(cannot) => super::error::storage_fault_response(cannot.fault),
            None => Json(Readiness { status: "ready" }).into_response(),
        },
        Err(error) => match storage.check(&error, "probe") {
            Some(fault) => super::error::storage_fault_response(fault),
            None => {
                tracing::error!(%error, "readiness: the database does not take a write");
                let mut response = crate::problem::Problem::from_status(
                    503,
                    "Service Unavailable",
                    "the database does not take a write (see the service's log)",
                )
                .into_response();
                response.headers_mut().insert(
                    header::RETRY_AFTER,
                    HeaderValue::from(super::error::STORAGE_RETRY_SECONDS),
                );
                response
            }
        },
    }
}

/// Prometheus metrics
///
/// Text exposition format: `chocmodal_jobs{status}` (gauge), `chocmodal_job_duration_seconds`
/// and `chocmodal_job_queue_wait_seconds` (histograms, s), `chocmodal_job_verdicts_total{process,verdict}`
/// (jobs computed to success by quality verdict), `chocmodal_jobs_rescued_total`,
/// `chocmodal_jobs_abandoned_total`, `chocmodal_http_requests_total{method,route,status}`,
/// `chocmodal_http_request_duration_seconds` (s), `chocmodal_failed_writes_total{cause,during}`
/// (writes the storage refused).
#[utoipa::path(get, path = "/metrics", operation_id = "getMetrics", tag = "Operations",
    responses((status = 200, description = "Prometheus text format", body = String,
        content_type = "text/plain; version=0.0.4")))]
pub async fn metrics(State(state): State<AppState>) -> Result<Response, ApiError> {
    let counts = state.queue.count_by_status().await?;
    let text = state.metrics.render(&counts);
    Ok((
        StatusCode::OK,
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static("text/plain; version=0.0.4; charset=utf-8"),
        )],
        text,
    )
        .into_response())
}

/// The API definition (OpenAPI)
#[utoipa::path(get, path = "/openapi.json", operation_id = "getOpenApi", tag = "Capabilities",
    responses((status = 200, description = "This API's OpenAPI document", body = Object,
        content_type = "application/vnd.oai.openapi+json;version=3.1")))]
pub async fn openapi_document(State(state): State<AppState>) -> Response {
    (
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/vnd.oai.openapi+json;version=3.1"),
        )],
        openapi::json_for(&state.registry),
    )
        .into_response()
}
