//! The member at fault when a tagged object fails to parse.
//!
//! serde reads an internally tagged object (`{"type": "random", "seed": -1, ...}`) whole
//! before it knows which variant it is, so a wrong value inside it (a negative seed, a
//! string for a number) is reported at the object, not at the member. The inputs'
//! schema knows each member's type: [`locate`] finds the member whose value does not
//! fit it, so that the refusal points at it (`/inputs/bundle/gaps/seed`).

use serde_json::{Map, Value};

/// The alternatives of `schema` (`oneOf`/`anyOf`, flattened; itself when it has none).
fn alternatives(schema: &Value) -> Vec<&Value> {
    match schema["oneOf"].as_array().or(schema["anyOf"].as_array()) {
        Some(options) => options.iter().flat_map(alternatives).collect(),
        None => vec![schema],
    }
}

/// The properties of an object schema, its `allOf` parts' included.
fn properties(schema: &Value) -> Map<String, Value> {
    let mut out = schema["properties"].as_object().cloned().unwrap_or_default();
    for part in schema["allOf"].as_array().into_iter().flatten() {
        out.extend(properties(part));
    }
    out
}

/// The alternative of `schema` an object `value` takes: the one whose `type` tag it
/// names, else the only object alternative.
fn object_alternative<'a>(schema: &'a Value, value: &Map<String, Value>) -> Option<&'a Value> {
    let objects: Vec<&Value> = alternatives(schema)
        .into_iter()
        .filter(|o| !properties(o).is_empty() || o["type"] == "object")
        .collect();
    match value.get("type").and_then(Value::as_str) {
        Some(tag) => objects.into_iter().find(|o| {
            properties(o)
                .get("type")
                .and_then(|t| t["enum"].as_array())
                .is_some_and(|names| names.iter().any(|n| n == tag))
        }),
        None if objects.len() == 1 => objects.first().copied(),
        None => None,
    }
}

/// Whether `value` is of a JSON type `schema` (one of its alternatives) allows; a
/// schema that names no type allows any.
fn fits(schema: &Value, value: &Value) -> bool {
    alternatives(schema).into_iter().any(|option| {
        let kinds: Vec<&str> = match &option["type"] {
            Value::String(kind) => vec![kind.as_str()],
            Value::Array(kinds) => kinds.iter().filter_map(Value::as_str).collect(),
            _ => return true,
        };
        kinds.into_iter().any(|kind| match (kind, value) {
            ("integer", Value::Number(n)) => {
                n.is_u64() || (n.is_i64() && option["minimum"].as_f64().is_none_or(|m| m < 0.0))
            }
            ("number", Value::Number(_)) | ("boolean", Value::Bool(_)) | ("null", Value::Null) => true,
            ("string", Value::String(s)) => option["enum"]
                .as_array()
                .is_none_or(|names| names.iter().any(|n| n == s)),
            ("array", Value::Array(_)) | ("object", Value::Object(_)) => true,
            _ => false,
        })
    })
}

fn escape(name: &str) -> String {
    name.replace('~', "~0").replace('/', "~1")
}

/// The deepest member of `value` (at `at`, described by `schema`) whose value does not
/// fit its schema's type, and its pointer.
fn deepest(schema: &Value, value: &Value, at: &str) -> Option<String> {
    match value {
        Value::Object(members) => {
            let properties = properties(object_alternative(schema, members)?);
            members.iter().find_map(|(name, member)| {
                let member_schema = properties.get(name)?;
                let pointer = format!("{at}/{}", escape(name));
                deepest(member_schema, member, &pointer)
                    .or_else(|| (!fits(member_schema, member)).then_some(pointer))
            })
        }
        Value::Array(items) => {
            let item_schema = alternatives(schema).into_iter().find_map(|o| o.get("items"))?;
            items.iter().enumerate().find_map(|(index, item)| {
                let pointer = format!("{at}/{index}");
                deepest(item_schema, item, &pointer).or_else(|| (!fits(item_schema, item)).then_some(pointer))
            })
        }
        _ => None,
    }
}

/// The schema of the member at `pointer` in `value` (described by `schema`), the
/// alternatives on the way chosen by the value.
fn schema_at<'a>(schema: &'a Value, value: &Value, pointer: &str) -> Option<&'a Value> {
    let mut schema = schema;
    let mut value = value;
    for token in pointer.split('/').skip(1) {
        let name = token.replace("~1", "/").replace("~0", "~");
        match value {
            Value::Object(members) => {
                let alternative = object_alternative(schema, members)?;
                schema = alternative["properties"].get(&name).or_else(|| {
                    alternative["allOf"]
                        .as_array()?
                        .iter()
                        .find_map(|part| part["properties"].get(&name))
                })?;
                value = members.get(&name)?;
            }
            Value::Array(items) => {
                schema = alternatives(schema).into_iter().find_map(|o| o.get("items"))?;
                value = items.get(name.parse::<usize>().ok()?)?;
            }
            _ => return None,
        }
    }
    Some(schema)
}

/// The pointer (relative to `inputs`, as `at` is) of the member under `at` whose value
/// does not fit the type `schema` gives it, when serde reported a failure at `at`.
pub fn locate(schema: &Value, inputs: &Value, at: &str) -> Option<String> {
    let value = inputs.pointer(at)?;
    deepest(schema_at(schema, inputs, at)?, value, at)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn schema() -> Value {
        json!({"type": "object", "properties": {"gaps": {"oneOf": [
            {"type": "object", "properties": {"type": {"type": "string", "enum": ["uniform"]}}},
            {"type": "object", "properties": {
                "type": {"type": "string", "enum": ["random"]},
                "seed": {"type": "integer", "minimum": 0},
                "distribution": {"oneOf": [
                    {"type": "object", "properties": {
                        "type": {"type": "string", "enum": ["normal"]},
                        "mean": {"type": "number"}}}]},
                "values": {"type": "array", "items": {"type": "number"}}}}]}}})
    }

    #[test]
    fn the_member_that_does_not_fit_its_type_is_found_inside_tagged_objects() {
        let schema = schema();
        for (gaps, expected) in [
            (json!({"type": "random", "seed": -1}), "/gaps/seed"),
            (json!({"type": "random", "seed": 2.5}), "/gaps/seed"),
            (
                json!({"type": "random", "seed": 1, "distribution": {"type": "normal", "mean": "x"}}),
                "/gaps/distribution/mean",
            ),
            (json!({"type": "random", "values": [1.0, "x"]}), "/gaps/values/1"),
        ] {
            let inputs = json!({ "gaps": gaps });
            assert_eq!(
                locate(&schema, &inputs, "/gaps").as_deref(),
                Some(expected),
                "{inputs}"
            );
        }
        assert_eq!(
            locate(&schema, &json!({"gaps": {"type": "random", "seed": 3}}), "/gaps"),
            None
        );
    }
}
