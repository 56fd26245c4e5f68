//! CSV as chocmodal writes it, in every CSV it serves or saves (histories and their
//! spectra, the impact table, sweep results, a signal's samples and spectrum, the CLI's
//! `--out` files): one number format and one quoting rule, so that a script reads them
//! all alike.
//!
//! A number is the shortest text that reads back as the very same f64, written as the
//! JSON documents write it (`0.025`, `1e-7`, `3.0`, `-0.0`): pandas, spreadsheets and
//! `float()` all read it exactly. Counts (an impact's contact, its rebounds) are
//! integers. A cell holding a comma, a quote or a line break is quoted (RFC 4180).

use std::borrow::Cow;
use std::fmt::Write;

/// Appends `x` to `out`: the shortest text that reads back as `x`; `NaN`, `inf`, `-inf`
/// for the values JSON has no number for.
pub fn push_number(out: &mut String, x: f64) {
    match serde_json::Number::from_f64(x) {
        Some(number) => {
            let _ = write!(out, "{number}");
        }
        None if x.is_nan() => out.push_str("NaN"),
        None if x > 0.0 => out.push_str("inf"),
        None => out.push_str("-inf"),
    }
}

/// `x` as [`push_number`] writes it.
pub fn number(x: f64) -> String {
    let mut out = String::new();
    push_number(&mut out, x);
    out
}

/// `text` as a CSV cell: quoted when it holds a comma, a quote or a line break.
pub fn quote(text: &str) -> Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) {
        Cow::Owned(format!("\"{}\"", text.replace('"', "\"\"")))
    } else {
        Cow::Borrowed(text)
    }
}

/// A JSON scalar as a CSV cell: a number as [`push_number`] writes it (an integer as an
/// integer), a string quoted when needed, a boolean as `true`/`false`, null as empty;
/// anything else as its JSON text, quoted.
pub fn cell(value: &serde_json::Value) -> String {
    use serde_json::Value;
    match value {
        Value::Null => String::new(),
        Value::Number(n) if n.is_f64() => number(n.as_f64().unwrap_or(f64::NAN)),
        Value::Number(n) => n.to_string(),
        Value::String(text) => quote(text).into_owned(),
        Value::Bool(b) => b.to_string(),
        other => quote(&other.to_string()).into_owned(),
    }
}

/// A table of flat records as CSV: the columns as header, a row per record in the
/// columns' order; a member a record lacks (or a null) is an empty cell, the rest as
/// [`cell`] writes them. The one writer of every table of records (the job's contact,
/// pin and resultant tables, the sweeps' results and statistics).
pub fn records(columns: &[String], rows: &[serde_json::Map<String, serde_json::Value>]) -> String {
    let header: Vec<Cow<'_, str>> = columns.iter().map(|c| quote(c)).collect();
    let mut out = header.join(",");
    out.push('\n');
    for row in rows {
        let cells: Vec<String> = columns
            .iter()
            .map(|name| row.get(name).map(cell).unwrap_or_default())
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every number reads back as itself, in the fewest digits: the decimal a person
    /// would type when there is one.
    #[test]
    fn numbers_are_the_shortest_text_that_reads_back_exactly() {
        for (x, text) in [
            (0.025, "0.025"),
            (1e-7, "1e-7"),
            (3.0, "3.0"),
            (0.1 + 0.2, "0.30000000000000004"),
            (-2.5e300, "-2.5e+300"),
            (5e-324, "5e-324"),
            (0.0, "0.0"),
        ] {
            assert_eq!(number(x), text);
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{text}");
        }
        assert_eq!(number(f64::NAN), "NaN");
        assert_eq!(number(f64::INFINITY), "inf");
        assert_eq!(number(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn cells_are_quoted_only_when_they_must_be() {
        assert_eq!(quote("plain"), "plain");
        assert_eq!(quote("a,b"), "\"a,b\"");
        assert_eq!(quote("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(cell(&serde_json::json!(7)), "7");
        assert_eq!(cell(&serde_json::json!(0.5)), "0.5");
        assert_eq!(cell(&serde_json::json!(null)), "");
    }
}
