//! Labels and a note: what a user attaches to a job to find it again and to say what
//! it was for (`"labels": ["handling-5g", "clad-B"], "note": "ticket 4512, rev. C"`).
//! They never change the computation; they are stored with the job, returned in its
//! status and the job list, and the list filters on labels (`?label=`).
//!
//! Limits (docs/service.md "Labels and notes"): at most [`MAX_LABELS`] labels, each
//! text of 1 to [`MAX_LABEL_CHARS`] characters, without control characters or
//! surrounding spaces, all different; a note of at most [`MAX_NOTE_CHARS`] characters.
//! Anything else is refused (422) at the member's pointer (`/labels/2`, `/note`).

use serde_json::Value;

use crate::processes::FieldError;

/// Most labels on one resource.
pub const MAX_LABELS: usize = 20;
/// Longest label, in characters (Unicode scalar values).
pub const MAX_LABEL_CHARS: usize = 64;
/// Longest note, in characters.
pub const MAX_NOTE_CHARS: usize = 2000;

/// A resource's labels and note, checked.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Annotations {
    pub labels: Vec<String>,
    pub note: Option<String>,
}

impl Annotations {
    /// Checks the `labels` and `note` members of a request body (each optional; `null`
    /// is the same as absent): every fault, each at its pointer.
    pub fn parse(labels: Option<&Value>, note: Option<&Value>) -> Result<Self, Vec<FieldError>> {
        let mut errors = Vec::new();
        let labels = match labels {
            None | Some(Value::Null) => Vec::new(),
            Some(Value::Array(items)) => {
                if items.len() > MAX_LABELS {
                    errors.push(FieldError::new(
                        "/labels",
                        format!("has {} labels: at most {MAX_LABELS}", items.len()),
                    ));
                }
                let mut labels: Vec<String> = Vec::with_capacity(items.len());
                for (k, item) in items.iter().enumerate() {
                    let pointer = format!("/labels/{k}");
                    match item.as_str().map(|label| (label, label_fault(label))) {
                        None => errors.push(FieldError::new(pointer, "must be text")),
                        Some((_, Some(fault))) => errors.push(FieldError::new(pointer, fault)),
                        Some((label, None)) if labels.iter().any(|l| l == label) => {
                            errors.push(FieldError::new(pointer, format!("repeats the label `{label}`")))
                        }
                        Some((label, None)) => labels.push(label.to_owned()),
                    }
                }
                labels
            }
            Some(_) => {
                errors.push(FieldError::new("/labels", "must be a list of text labels"));
                Vec::new()
            }
        };
        let note = match note {
            None | Some(Value::Null) => None,
            Some(Value::String(text)) if text.chars().count() > MAX_NOTE_CHARS => {
                errors.push(FieldError::new(
                    "/note",
                    format!(
                        "has {} characters: at most {MAX_NOTE_CHARS}",
                        text.chars().count()
                    ),
                ));
                None
            }
            Some(Value::String(text)) => Some(text.clone()),
            Some(_) => {
                errors.push(FieldError::new("/note", "must be text"));
                None
            }
        };
        if errors.is_empty() {
            Ok(Self { labels, note })
        } else {
            Err(errors)
        }
    }

    /// The labels as stored: a JSON array of text.
    pub fn labels_json(&self) -> String {
        serde_json::to_string(&self.labels).expect("text serializes")
    }
}

/// Labels as a store keeps them (a JSON array of text), read back.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct StoredLabels(pub Vec<String>);

impl TryFrom<String> for StoredLabels {
    type Error = serde_json::Error;

    fn try_from(text: String) -> Result<Self, Self::Error> {
        serde_json::from_str(&text).map(StoredLabels)
    }
}

/// What is wrong with a label, if anything (also for the values of `?label=`).
pub fn label_fault(label: &str) -> Option<String> {
    let chars = label.chars().count();
    if chars == 0 {
        Some("must not be empty".into())
    } else if chars > MAX_LABEL_CHARS {
        Some(format!("has {chars} characters: at most {MAX_LABEL_CHARS}"))
    } else if label.chars().any(char::is_control) {
        Some("must not hold control characters (line breaks, tabs)".into())
    } else if label.trim() != label {
        Some("must not start or end with a space".into())
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn pointers(labels: Value, note: Value) -> Vec<String> {
        Annotations::parse(Some(&labels), Some(&note))
            .unwrap_err()
            .into_iter()
            .map(|e| e.pointer)
            .collect()
    }

    #[test]
    fn labels_and_a_note_within_the_limits_are_kept_in_order() {
        let parsed = Annotations::parse(
            Some(&json!(["b", "a-1", "zone:B/3", "é"])),
            Some(&json!("rev. C")),
        )
        .unwrap();
        assert_eq!(parsed.labels, ["b", "a-1", "zone:B/3", "é"]);
        assert_eq!(parsed.note.as_deref(), Some("rev. C"));
        assert_eq!(parsed.labels_json(), r#"["b","a-1","zone:B/3","é"]"#);
        assert_eq!(
            Annotations::parse(None, Some(&Value::Null)),
            Ok(Annotations::default())
        );
        let longest = "x".repeat(MAX_LABEL_CHARS);
        assert!(
            Annotations::parse(Some(&json!([longest])), Some(&json!("n".repeat(MAX_NOTE_CHARS)))).is_ok()
        );
    }

    #[test]
    fn every_bad_label_and_note_is_refused_at_its_pointer() {
        assert_eq!(pointers(json!("a"), json!(null)), ["/labels"]);
        assert_eq!(
            pointers(
                json!(["ok", 3, "", "x".repeat(MAX_LABEL_CHARS + 1), "a\nb", " a", "ok"]),
                json!(4)
            ),
            [
                "/labels/1",
                "/labels/2",
                "/labels/3",
                "/labels/4",
                "/labels/5",
                "/labels/6",
                "/note"
            ]
        );
        let many: Vec<String> = (0..=MAX_LABELS).map(|k| format!("l{k}")).collect();
        assert_eq!(pointers(json!(many), json!(null)), ["/labels"]);
        assert_eq!(
            pointers(json!([]), json!("n".repeat(MAX_NOTE_CHARS + 1))),
            ["/note"]
        );
        let errors = Annotations::parse(Some(&json!([{"a": 1}])), None).unwrap_err();
        assert_eq!(errors[0].detail, "must be text");
    }
}
