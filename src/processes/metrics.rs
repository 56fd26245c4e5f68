//! The scalar figures of a results document, as the metric columns of a sweep's
//! results table: the processes own what their documents hold.

use serde_json::Value;

/// Flattens a results document into `(dotted.name, scalar)` pairs: numbers, booleans
/// and strings of nested objects (`quality.verdict`), in the document's key order. Arrays
/// are left out (spectra, event lists, `quality.reasons`), and so is `outputs` (links);
/// processes add array entries they want as columns. Aggregates use the numeric columns.
pub fn flatten_scalars(document: &Value) -> Vec<(String, Value)> {
    fn walk(prefix: &str, value: &Value, out: &mut Vec<(String, Value)>) {
        match value {
            Value::Object(map) => {
                for (key, value) in map {
                    if prefix.is_empty() && key == "outputs" {
                        continue;
                    }
                    let name = if prefix.is_empty() {
                        key.clone()
                    } else {
                        format!("{prefix}.{key}")
                    };
                    walk(&name, value, out);
                }
            }
            Value::Number(_) | Value::Bool(_) | Value::String(_) => {
                out.push((prefix.to_owned(), value.clone()))
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk("", document, &mut out);
    out
}

/// The scalars of `field` (an object) in every item of the array `list`, as
/// `list.k.field.name` (`contacts.3.impact_statistics.impacts_per_second`).
pub fn item_scalars(document: &Value, list: &str, field: &str) -> Vec<(String, Value)> {
    let Some(items) = document[list].as_array() else {
        return Vec::new();
    };
    items
        .iter()
        .enumerate()
        .flat_map(|(k, item)| {
            flatten_scalars(&item[field])
                .into_iter()
                .map(move |(name, value)| (format!("{list}.{k}.{field}.{name}"), value))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn documents_flatten_to_dotted_scalars_without_arrays_or_links() {
        let doc = json!({"comparison": {"f_err": 0.1, "agrees": true}, "numerical": {"frequencies_hz": [1.0], "impacts": 3},
                         "outputs": {"x": {"href": "/jobs/a/results/x"}}, "label": "text",
                         "quality": {"verdict": "poor", "reasons": ["why"], "step_halving": null}});
        let flat = flatten_scalars(&doc);
        assert_eq!(
            flat,
            vec![
                ("comparison.agrees".to_owned(), json!(true)),
                ("comparison.f_err".to_owned(), json!(0.1)),
                ("label".to_owned(), json!("text")),
                ("numerical.impacts".to_owned(), json!(3)),
                ("quality.verdict".to_owned(), json!("poor")),
            ]
        );
    }
}
