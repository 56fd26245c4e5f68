//! Does an axis pointer name an input of the process? Checked against the process's JSON
//! schema of its inputs, so that a typo (`/contact/rkk`) refuses the sweep up front
//! instead of failing every one of its runs.
//!
//! The schema is walked along the pointer: an object's `properties`, an array's `items`
//! for an index, every alternative of `oneOf`/`anyOf`/`allOf` (a member of any one of
//! them is an input). An object that lists no properties, and an empty schema, accept
//! anything below them.

use std::collections::BTreeSet;

use serde_json::Value;

/// Why a pointer names no input: the sentence for the sweep's `/axes/{k}/pointer` error.
pub fn check(schema: &Value, pointer: &str) -> Result<(), String> {
    // The pointer's syntax is the request parser's business.
    let Ok(tokens) = super::pointer::tokens(pointer) else {
        return Ok(());
    };
    let mut here: Vec<&Value> = vec![schema];
    for (depth, token) in tokens.iter().enumerate() {
        let mut next = Vec::new();
        let mut names = BTreeSet::new();
        let mut takes_index = false;
        let mut scalars = BTreeSet::new();
        for schema in here.iter().flat_map(|schema| alternatives(schema)) {
            match Shape::of(schema) {
                Shape::Anything => return Ok(()),
                Shape::Object(properties) => {
                    names.extend(properties.keys().map(String::as_str));
                    next.extend(properties.get(token));
                }
                Shape::Map(values) => next.push(values),
                Shape::Array(items) => {
                    takes_index = true;
                    if token.parse::<usize>().is_ok() {
                        next.push(items);
                    }
                }
                Shape::Scalar(kind) => {
                    scalars.insert(kind);
                }
            }
        }
        if next.is_empty() {
            let parent = format!("/{}", tokens[..depth].join("/"));
            return Err(no_input(token, &parent, &names, takes_index, &scalars));
        }
        here = next;
    }
    Ok(())
}

/// The sentence for `token`, no input under `parent` whose schema offers `names` (and
/// indices when `takes_index`), or only values of the kinds `scalars`.
fn no_input(
    token: &str,
    parent: &str,
    names: &BTreeSet<&str>,
    takes_index: bool,
    scalars: &BTreeSet<&str>,
) -> String {
    let under = if parent == "/" {
        String::new()
    } else {
        format!(" under {parent}")
    };
    let mut valid: Vec<String> = names.iter().map(|name| (*name).to_owned()).collect();
    if takes_index {
        valid.push("a list index (0, 1, ...)".to_owned());
    }
    if valid.is_empty() {
        let kinds: Vec<&str> = scalars.iter().copied().collect();
        let kind = if kinds.is_empty() {
            "a value".to_owned()
        } else {
            kinds.join(" or ")
        };
        return format!("no input `{token}`{under}, which is {kind}");
    }
    format!("no input `{token}`{under}; valid: {}", valid.join(", "))
}

/// The schemas a value of `schema` may match: its `oneOf`/`anyOf`/`allOf` alternatives,
/// flattened (itself when it has none).
fn alternatives(schema: &Value) -> Vec<&Value> {
    let nested: Vec<&Value> = ["oneOf", "anyOf", "allOf"]
        .iter()
        .filter_map(|keyword| schema.get(keyword)?.as_array())
        .flatten()
        .collect();
    if nested.is_empty() {
        return vec![schema];
    }
    let mut all: Vec<&Value> = nested.into_iter().flat_map(alternatives).collect();
    // Members beside the alternatives (rare) count as well.
    if schema.get("properties").is_some() || schema.get("items").is_some() {
        all.push(schema);
    }
    all
}

/// What lies below one (alternative-free) schema.
enum Shape<'a> {
    /// An empty schema, or an object that lists no members: anything may be below.
    Anything,
    /// An object with these members.
    Object(&'a serde_json::Map<String, Value>),
    /// An object whose members, any names, are all of this schema.
    Map(&'a Value),
    /// A list of values of this schema.
    Array(&'a Value),
    /// A value with nothing inside (`a number`, `a string`, ...).
    Scalar(&'static str),
}

impl<'a> Shape<'a> {
    fn of(schema: &'a Value) -> Self {
        if let Some(properties) = schema.get("properties").and_then(Value::as_object) {
            return Self::Object(properties);
        }
        if let Some(items) = schema.get("items") {
            return Self::Array(items);
        }
        let types: Vec<&str> = match schema.get("type") {
            Some(Value::String(kind)) => vec![kind.as_str()],
            Some(Value::Array(kinds)) => kinds.iter().filter_map(Value::as_str).collect(),
            _ => Vec::new(),
        };
        if types.contains(&"object") || types.is_empty() && schema.get("enum").is_none() {
            return match schema.get("additionalProperties") {
                Some(values @ Value::Object(_)) => Self::Map(values),
                Some(Value::Bool(false)) => Self::Scalar("an empty object"),
                _ => Self::Anything,
            };
        }
        let kind = types
            .iter()
            .find(|kind| **kind != "null")
            .or(types.first())
            .copied()
            .unwrap_or("string");
        Self::Scalar(match kind {
            "number" => "a number",
            "integer" => "an integer",
            "boolean" => "a boolean",
            "array" => "a list",
            "null" => "null",
            _ => "a string",
        })
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;
    use crate::processes::Registry;

    fn inputs_schema(process: &str) -> Value {
        Registry::builtin()
            .get(process)
            .unwrap()
            .inputs_schema()
            .expect("a typed process has an inputs schema")
    }

    #[test]
    fn pointers_of_the_examples_and_the_docs_name_inputs() {
        let cantilever = inputs_schema("cantilever-impact");
        for pointer in [
            "/contact/rk",
            "/contact/stiffness",
            "/solver/time_step",
            "/beam/modes",
            "/beam/static_correction",
            "/beam/section/outer_diameter",
            "/beam/section/area",
            "/beam/damping_ratio",
            "/beam/damping_ratio/0",
            "/release/tip_displacement",
            "/reference/modes",
        ] {
            assert_eq!(check(&cantilever, pointer), Ok(()), "{pointer}");
        }
        let bundle = inputs_schema("bundle-dynamics");
        for pointer in [
            "/bundle/gaps/seed",
            "/bundle/levels/spacing",
            "/bundle/levels/2",
            "/contacts/0/gap",
            "/pin/modes",
            "/excitation/base_acceleration/amplitude",
            "/excitation/base_acceleration/frequency",
            "/initial/tip_displacements/1",
        ] {
            assert_eq!(check(&bundle, pointer), Ok(()), "{pointer}");
        }
    }

    #[test]
    fn a_typo_is_refused_naming_the_valid_members_at_its_level() {
        let cantilever = inputs_schema("cantilever-impact");
        assert_eq!(
            check(&cantilever, "/contact/rkk"),
            Err("no input `rkk` under /contact; valid: damping, gap, law, rk, stiffness".to_owned())
        );
        let top = check(&cantilever, "/contcat/rk").unwrap_err();
        assert!(
            top.starts_with("no input `contcat`; valid: beam, contact, "),
            "{top}"
        );
        // A member of any alternative is valid; one of none names them all.
        let section = check(&cantilever, "/beam/section/diameter").unwrap_err();
        assert!(
            section.contains("area, inertia, inner_diameter, outer_diameter, type"),
            "{section}"
        );
    }

    #[test]
    fn nothing_is_inside_a_number_and_lists_take_indices() {
        let cantilever = inputs_schema("cantilever-impact");
        assert_eq!(
            check(&cantilever, "/contact/rk/value"),
            Err("no input `value` under /contact/rk, which is a number".to_owned())
        );
        assert_eq!(
            check(&cantilever, "/solver/time_step/auto"),
            Err("no input `auto` under /solver/time_step, which is a number or a string".to_owned())
        );
        let bundle = inputs_schema("bundle-dynamics");
        assert_eq!(
            check(&bundle, "/contacts/first/gap"),
            Err("no input `first` under /contacts; valid: a list index (0, 1, ...)".to_owned())
        );
        let levels = check(&bundle, "/bundle/levels/start").unwrap_err();
        assert!(levels.ends_with(", a list index (0, 1, ...)"), "{levels}");
    }

    #[test]
    fn free_form_objects_and_maps_accept_what_is_below_them() {
        let schema = json!({"type": "object", "properties": {
            "free": {"type": "object"},
            "any": {},
            "map": {"type": "object", "additionalProperties": {"type": "object",
                     "properties": {"x": {"type": "number"}}}},
        }});
        assert_eq!(check(&schema, "/free/anything/below"), Ok(()));
        assert_eq!(check(&schema, "/any/0/x"), Ok(()));
        assert_eq!(check(&schema, "/map/some-key/x"), Ok(()));
        assert!(check(&schema, "/map/some-key/y").is_err());
    }
}
