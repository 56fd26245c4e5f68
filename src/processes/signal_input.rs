//! The `signal` base acceleration: a stored accelerogram referenced by its id (the
//! service) or a record file (`chocmodal run`), times a `scale`.
//!
//! # Why the job keeps the reference, not the samples
//! A recorded accelerogram holds tens or hundreds of thousands of samples. A job keeps
//! `{"type": "signal", "id", "scale"}` as its inputs, and the worker loads the samples
//! when it runs the job, because:
//! - the record is stored once (`POST /signals`), not once per job: a sweep of a thousand
//!   scales over a 200 000-sample record would otherwise store 8 GB of JSON;
//! - a stored signal never changes (there is no update), so the id names exactly the
//!   samples the job was validated with, and the content hash of identical inputs
//!   (job reuse) stays meaningful;
//! - the job stays durable: a signal cannot be deleted while a queued or running job of
//!   its tenant refers to it (`DELETE /signals/{id}` is then a 409), so a job claimed
//!   again after a crash finds its record. Once finished a job has its results; only a
//!   resubmission of its inputs needs the signal again.
//!
//! The service resolves every reference when the job is submitted (an unknown id, or
//! another tenant's, is a 422 at `…/base_acceleration/id`, before anything is queued),
//! and again in the worker, from a [`SignalLibrary`] it loads for the job's tenant.

use std::collections::HashMap;
use std::sync::Arc;

use serde::Deserialize;
use utoipa::ToSchema;

use super::FieldError;
use crate::physics::InputIssue;
use crate::physics::loads::Table;

/// A signal reference in a process's inputs and the JSON pointer of its object.
pub type SignalSlot<'a> = (String, &'a mut SignalInput);

/// A stored accelerogram as a base acceleration: `scale` × the record, linear between
/// samples, 0 outside them.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SignalInput {
    /// Id of a signal uploaded with `POST /signals` (`GET /signals` lists them). For
    /// `chocmodal run`, the path of a record file (CSV or JSON, as `POST /signals` takes).
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = String)]
    pub id: Option<String>,
    /// `chocmodal run` only: the path of a record file (CSV `time,acceleration`, or
    /// JSON `{"time", "acceleration"}`), relative to the job file. The service refuses
    /// it: upload the record and give its `id`.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = String)]
    pub path: Option<String>,
    /// Factor on every sample (dimensionless, signed): a sweep over it scales the record.
    #[serde(default = "one")]
    #[schema(default = 1.0)]
    pub scale: f64,
    /// The record, attached by [`SignalInput::resolve`] (not an input).
    #[serde(skip)]
    record: Attached,
}

fn one() -> f64 {
    1.0
}

/// A field that may be left out but not given as null.
fn present<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(
    deserializer: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(deserializer).map(Some)
}

/// The record a reference resolved to; derived data, so it takes no part in equality.
#[derive(Debug, Clone, Default)]
struct Attached(Option<Arc<Table>>);

impl PartialEq for Attached {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Where the records of a [`SignalLibrary`] come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SignalSource {
    /// Signals stored by the service, by id: `path` is refused.
    #[default]
    Stored,
    /// Files read by `chocmodal run`, by the path given as `path` or `id`.
    Files,
}

/// The records signal references resolve to: by id (the service, for one tenant) or by
/// file path (the CLI), each loaded once and shared by every run that uses it.
#[derive(Debug, Clone, Default)]
pub struct SignalLibrary {
    source: SignalSource,
    /// Record, or why the reference cannot be read (a file's parse error).
    records: HashMap<String, Result<Arc<Table>, String>>,
}

impl SignalLibrary {
    /// An empty library of `source`: every reference is unknown until inserted.
    pub fn new(source: SignalSource) -> Self {
        Self {
            source,
            records: HashMap::new(),
        }
    }

    /// Adds the record known as `key` (an id or a path).
    pub fn insert(&mut self, key: impl Into<String>, record: Arc<Table>) {
        self.records.insert(key.into(), Ok(record));
    }

    /// Records that `key` names no usable record, and why (shown at its pointer).
    pub fn insert_error(&mut self, key: impl Into<String>, why: impl Into<String>) {
        self.records.insert(key.into(), Err(why.into()));
    }

    pub fn source(&self) -> SignalSource {
        self.source
    }

    fn get(&self, key: &str) -> Option<&Result<Arc<Table>, String>> {
        self.records.get(key)
    }
}

/// Every string an execution request or sweep holds where a signal reference could
/// name its record: the `id` and `path` members of `{"type": "signal"}` objects, and
/// every string of a list (a sweep axis over ids). Loading more than is used is
/// harmless; a reference missed here is reported unknown by [`SignalInput::resolve`].
pub fn referenced_keys(document: &serde_json::Value) -> Vec<String> {
    keys(document, true)
}

/// The `id` and `path` members of the `{"type": "signal"}` objects of `document`.
pub fn signal_keys(document: &serde_json::Value) -> Vec<String> {
    keys(document, false)
}

fn keys(document: &serde_json::Value, listed: bool) -> Vec<String> {
    fn walk(value: &serde_json::Value, in_list: bool, listed: bool, keys: &mut Vec<String>) {
        match value {
            serde_json::Value::Object(map) => {
                if map.get("type").and_then(|t| t.as_str()) == Some("signal") {
                    for member in ["id", "path"] {
                        if let Some(key) = map.get(member).and_then(|v| v.as_str()) {
                            keys.push(key.to_owned());
                        }
                    }
                }
                map.values().for_each(|child| walk(child, false, listed, keys));
            }
            serde_json::Value::Array(items) => items.iter().for_each(|child| walk(child, true, listed, keys)),
            serde_json::Value::String(text) if in_list && listed => keys.push(text.clone()),
            _ => {}
        }
    }
    let mut keys = Vec::new();
    walk(document, false, listed, &mut keys);
    keys.sort();
    keys.dedup();
    keys
}

impl SignalInput {
    /// Attaches the record this reference names from `library`; `pointer` is the
    /// signal object's own (`/inputs/excitation/base_acceleration`).
    pub fn resolve(&mut self, library: &SignalLibrary, pointer: &str) -> Result<(), FieldError> {
        let (key, member) = match (&self.id, &self.path) {
            (Some(_), Some(_)) => {
                return Err(FieldError::new(
                    format!("{pointer}/path"),
                    "give the signal's `id` or a file `path`, not both",
                ));
            }
            (None, None) => {
                return Err(FieldError::new(
                    format!("{pointer}/id"),
                    "is required: the id of a signal uploaded with POST /signals",
                ));
            }
            (Some(id), None) => (id, "id"),
            (None, Some(path)) => (path, "path"),
        };
        if member == "path" && library.source() == SignalSource::Stored {
            return Err(FieldError::new(
                format!("{pointer}/path"),
                "a record file is read only by `chocmodal run`: upload it with POST /signals and give its `id`",
            ));
        }
        match library.get(key) {
            Some(Ok(record)) => {
                self.record = Attached(Some(record.clone()));
                Ok(())
            }
            Some(Err(why)) => Err(FieldError::new(format!("{pointer}/{member}"), why.clone())),
            None => Err(FieldError::new(
                format!("{pointer}/{member}"),
                match library.source() {
                    SignalSource::Stored => {
                        format!("there is no signal `{key}` (GET /signals lists yours)")
                    }
                    SignalSource::Files => format!("cannot read the record file `{key}`"),
                },
            )),
        }
    }

    /// The attached record (`None` before [`Self::resolve`] succeeded).
    pub fn record(&self) -> Option<&Table> {
        self.record.0.as_deref()
    }

    /// Problems with the scale (fields relative to the excitation object): finite, and
    /// small enough that the scaled record stays finite.
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if !self.scale.is_finite() {
            issues.push(InputIssue::new("scale", "must be a finite number"));
        } else if let Some(record) = self.record() {
            let pga = record.values.iter().fold(0.0f64, |peak, a| peak.max(a.abs()));
            if !(self.scale * pga).is_finite() {
                issues.push(InputIssue::new(
                    "scale",
                    format!("scales the peak acceleration {pga} m/s² beyond any finite number"),
                ));
            }
        }
        issues
    }

    /// The scaled record (time in s, acceleration in m/s²); an empty table (no
    /// excitation) before [`Self::resolve`] succeeded.
    pub fn table(&self) -> Table {
        match self.record() {
            Some(record) => Table {
                time: record.time.clone(),
                values: record.values.iter().map(|a| self.scale * a).collect(),
            },
            None => Table {
                time: Vec::new(),
                values: Vec::new(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    fn record() -> Arc<Table> {
        Arc::new(Table {
            time: vec![0.0, 0.5, 1.0],
            values: vec![0.0, 2.0, -1.0],
        })
    }

    fn reference(value: serde_json::Value) -> SignalInput {
        serde_json::from_value(value).unwrap()
    }

    #[test]
    fn a_known_id_attaches_its_record_scaled() {
        let mut library = SignalLibrary::new(SignalSource::Stored);
        library.insert("abc", record());
        let mut signal = reference(json!({"id": "abc", "scale": -2.0}));
        signal.resolve(&library, "/inputs/x").unwrap();
        assert_eq!(signal.table().values, vec![-0.0, -4.0, 2.0]);
        assert!(signal.validate().is_empty());
    }

    #[test]
    fn unknown_ids_and_paths_in_the_service_are_refused_at_their_member() {
        let library = SignalLibrary::new(SignalSource::Stored);
        let error = reference(json!({"id": "nope"}))
            .resolve(&library, "/inputs/x")
            .unwrap_err();
        assert_eq!(error.pointer, "/inputs/x/id");
        assert!(error.detail.contains("no signal `nope`"), "{}", error.detail);
        let error = reference(json!({"path": "a.csv"}))
            .resolve(&library, "/inputs/x")
            .unwrap_err();
        assert_eq!(error.pointer, "/inputs/x/path");
        let error = reference(json!({})).resolve(&library, "/inputs/x").unwrap_err();
        assert_eq!(error.pointer, "/inputs/x/id");
    }

    #[test]
    fn referenced_keys_are_signal_members_and_listed_strings() {
        let body = json!({"inputs": {"excitation": {"base_acceleration": {"type": "signal", "id": "a", "scale": 2}},
                          "section": {"type": "tube"}},
                          "axes": [{"pointer": "/excitation/base_acceleration/id", "values": ["b", "a"]}]});
        assert_eq!(referenced_keys(&body), vec!["a", "b"]);
        assert_eq!(signal_keys(&body), vec!["a"]);
    }
}
