//! What a results document says about its own accuracy, put in the words users see
//! wherever they look: the job's status message, the CLI's warning, a sweep's counts.
//!
//! Every process writes `quality.verdict` (`good`, `unchecked`, `doubtful`, `poor`) and
//! `quality.reasons` (sentences) into its results document. A `good` result needs no
//! note; any other carries its verdict and reasons everywhere, while
//! the job itself stays `successful` (the numbers exist, they are just not to be trusted
//! blindly). A leaf module: the worker, the reuse of results, the CLI and the sweep
//! aggregates all read the verdict the same way.

use std::fmt;

use serde_json::Value;

use crate::physics::integrate::Verdict;

/// The status message of a job that ended with results.
pub const FINISHED: &str = "finished";

/// The verdict a results document states, `None` when it states none (a process
/// without a quality section) or an unknown one.
pub fn verdict_of(document: &Value) -> Option<Verdict> {
    parse_verdict(document.pointer("/quality/verdict")?.as_str()?)
}

/// `good`, `unchecked`, `doubtful` or `poor` as a [`Verdict`].
pub fn parse_verdict(name: &str) -> Option<Verdict> {
    Verdict::ALL.into_iter().find(|verdict| verdict.as_str() == name)
}

/// A verdict other than `good`, with its reasons.
#[derive(Debug, Clone, PartialEq)]
pub struct QualityNote {
    pub verdict: Verdict,
    /// Why, one sentence each (from `quality.reasons`).
    pub reasons: Vec<String>,
}

impl QualityNote {
    /// The note of a results document: `None` when its verdict is `good` or absent.
    pub fn of(document: &Value) -> Option<Self> {
        let verdict = verdict_of(document).filter(|v| *v != Verdict::Good)?;
        let reasons = document
            .pointer("/quality/reasons")
            .and_then(Value::as_array)
            .map(|reasons| {
                reasons
                    .iter()
                    .filter_map(Value::as_str)
                    .map(str::to_owned)
                    .collect()
            })
            .unwrap_or_default();
        Some(Self { verdict, reasons })
    }
}

impl fmt::Display for QualityNote {
    /// `quality poor: <reason>; <reason>` (or `quality poor` without reasons).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "quality {}", self.verdict.as_str())?;
        if !self.reasons.is_empty() {
            write!(f, ": {}", self.reasons.join("; "))?;
        }
        Ok(())
    }
}

/// The status message of a job that ended with `document`: `finished`, or when the
/// verdict is not good `finished; quality poor: <reason>; <reason>`. `origin` names
/// where the results came from when not computed by the job itself (`reused the results
/// of job …`), placed after `finished: `.
pub fn finished_message(document: &Value, origin: Option<&str>) -> String {
    let mut message = match origin {
        Some(origin) => format!("{FINISHED}: {origin}"),
        None => FINISHED.to_owned(),
    };
    if let Some(note) = QualityNote::of(document) {
        message.push_str("; ");
        message.push_str(&note.to_string());
    }
    message
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_good_result_or_one_without_quality_just_finished() {
        let good = json!({"quality": {"verdict": "good", "reasons": []}});
        assert_eq!(finished_message(&good, None), "finished");
        assert_eq!(finished_message(&json!({"sum": 3}), None), "finished");
        assert_eq!(QualityNote::of(&good), None);
    }

    #[test]
    fn a_poor_result_says_so_with_every_reason_in_order() {
        let poor = json!({"quality": {"verdict": "poor", "reasons": ["first reason", "second reason"]}});
        assert_eq!(
            finished_message(&poor, None),
            "finished; quality poor: first reason; second reason"
        );
        assert_eq!(
            finished_message(&poor, Some("reused the results of job a")),
            "finished: reused the results of job a; quality poor: first reason; second reason"
        );
    }

    #[test]
    fn a_doubtful_result_without_reasons_still_names_its_verdict() {
        let doubtful = json!({"quality": {"verdict": "doubtful"}});
        assert_eq!(finished_message(&doubtful, None), "finished; quality doubtful");
    }

    #[test]
    fn verdict_names_parse_back_and_unknown_ones_do_not() {
        for verdict in Verdict::ALL {
            assert_eq!(parse_verdict(verdict.as_str()), Some(verdict));
        }
        assert_eq!(parse_verdict("excellent"), None);
    }
}
