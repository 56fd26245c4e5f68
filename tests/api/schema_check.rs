//! Does a served document follow the OpenAPI document the service serves? The paths whose
//! template matches a URL, and a small JSON Schema check (`$ref`, `type`, `required`,
//! `properties`, `items`, `oneOf`, `enum`, `minimum`) of a body against a schema of it.

use serde_json::Value;

/// The path templates of `openapi` that match `path` (`{name}` matches one segment).
pub fn matching_templates<'a>(openapi: &'a Value, path: &str) -> Vec<&'a str> {
    let segments: Vec<&str> = path.trim_matches('/').split('/').collect();
    openapi["paths"]
        .as_object()
        .expect("paths")
        .keys()
        .filter(|template| {
            let parts: Vec<&str> = template.trim_matches('/').split('/').collect();
            parts.len() == segments.len()
                && parts
                    .iter()
                    .zip(&segments)
                    .all(|(part, segment)| part.starts_with('{') || part == segment)
        })
        .map(String::as_str)
        .collect()
}

/// Where `value` breaks `schema` (resolving `$ref` in `openapi`), as `pointer: reason`.
pub fn violations(openapi: &Value, schema: &Value, value: &Value) -> Vec<String> {
    let mut found = Vec::new();
    check(openapi, schema, value, "", &mut found);
    found
}

fn resolve<'a>(openapi: &'a Value, schema: &'a Value) -> &'a Value {
    match schema.get("$ref").and_then(Value::as_str) {
        Some(reference) => {
            let pointer = reference.trim_start_matches('#');
            resolve(
                openapi,
                openapi
                    .pointer(pointer)
                    .unwrap_or_else(|| panic!("unresolved {reference}")),
            )
        }
        None => schema,
    }
}

fn type_matches(name: &str, value: &Value) -> bool {
    match name {
        "object" => value.is_object(),
        "array" => value.is_array(),
        "string" => value.is_string(),
        "boolean" => value.is_boolean(),
        "null" => value.is_null(),
        "number" => value.is_number(),
        "integer" => value.is_i64() || value.is_u64(),
        other => panic!("unknown schema type {other}"),
    }
}

fn check(openapi: &Value, schema: &Value, value: &Value, at: &str, found: &mut Vec<String>) {
    let schema = resolve(openapi, schema);
    if let Some(options) = schema.get("oneOf").and_then(Value::as_array) {
        let passing = options
            .iter()
            .filter(|option| violations(openapi, option, value).is_empty())
            .count();
        if passing != 1 {
            found.push(format!(
                "{at}: matches {passing} of the {} `oneOf` schemas, not 1",
                options.len()
            ));
        }
    }
    for part in schema
        .get("allOf")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        check(openapi, part, value, at, found);
    }
    if let Some(types) = schema.get("type") {
        let names: Vec<&str> = match types {
            Value::String(name) => vec![name.as_str()],
            Value::Array(names) => names.iter().filter_map(Value::as_str).collect(),
            _ => Vec::new(),
        };
        if !names.iter().any(|name| type_matches(name, value)) {
            found.push(format!("{at}: {value} is not of type {types}"));
            return;
        }
    }
    if let Some(allowed) = schema.get("enum").and_then(Value::as_array)
        && !allowed.contains(value)
    {
        found.push(format!("{at}: {value} is not one of {allowed:?}"));
    }
    if let (Some(minimum), Some(number)) = (schema.get("minimum").and_then(Value::as_f64), value.as_f64())
        && number < minimum
    {
        found.push(format!("{at}: {number} is below the minimum {minimum}"));
    }
    if let Some(object) = value.as_object() {
        for name in schema
            .get("required")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            let name = name.as_str().unwrap();
            if !object.contains_key(name) {
                found.push(format!("{at}: required member `{name}` is missing"));
            }
        }
        if let Some(properties) = schema.get("properties").and_then(Value::as_object) {
            for (name, member) in object {
                if let Some(member_schema) = properties.get(name) {
                    check(openapi, member_schema, member, &format!("{at}/{name}"), found);
                } else if schema.get("additionalProperties") == Some(&Value::Bool(false)) {
                    found.push(format!("{at}: member `{name}` is not allowed"));
                }
            }
        }
    }
    if let (Some(items), Some(array)) = (schema.get("items"), value.as_array()) {
        for (index, item) in array.iter().enumerate() {
            check(openapi, items, item, &format!("{at}/{index}"), found);
        }
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    #[test]
    fn the_check_finds_missing_members_wrong_types_and_ambiguous_one_ofs() {
        let openapi = json!({"components": {"schemas": {
            "A": {"type": "object", "required": ["a"], "properties": {"a": {"type": "integer", "minimum": 0}}},
            "B": {"type": "object", "required": ["b"], "properties": {"b": {"type": "array", "items": {"type": "string"}}}}
        }}});
        let a = json!({"$ref": "#/components/schemas/A"});
        let either =
            json!({"oneOf": [{"$ref": "#/components/schemas/A"}, {"$ref": "#/components/schemas/B"}]});
        assert!(violations(&openapi, &a, &json!({"a": 3})).is_empty());
        assert_eq!(violations(&openapi, &a, &json!({"b": 3})).len(), 1);
        assert_eq!(violations(&openapi, &a, &json!({"a": -1})).len(), 1);
        assert_eq!(violations(&openapi, &a, &json!({"a": "x"})).len(), 1);
        assert!(violations(&openapi, &either, &json!({"b": ["x"]})).is_empty());
        assert_eq!(violations(&openapi, &either, &json!({"b": [1]})).len(), 1);
        assert_eq!(
            violations(&openapi, &either, &json!({"a": 1, "b": []})).len(),
            1,
            "both match"
        );
    }
}
