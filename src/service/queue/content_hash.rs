//! Content hash of a run: identical runs (same process, same inputs, same solver) are
//! computed once and their results reused (see [`super::reuse`]).
//!
//! SHA-256, as lowercase hex, of `process id`, a newline, the canonical JSON of the
//! inputs (object members sorted by key at every level, no whitespace, numbers and
//! strings as serde_json writes them), a newline, and the solver version
//! (`CARGO_PKG_VERSION`): a new release never reuses results of an older one. `1` and
//! `1.0` are different texts, hence different hashes: a miss, never a wrong reuse.

use serde_json::Value;
use sha2::{Digest, Sha256};

/// The solver version in every hash.
pub const SOLVER_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Hex SHA-256 of process id, canonical inputs and solver version.
pub fn content_hash(process_id: &str, inputs: &Value) -> String {
    let mut text = String::with_capacity(512);
    text.push_str(process_id);
    text.push('\n');
    canonical(inputs, &mut text);
    text.push('\n');
    text.push_str(SOLVER_VERSION);
    Sha256::digest(text.as_bytes())
        .iter()
        .map(|byte| format!("{byte:02x}"))
        .collect()
}

/// Canonical JSON: members sorted by key, no whitespace.
pub(crate) fn canonical(value: &Value, out: &mut String) {
    match value {
        Value::Object(map) => {
            let mut members: Vec<(&String, &Value)> = map.iter().collect();
            members.sort_by(|a, b| a.0.cmp(b.0));
            out.push('{');
            for (i, (key, value)) in members.into_iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                out.push_str(&Value::String(key.clone()).to_string());
                out.push(':');
                canonical(value, out);
            }
            out.push('}');
        }
        Value::Array(items) => {
            out.push('[');
            for (i, item) in items.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                canonical(item, out);
            }
            out.push(']');
        }
        scalar => out.push_str(&scalar.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn member_order_does_not_change_the_hash_but_values_and_processes_do() {
        let a: Value = serde_json::from_str(r#"{"b": {"y": 1, "x": [1, 2]}, "a": 0.5}"#).unwrap();
        let b: Value = serde_json::from_str(r#"{"a": 0.5, "b": {"x": [1, 2], "y": 1}}"#).unwrap();
        assert_eq!(content_hash("p", &a), content_hash("p", &b));
        assert_ne!(content_hash("p", &a), content_hash("q", &a));
        assert_ne!(content_hash("p", &a), content_hash("p", &json!({"a": 0.5})));
        assert_eq!(content_hash("p", &a).len(), 64);
    }
}
