//! What the process descriptions promise to clients that build forms and plots from
//! them (the dashboard's submit form and job page do): every number input states its
//! unit, every history output its kind.
//!
//! The unit of an input is the first parenthesized group of its description whose first
//! word is an SI unit expression (`(m)`, `(N·s/m)`, `(m/s², ≥ 0)`, `(kg/m³)`) or
//! `dimensionless`; `degrees` counts for angles. `assets/schema.js` reads it the same way.

use chocmodal::processes::Registry;
use serde_json::Value;

use crate::helpers::spawn_app_with_processes;

const UNITS: [&str; 10] = ["m", "s", "Pa", "N", "kg", "Hz", "J", "W", "rad", "degrees"];
const POWERS: [&str; 6] = ["", "²", "³", "⁴", "⁻¹", "⁻²"];

/// Whether `word` is a unit expression: units with an optional power, joined by `/` or `·`.
fn is_unit(word: &str) -> bool {
    !word.is_empty()
        && word.split(['/', '·']).enumerate().all(|(k, factor)| {
            (k == 0 && factor == "1")
                || UNITS
                    .iter()
                    .any(|unit| POWERS.iter().any(|power| factor == format!("{unit}{power}")))
        })
}

/// The unit a description states ([module doc](self)).
fn unit_of(description: &str) -> Option<&str> {
    description
        .split('(')
        .skip(1)
        .filter_map(|group| group.split(')').next())
        .filter_map(|group| group.trim().split([',', ';', ' ']).next())
        .find(|word| *word == "dimensionless" || is_unit(word))
}

/// Whether a schema is a number, an array of numbers, or an alternative with one.
fn is_number(schema: &Value) -> bool {
    let types: Vec<&str> = match &schema["type"] {
        Value::String(t) => vec![t.as_str()],
        Value::Array(list) => list.iter().filter_map(Value::as_str).collect(),
        _ => Vec::new(),
    };
    types.contains(&"number")
        || (types.contains(&"array") && is_number(&schema["items"]))
        || ["oneOf", "anyOf", "allOf"]
            .iter()
            .filter_map(|key| schema[*key].as_array())
            .flatten()
            .any(is_number)
}

/// The object schemas inside `schema` (itself, alternatives, array items).
fn objects(schema: &Value) -> Vec<&Value> {
    let mut found = Vec::new();
    if schema["properties"].is_object() {
        found.push(schema);
    }
    for key in ["oneOf", "anyOf", "allOf"] {
        for alternative in schema[key].as_array().into_iter().flatten() {
            found.extend(objects(alternative));
        }
    }
    if schema["type"] == "array" {
        found.extend(objects(&schema["items"]));
    }
    found
}

/// The description of a property, or of the first alternative that has one.
fn description(schema: &Value) -> &str {
    schema["description"].as_str().unwrap_or_else(|| {
        ["oneOf", "anyOf"]
            .iter()
            .filter_map(|key| schema[*key].as_array())
            .flatten()
            .find_map(|alternative| alternative["description"].as_str())
            .unwrap_or("")
    })
}

/// `pointer: description` of every number input without a unit under `schema`.
fn unitless(schema: &Value, pointer: &str, missing: &mut Vec<String>) {
    for object in objects(schema) {
        for (name, property) in object["properties"].as_object().unwrap() {
            let at = format!("{pointer}/{name}");
            if objects(property).is_empty() && is_number(property) && unit_of(description(property)).is_none()
            {
                missing.push(format!("{at}: {:?}", description(property)));
            }
            unitless(property, &at, missing);
        }
    }
}

#[test]
fn units_are_read_from_the_first_group_that_names_one() {
    assert_eq!(unit_of("Length L (m)."), Some("m"));
    assert_eq!(unit_of("Dashpot (N·s/m)."), Some("N·s/m"));
    assert_eq!(unit_of("Height (m from the foot)"), Some("m"));
    assert_eq!(unit_of("rest time (s, ≥ 0)"), Some("s"));
    assert_eq!(
        unit_of("(default 0.1) ratio (dimensionless)"),
        Some("dimensionless")
    );
    assert_eq!(unit_of("Density ρ (kg/m³)."), Some("kg/m³"));
    assert_eq!(unit_of("a rate (1/s)"), Some("1/s"));
    assert_eq!(unit_of("Seed (any integer)"), None);
    assert_eq!(unit_of("(default 1.1)"), None);
}

#[tokio::test]
async fn every_number_input_states_its_unit_and_every_history_its_kind() {
    let registry = Registry::builtin();
    let app = spawn_app_with_processes(registry.all().to_vec(), |_| {}).await;
    for process in registry.all().iter().map(|p| p.id()) {
        let description = app.get_json(&format!("/processes/{process}")).await;
        let mut missing = Vec::new();
        for (name, input) in description["inputs"].as_object().unwrap() {
            let wrapper = serde_json::json!({"properties": {name: input["schema"]}});
            unitless(&wrapper, "/inputs", &mut missing);
        }
        assert!(
            missing.is_empty(),
            "{process}: number inputs without a unit: {missing:#?}"
        );
        for (name, output) in description["outputs"].as_object().unwrap() {
            let kind = output["kind"].as_str().unwrap_or_default();
            assert!(
                [
                    "displacement",
                    "acceleration",
                    "force",
                    "moment",
                    "peaks",
                    "table"
                ]
                .contains(&kind),
                "{process} output {name}: kind {kind:?}"
            );
        }
        let displacement = description["outputs"]
            .as_object()
            .unwrap()
            .values()
            .filter(|o| o["kind"] == "displacement")
            .count();
        assert!(displacement >= 1, "{process} has a displacement history");
    }
}
