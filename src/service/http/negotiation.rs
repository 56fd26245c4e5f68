//! Content negotiation for the whole API: which representation of a resource a request
//! gets, decided in one place for every route ([`layer`]).
//!
//! Each route template offers a list of [`Format`]s ([`offers`]), its default first.
//! A GET or HEAD request is answered in:
//! - the `format` query parameter (or its OGC alias `f`) when given: `json`, `csv`,
//!   `html`, as the route offers; anything else is a 400 `invalid-query` naming the
//!   formats the route has;
//! - otherwise the offer `Accept` prefers (RFC 9110 §12.5.1): each offer takes the
//!   quality of the most specific media range that matches it (`text/csv`, then
//!   `text/*`, then `*/*`); the highest quality above zero wins, a tie goes to the range
//!   listed first, then to the route's default. HTML is given only to a request that
//!   names `text/html` (or `application/xhtml+xml`) itself: a wildcard never turns a
//!   JSON client into a page reader (on a route whose only format is HTML, the
//!   calculation note, a wildcard selects it). No `Accept` (or an empty one) is the default; an
//!   `Accept` that excludes every offer is a 406 `not-acceptable` naming them.
//!
//! The choice travels to the handler as a [`Format`] in the request's extensions (an
//! extractor); a route that offers more than one says `Vary: Accept`. The HTML of a
//! dashboard page is drawn by [`super::dashboard`] around the JSON answer.

use axum::extract::{FromRequestParts, MatchedPath, Request};
use axum::http::request::Parts;
use axum::http::{HeaderMap, HeaderValue, Method, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use super::dashboard::{self, Page};
use super::error::ApiError;
use crate::problem::Problem;

/// A representation the API serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Json,
    Csv,
    /// A dashboard page.
    Html,
    /// Prometheus' text exposition format (`/metrics`).
    Prometheus,
}

impl Format {
    /// The name of the `format` query parameter's value.
    pub fn token(self) -> &'static str {
        match self {
            Format::Json => "json",
            Format::Csv => "csv",
            Format::Html => "html",
            Format::Prometheus => "prometheus",
        }
    }

    /// The `Content-Type` of a response in this format.
    pub fn content_type(self) -> &'static str {
        match self {
            Format::Json => "application/json",
            Format::Csv => "text/csv; charset=utf-8",
            Format::Html => "text/html; charset=utf-8",
            Format::Prometheus => "text/plain; version=0.0.4",
        }
    }

    /// The media types `Accept` may name for this format.
    fn media_types(self) -> &'static [(&'static str, &'static str)] {
        match self {
            Format::Json => &[("application", "json")],
            Format::Csv => &[("text", "csv")],
            Format::Html => &[("text", "html"), ("application", "xhtml+xml")],
            Format::Prometheus => &[("text", "plain")],
        }
    }

    /// Whether a wildcard range (`text/*`, `*/*`) may select this format.
    fn wildcards_select(self) -> bool {
        self != Format::Html
    }
}

const JSON: &[Format] = &[Format::Json];
const JSON_OR_HTML: &[Format] = &[Format::Json, Format::Html];
const JSON_OR_CSV: &[Format] = &[Format::Json, Format::Csv];
const PROMETHEUS: &[Format] = &[Format::Prometheus];
const HTML: &[Format] = &[Format::Html];

/// The formats a route template offers, its default first; `None` for the dashboard's
/// own files (scripts, style, the submit form), served as they are.
pub fn offers(route: &str) -> Option<&'static [Format]> {
    if Page::for_route(route).is_some() {
        return Some(JSON_OR_HTML);
    }
    match route {
        "/jobs/{jobId}/results/{output}"
        | "/jobs/{jobId}/results/impacts"
        | "/jobs/{jobId}/results/contacts"
        | "/jobs/{jobId}/results/pins"
        | "/jobs/{jobId}/results/resultants"
        | "/jobs/{jobId}/results/{output}/spectrum"
        | "/jobs/{jobId}/results/{output}/response_spectrum"
        | "/sweeps/{sweepId}/results"
        | "/sweeps/{sweepId}/statistics"
        | "/sweeps/{sweepId}/statistics/contacts"
        | "/sweeps/{sweepId}/statistics/pins"
        | "/sweeps/{sweepId}/statistics/convergence"
        | "/signals/{signalId}/samples"
        | "/signals/{signalId}/spectrum" => Some(JSON_OR_CSV),
        "/metrics" => Some(PROMETHEUS),
        "/jobs/{jobId}/report" => Some(HTML),
        route if route.starts_with("/ui/") => None,
        _ => Some(JSON),
    }
}

/// Why no representation could be chosen.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refusal {
    /// The `format` parameter names a format the route does not offer (400 `invalid-query`).
    UnsupportedFormat {
        asked: String,
        offered: &'static [Format],
    },
    /// `Accept` excludes every format the route offers (406).
    NotAcceptable { offered: &'static [Format] },
    /// `format` and `f` disagree (400).
    Conflicting,
}

impl Refusal {
    pub fn problem(&self) -> Problem {
        let list = |offered: &[Format]| {
            offered
                .iter()
                .map(|f| format!("`{}` ({})", f.token(), f.content_type()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        match self {
            Refusal::UnsupportedFormat { asked, offered } => Problem::invalid_query(format!(
                "this resource is not served as `{asked}`; its formats: {}",
                list(offered)
            )),
            Refusal::NotAcceptable { offered } => Problem::not_acceptable(format!(
                "`Accept` excludes every format of this resource: {}",
                list(offered)
            )),
            Refusal::Conflicting => {
                Problem::invalid_query("`format` and `f` name different formats: give one")
            }
        }
    }
}

/// One media range of an `Accept` header.
#[derive(Debug, Clone, Copy, PartialEq)]
struct MediaRange<'a> {
    kind: &'a str,
    subtype: &'a str,
    quality: f64,
    position: usize,
}

fn parse_accept(accept: &str) -> Vec<MediaRange<'_>> {
    accept
        .split(',')
        .enumerate()
        .filter_map(|(position, item)| {
            let mut parts = item.split(';');
            let (kind, subtype) = parts.next()?.trim().split_once('/')?;
            // A malformed quality counts as 1 (the default); one out of range is ignored.
            let quality = parts
                .filter_map(|p| {
                    let (name, value) = p.split_once('=')?;
                    name.trim().eq_ignore_ascii_case("q").then(|| value.trim())
                })
                .find_map(|q| q.parse::<f64>().ok())
                .filter(|q| (0.0..=1.0).contains(q))
                .unwrap_or(1.0);
            Some(MediaRange {
                kind: kind.trim(),
                subtype: subtype.trim(),
                quality,
                position,
            })
        })
        .collect()
}

/// Quality and position of the most specific range of `ranges` matching `format`;
/// wildcard ranges count only when `wildcards`.
fn preference(ranges: &[MediaRange<'_>], format: Format, wildcards: bool) -> Option<(f64, usize)> {
    ranges
        .iter()
        .filter_map(|r| {
            let specificity = format
                .media_types()
                .iter()
                .filter_map(|(kind, subtype)| match (r.kind, r.subtype) {
                    (k, s) if k.eq_ignore_ascii_case(kind) && s.eq_ignore_ascii_case(subtype) => Some(3),
                    (k, "*") if k.eq_ignore_ascii_case(kind) && wildcards => Some(2),
                    ("*", "*") if wildcards => Some(1),
                    _ => None,
                })
                .max()?;
            Some((specificity, r))
        })
        // The most specific; among equally specific ones (HTML's two types), the best.
        .max_by(|(sa, a), (sb, b)| {
            sa.cmp(sb)
                .then(a.quality.total_cmp(&b.quality))
                .then(b.position.cmp(&a.position))
        })
        .map(|(_, r)| (r.quality, r.position))
}

/// The offer an `Accept` header value prefers (see the module documentation); `None`
/// when it excludes them all. `offered` is not empty; its first is the default.
pub fn preferred(accept: Option<&str>, offered: &[Format]) -> Option<Format> {
    let accept = accept.map(str::trim).filter(|a| !a.is_empty());
    let Some(accept) = accept else {
        return offered.first().copied();
    };
    let ranges = parse_accept(accept);
    // A route whose only format is HTML (the calculation note) is what any client asks
    // for with a wildcard: there is no JSON to keep it from.
    let alone = offered.len() == 1;
    offered
        .iter()
        .enumerate()
        .filter_map(|(order, &format)| {
            let (quality, position) = preference(&ranges, format, alone || format.wildcards_select())?;
            (quality > 0.0).then_some((quality, position, order, format))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)).then(b.2.cmp(&a.2)))
        .map(|(_, _, _, format)| format)
}

/// The `format` (or `f`) parameter of a query string, if given.
fn format_parameter(query: Option<&str>) -> Result<Option<String>, Refusal> {
    let mut asked: Option<String> = None;
    for pair in query.into_iter().flat_map(|q| q.split('&')) {
        let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
        if key == "format" || key == "f" {
            let value = percent_decoded(value);
            match &asked {
                Some(previous) if *previous != value => return Err(Refusal::Conflicting),
                _ => asked = Some(value),
            }
        }
    }
    Ok(asked)
}

/// `text` with `+` and `%XX` decoded (a format name is ASCII; anything else is kept
/// as is, to be named in the refusal).
fn percent_decoded(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < bytes.len() => match (hex_digit(bytes[i + 1]), hex_digit(bytes[i + 2])) {
                (Some(high), Some(low)) => {
                    out.push(high * 16 + low);
                    i += 2;
                }
                _ => out.push(b'%'),
            },
            byte => out.push(byte),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn hex_digit(byte: u8) -> Option<u8> {
    (byte as char).to_digit(16).map(|d| d as u8)
}

/// The format a request to `route` gets, or why it gets none (see the module documentation).
pub fn choose(
    offered: &'static [Format],
    headers: &HeaderMap,
    query: Option<&str>,
) -> Result<Format, Refusal> {
    if let Some(asked) = format_parameter(query)? {
        return offered
            .iter()
            .copied()
            .find(|f| f.token().eq_ignore_ascii_case(&asked))
            .ok_or(Refusal::UnsupportedFormat { asked, offered });
    }
    let accept = headers.get(header::ACCEPT).and_then(|v| v.to_str().ok());
    preferred(accept, offered).ok_or(Refusal::NotAcceptable { offered })
}

/// Whether a request asks for the HTML page of its route (for the 401 of a page).
pub fn wants_page(request: &Request) -> Option<Page> {
    if !matches!(*request.method(), Method::GET | Method::HEAD) {
        return None;
    }
    let route = request.extensions().get::<MatchedPath>()?.as_str();
    let page = Page::for_route(route)?;
    let offered = offers(route)?;
    (choose(offered, request.headers(), request.uri().query()) == Ok(Format::Html)).then_some(page)
}

/// Middleware on every route: chooses the representation, refuses a request that can
/// have none, hands the choice to the handler and draws a dashboard page around the
/// JSON answer when the choice is HTML.
pub async fn layer(mut request: Request, next: Next) -> Response {
    if !matches!(*request.method(), Method::GET | Method::HEAD) {
        return next.run(request).await;
    }
    let route = request
        .extensions()
        .get::<MatchedPath>()
        .map(|r| r.as_str().to_owned());
    let Some(offered) = route.as_deref().and_then(offers) else {
        return next.run(request).await;
    };
    let format = match choose(offered, request.headers(), request.uri().query()) {
        Ok(format) => format,
        Err(refusal) => return refusal.problem().into_response(),
    };
    let page = route
        .as_deref()
        .and_then(Page::for_route)
        .filter(|_| format == Format::Html);
    if page.is_some() {
        // The page has the status of the JSON answer (an unknown job is a 404 page).
        let headers = request.headers_mut();
        headers.insert(header::ACCEPT, HeaderValue::from_static("application/json"));
        headers.remove(header::IF_NONE_MATCH);
        request.extensions_mut().insert(Format::Json);
    } else {
        request.extensions_mut().insert(format);
    }
    let response = next.run(request).await;
    let mut response = match page {
        Some(page) => dashboard::html_page(page, response.status()),
        None => response,
    };
    let varies = response.headers().get_all(header::VARY).iter().any(|v| {
        v.to_str()
            .is_ok_and(|v| v.to_ascii_lowercase().contains("accept"))
    });
    if offered.len() > 1 && !varies {
        response
            .headers_mut()
            .append(header::VARY, HeaderValue::from_static("accept"));
    }
    response
}

impl<S: Send + Sync> FromRequestParts<S> for Format {
    type Rejection = ApiError;

    /// The format [`layer`] chose.
    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, Self::Rejection> {
        parts
            .extensions
            .get::<Format>()
            .copied()
            .ok_or_else(|| ApiError::Internal("no format was negotiated for this route".into()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHROMIUM: &str = "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,\
                            image/apng,*/*;q=0.8,application/signed-exchange;v=b3;q=0.7";
    const FIREFOX: &str = "text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8";

    fn page(accept: &str) -> Format {
        preferred(Some(accept), JSON_OR_HTML).unwrap_or(Format::Json)
    }

    fn table(accept: &str) -> Option<Format> {
        preferred(Some(accept), JSON_OR_CSV)
    }

    #[test]
    fn browsers_get_html() {
        for accept in [CHROMIUM, FIREFOX, "text/html"] {
            assert_eq!(page(accept), Format::Html, "{accept}");
        }
    }

    #[test]
    fn json_clients_and_wildcards_get_json() {
        for accept in [
            "",
            "*/*",
            "application/json",
            "application/json, text/plain, */*",
            "text/*",
            "application/json, text/html",
            "text/html;q=0.5, application/json",
            "text/html;q=0, */*",
            "application/*, text/html;q=0.9",
        ] {
            assert_eq!(page(accept), Format::Json, "{accept:?} should get JSON");
        }
    }

    #[test]
    fn quality_then_order_decides_between_html_and_json() {
        for accept in [
            "text/html, application/json",
            "application/json;q=0.5, text/html",
            "text/html, */*",
            "TEXT/HTML; charset=utf-8, application/json; Q=0.9",
        ] {
            assert_eq!(page(accept), Format::Html, "{accept}");
        }
    }

    #[test]
    fn quality_values_decide_between_csv_and_json() {
        let cases = [
            ("text/csv;q=0.1, application/json", Format::Json),
            ("text/csv, application/json;q=0.5", Format::Csv),
            ("text/csv;q=0.9, */*;q=0.1", Format::Csv),
            ("application/json;q=0.2, text/csv;q=0.3", Format::Csv),
            ("text/csv", Format::Csv),
            ("text/csv, application/json", Format::Csv),
            ("application/json, text/csv", Format::Json),
            ("*/*", Format::Json),
            ("text/csv;q=0, */*", Format::Json),
            ("text/*;q=0.5, application/json;q=0.4", Format::Csv),
            ("application/json;q=0, text/*", Format::Csv),
        ];
        for (accept, expected) in cases {
            assert_eq!(table(accept), Some(expected), "Accept: {accept}");
        }
    }

    #[test]
    fn an_accept_that_excludes_every_offer_has_no_choice_but_no_accept_has_the_default() {
        assert_eq!(table("application/xml"), None);
        assert_eq!(table("text/csv;q=0, application/json;q=0"), None);
        assert_eq!(preferred(Some("text/html"), JSON), None);
        assert_eq!(preferred(None, JSON_OR_CSV), Some(Format::Json));
        assert_eq!(preferred(Some("  "), JSON_OR_CSV), Some(Format::Json));
    }

    #[test]
    fn a_route_whose_only_format_is_html_serves_it_to_wildcards_but_not_to_json_clients() {
        for accept in [
            "*/*",
            "text/*",
            "text/html",
            "",
            "application/json;q=0.5, */*;q=0.1",
        ] {
            assert_eq!(preferred(Some(accept), HTML), Some(Format::Html), "{accept:?}");
        }
        assert_eq!(preferred(Some("application/json"), HTML), None);
        let refused = choose(HTML, &HeaderMap::new(), Some("format=json")).unwrap_err();
        assert!(
            refused.problem().detail.contains("`html`"),
            "{}",
            refused.problem().detail
        );
    }

    fn headers(accept: &str) -> HeaderMap {
        let mut headers = HeaderMap::new();
        headers.insert(header::ACCEPT, accept.parse().unwrap());
        headers
    }

    #[test]
    fn the_format_parameter_overrides_accept_and_names_what_the_route_has() {
        assert_eq!(
            choose(JSON_OR_HTML, &headers(CHROMIUM), Some("limit=5&f=json")),
            Ok(Format::Json)
        );
        assert_eq!(
            choose(JSON_OR_HTML, &HeaderMap::new(), Some("f=html")),
            Ok(Format::Html)
        );
        assert_eq!(
            choose(JSON_OR_CSV, &headers("application/json"), Some("format=csv")),
            Ok(Format::Csv)
        );
        assert_eq!(
            choose(JSON_OR_CSV, &HeaderMap::new(), Some("format=CSV")),
            Ok(Format::Csv)
        );
        assert_eq!(
            choose(JSON, &HeaderMap::new(), Some("status=running")),
            Ok(Format::Json)
        );
        let refused = choose(JSON_OR_CSV, &HeaderMap::new(), Some("format=xml")).unwrap_err();
        let problem = refused.problem();
        assert_eq!(problem.status, 400);
        assert!(
            problem.detail.contains("`json`") && problem.detail.contains("`csv`"),
            "{}",
            problem.detail
        );
        assert!(choose(JSON, &HeaderMap::new(), Some("format=csv")).is_err());
        assert_eq!(
            choose(JSON, &HeaderMap::new(), Some("f=json&format=csv")),
            Err(Refusal::Conflicting)
        );
        assert_eq!(
            choose(JSON_OR_CSV, &HeaderMap::new(), Some("format=c%73v")),
            Ok(Format::Csv)
        );
        let refused = choose(JSON_OR_CSV, &headers("application/xml"), None).unwrap_err();
        assert_eq!(refused.problem().status, 406);
    }

    #[test]
    fn every_route_with_a_page_offers_html_and_tables_offer_csv() {
        for route in [
            "/",
            "/jobs",
            "/jobs/{jobId}",
            "/sweeps",
            "/sweeps/{sweepId}",
            "/signals",
            "/signals/{signalId}",
        ] {
            assert_eq!(offers(route), Some(JSON_OR_HTML), "{route}");
        }
        assert_eq!(offers("/jobs/{jobId}/results/contacts"), Some(JSON_OR_CSV));
        for table in ["", "/contacts", "/pins", "/convergence"] {
            let route = format!("/sweeps/{{sweepId}}/statistics{table}");
            assert_eq!(offers(&route), Some(JSON_OR_CSV), "{route}");
        }
        assert_eq!(offers("/jobs/{jobId}/results"), Some(JSON));
        assert_eq!(offers("/jobs/{jobId}/report"), Some(HTML));
        assert_eq!(offers("/ui/assets/{file}"), None);
    }
}
