//! The HTTP API (OGC API – Processes): routes, shared state, and the layers every
//! request goes through (tracing, metrics, CORS when configured, authentication, body
//! limit, timeout, panic catching, and the rewrite of any bare error response into a
//! problem document).

pub mod auth;
pub mod conditional;
pub mod contacts;
pub mod cors;
pub mod dashboard;
pub mod error;
pub mod extract;
mod history_view;
pub mod idempotency;
pub mod impacts;
pub mod job_inputs;
pub mod jobs;
pub mod landing;
pub mod models;
pub mod negotiation;
pub mod openapi;
pub mod processes;
pub mod report;
pub mod response_spectra;
pub mod results;
pub mod signal_models;
pub mod signals;
pub mod spectra;
pub mod streamed;
pub mod sweep_models;
pub mod sweep_statistics;
pub mod sweeps;

use std::sync::Arc;
use std::time::{Duration, Instant};

use axum::Router;
use axum::extract::{DefaultBodyLimit, MatchedPath, Request, State};
use axum::handler::Handler;
use axum::http::{StatusCode, Uri, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use tokio::sync::Notify;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::CompressionLayer;
use tower_http::timeout::TimeoutLayer;
use tower_http::trace::{DefaultMakeSpan, DefaultOnResponse, TraceLayer};
use tracing::Level;

use super::auth::TokenTable;
use super::callbacks::CallbackPolicy;
use super::db::fault::StorageFault;
use super::metrics::Metrics;
use super::queue::JobQueue;
use super::shutdown::ShutdownHandle;
use super::signals::SignalStore;
use super::worker::RunningJobs;
use crate::problem::Problem;
use crate::processes::{CostLimits, Registry};
use auth::AuthPolicy;
use error::{PROBLEM_JSON, problem_response};

/// What every handler can reach.
#[derive(Debug, Clone)]
pub struct AppState {
    pub queue: JobQueue,
    /// The process's shutdown: writes are refused once it is stopping.
    pub shutdown: ShutdownHandle,
    pub registry: Registry,
    /// Jobs running in this instance (to cancel them at once on dismissal).
    pub running: RunningJobs,
    pub metrics: Metrics,
    /// Wakes an idle worker when a job is queued.
    pub wake: Arc<Notify>,
    /// Most runs one sweep may expand into.
    pub max_sweep_runs: usize,
    /// Ceilings on the estimated cost of one run (every run of a sweep too).
    pub limits: CostLimits,
    /// Most queued jobs per tenant (sweep runs included); `None`: no limit.
    pub max_queued_jobs: Option<u64>,
    /// Most rows of one history response.
    pub max_history_points: usize,
    /// The working memory the history responses being made may use together.
    pub response_memory: streamed::ResponseMemory,
    /// Stored signals (accelerograms) of every tenant.
    pub signals: SignalStore,
    /// Largest body of `POST /signals` (bytes; the general limit does not apply there).
    pub max_signal_bytes: usize,
    /// Most samples of one stored signal.
    pub max_signal_samples: usize,
    /// What a job's `subscriber` is checked against (allowed hosts, tenants' secrets).
    pub callbacks: Arc<CallbackPolicy>,
}

/// Settings of the layers around the routes.
#[derive(Debug, Clone)]
pub struct HttpSettings {
    /// Largest request body (413 above).
    pub max_body_bytes: usize,
    /// Longest time a request may take, body included (408 after that).
    pub request_timeout: Duration,
    /// Tenants' tokens; `None`: no authentication.
    pub auth: Option<TokenTable>,
    /// `/metrics` answers without a token.
    pub metrics_public: bool,
    /// Web origins allowed to call the API from a browser; empty: no CORS.
    pub cors_origins: Vec<cors::CorsOrigin>,
}

/// The application's router with all its layers.
pub fn router(state: AppState, settings: &HttpSettings) -> Router {
    let policy = Arc::new(AuthPolicy {
        tokens: settings.auth.clone(),
        metrics_public: settings.metrics_public,
    });
    let routes = Router::new()
        .route("/", get(landing::landing))
        .route("/conformance", get(landing::conformance))
        .route("/healthz", get(landing::healthz))
        .route("/readyz", get(landing::readyz))
        .route("/metrics", get(landing::metrics))
        .route("/openapi.json", get(landing::openapi_document))
        .route("/processes", get(processes::list))
        .route("/processes/{processId}", get(processes::describe))
        .route("/processes/{processId}/execution", post(processes::execute))
        .route("/jobs", get(jobs::list))
        .route("/jobs/{jobId}", get(jobs::status).delete(jobs::dismiss))
        .route("/jobs/{jobId}/results", get(results::results))
        .route("/jobs/{jobId}/inputs", get(job_inputs::inputs))
        .route("/jobs/{jobId}/report", get(report::report))
        .route("/jobs/{jobId}/results/impacts", get(impacts::impacts))
        .route("/jobs/{jobId}/results/contacts", get(contacts::contacts))
        .route("/jobs/{jobId}/results/pins", get(contacts::pins))
        .route("/jobs/{jobId}/results/resultants", get(contacts::resultants))
        .route("/jobs/{jobId}/results/{output}", get(results::output))
        .route("/jobs/{jobId}/results/{output}/spectrum", get(spectra::spectrum))
        .route(
            "/jobs/{jobId}/results/{output}/response_spectrum",
            get(response_spectra::response_spectrum),
        )
        .route("/sweeps", get(sweeps::list).post(sweeps::create))
        .route("/sweeps/runs-needed", get(sweep_statistics::runs_needed))
        // A record is far larger than an execution request: this route has its own
        // body limit (the innermost limit is the one that applies).
        .route(
            "/signals",
            get(signals::list).post(signals::create.layer(DefaultBodyLimit::max(state.max_signal_bytes))),
        )
        .route(
            "/signals/{signalId}",
            get(signals::metadata).delete(signals::delete),
        )
        .route("/signals/{signalId}/samples", get(signals::samples))
        .route("/signals/{signalId}/spectrum", get(signals::spectrum))
        .route("/sweeps/{sweepId}", get(sweeps::status).delete(sweeps::dismiss))
        .route("/sweeps/{sweepId}/results", get(sweeps::results))
        .route("/sweeps/{sweepId}/statistics", get(sweep_statistics::statistics))
        .route(
            "/sweeps/{sweepId}/statistics/contacts",
            get(sweep_statistics::contacts),
        )
        .route("/sweeps/{sweepId}/statistics/pins", get(sweep_statistics::pins))
        .route(
            "/sweeps/{sweepId}/statistics/convergence",
            get(sweep_statistics::convergence),
        )
        .merge(dashboard::routes())
        .fallback(not_found)
        // The representation of every GET (innermost: it sees the route): the `format`
        // parameter or `Accept`, and HTML for browsers on the routes that have a page.
        .layer(middleware::from_fn(negotiation::layer))
        .layer(middleware::from_fn_with_state(
            state.clone(),
            refuse_writes_while_stopping,
        ))
        // Layers run outside-in from the last one added: trace and count every request,
        // turn any bare error below (timeout, panic, 405, 413) into a problem, and
        // authenticate before anything reads the body.
        .layer(DefaultBodyLimit::max(settings.max_body_bytes))
        .layer(middleware::from_fn_with_state(policy, auth::authenticate))
        .layer(CatchPanicLayer::custom(|_panic| {
            tracing::error!("a request handler panicked");
            problem_response(&Problem::internal())
        }))
        .layer(TimeoutLayer::with_status_code(
            StatusCode::REQUEST_TIMEOUT,
            settings.request_timeout,
        ))
        .layer(middleware::map_response(problem_for_bare_errors));
    // CORS outside authentication (a preflight carries no token) and outside the error
    // rewriting (a script must be able to read a 401 or 413 too).
    let routes = match cors::layer(&settings.cors_origins) {
        Some(cors) => routes.layer(cors),
        None => routes,
    };
    routes
        // Compression inside the tag weakening (a response goes outward through both).
        .layer(compression())
        .layer(middleware::map_response(weaken_tags_of_encoded_bodies))
        .layer(middleware::from_fn_with_state(state.clone(), track_request))
        .layer(
            TraceLayer::new_for_http()
                .make_span_with(DefaultMakeSpan::new().level(Level::INFO))
                .on_response(DefaultOnResponse::new().level(Level::INFO)),
        )
        .with_state(state)
}

/// gzip or zstd bodies for clients that accept them (`Accept-Encoding`, q-values
/// honoured; zstd preferred on a tie), streamed bodies included (each chunk compressed
/// as it is written). tower-http's default predicate leaves alone bodies under 32 bytes,
/// images, gRPC and server-sent events.
fn compression() -> CompressionLayer {
    CompressionLayer::new().no_br().no_deflate()
}

/// An `ETag` names the bytes of one representation (RFC 9110 §8.8.3): a compressed body
/// is other bytes, so its tag becomes weak (`W/"..."`). `If-None-Match` compares tags
/// weakly ([`conditional::if_none_match`]), so revalidation still answers 304.
async fn weaken_tags_of_encoded_bodies(mut response: Response) -> Response {
    if !response.headers().contains_key(header::CONTENT_ENCODING) {
        return response;
    }
    let weak = response
        .headers()
        .get(header::ETAG)
        .and_then(|tag| tag.to_str().ok())
        .filter(|tag| !tag.starts_with("W/"))
        .and_then(|tag| header::HeaderValue::from_str(&format!("W/{tag}")).ok());
    if let Some(weak) = weak {
        response.headers_mut().insert(header::ETAG, weak);
    }
    response
}

/// The worker role's optional port: liveness and metrics only.
pub fn health_router(state: AppState) -> Router {
    Router::new()
        .route("/healthz", get(landing::healthz))
        .route("/readyz", get(landing::readyz))
        .route("/metrics", get(landing::metrics))
        .fallback(not_found)
        .layer(compression())
        .with_state(state)
}

/// Unknown routes: 404 problem.
async fn not_found(uri: Uri) -> Response {
    Problem::from_status(
        404,
        "Not Found",
        format!("there is no resource at `{}`", uri.path()),
    )
    .into_response()
}

/// Turns error responses produced outside the handlers (405 from the method router,
/// 413 from the body limit, 408 from the timeout, ...) into problem documents, keeping
/// their status and headers (`Allow` on 405).
async fn problem_for_bare_errors(response: Response) -> Response {
    let status = response.status();
    let is_problem = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(PROBLEM_JSON.as_bytes()));
    // The dashboard's pages carry the status of the resource they show (a 404 page).
    let is_page = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"text/html"));
    if !(status.is_client_error() || status.is_server_error()) || is_problem || is_page {
        return response;
    }
    let title = status.canonical_reason().unwrap_or("Error");
    let detail = match status {
        StatusCode::METHOD_NOT_ALLOWED => {
            "this resource does not support this method; see `Allow`".to_owned()
        }
        StatusCode::PAYLOAD_TOO_LARGE => "the request body is larger than this server accepts".to_owned(),
        StatusCode::REQUEST_TIMEOUT => "the request took too long".to_owned(),
        _ => title.to_lowercase(),
    };
    let problem = if status == StatusCode::PAYLOAD_TOO_LARGE {
        Problem::payload_too_large(detail)
    } else if status.is_server_error() {
        Problem::internal()
    } else {
        Problem::from_status(status.as_u16(), title, detail)
    };
    let (mut parts, _) = response.into_parts();
    let rendered = problem_response(&problem);
    parts.headers.remove(header::CONTENT_LENGTH);
    parts.headers.insert(
        header::CONTENT_TYPE,
        header::HeaderValue::from_static(PROBLEM_JSON),
    );
    Response::from_parts(parts, rendered.into_body())
}

/// Seconds a client refused by a stopping process is asked to wait (`Retry-After`):
/// about the time a restart or a load balancer takes to send it elsewhere.
pub const SHUTTING_DOWN_RETRY_SECONDS: u64 = 5;

/// Once the process is stopping, requests that would change something (any method but
/// GET, HEAD and OPTIONS) get 503 with `Retry-After`; reads are served until the
/// workers are done.
async fn refuse_writes_while_stopping(
    State(state): State<AppState>,
    request: Request,
    next: Next,
) -> Response {
    let safe = request.method().is_safe();
    if !safe && state.shutdown.is_stopping() {
        return error::ApiError::RetryLater {
            problem: Box::new(Problem::shutting_down()),
            retry_after: SHUTTING_DOWN_RETRY_SECONDS,
        }
        .into_response();
    }
    next.run(request).await
}

/// Counts and times every request by method, route template and status.
async fn track_request(State(state): State<AppState>, request: Request, next: Next) -> Response {
    let method = request.method().to_string();
    let route = request
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| "unmatched".to_owned(), |p| p.as_str().to_owned());
    let started = Instant::now();
    let response = next.run(request).await;
    state
        .metrics
        .observe_request(&method, &route, response.status().as_u16(), started.elapsed());
    // A refused write says why (`error::storage_fault_response`); `/readyz` reports its
    // own probe.
    if let Some(fault) = response.extensions().get::<StorageFault>()
        && route != "/readyz"
    {
        state.metrics.storage().failed(*fault, "request");
    }
    response
}
