//! Cross-origin requests (CORS): which web origins may call the API from a browser
//! (a dashboard served elsewhere), and the layer that answers their preflights.
//!
//! Off unless origins are configured (`--cors-origin`). The layer sits outside
//! authentication: a browser sends its preflight `OPTIONS` without the bearer token, and
//! the 401s, 413s and 408s the API answers must carry the CORS headers too, or the page's
//! script could not read them.

use std::fmt;
use std::str::FromStr;
use std::time::Duration;

use axum::http::{HeaderName, HeaderValue, Method, header};
use tower_http::cors::{AllowOrigin, CorsLayer};

/// One origin allowed to call the API from a browser.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CorsOrigin {
    /// `*`: every origin.
    Any,
    /// One origin, `scheme://host[:port]` as browsers send it (lower case, no path).
    Exact(HeaderValue),
}

/// Why a `--cors-origin` value is not an origin.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "`{given}` is not an origin: give `*` or `scheme://host[:port]` (e.g. `https://dash.example.com`, no path, no trailing `/`)"
)]
pub struct InvalidOrigin {
    given: String,
}

impl FromStr for CorsOrigin {
    type Err = InvalidOrigin;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let text = text.trim();
        if text == "*" {
            return Ok(Self::Any);
        }
        let invalid = || InvalidOrigin {
            given: text.to_owned(),
        };
        let (scheme, authority) = text.split_once("://").ok_or_else(invalid)?;
        let scheme_ok = scheme.starts_with(|c: char| c.is_ascii_alphabetic())
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
        let authority_ok = !authority.is_empty()
            && authority
                .chars()
                .all(|c| c.is_ascii_graphic() && !"/?#@*,".contains(c));
        if !(scheme_ok && authority_ok) {
            return Err(invalid());
        }
        // Browsers serialise the origin in lower case; compare against that form.
        HeaderValue::from_str(&text.to_ascii_lowercase())
            .map(Self::Exact)
            .map_err(|_| invalid())
    }
}

impl fmt::Display for CorsOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Any => f.write_str("*"),
            Self::Exact(origin) => f.write_str(origin.to_str().unwrap_or("?")),
        }
    }
}

/// Methods the API's routes use.
const METHODS: [Method; 4] = [Method::GET, Method::HEAD, Method::POST, Method::DELETE];

/// Request headers a client sends beyond the CORS-safelisted ones.
const REQUEST_HEADERS: [HeaderName; 4] = [
    header::AUTHORIZATION,
    header::CONTENT_TYPE,
    header::ACCEPT,
    header::IF_NONE_MATCH,
];

/// Response headers the API sets that a client reads: the new job's address, the
/// validator of cacheable results, the back-off of a 429/503, the auth challenge.
const EXPOSED_HEADERS: [HeaderName; 5] = [
    header::LOCATION,
    header::ETAG,
    header::RETRY_AFTER,
    header::WWW_AUTHENTICATE,
    // Whether the per-impact table served is complete or truncated.
    HeaderName::from_static(crate::processes::impact_report::HEADER),
];

/// How long a browser may cache a preflight's answer.
const PREFLIGHT_MAX_AGE: Duration = Duration::from_secs(600);

/// The layer for these origins; `None` (no CORS headers, `OPTIONS` a 405) when the list
/// is empty. `*` anywhere in the list allows every origin.
pub fn layer(origins: &[CorsOrigin]) -> Option<CorsLayer> {
    if origins.is_empty() {
        return None;
    }
    let allow_origin = if origins.contains(&CorsOrigin::Any) {
        AllowOrigin::any()
    } else {
        AllowOrigin::list(origins.iter().filter_map(|origin| match origin {
            CorsOrigin::Exact(value) => Some(value.clone()),
            CorsOrigin::Any => None,
        }))
    };
    Some(
        CorsLayer::new()
            .allow_origin(allow_origin)
            .allow_methods(METHODS.to_vec())
            .allow_headers(REQUEST_HEADERS.to_vec())
            .expose_headers(EXPOSED_HEADERS.to_vec())
            .max_age(PREFLIGHT_MAX_AGE),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn origins_parse_as_browsers_send_them() {
        assert_eq!("*".parse::<CorsOrigin>(), Ok(CorsOrigin::Any));
        assert_eq!(
            "https://Dash.Example.com:8443".parse::<CorsOrigin>(),
            Ok(CorsOrigin::Exact(HeaderValue::from_static(
                "https://dash.example.com:8443"
            )))
        );
        assert_eq!(
            " http://localhost:5173 "
                .parse::<CorsOrigin>()
                .map(|o| o.to_string()),
            Ok("http://localhost:5173".to_owned())
        );
    }

    #[test]
    fn paths_missing_schemes_and_wildcards_inside_are_not_origins() {
        for text in [
            "https://dash.example.com/",
            "https://dash.example.com/app",
            "dash.example.com",
            "https://",
            "https://*.example.com",
            "://x",
            "",
        ] {
            assert!(text.parse::<CorsOrigin>().is_err(), "`{text}` was accepted");
        }
    }

    #[test]
    fn no_origins_no_layer() {
        assert!(layer(&[]).is_none());
        assert!(layer(&[CorsOrigin::Any]).is_some());
    }
}
