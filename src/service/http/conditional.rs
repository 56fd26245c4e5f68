//! Conditional requests: strong entity tags from the representation's bytes, and
//! `304 Not Modified` when `If-None-Match` already names the current one.
//!
//! The tag hashes exactly the bytes sent (FNV-1a, 64 bit), so it changes whenever the
//! representation does and never otherwise: a poller that sends back the tag of the
//! last status it saw gets an empty 304 until progress moves. A streamed history's tag
//! hashes what its bytes are made from instead ([`entity_tag_of_parts`]).

use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

/// Strong entity tag of a representation, e.g. `"9f0c2b7e61d3a845"`.
pub fn entity_tag(body: &[u8]) -> HeaderValue {
    tag_of_hash(fnv1a(0xcbf2_9ce4_8422_2325, body))
}

/// Strong entity tag of a representation streamed as it is written, whose bytes are not
/// there to hash before the headers go: the hash of everything the bytes are a function
/// of (the stored data, the query, the service version), in `parts`.
pub fn entity_tag_of_parts(parts: &[&[u8]]) -> HeaderValue {
    let hash = parts.iter().fold(0xcbf2_9ce4_8422_2325, |hash, part| {
        // The length first, so that moving bytes between parts changes the tag.
        let hash = fnv1a(hash, &(part.len() as u64).to_le_bytes());
        fnv1a(hash, part)
    });
    tag_of_hash(hash)
}

fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    for byte in bytes {
        hash ^= u64::from(*byte);
        hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
    hash
}

fn tag_of_hash(hash: u64) -> HeaderValue {
    HeaderValue::from_str(&format!("\"{hash:016x}\"")).expect("hex is a valid header value")
}

/// Whether `If-None-Match` matches `etag` (weak comparison, as RFC 9110 asks for GET).
pub fn if_none_match(headers: &HeaderMap, etag: &HeaderValue) -> bool {
    let Ok(current) = etag.to_str() else {
        return false;
    };
    let current = current.trim_start_matches("W/");
    headers
        .get_all(header::IF_NONE_MATCH)
        .iter()
        .filter_map(|value| value.to_str().ok())
        .flat_map(|value| value.split(','))
        .map(str::trim)
        .any(|candidate| candidate == "*" || candidate.trim_start_matches("W/") == current)
}

/// `200` with `body`, its content type and a strong `ETag`, or an empty `304` when the
/// client already has it; `extra` headers go on both.
pub fn tagged(
    request_headers: &HeaderMap,
    content_type: &'static str,
    body: Vec<u8>,
    extra: HeaderMap,
) -> Response {
    let etag = entity_tag(&body);
    let mut headers = extra;
    headers.insert(header::ETAG, etag.clone());
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    if if_none_match(request_headers, &etag) {
        return (StatusCode::NOT_MODIFIED, headers).into_response();
    }
    headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    (StatusCode::OK, headers, body).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entity_tags_differ_when_bytes_differ() {
        assert_ne!(entity_tag(b"{\"progress\":1}"), entity_tag(b"{\"progress\":2}"));
        assert_eq!(entity_tag(b"same"), entity_tag(b"same"));
    }

    #[test]
    fn if_none_match_accepts_lists_weak_tags_and_star() {
        let etag = entity_tag(b"x");
        let tag = etag.to_str().unwrap().to_owned();
        for header_value in [
            tag.clone(),
            format!("\"other\", {tag}"),
            format!("W/{tag}"),
            "*".into(),
        ] {
            let mut headers = HeaderMap::new();
            headers.insert(
                header::IF_NONE_MATCH,
                HeaderValue::from_str(&header_value).unwrap(),
            );
            assert!(if_none_match(&headers, &etag), "{header_value}");
        }
        let mut headers = HeaderMap::new();
        headers.insert(header::IF_NONE_MATCH, HeaderValue::from_static("\"other\""));
        assert!(!if_none_match(&headers, &etag));
    }
}
