//! The dashboard: HTML pages for people, on the same addresses as the JSON API.
//!
//! A browser asking for `/`, `/jobs`, `/jobs/{jobId}`, `/sweeps`, `/sweeps/{sweepId}`,
//! `/signals` or `/signals/{signalId}` gets a small HTML page ([`super::negotiation`]
//! decides);
//! every other client gets the JSON exactly as before. The page's scripts then read the
//! JSON API like any client and draw the plots in the browser (line plots with the
//! vendored uPlot, maps, histograms and bars as SVG). `/ui/submit` is the submit form, `/ui/assets/{file}`
//! the scripts and style sheet, `/ui/examples.json` the shipped examples: all embedded in
//! the binary ([`assets`]), nothing fetched from elsewhere.

pub mod assets;

use axum::Router;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;

use super::AppState;
use crate::problem::Problem;

/// A page of the dashboard: the `data-page` its scripts dispatch on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Page {
    Home,
    Jobs,
    Job,
    Sweeps,
    Sweep,
    Signals,
    Signal,
    Submit,
}

impl Page {
    /// The page shown for an API route template, if that route has one.
    pub fn for_route(route: &str) -> Option<Self> {
        match route {
            "/" => Some(Self::Home),
            "/jobs" => Some(Self::Jobs),
            "/jobs/{jobId}" => Some(Self::Job),
            "/sweeps" => Some(Self::Sweeps),
            "/sweeps/{sweepId}" => Some(Self::Sweep),
            "/signals" => Some(Self::Signals),
            "/signals/{signalId}" => Some(Self::Signal),
            _ => None,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Home => "home",
            Self::Jobs => "jobs",
            Self::Job => "job",
            Self::Sweeps => "sweeps",
            Self::Sweep => "sweep",
            Self::Signals => "signals",
            Self::Signal => "signal",
            Self::Submit => "submit",
        }
    }

    fn title(self) -> &'static str {
        match self {
            Self::Home => "chocmodal",
            Self::Jobs => "Jobs · chocmodal",
            Self::Job => "Job · chocmodal",
            Self::Sweeps => "Sweeps · chocmodal",
            Self::Sweep => "Sweep · chocmodal",
            Self::Signals => "Signals · chocmodal",
            Self::Signal => "Signal · chocmodal",
            Self::Submit => "Submit · chocmodal",
        }
    }
}

/// The HTML page of `page`: a shell that loads the dashboard's scripts, which fill it
/// from the JSON API. Nothing of the request is echoed into it.
pub fn shell(page: Page) -> String {
    format!(
        r#"<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<link rel="stylesheet" href="/ui/assets/uPlot.min.css">
<link rel="stylesheet" href="/ui/assets/style.css">
<script type="module" src="/ui/assets/app.js"></script>
</head>
<body data-page="{page}">
<header class="top">
<a class="brand" href="/">chocmodal</a>
<nav>
<a href="/jobs" data-nav="jobs">Jobs</a>
<a href="/sweeps" data-nav="sweeps">Sweeps</a>
<a href="/signals" data-nav="signals">Signals</a>
<a href="/ui/submit" data-nav="submit">Submit</a>
<a href="/openapi.json">API</a>
</nav>
</header>
<main id="main">
<noscript><p>The dashboard draws its pages with JavaScript. The same addresses serve JSON
to any client that does not ask for HTML (see <a href="/openapi.json">the API</a>).</p></noscript>
</main>
<footer class="bottom">JSON API: <a href="/processes">processes</a> · <a href="/jobs?f=json">jobs</a> ·
<a href="/sweeps?f=json">sweeps</a> · <a href="/signals?f=json">signals</a> · <a href="/conformance">conformance</a> · <a href="/openapi.json">OpenAPI</a> ·
<a href="/healthz">health</a> · <a href="/metrics">metrics</a></footer>
</body>
</html>
"#,
        title = page.title(),
        page = page.name(),
    )
}

/// The page `page` with `status` (and `Cache-Control: no-cache`).
pub fn html_page(page: Page, status: StatusCode) -> Response {
    let mut response = (status, Html(shell(page))).into_response();
    response
        .headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    response
}

/// The dashboard's own routes, under `/ui`.
pub fn routes() -> Router<AppState> {
    Router::new()
        .route("/ui/submit", get(submit_page))
        .route("/ui/examples.json", get(examples))
        .route("/ui/assets/{file}", get(asset))
}

async fn submit_page() -> Response {
    html_page(Page::Submit, StatusCode::OK)
}

async fn examples(State(state): State<AppState>, headers: HeaderMap) -> Response {
    super::conditional::tagged(
        &headers,
        "application/json",
        assets::examples_json(&state.registry).into_bytes(),
        HeaderMap::new(),
    )
}

async fn asset(Path(file): Path<String>, headers: HeaderMap) -> Response {
    match assets::find(&file) {
        Some(asset) => {
            // `no-cache` with an `ETag`: revalidated on each load, a cheap 304 until the binary changes.
            super::conditional::tagged(
                &headers,
                asset.content_type,
                asset.bytes.to_vec(),
                HeaderMap::new(),
            )
        }
        None => Problem::from_status(404, "Not Found", format!("the dashboard has no asset `{file}`"))
            .into_response(),
    }
}
