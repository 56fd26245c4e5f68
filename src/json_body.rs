//! Request bodies as JSON values, for the HTTP API and the CLI alike.
//!
//! JSON's grammar allows numbers of any size, but a double cannot hold `1e400`: serde
//! refuses it rather than turning it into infinity, and here that refusal names the
//! member that holds it (`/inputs/beam/length`), as a 422 like any other bad input.
//! Anything else that is not JSON, or nests deeper than serde_json's limit of 128
//! levels, is a 400 `malformed-body`.

use serde_json::Value;

use crate::pointer::pointer_of;
use crate::problem::Problem;
use crate::processes::{FieldError, InvalidInputs};

/// Deepest nesting of arrays and objects a body may have (serde_json's recursion limit).
pub const MAX_DEPTH: usize = 128;

/// Parses a request body; the errors are problem documents (400, or 422 with a pointer
/// for a number out of range).
pub fn parse(text: &str) -> Result<Value, Problem> {
    let mut deserializer = serde_json::Deserializer::from_str(text);
    let value: Value = serde_path_to_error::deserialize(&mut deserializer).map_err(|error| {
        let pointer = pointer_of(error.path());
        let inner = error.into_inner();
        let message = inner.to_string();
        if message.starts_with("number out of range") {
            Problem::invalid_inputs(&InvalidInputs(vec![FieldError::new(
                pointer,
                "is out of range: numbers must be finite doubles (magnitude below 1.8e308)",
            )]))
        } else if message.starts_with("recursion limit exceeded") {
            Problem::malformed_body(format!(
                "the body nests arrays and objects deeper than {MAX_DEPTH} levels ({message})"
            ))
        } else {
            Problem::malformed_body(format!("the body is not valid JSON: {message}"))
        }
    })?;
    deserializer
        .end()
        .map_err(|e| Problem::malformed_body(format!("the body is not valid JSON: {e}")))?;
    Ok(value)
}

/// The members of an execution request the service reads: `inputs`, and `subscriber`,
/// `labels` and `note` as given (the service checks the first against its callback
/// policy, the others with [`crate::annotations`]). `outputs` and
/// `response` are accepted and ignored (every execution is asynchronous, every output
/// is returned).
#[derive(Debug, Clone, PartialEq)]
pub struct ExecutionRequest {
    /// The `inputs` object.
    pub inputs: Value,
    /// The `subscriber` member, if present.
    pub subscriber: Option<Value>,
    /// The `labels` member, if present (checked by [`crate::annotations`]).
    pub labels: Option<Value>,
    /// The `note` member, if present.
    pub note: Option<Value>,
}

/// Parses an execution request body and returns its `inputs` object.
pub fn parse_envelope(text: &str) -> Result<Value, Problem> {
    parse_execution_request(text).map(|request| request.inputs)
}

/// Parses an execution request body into its `inputs` and `subscriber`.
pub fn parse_execution_request(text: &str) -> Result<ExecutionRequest, Problem> {
    let body = parse(text)?;
    let Value::Object(mut map) = body else {
        return Err(Problem::malformed_body(
            "the body must be a JSON object `{\"inputs\": {...}}`",
        ));
    };
    if let Some(unknown) = map.keys().find(|k| {
        !matches!(
            k.as_str(),
            "inputs" | "outputs" | "response" | "subscriber" | "labels" | "note"
        )
    }) {
        let invalid = InvalidInputs(vec![FieldError::new(
            format!("/{}", crate::pointer::escape(unknown)),
            "unknown member of the execution request",
        )]);
        return Err(Problem::invalid_inputs(&invalid));
    }
    let subscriber = map.remove("subscriber");
    let (labels, note) = (map.remove("labels"), map.remove("note"));
    match map.remove("inputs") {
        Some(inputs @ Value::Object(_)) => Ok(ExecutionRequest {
            inputs,
            subscriber,
            labels,
            note,
        }),
        Some(_) => Err(Problem::invalid_inputs(&InvalidInputs(vec![FieldError::new(
            "/inputs",
            "must be an object",
        )]))),
        None => Err(Problem::invalid_inputs(&InvalidInputs(vec![FieldError::new(
            "/inputs",
            "is required",
        )]))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_out_of_range_is_refused_at_its_member() {
        let problem = parse(r#"{"inputs": {"beam": {"length": 1.0, "modes": [1, -1e400]}}}"#).unwrap_err();
        assert_eq!(problem.status, 422);
        assert_eq!(problem.errors[0].pointer, "/inputs/beam/modes/1");
        let problem = parse(r#"{"a/b": 1e999}"#).unwrap_err();
        assert_eq!(problem.errors[0].pointer, "/a~1b");
    }

    #[test]
    fn the_subscriber_is_kept_as_given_and_unknown_members_refused() {
        let request = parse_execution_request(
            r#"{"inputs": {"a": 1}, "subscriber": {"successUri": "x"}, "response": "document"}"#,
        )
        .unwrap();
        assert_eq!(request.inputs, serde_json::json!({"a": 1}));
        assert_eq!(request.subscriber, Some(serde_json::json!({"successUri": "x"})));
        let problem = parse_execution_request(r#"{"inputs": {}, "callback/uri": "x"}"#).unwrap_err();
        assert_eq!(problem.errors[0].pointer, "/callback~1uri");
    }

    #[test]
    fn large_but_finite_numbers_and_tiny_ones_parse() {
        let value = parse(r#"{"x": 1.7e308, "y": 1e-400}"#).unwrap();
        assert_eq!(value["x"], 1.7e308);
        assert_eq!(value["y"], 0.0);
    }

    #[test]
    fn nesting_beyond_the_limit_is_a_malformed_body() {
        let deep = format!("{}{}", "[".repeat(MAX_DEPTH + 1), "]".repeat(MAX_DEPTH + 1));
        let problem = parse(&deep).unwrap_err();
        assert_eq!(problem.status, 400);
        assert!(problem.detail.contains("deeper than 128"), "{}", problem.detail);
        let fine = format!("{}{}", "[".repeat(MAX_DEPTH - 1), "]".repeat(MAX_DEPTH - 1));
        assert!(parse(&fine).is_ok());
    }

    #[test]
    fn syntax_errors_and_trailing_text_are_malformed_bodies() {
        for text in [
            "{",
            "{\"a\": 1} x",
            "",
            "nul",
            "{\"a\": NaN}",
            "{\"a\": Infinity}",
        ] {
            assert_eq!(parse(text).unwrap_err().status, 400, "{text:?}");
        }
    }
}
