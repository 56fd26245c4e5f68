//! The `Idempotency-Key` request header of the creation routes (jobs, sweeps, signals):
//! its extractor, its refusals, and the answer to a replayed request.
//!
//! A retried creation with the same key and the same request gets the same answer as
//! the first: `201 Created`, the same `Location`, the resource as it is now, plus
//! `Idempotent-Replayed: true`. The same key with another request is a 422
//! `idempotency-key-reused` naming the header; a key that is not 1 to 255 visible ASCII
//! characters is a 400 `invalid-header` naming it. The key logic and its storage live
//! in [`crate::service::queue::idempotency`].

use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{HeaderMap, HeaderValue};

use super::error::ApiError;
use crate::problem::{CHOCMODAL_PROBLEMS, Problem};
use crate::service::queue::idempotency::{HEADER, IdempotencyKey, KeyConflict};

/// The response header that marks a replayed answer.
pub const REPLAYED_HEADER: &str = "idempotent-replayed";

/// The request's `Idempotency-Key`, if it has one (a valid one: else a 400).
#[derive(Debug, Clone)]
pub struct IdempotencyHeader(pub Option<IdempotencyKey>);

impl<S: Send + Sync> FromRequestParts<S> for IdempotencyHeader {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, Self::Rejection> {
        let mut values = parts.headers.get_all(HEADER).iter();
        let Some(value) = values.next() else {
            return Ok(Self(None));
        };
        if values.next().is_some() {
            return Err(invalid_header("is sent more than once; send one key per request").into());
        }
        IdempotencyKey::parse(value.as_bytes())
            .map(|key| Self(Some(key)))
            .map_err(|why| invalid_header(&why).into())
    }
}

fn invalid_header(why: &str) -> Problem {
    Problem::new(
        format!("{CHOCMODAL_PROBLEMS}/invalid-header"),
        "Invalid header",
        400,
        format!("the `{HEADER}` header {why} (a key is 1 to 255 visible ASCII characters, no spaces)"),
    )
}

/// 422: the key was first used with another request.
pub fn key_reused(conflict: &KeyConflict) -> ApiError {
    let first = conflict.kind.as_str();
    let reason = if conflict.other_kind {
        format!(
            "was first sent to create a {first} ({first} `{}`), not this kind of resource",
            conflict.resource_id
        )
    } else {
        format!(
            "was first sent with another request body, which created {first} `{}`",
            conflict.resource_id
        )
    };
    Problem::new(
        format!("{CHOCMODAL_PROBLEMS}/idempotency-key-reused"),
        "Idempotency key reused",
        422,
        format!(
            "the `{HEADER}` header `{}` {reason}: a key names one request; send this request \
             with a new key",
            conflict.key
        ),
    )
    .into()
}

/// Marks `headers` as those of a replayed answer.
pub fn mark_replayed(headers: &mut HeaderMap) {
    headers.insert(REPLAYED_HEADER, HeaderValue::from_static("true"));
}
