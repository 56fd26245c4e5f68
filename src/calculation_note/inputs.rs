//! The note's inputs section: every member of the submitted inputs as a row, at the JSON
//! pointer the API's errors use (`/inputs/pin/length`), values as submitted. Long lists
//! (a table excitation, a list of 180 contacts) show their first and last entries and
//! how many are left out: the inputs hash identifies the whole, and the service gives it
//! back (`/jobs/{jobId}/inputs`).

use std::fmt::Write;

use serde_json::Value;

use super::escape;
use super::open_section;

/// Entries of a list shown in full below this length.
const SHOWN_ENTRIES: usize = 12;
/// Entries shown at the head and at the tail of a longer list.
const HEAD: usize = 6;
const TAIL: usize = 2;

/// One row: the member's pointer and its value as text (or what was left out).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Row {
    pub pointer: String,
    pub value: String,
    /// Whether the value stands for entries left out.
    pub elided: bool,
}

/// `~` and `/` escaped in a pointer token (RFC 6901).
fn token(name: &str) -> String {
    name.replace('~', "~0").replace('/', "~1")
}

fn scalar(value: &Value) -> Option<String> {
    match value {
        Value::Null => Some("null".into()),
        Value::Bool(b) => Some(b.to_string()),
        Value::Number(n) => Some(n.to_string()),
        Value::String(s) => Some(format!("\"{s}\"")),
        _ => None,
    }
}

/// The rows of `value` at `pointer`.
pub(super) fn rows(value: &Value, pointer: &str, out: &mut Vec<Row>) {
    match value {
        Value::Object(members) if !members.is_empty() => {
            for (name, member) in members {
                rows(member, &format!("{pointer}/{}", token(name)), out);
            }
        }
        Value::Array(items) if !items.is_empty() => {
            let scalars: Option<Vec<String>> = items.iter().map(scalar).collect();
            match scalars {
                Some(texts) if texts.len() <= SHOWN_ENTRIES => out.push(Row {
                    pointer: pointer.to_owned(),
                    value: format!("[{}]", texts.join(", ")),
                    elided: false,
                }),
                Some(texts) => out.push(Row {
                    pointer: pointer.to_owned(),
                    value: format!(
                        "[{}, … {} more …, {}] ({} values)",
                        texts[..HEAD].join(", "),
                        texts.len() - HEAD - TAIL,
                        texts[texts.len() - TAIL..].join(", "),
                        texts.len()
                    ),
                    elided: true,
                }),
                None => {
                    let long = items.len() > SHOWN_ENTRIES;
                    for (k, item) in items.iter().enumerate() {
                        if long && k == HEAD {
                            out.push(Row {
                                pointer: format!("{pointer}/{HEAD}…{}", items.len() - TAIL - 1),
                                value: format!(
                                    "{} entries not shown ({} in all)",
                                    items.len() - HEAD - TAIL,
                                    items.len()
                                ),
                                elided: true,
                            });
                        }
                        if long && (HEAD..items.len() - TAIL).contains(&k) {
                            continue;
                        }
                        rows(item, &format!("{pointer}/{k}"), out);
                    }
                }
            }
        }
        other => out.push(Row {
            pointer: pointer.to_owned(),
            value: scalar(other).unwrap_or_else(|| other.to_string()),
            elided: false,
        }),
    }
}

/// The section: the rows of `inputs`, and where the whole is.
pub(super) fn section(page: &mut String, inputs: &Value, job_id: Option<&str>) {
    open_section(page, "inputs", "Inputs");
    let mut all = Vec::new();
    rows(inputs, "/inputs", &mut all);
    let whole = match job_id {
        Some(job) => format!(
            "the whole request: <a class=\"mono\" href=\"/jobs/{0}/inputs\">/jobs/{0}/inputs</a>",
            escape(job)
        ),
        None => "the whole request: the body file given to <code>chocmodal run</code>".to_owned(),
    };
    let _ = write!(
        page,
        "<p class=\"lead\">As submitted (SI units: m, s, N, kg, Pa; members left out take their \
         defaults, listed by <code>/processes/{{processId}}</code>). Long lists show their first \
         and last entries; the inputs SHA-256 above identifies {whole}.</p>\
         <table class=\"inputs\" data-rows=\"{}\"><thead><tr><th>member</th><th>value</th></tr></thead><tbody>",
        all.len()
    );
    for row in &all {
        let _ = write!(
            page,
            "<tr{}><td class=\"mono\">{}</td><td class=\"mono\">{}</td></tr>",
            if row.elided {
                " class=\"muted\" data-elided"
            } else {
                " data-input"
            },
            escape(&row.pointer),
            escape(&row.value)
        );
    }
    page.push_str("</tbody></table></section>");
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn every_member_is_a_row_at_its_pointer_and_long_lists_are_cut_in_the_middle() {
        let inputs = json!({"pin": {"length": 1.8, "section": {"type": "tube"}},
                            "a/b": [1, 2, 3],
                            "table": (0..100).collect::<Vec<i32>>(),
                            "contacts": (0..20).map(|k| json!({"gap": k})).collect::<Vec<_>>()});
        let mut out = Vec::new();
        rows(&inputs, "/inputs", &mut out);
        let find = |p: &str| out.iter().find(|r| r.pointer == p).map(|r| r.value.clone());
        assert_eq!(find("/inputs/pin/length").as_deref(), Some("1.8"));
        assert_eq!(find("/inputs/pin/section/type").as_deref(), Some("\"tube\""));
        assert_eq!(find("/inputs/a~1b").as_deref(), Some("[1, 2, 3]"));
        assert_eq!(
            find("/inputs/table").as_deref(),
            Some("[0, 1, 2, 3, 4, 5, … 92 more …, 98, 99] (100 values)")
        );
        assert_eq!(find("/inputs/contacts/5/gap").as_deref(), Some("5"));
        assert_eq!(find("/inputs/contacts/6/gap"), None);
        assert_eq!(find("/inputs/contacts/18/gap").as_deref(), Some("18"));
        assert_eq!(
            find("/inputs/contacts/6…17").as_deref(),
            Some("12 entries not shown (20 in all)")
        );
    }
}
