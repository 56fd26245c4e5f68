//! Capabilities and operations: landing page, conformance, health, metrics, OpenAPI.

use axum::Json;
use axum::extract::State;
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::error::ApiError;
use super::models::{Conformance, Health, LandingPage, Link};
use super::openapi;

const OGC_CONFORMANCE: &[&str] = &[
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/core",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/ogc-process-description",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/json",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/html",
    "http://www.opengis.net/spec/ogcapi-processes-1/1.0/conf/oas30",
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
/// 200 while the service answers and its database responds, 503 otherwise.
#[utoipa::path(get, path = "/healthz", operation_id = "getHealth", tag = "Operations",
    responses(
        (status = 200, description = "Alive", body = Health),
        (status = 503, description = "The database does not respond", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn healthz(State(state): State<AppState>) -> Response {
    match state.queue.database().ping().await {
        Ok(()) => Json(Health { status: "ok" }).into_response(),
        Err(error) => {
            tracing::error!(%error, "health check: database unavailable");
            crate::problem::Problem::from_status(503, "Service Unavailable", "the database does not respond")
                .into_response()
        }
    }
}

/// Prometheus metrics
///
/// Text exposition format: `chocmodal_jobs{status}` (gauge), `chocmodal_job_duration_seconds`
/// and `chocmodal_job_queue_wait_seconds` (histograms, s), `chocmodal_jobs_rescued_total`,
/// `chocmodal_jobs_abandoned_total`, `chocmodal_http_requests_total{method,route,status}`,
/// `chocmodal_http_request_duration_seconds` (s).
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
