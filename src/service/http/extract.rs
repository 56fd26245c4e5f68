//! Extractors whose rejections are problem documents, not axum's plain-text defaults.

use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{FromRequest, FromRequestParts, Query, Request};
use axum::http::request::Parts;
use axum::http::{StatusCode, header};
use serde::de::DeserializeOwned;

use super::error::ApiError;
use crate::json_body::{ExecutionRequest, parse_execution_request};
use crate::problem::Problem;

/// The `inputs` object and the `subscriber` member of an execution request body
/// `{"inputs": {...}, "subscriber": {...}}`.
///
/// Rejections: 413 over the body limit, 415 when the body is declared as something else
/// than JSON, 400 when it is not JSON, 422 when it is not the expected envelope.
#[derive(Debug)]
pub struct ExecutionInputs(pub ExecutionRequest);

impl<S: Send + Sync> FromRequest<S> for ExecutionInputs {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, Self::Rejection> {
        let text = json_text(req, state, "the execution request").await?;
        Ok(Self(parse_execution_request(&text)?))
    }
}

/// Any JSON body (a sweep request), with the same rejections as [`ExecutionInputs`] but
/// for the envelope: 413, 415, 400 when it is not JSON.
#[derive(Debug)]
pub struct JsonBody(pub serde_json::Value);

impl<S: Send + Sync> FromRequest<S> for JsonBody {
    type Rejection = ApiError;

    async fn from_request(req: Request, state: &S) -> Result<Self, Self::Rejection> {
        let text = json_text(req, state, "the request").await?;
        Ok(Self(crate::json_body::parse(&text)?))
    }
}

/// The body as text, refusing bodies declared as something else than JSON.
async fn json_text<S: Send + Sync>(req: Request, state: &S, what: &str) -> Result<String, ApiError> {
    if let Some(content_type) = req.headers().get(header::CONTENT_TYPE) {
        let content_type = content_type.to_str().unwrap_or_default().to_ascii_lowercase();
        let essence = content_type.split(';').next().unwrap_or_default().trim();
        if !(essence == "application/json" || essence.ends_with("+json")) {
            return Err(Problem::unsupported_media_type(format!(
                "{what} must be `application/json`, not `{essence}`"
            ))
            .into());
        }
    }
    let bytes = Bytes::from_request(req, state).await.map_err(body_rejection)?;
    let text =
        std::str::from_utf8(&bytes).map_err(|_| Problem::malformed_body("the body is not valid UTF-8"))?;
    Ok(text.to_owned())
}

fn body_rejection(rejection: BytesRejection) -> ApiError {
    if rejection.status() == StatusCode::PAYLOAD_TOO_LARGE {
        Problem::payload_too_large("the request body is larger than this server accepts").into()
    } else {
        Problem::malformed_body(format!("cannot read the request body: {rejection}")).into()
    }
}

/// Query parameters parsed with serde; a bad value is a 400 problem.
#[derive(Debug)]
pub struct ApiQuery<T>(pub T);

impl<T: DeserializeOwned, S: Send + Sync> FromRequestParts<S> for ApiQuery<T> {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, state: &S) -> Result<Self, Self::Rejection> {
        Query::<T>::from_request_parts(parts, state)
            .await
            .map(|Query(value)| Self(value))
            .map_err(|rejection| Problem::invalid_query(query_error(&rejection.body_text())).into())
    }
}

/// A query-string parse error in words: `limit: invalid digit found in string` →
/// `limit: must be a whole number`.
fn query_error(text: &str) -> String {
    let text = text
        .strip_prefix("Failed to deserialize query string: ")
        .unwrap_or(text);
    let plain = text
        .replace(
            "invalid digit found in string",
            "must be a whole number, 0 or more",
        )
        .replace(
            "cannot parse integer from empty string",
            "must be a whole number, not empty",
        )
        .replace("number too large to fit in target type", "is too large")
        .replace("invalid float literal", "must be a number");
    crate::processes::common_inputs::plain(&plain)
}

#[cfg(test)]
mod tests {
    use super::query_error;

    #[test]
    fn query_errors_are_in_words() {
        assert_eq!(
            query_error("Failed to deserialize query string: limit: invalid digit found in string"),
            "limit: must be a whole number, 0 or more"
        );
        assert_eq!(
            query_error("damping: invalid float literal"),
            "damping: must be a number"
        );
    }
}
