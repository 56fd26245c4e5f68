//! Which representation a request asks for: HTML for a browser, JSON for everyone else.
//!
//! The rule (documented in docs/service.md): `?f=html` or `?f=json` decides when given.
//! Otherwise HTML is served only when `Accept` names `text/html` (or
//! `application/xhtml+xml`) explicitly, with a quality above zero and above that of
//! `application/json` (taken from the most specific range matching it: `application/json`,
//! `application/*`, `*/*`), or equal to it and listed first. So a browser
//! (`text/html,...,*/*;q=0.8`) gets HTML, while `application/json`, `*/*`, no `Accept`,
//! and anything else get JSON, exactly as before the dashboard existed.

use axum::http::{HeaderMap, header};

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
            let quality = parts
                .filter_map(|p| p.trim().strip_prefix("q="))
                .find_map(|q| q.trim().parse::<f64>().ok())
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

/// Quality and position of the most specific range matching `kind/subtype`.
fn best_match(ranges: &[MediaRange<'_>], kind: &str, subtype: &str) -> Option<(f64, usize)> {
    ranges
        .iter()
        .filter_map(|r| {
            let specificity = match (r.kind, r.subtype) {
                (k, s) if k.eq_ignore_ascii_case(kind) && s.eq_ignore_ascii_case(subtype) => 3,
                (k, "*") if k.eq_ignore_ascii_case(kind) => 2,
                ("*", "*") => 1,
                _ => return None,
            };
            Some((specificity, r))
        })
        .max_by_key(|(specificity, _)| *specificity)
        .map(|(_, r)| (r.quality, r.position))
}

/// Whether an `Accept` header value prefers HTML (see the module documentation).
pub fn accept_prefers_html(accept: &str) -> bool {
    let ranges = parse_accept(accept);
    let html = ranges
        .iter()
        .filter(|r| {
            (r.kind.eq_ignore_ascii_case("text") && r.subtype.eq_ignore_ascii_case("html"))
                || (r.kind.eq_ignore_ascii_case("application") && r.subtype.eq_ignore_ascii_case("xhtml+xml"))
        })
        .map(|r| (r.quality, r.position))
        .max_by(|a, b| a.0.total_cmp(&b.0).then(b.1.cmp(&a.1)));
    let Some((html_quality, html_position)) = html else {
        return false;
    };
    if html_quality <= 0.0 {
        return false;
    }
    match best_match(&ranges, "application", "json") {
        None => true,
        Some((json_quality, json_position)) => {
            html_quality > json_quality || (html_quality == json_quality && html_position < json_position)
        }
    }
}

/// Whether a request (its headers and query string) should get the HTML page.
pub fn wants_html(headers: &HeaderMap, query: Option<&str>) -> bool {
    let format = query.into_iter().flat_map(|q| q.split('&')).find_map(|pair| {
        let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
        (key == "f").then_some(value)
    });
    match format {
        Some("html") => return true,
        Some("json") => return false,
        _ => {}
    }
    headers
        .get(header::ACCEPT)
        .and_then(|v| v.to_str().ok())
        .is_some_and(accept_prefers_html)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHROMIUM: &str = "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,\
                            image/apng,*/*;q=0.8,application/signed-exchange;v=b3;q=0.7";
    const FIREFOX: &str = "text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8";

    #[test]
    fn browsers_get_html() {
        assert!(accept_prefers_html(CHROMIUM));
        assert!(accept_prefers_html(FIREFOX));
        assert!(accept_prefers_html("text/html"));
    }

    #[test]
    fn json_clients_and_wildcards_get_json() {
        for accept in [
            "",
            "*/*",
            "application/json",
            "application/json, text/plain, */*",
            "text/plain",
            "text/*",
            "application/json, text/html",
            "text/html;q=0.5, application/json",
            "text/html;q=0, */*",
            "application/*, text/html;q=0.9",
        ] {
            assert!(!accept_prefers_html(accept), "{accept:?} should get JSON");
        }
    }

    #[test]
    fn quality_then_order_decides_between_html_and_json() {
        assert!(accept_prefers_html("text/html, application/json"));
        assert!(accept_prefers_html("application/json;q=0.5, text/html"));
        assert!(accept_prefers_html("text/html, */*"));
        assert!(accept_prefers_html(
            "TEXT/HTML; charset=utf-8, application/json; q=0.9"
        ));
    }

    #[test]
    fn the_f_parameter_overrides_accept() {
        let mut browser = HeaderMap::new();
        browser.insert(header::ACCEPT, CHROMIUM.parse().unwrap());
        assert!(wants_html(&browser, None));
        assert!(!wants_html(&browser, Some("limit=5&f=json")));
        assert!(wants_html(&HeaderMap::new(), Some("f=html")));
        assert!(!wants_html(&HeaderMap::new(), Some("status=running")));
        assert!(wants_html(&browser, Some("f=xml")));
    }
}
