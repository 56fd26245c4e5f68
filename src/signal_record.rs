//! An accelerogram as a client sends it (`POST /signals`, or a record file named in a
//! job given to `chocmodal run`): CSV or JSON text into a checked record, every problem
//! with the JSON pointer of its sample (`/acceleration/17`, the same for both formats)
//! and, for CSV, its line.
//!
//! - CSV: an optional header line, then one sample per line: `time,acceleration` (s,
//!   m/s²), or the acceleration alone with a sampling rate given apart (samples per
//!   second; times k / rate from 0). Blank lines and lines starting with `#` are skipped.
//! - JSON: `{"time": [...], "acceleration": [...]}` (the `table` excitation's names) or
//!   `{"sampling_rate": 200, "acceleration": [...]}`.
//!
//! - PEER AT2 (the NGA strong-motion databases' files), recognised by their first line
//!   (`PEER …`) or a `NPTS` count on their fourth: three title lines (the third naming
//!   the unit, `… IN UNITS OF G`), a fourth giving the count and the interval
//!   (`NPTS=  3908, DT= .0100 SEC`, or the older `3908 .0100 NPTS, DT`), then the
//!   accelerations, several to a line, at k·DT from 0.
//! - One column after a header line giving the interval: `dt=0.005` (also `dt,0.005`,
//!   `dt: 0.005 s`), times k·dt from 0.
//!
//! Accelerations are in m/s², or in g with `unit` = g (9.80665 m/s², the standard
//! gravity): a record is stored in m/s² whatever its unit. An AT2 file is in g by its
//! format; a unit given with it must say so.
//!
//! A record has at least two samples, times non-negative and strictly increasing, every
//! value finite: the rules of a `table` excitation, so that a stored record is a valid
//! excitation as it is.

use std::sync::Arc;

use serde::Deserialize;

use crate::physics::loads::Table;
use crate::processes::FieldError;
pub use crate::processes::excitation::{AccelerationUnit, STANDARD_GRAVITY};

mod at2;

/// At most this many problems are reported for one record (a broken file would
/// otherwise list every line).
pub const MAX_REPORTED: usize = 20;

/// The format of a record's text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordFormat {
    Csv,
    Json,
}

impl RecordFormat {
    /// JSON when the text starts with `{` (after blanks), CSV otherwise.
    pub fn sniff(text: &str) -> Self {
        if text.trim_start().starts_with('{') {
            Self::Json
        } else {
            Self::Csv
        }
    }
}

/// Why a record is refused; each variant's doc says its HTTP status.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RecordError {
    /// 400 `malformed-body`: not JSON (the parser's message).
    #[error("{0}")]
    Malformed(String),
    /// 422 `invalid-signal`: problems at samples or members, at most [`MAX_REPORTED`].
    #[error("invalid record: {}", .0.iter().map(|e| format!("{}: {}", e.pointer, e.detail)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<FieldError>),
    /// 413 `payload-too-large`: more samples than the limit.
    #[error("the record has {samples} samples, more than the limit of {limit}")]
    TooLarge { samples: usize, limit: usize },
}

/// Parses and checks a record of at most `max_samples` samples, into m/s².
/// `sampling_rate` (samples per second) comes with a single-column CSV record, and
/// `unit` (m/s² when absent) with CSV text, from outside its text.
pub fn parse(
    text: &str,
    format: RecordFormat,
    sampling_rate: Option<f64>,
    unit: Option<AccelerationUnit>,
    max_samples: usize,
) -> Result<Table, RecordError> {
    let (mut record, lines, unit) = match format {
        RecordFormat::Csv if at2::recognises(text) => {
            if sampling_rate.is_some() {
                return Err(invalid(
                    "/sampling_rate",
                    "a PEER AT2 file gives its own interval (DT on its fourth line)",
                ));
            }
            if unit.is_some_and(|u| u != AccelerationUnit::G) {
                return Err(invalid(
                    "/unit",
                    "a PEER AT2 file is in g (its third line says so)",
                ));
            }
            let (record, lines) = at2::parse(text)?;
            (record, lines, AccelerationUnit::G)
        }
        RecordFormat::Csv => {
            let (record, lines) = parse_csv(text, sampling_rate)?;
            (record, lines, unit.unwrap_or_default())
        }
        RecordFormat::Json => {
            let (record, json_unit) = parse_json(text)?;
            if unit.is_some() {
                return Err(invalid(
                    "/unit",
                    "a JSON record gives its unit as its `unit` member, not in the query",
                ));
            }
            (record, Vec::new(), json_unit.unwrap_or_default())
        }
    };
    if unit != AccelerationUnit::MetresPerSecondSquared {
        let factor = unit.factor();
        record.values.iter_mut().for_each(|a| *a *= factor);
    }
    if record.time.len() > max_samples {
        return Err(RecordError::TooLarge {
            samples: record.time.len(),
            limit: max_samples,
        });
    }
    check(&record, &lines)?;
    Ok(record)
}

fn invalid(pointer: impl Into<String>, detail: impl Into<String>) -> RecordError {
    RecordError::Invalid(vec![FieldError::new(pointer, detail)])
}

fn check_rate(rate: f64, pointer: &str) -> Result<(), RecordError> {
    if rate.is_finite() && rate > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            pointer,
            format!("the sampling rate must be a positive number of samples per second (got {rate})"),
        ))
    }
}

fn uniform_times(samples: usize, rate: f64) -> Vec<f64> {
    (0..samples).map(|k| k as f64 / rate).collect()
}

/// The record and, for CSV, the line of each sample.
fn parse_csv(text: &str, sampling_rate: Option<f64>) -> Result<(Table, Vec<usize>), RecordError> {
    let mut columns: Option<usize> = None;
    let mut interval: Option<f64> = None;
    let mut first = true;
    let mut time = Vec::new();
    let mut values = Vec::new();
    let mut lines = Vec::new();
    let mut errors = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.trim();
        if content.is_empty() || content.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = content.split(',').map(str::trim).collect();
        if first {
            first = false;
            if let Some(dt) = interval_header(content, line)? {
                interval = Some(dt);
                columns = Some(1);
                continue;
            }
            if fields[0].parse::<f64>().is_err() {
                columns = Some(header(&fields, line)?);
                continue;
            }
        }
        let expected = *columns.get_or_insert(fields.len());
        if !(1..=2).contains(&expected) {
            return Err(invalid(
                "",
                format!(
                    "line {line}: {} columns; a record has `time,acceleration` or the acceleration alone",
                    fields.len()
                ),
            ));
        }
        let sample = values.len();
        if fields.len() != expected {
            errors.push(FieldError::new(
                format!("/acceleration/{sample}"),
                format!("line {line}: {} fields, expected {expected}", fields.len()),
            ));
            // A stand-in keeps the following samples at their index.
            if expected == 2 {
                time.push(0.0);
            }
            values.push(0.0);
        } else {
            let names: &[&str] = if expected == 2 {
                &["time", "acceleration"]
            } else {
                &["acceleration"]
            };
            let mut parsed = [0.0; 2];
            for (k, (field, name)) in fields.iter().zip(names).enumerate() {
                match field.parse::<f64>() {
                    Ok(value) if value.is_finite() => parsed[k] = value,
                    _ => errors.push(FieldError::new(
                        format!("/{name}/{sample}"),
                        format!("line {line}: `{field}` is not a finite number ({name})"),
                    )),
                }
            }
            if expected == 2 {
                time.push(parsed[0]);
            }
            values.push(parsed[expected - 1]);
        }
        lines.push(line);
        if errors.len() >= MAX_REPORTED {
            break;
        }
    }
    if !errors.is_empty() {
        errors.truncate(MAX_REPORTED);
        return Err(RecordError::Invalid(errors));
    }
    if let Some(dt) = interval {
        if sampling_rate.is_some() {
            return Err(invalid(
                "/sampling_rate",
                "this record gives its interval in its header (`dt=`); give one or the other",
            ));
        }
        return Ok((
            Table {
                time: (0..values.len()).map(|k| k as f64 * dt).collect(),
                values,
            },
            lines,
        ));
    }
    match (columns, sampling_rate) {
        (Some(2), Some(_)) => Err(invalid(
            "/sampling_rate",
            "this record has a time column; a sampling rate applies to the acceleration alone",
        )),
        (Some(1), None) => Err(invalid(
            "/sampling_rate",
            "a record of accelerations alone needs its sampling rate (samples per second), \
             e.g. `?sampling_rate=200`",
        )),
        (Some(1), Some(rate)) => {
            check_rate(rate, "/sampling_rate")?;
            Ok((
                Table {
                    time: uniform_times(values.len(), rate),
                    values,
                },
                lines,
            ))
        }
        _ => Ok((Table { time, values }, lines)),
    }
}

/// The interval of a `dt=0.005` header line (also `dt,0.005`, `dt: 0.005 s`), `None`
/// for any other line.
fn interval_header(content: &str, line: usize) -> Result<Option<f64>, RecordError> {
    let lower = content.to_ascii_lowercase();
    let Some(rest) = lower.strip_prefix("dt") else {
        return Ok(None);
    };
    let rest = rest.trim_start();
    let Some(value) = rest.strip_prefix(['=', ',', ':']) else {
        return Ok(None);
    };
    let value = value.trim();
    let value = value.strip_suffix('s').unwrap_or(value).trim();
    match value.parse::<f64>() {
        Ok(dt) if dt.is_finite() && dt > 0.0 => Ok(Some(dt)),
        _ => Err(invalid(
            "/dt",
            format!("line {line}: the interval `{value}` is not a positive number of seconds"),
        )),
    }
}

/// The column count a header line announces.
fn header(fields: &[&str], line: usize) -> Result<usize, RecordError> {
    let names: Vec<String> = fields.iter().map(|f| f.to_ascii_lowercase()).collect();
    match names.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        ["time", "acceleration"] => Ok(2),
        ["acceleration"] => Ok(1),
        _ => Err(invalid(
            "",
            format!(
                "line {line}: the header `{}` is not `time,acceleration` nor `acceleration`",
                fields.join(",")
            ),
        )),
    }
}

/// The JSON record: `time` with `acceleration`, or `sampling_rate` with `acceleration`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonRecord {
    time: Option<Vec<f64>>,
    sampling_rate: Option<f64>,
    acceleration: Vec<f64>,
    unit: Option<AccelerationUnit>,
}

fn parse_json(text: &str) -> Result<(Table, Option<AccelerationUnit>), RecordError> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| RecordError::Malformed(format!("the body is not JSON: {e}")))?;
    let record: JsonRecord = serde_path_to_error::deserialize(&value).map_err(|error| {
        let pointer = crate::pointer::pointer_of(error.path());
        invalid(pointer, error.into_inner().to_string())
    })?;
    let unit = record.unit;
    let table = match (record.time, record.sampling_rate) {
        (Some(_), Some(_)) => Err(invalid(
            "/sampling_rate",
            "give `time` or `sampling_rate`, not both",
        )),
        (None, None) => Err(invalid(
            "/time",
            "is required (or `sampling_rate`, for samples evenly spaced from t = 0)",
        )),
        (Some(time), None) => {
            if time.len() != record.acceleration.len() {
                return Err(invalid(
                    "/acceleration",
                    format!(
                        "has {} samples but `time` has {}",
                        record.acceleration.len(),
                        time.len()
                    ),
                ));
            }
            Ok(Table {
                time,
                values: record.acceleration,
            })
        }
        (None, Some(rate)) => {
            check_rate(rate, "/sampling_rate")?;
            Ok(Table {
                time: uniform_times(record.acceleration.len(), rate),
                values: record.acceleration,
            })
        }
    }?;
    Ok((table, unit))
}

/// At least two samples; times non-negative and strictly increasing; an Arias intensity
/// that a number can hold.
fn check(record: &Table, lines: &[usize]) -> Result<(), RecordError> {
    check_samples(record, lines)?;
    check_intensity(record)
}

/// The record's Arias intensity π/(2g) ∫ a² dt must be finite (at most `f64::MAX`,
/// about 1.8e308 m/s): computed without overflow, it is infinite only for
/// accelerations of order 1e154 m/s² held for seconds, or larger.
fn check_intensity(record: &Table) -> Result<(), RecordError> {
    match crate::physics::accelerogram::RecordSummary::of(record) {
        Some(summary) if !summary.arias_intensity.is_finite() => Err(invalid(
            "/acceleration",
            format!(
                "the record's Arias intensity π/(2g)∫a²dt exceeds the largest representable \
                 number ({:e} m/s): accelerations of {:e} m/s² are too large (keep the intensity \
                 at most {:e} m/s)",
                f64::MAX,
                summary.pga,
                f64::MAX
            ),
        )),
        _ => Ok(()),
    }
}

/// At least two samples; times non-negative and strictly increasing.
fn check_samples(record: &Table, lines: &[usize]) -> Result<(), RecordError> {
    let at_line = |k: usize| {
        lines
            .get(k)
            .map_or(String::new(), |line| format!("line {line}: "))
    };
    if record.time.len() < 2 {
        return Err(invalid(
            "/acceleration",
            format!("a record needs at least 2 samples, got {}", record.time.len()),
        ));
    }
    let mut errors = Vec::new();
    for (k, &t) in record.time.iter().enumerate() {
        if t < 0.0 {
            errors.push(FieldError::new(
                format!("/time/{k}"),
                format!("{}time {t} s is negative (a record starts at t ≥ 0)", at_line(k)),
            ));
        } else if k > 0 && t <= record.time[k - 1] {
            errors.push(FieldError::new(
                format!("/time/{k}"),
                format!(
                    "{}time {t} s does not follow {} s: times must be strictly increasing",
                    at_line(k),
                    record.time[k - 1]
                ),
            ));
        }
        if errors.len() >= MAX_REPORTED {
            break;
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(RecordError::Invalid(errors))
    }
}

/// The record as CSV lines `time,acceleration` (with that header), each number as
/// [`crate::csv_format`] writes it, produced `rows` lines at a time.
pub fn csv_chunks(record: Arc<Table>, rows: usize) -> impl Iterator<Item = String> + Send + 'static {
    let rows = rows.max(1);
    let header = std::iter::once("time,acceleration\n".to_owned());
    let body = (0..record.time.len()).step_by(rows).map(move |first| {
        let last = (first + rows).min(record.time.len());
        let mut chunk = String::with_capacity((last - first) * 48);
        for k in first..last {
            crate::csv_format::push_number(&mut chunk, record.time[k]);
            chunk.push(',');
            crate::csv_format::push_number(&mut chunk, record.values[k]);
            chunk.push('\n');
        }
        chunk
    });
    header.chain(body)
}

/// The record as the JSON document `{"time": [...], "acceleration": [...]}` (the upload
/// format), produced `rows` numbers at a time.
pub fn json_chunks(record: Arc<Table>, rows: usize) -> impl Iterator<Item = String> + Send + 'static {
    let rows = rows.max(1);
    let samples = record.time.len();
    let numbers = move |record: Arc<Table>, column: fn(&Table) -> &[f64]| {
        (0..samples).step_by(rows).map(move |first| {
            let values = &column(&record)[first..(first + rows).min(samples)];
            let mut text = String::with_capacity(values.len() * 24);
            for (k, v) in values.iter().enumerate() {
                if first + k > 0 {
                    text.push(',');
                }
                // serde_json writes the shortest text that reads back as the same f64.
                text.push_str(&serde_json::Value::from(*v).to_string());
            }
            text
        })
    };
    std::iter::once("{\"time\":[".to_owned())
        .chain(numbers(record.clone(), |r| &r.time))
        .chain(std::iter::once("],\"acceleration\":[".to_owned()))
        .chain(numbers(record, |r| &r.values))
        .chain(std::iter::once("]}".to_owned()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csv(text: &str, rate: Option<f64>) -> Result<Table, RecordError> {
        parse(text, RecordFormat::Csv, rate, None, 1000)
    }

    fn errors(result: Result<Table, RecordError>) -> Vec<FieldError> {
        match result {
            Err(RecordError::Invalid(errors)) => errors,
            other => panic!("expected invalid, got {other:?}"),
        }
    }

    #[test]
    fn both_csv_forms_and_both_json_forms_read_the_same_record() {
        let expected = Table {
            time: vec![0.0, 0.5, 1.0],
            values: vec![1.0, -2.0, 0.25],
        };
        assert_eq!(
            csv("time,acceleration\n0,1\n0.5,-2\n1,0.25\n", None),
            Ok(expected.clone())
        );
        assert_eq!(
            csv("# comment\r\n0,1\r\n\r\n0.5,-2\r\n1,0.25", None),
            Ok(expected.clone())
        );
        assert_eq!(
            csv("acceleration\n1\n-2\n0.25\n", Some(2.0)),
            Ok(expected.clone())
        );
        let json = r#"{"time": [0, 0.5, 1], "acceleration": [1, -2, 0.25]}"#;
        assert_eq!(
            parse(json, RecordFormat::Json, None, None, 10),
            Ok(expected.clone())
        );
        let json = r#"{"sampling_rate": 2, "acceleration": [1, -2, 0.25]}"#;
        assert_eq!(parse(json, RecordFormat::Json, None, None, 10), Ok(expected));
    }

    #[test]
    fn a_bad_number_is_reported_with_its_line_and_sample() {
        let found = errors(csv("time,acceleration\n0,1\n\n0.5,abc\n1,NaN\n", None));
        assert_eq!(found[0].pointer, "/acceleration/1");
        assert!(found[0].detail.starts_with("line 4:"), "{}", found[0].detail);
        assert_eq!(found[1].pointer, "/acceleration/2");
        assert!(
            found[1].detail.starts_with("line 5: `NaN`"),
            "{}",
            found[1].detail
        );
    }

    #[test]
    fn times_must_increase_and_rates_be_positive() {
        let found = errors(csv("0,1\n0.5,2\n0.5,3\n", None));
        assert_eq!(found[0].pointer, "/time/2");
        assert!(found[0].detail.starts_with("line 3:"), "{}", found[0].detail);
        let found = errors(csv("acceleration\n1\n2\n", Some(0.0)));
        assert_eq!(found[0].pointer, "/sampling_rate");
        let found = errors(csv("acceleration\n1\n2\n", None));
        assert_eq!(found[0].pointer, "/sampling_rate");
        let found = errors(parse(
            r#"{"sampling_rate": -5, "acceleration": [1, 2]}"#,
            RecordFormat::Json,
            None,
            None,
            10,
        ));
        assert_eq!(found[0].pointer, "/sampling_rate");
    }

    #[test]
    fn too_many_samples_name_the_limit() {
        assert_eq!(
            parse("0,1\n1,2\n2,3\n", RecordFormat::Csv, None, None, 2),
            Err(RecordError::TooLarge { samples: 3, limit: 2 })
        );
    }

    #[test]
    fn the_streamed_forms_read_back_bit_for_bit() {
        let record = Table {
            time: (0..7).map(|k| k as f64 / 3.0).collect(),
            values: (0..7).map(|k| (k as f64).sin() * 1e-3).collect(),
        };
        let text: String = csv_chunks(Arc::new(record.clone()), 3).collect();
        assert_eq!(csv(&text, None), Ok(record.clone()));
        let text: String = json_chunks(Arc::new(record.clone()), 3).collect();
        assert_eq!(parse(&text, RecordFormat::Json, None, None, 10), Ok(record));
    }

    /// A record in g, as an NGA-West2 AT2 file (4 samples on two lines, the values of a
    /// half cycle), as a one-column text with a `dt=` header and `unit` g, and as JSON
    /// with `"unit": "g"`: all three are the same record in m/s², 9.80665 × each value.
    #[test]
    fn a_record_in_g_is_stored_in_metres_per_second_squared_whatever_its_format() {
        let g = [0.0, 0.5e-1, -0.25, 0.125e-2];
        let expected = Table {
            time: vec![0.0, 0.01, 0.02, 0.03],
            values: g.iter().map(|a| a * STANDARD_GRAVITY).collect(),
        };
        let at2 = "PEER NGA STRONG MOTION DATABASE RECORD\n\
                   Somewhere, 1/1/2000, Station, 090\n\
                   ACCELERATION TIME SERIES IN UNITS OF G\n\
                   NPTS=     4, DT=   .0100 SEC\n\
                   \x20 .0000000E+00  .5000000E-01 -.2500000E+00\n\
                   \x20 .1250000E-02\n";
        let read = parse(at2, RecordFormat::Csv, None, None, 100).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(read.time.len(), 4);
        for (got, want) in read.values.iter().zip(&expected.values) {
            assert!((got - want).abs() <= 1e-15 * want.abs(), "{read:?}");
        }
        for (got, want) in read.time.iter().zip(&expected.time) {
            assert!((got - want).abs() < 1e-15, "{read:?}");
        }
        // The layout of the older files: count and interval first.
        let older = at2.replace("NPTS=     4, DT=   .0100 SEC", "    4    0.0100    NPTS, DT");
        assert_eq!(
            parse(&older, RecordFormat::Csv, None, None, 100),
            Ok(read.clone())
        );
        let column = "dt=0.01\n0\n0.05\n-0.25\n0.00125\n";
        let in_g = Some(AccelerationUnit::G);
        assert_eq!(
            parse(column, RecordFormat::Csv, None, in_g, 100),
            Ok(read.clone())
        );
        let json = r#"{"sampling_rate": 100, "acceleration": [0, 0.05, -0.25, 0.00125], "unit": "g"}"#;
        let from_json = parse(json, RecordFormat::Json, None, None, 100).unwrap_or_else(|e| panic!("{e}"));
        for (got, want) in from_json.values.iter().zip(&read.values) {
            assert!((got - want).abs() <= 1e-15 * want.abs(), "{from_json:?}");
        }
    }

    #[test]
    fn an_at2_file_that_contradicts_itself_is_refused_at_its_pointer() {
        let at2 = |count: &str, third: &str, unit: Option<AccelerationUnit>| {
            let text = format!("PEER\ntitle\n{third}\nNPTS= {count}, DT= .005 SEC\n1.0 2.0\n3.0\n");
            errors(parse(&text, RecordFormat::Csv, None, unit, 100))
        };
        let found = at2("4", "ACCELERATION IN UNITS OF G", None);
        assert_eq!(found[0].pointer, "/acceleration");
        assert!(
            found[0].detail.contains("3 samples") && found[0].detail.contains("NPTS = 4"),
            "{found:?}"
        );
        let found = at2("3", "VELOCITY IN UNITS OF CM/S", None);
        assert!(
            found[0].detail.contains("not an acceleration record"),
            "{found:?}"
        );
        let found = at2(
            "3",
            "ACCELERATION IN UNITS OF G",
            Some(AccelerationUnit::MetresPerSecondSquared),
        );
        assert_eq!(found[0].pointer, "/unit");
        let found = at2("x", "ACCELERATION IN UNITS OF G", None);
        assert_eq!(found[0].pointer, "/dt");
        let found = errors(parse("dt=-1\n1\n2\n", RecordFormat::Csv, None, None, 100));
        assert_eq!(found[0].pointer, "/dt");
        let found = errors(parse("dt=0.1\n1\n2\n", RecordFormat::Csv, Some(10.0), None, 100));
        assert_eq!(found[0].pointer, "/sampling_rate");
    }
}
