//! Every missing member at once, with the inputs' other problems, in one 422.
//!
//! serde stops at the first problem, so a request missing three members would learn of
//! them on three tries, and of its value errors only after them. When parsing fails,
//! the inputs' schema ([`super::input_schema::schema_of`]) names every required member that
//! is absent, at any depth (inside the alternative a tagged object's `type` selects).
//! Each is then filled with a stand-in that validation refuses (a negative number, 0
//! for a count, the first of an enumeration, an object of stand-ins), and the filled
//! inputs are prepared as any others: their value errors are real, but for those at
//! a stand-in, which `is required` replaces. The processes already keep an error
//! derived from a refused value from showing up elsewhere (a contact stiffness from a
//! refused beam): a refused stand-in is one more refused value.

use serde::de::DeserializeOwned;
use serde_json::Value;
use utoipa::ToSchema;

use super::{FieldError, InvalidInputs, common_inputs};

/// Parses `json` as `I` and prepares it with `prepare`; a parse failure with members
/// missing reports all of them, with every other problem `prepare` finds.
pub fn prepare<I: DeserializeOwned + ToSchema, P>(
    json: &Value,
    prepare: impl FnOnce(I) -> Result<P, InvalidInputs>,
) -> Result<P, InvalidInputs> {
    let first = match common_inputs::parse::<I>(json) {
        Ok(parsed) => return prepare(parsed),
        Err(error) => error,
    };
    let mut filled = json.clone();
    let mut missing = Vec::new();
    fill(
        &mut filled,
        &super::input_schema::schema_of::<I>(),
        "/inputs",
        &mut missing,
    );
    if missing.is_empty() {
        return Err(first);
    }
    let others = match common_inputs::parse::<I>(&filled) {
        Ok(parsed) => prepare(parsed).err().map(|e| e.0).unwrap_or_default(),
        Err(error) => error.0,
    };
    let at_stand_in = |pointer: &str| {
        missing.iter().any(|m: &String| {
            pointer == m
                || pointer
                    .strip_prefix(m.as_str())
                    .is_some_and(|rest| rest.starts_with('/'))
        })
    };
    let mut errors: Vec<FieldError> = missing
        .iter()
        .map(|pointer| FieldError::new(pointer.clone(), "is required"))
        .collect();
    for error in others {
        // `/inputs` as a whole is where a model refused for a stand-in would land.
        if !at_stand_in(&error.pointer) && error.pointer != "/inputs" && !errors.contains(&error) {
            errors.push(error);
        }
    }
    Err(InvalidInputs(errors))
}

/// Adds a stand-in for every required member absent from `value` (an object described
/// by `schema`, at pointer `at`), recursively; their pointers go to `missing`.
fn fill(value: &mut Value, schema: &Value, at: &str, missing: &mut Vec<String>) {
    if let Some(parts) = schema["allOf"].as_array() {
        for part in parts {
            fill(value, part, at, missing);
        }
        return;
    }
    if let Some(options) = schema["oneOf"].as_array().or(schema["anyOf"].as_array()) {
        // A tagged object: the alternative its `type` names.
        if let Some(tag) = value.get("type").and_then(Value::as_str)
            && let Some(chosen) = options.iter().find(|o| {
                o["properties"]["type"]["enum"]
                    .as_array()
                    .is_some_and(|names| names.iter().any(|n| n == tag))
            })
        {
            fill(value, chosen, at, missing);
        }
        return;
    }
    match value {
        Value::Object(map) => {
            let Some(properties) = schema["properties"].as_object() else {
                return;
            };
            for name in schema["required"].as_array().into_iter().flatten() {
                let Some(name) = name.as_str() else { continue };
                if !map.contains_key(name)
                    && let Some(stand_in) = properties.get(name).and_then(stand_in)
                {
                    map.insert(name.to_owned(), stand_in);
                    missing.push(format!("{at}/{}", name.replace('~', "~0").replace('/', "~1")));
                }
            }
            for (name, member) in map.iter_mut() {
                if let Some(property) = properties.get(name) {
                    let pointer = format!("{at}/{}", name.replace('~', "~0").replace('/', "~1"));
                    fill(member, property, &pointer, missing);
                }
            }
        }
        Value::Array(items) => {
            for (index, item) in items.iter_mut().enumerate() {
                fill(item, &schema["items"], &format!("{at}/{index}"), missing);
            }
        }
        _ => {}
    }
}

/// A value of the type `schema` describes that validation refuses where it can: a
/// negative number, a zero count, the first keyword of an enumeration, an object of
/// stand-ins for its required members.
fn stand_in(schema: &Value) -> Option<Value> {
    if let Some(parts) = schema["allOf"].as_array() {
        return parts.iter().find_map(stand_in);
    }
    if let Some(options) = schema["oneOf"].as_array().or(schema["anyOf"].as_array()) {
        return options.iter().find_map(stand_in);
    }
    if let Some(first) = schema["enum"].as_array().and_then(|names| names.first()) {
        return Some(first.clone());
    }
    let kind = match &schema["type"] {
        Value::String(kind) => kind.as_str(),
        Value::Array(kinds) => kinds.iter().filter_map(Value::as_str).find(|k| *k != "null")?,
        _ if schema["properties"].is_object() => "object",
        _ => return None,
    };
    Some(match kind {
        "number" => Value::from(-1.0),
        "integer" => Value::from(0),
        "string" => Value::from(""),
        "boolean" => Value::Bool(false),
        "array" => Value::Array(Vec::new()),
        "object" => {
            let mut object = Value::Object(serde_json::Map::new());
            fill(&mut object, schema, "", &mut Vec::new());
            object
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn every_absent_required_member_gets_a_stand_in_at_its_pointer() {
        let schema = json!({"type": "object", "required": ["a", "b", "c"], "properties": {
            "a": {"type": "number"},
            "b": {"oneOf": [
                {"type": "object", "required": ["type", "x"], "properties": {
                    "type": {"type": "string", "enum": ["one"]}, "x": {"type": "number"}}},
                {"type": "object", "required": ["type", "y"], "properties": {
                    "type": {"type": "string", "enum": ["two"]}, "y": {"type": "integer"}}}]},
            "c": {"type": "array", "items": {"type": "object", "required": ["z"],
                                             "properties": {"z": {"type": "number"}}}}}});
        let mut value = json!({"b": {"type": "two"}, "c": [{"z": 1.0}, {}]});
        let mut missing = Vec::new();
        fill(&mut value, &schema, "/inputs", &mut missing);
        assert_eq!(missing, ["/inputs/a", "/inputs/b/y", "/inputs/c/1/z"]);
        assert_eq!(value["a"], -1.0);
        assert_eq!(value["b"]["y"], 0);
        assert_eq!(value["c"][1]["z"], -1.0);

        let mut empty = json!({});
        let mut missing = Vec::new();
        fill(&mut empty, &schema, "/inputs", &mut missing);
        assert_eq!(missing, ["/inputs/a", "/inputs/b", "/inputs/c"]);
        assert_eq!(empty["b"], json!({"type": "one", "x": -1.0}));
    }
}
