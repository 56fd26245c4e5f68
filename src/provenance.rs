//! Where a result comes from: the solver's version, the build, and a hash of the inputs
//! it was computed from, stamped on every results document (`provenance`) by whoever
//! assembles it (the worker, `chocmodal run`), never by the processes themselves.
//!
//! The inputs hash is the SHA-256 (lowercase hex) of the **canonical JSON** of the
//! submitted `inputs` object, in the form of RFC 8785 (the JSON Canonicalization
//! Scheme): object members sorted by name, no whitespace, strings escaped as JSON
//! requires and no more, numbers in ECMAScript's shortest form (`1.0` and `1` are both
//! `1`, `1e-5` is `0.00001`, `2.1e11` is `210000000000`), integers beyond 2^53 kept
//! exactly. So two submissions that differ only in member order, whitespace or the
//! spelling of a number have the same hash, and any change of a value changes it. It
//! hashes the request as written, not the inputs after defaults are filled in: spelling
//! out a default (`"damping": 0.0`) gives another hash, though the same run.

use serde::Serialize;
use serde_json::Value;
use sha2::{Digest, Sha256};

/// The solver's version: the crate's.
pub const SOLVER_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The git commit the binary was built from (`build.rs`: `CHOCMODAL_BUILD_COMMIT` when
/// set at build time, else `git rev-parse HEAD` of the source tree); `None` when neither
/// could tell (a source tarball).
pub const BUILD_COMMIT: Option<&str> = option_env!("CHOCMODAL_BUILD_COMMIT");

/// The `provenance` member of a results document.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, utoipa::ToSchema)]
pub struct Provenance {
    /// Always `chocmodal`.
    pub solver: &'static str,
    /// The solver's version, e.g. `0.2.0`.
    pub solver_version: &'static str,
    /// The git commit of the build, when known (null from a tarball without `.git`).
    pub build: Option<&'static str>,
    /// SHA-256 (hex) of the canonical JSON of the submitted inputs (see docs/service.md
    /// "Provenance"): equal for equivalent submissions, different when a value changes.
    pub inputs_sha256: String,
}

impl Provenance {
    /// The provenance of a result computed from `inputs` by this binary.
    pub fn of(inputs: &Value) -> Self {
        Self {
            solver: "chocmodal",
            solver_version: SOLVER_VERSION,
            build: BUILD_COMMIT.filter(|commit| !commit.is_empty()),
            inputs_sha256: inputs_sha256(inputs),
        }
    }

    /// Adds itself to a results document (an object) as `provenance`.
    pub fn stamp(&self, document: &mut Value) {
        if let Value::Object(map) = document {
            map.insert(
                "provenance".into(),
                serde_json::to_value(self).expect("provenance serializes"),
            );
        }
    }
}

/// SHA-256 (lowercase hex) of the canonical JSON of `inputs`.
pub fn inputs_sha256(inputs: &Value) -> String {
    let mut text = String::with_capacity(512);
    canonical(inputs, &mut text);
    Sha256::digest(text.as_bytes())
        .iter()
        .map(|byte| format!("{byte:02x}"))
        .collect()
}

/// Writes `value` as canonical JSON (see the module documentation) to `out`.
pub fn canonical(value: &Value, out: &mut String) {
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
        Value::Number(number) => match (number.as_u64(), number.as_i64(), number.as_f64()) {
            (Some(n), _, _) => out.push_str(&n.to_string()),
            (None, Some(n), _) => out.push_str(&n.to_string()),
            (None, None, Some(x)) => push_ecmascript_number(out, x),
            (None, None, None) => out.push_str(&number.to_string()),
        },
        scalar => out.push_str(&scalar.to_string()),
    }
}

/// `x` as ECMAScript's `Number.prototype.toString` writes it (RFC 8785 §3.2.2.3): the
/// shortest digits that read back as `x`, plain for exponents from -7 to 20, else
/// `d.ddde±n`; `-0` as `0`. JSON has no NaN or infinity, so they never come here.
fn push_ecmascript_number(out: &mut String, x: f64) {
    if x == 0.0 {
        out.push('0');
        return;
    }
    if x < 0.0 {
        out.push('-');
    }
    // Rust's `{:e}` gives the shortest round-trip digits: `d.ddd` and the exponent.
    let scientific = format!("{:e}", x.abs());
    let (mantissa, exponent) = scientific.split_once('e').expect("`{:e}` has an exponent");
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let exponent: i32 = exponent.parse().expect("`{:e}` exponent is an integer");
    let k = digits.len() as i32;
    // ECMAScript's n: the position of the decimal point relative to the digits.
    let n = exponent + 1;
    if k <= n && n <= 21 {
        out.push_str(&digits);
        out.extend(std::iter::repeat_n('0', (n - k) as usize));
    } else if 0 < n && n <= 21 {
        out.push_str(&digits[..n as usize]);
        out.push('.');
        out.push_str(&digits[n as usize..]);
    } else if -6 < n && n <= 0 {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', (-n) as usize));
        out.push_str(&digits);
    } else {
        out.push_str(&digits[..1]);
        if k > 1 {
            out.push('.');
            out.push_str(&digits[1..]);
        }
        out.push('e');
        out.push(if n > 0 { '+' } else { '-' });
        out.push_str(&(n - 1).abs().to_string());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn canonical_text(value: &Value) -> String {
        let mut out = String::new();
        canonical(value, &mut out);
        out
    }

    #[test]
    fn numbers_are_written_as_ecmascript_writes_them() {
        // Expected texts from RFC 8785 appendix B and `String(x)` in a JavaScript engine.
        let cases = [
            (1.0, "1"),
            (0.5, "0.5"),
            (1e-5, "0.00001"),
            (1e-7, "1e-7"),
            (2.1e11, "210000000000"),
            (1e21, "1e+21"),
            (1e20, "100000000000000000000"),
            (123.456, "123.456"),
            (-0.0, "0"),
            (-2.5e-9, "-2.5e-9"),
            (9.766, "9.766"),
            (0.000001, "0.000001"),
            (5e-324, "5e-324"),
            (1.7976931348623157e308, "1.7976931348623157e+308"),
            (0.009000000000000001, "0.009000000000000001"),
        ];
        for (x, expected) in cases {
            let mut out = String::new();
            push_ecmascript_number(&mut out, x);
            assert_eq!(out, expected, "{x:e}");
        }
    }

    #[test]
    fn member_order_whitespace_and_number_spelling_do_not_change_the_hash_but_values_do() {
        let a: Value =
            serde_json::from_str(r#"{"beam": {"modes": 10, "length": 1.0}, "solver": {"time_step": 1e-5}}"#)
                .unwrap();
        let b: Value = serde_json::from_str(
            r#"{ "solver" : { "time_step" : 0.00001 },
                 "beam" : { "length" : 1, "modes" : 10.0 } }"#,
        )
        .unwrap();
        assert_eq!(
            canonical_text(&a),
            r#"{"beam":{"length":1,"modes":10},"solver":{"time_step":0.00001}}"#
        );
        assert_eq!(inputs_sha256(&a), inputs_sha256(&b));
        let changed = json!({"beam": {"modes": 11, "length": 1.0}, "solver": {"time_step": 1e-5}});
        assert_ne!(inputs_sha256(&a), inputs_sha256(&changed));
        assert_eq!(inputs_sha256(&a).len(), 64);
    }

    #[test]
    fn large_integers_and_strings_stay_exact() {
        let seeds = json!({"seed": 18446744073709551615u64, "name": "a\"b\u{1}é"});
        assert_eq!(
            canonical_text(&seeds),
            "{\"name\":\"a\\\"b\\u0001é\",\"seed\":18446744073709551615}"
        );
        assert_ne!(
            inputs_sha256(&json!({"seed": 9007199254740993u64})),
            inputs_sha256(&json!({"seed": 9007199254740992u64}))
        );
    }

    #[test]
    fn the_stamp_names_this_solver() {
        let mut document = json!({"numerical": {"impacts": 3}});
        Provenance::of(&json!({"a": 1})).stamp(&mut document);
        assert_eq!(document["provenance"]["solver_version"], SOLVER_VERSION);
        assert_eq!(
            document["provenance"]["inputs_sha256"],
            inputs_sha256(&json!({"a": 1}))
        );
    }
}
