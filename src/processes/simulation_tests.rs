//! The adapter from [`Simulation`] to [`Process`]: a results document is exactly what its
//! published schema says (every property named in the schema, every required one
//! present, at every depth), the histories are the declared ones, and the absolute
//! ceilings refuse at the fields that drive them.

use std::collections::HashMap;
use std::ops::ControlFlow;

use serde_json::{Value, json};

use super::bundle_dynamics::BundleDynamics;
use super::cantilever_impact::CantileverImpact;
use super::{Process, RunOutput};

fn example(name: &str) -> Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    let body: Value = serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("JSON");
    body["inputs"].clone()
}

fn run(process: &dyn Process, inputs: &Value) -> RunOutput {
    process.validate(inputs).expect("valid inputs");
    process
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .expect("run succeeds")
}

/// The process's schemas by name, as JSON.
fn components(process: &dyn Process) -> HashMap<String, Value> {
    let mut schemas = Vec::new();
    process.schemas(&mut schemas);
    schemas
        .into_iter()
        .map(|(name, schema)| (name, serde_json::to_value(schema).expect("schema serializes")))
        .collect()
}

/// Checks `value` against `schema` as far as object shapes go: no property the schema
/// does not name, every required one present, recursively through `$ref`, `allOf`,
/// `oneOf`, arrays and nullable values. Returns the problems found.
fn shape_problems(
    value: &Value,
    schema: &Value,
    components: &HashMap<String, Value>,
    at: &str,
) -> Vec<String> {
    if let Some(reference) = schema["$ref"].as_str() {
        let name = reference.trim_start_matches("#/components/schemas/");
        let Some(target) = components.get(name) else {
            return vec![format!("{at}: unknown schema {name}")];
        };
        return shape_problems(value, target, components, at);
    }
    if let Some(parts) = schema["allOf"].as_array() {
        // Flattened structs: each part names some of the properties.
        let mut named = serde_json::Map::new();
        let mut problems = Vec::new();
        // A part can be flattened itself (an `allOf` of its own parts).
        fn gather<'a>(part: &'a Value, components: &'a HashMap<String, Value>, out: &mut Vec<&'a Value>) {
            let part = resolve(part, components);
            match part["allOf"].as_array() {
                Some(parts) => parts.iter().for_each(|p| gather(p, components, out)),
                None => out.push(part),
            }
        }
        let mut flat = Vec::new();
        parts.iter().for_each(|p| gather(p, components, &mut flat));
        for part in flat {
            for (key, property) in part["properties"].as_object().into_iter().flatten() {
                named.insert(key.clone(), property.clone());
            }
            for key in part["required"].as_array().into_iter().flatten() {
                if value.get(key.as_str().unwrap_or_default()).is_none() {
                    problems.push(format!("{at}: required {key} missing"));
                }
            }
        }
        let merged = json!({"type": "object", "properties": named});
        problems.extend(shape_problems(value, &merged, components, at));
        return problems;
    }
    if let Some(options) = schema["oneOf"].as_array() {
        if value.is_null() && options.iter().any(|o| o["type"] == "null") {
            return vec![];
        }
        let candidates: Vec<Vec<String>> = options
            .iter()
            .filter(|o| o["type"] != "null")
            .map(|o| shape_problems(value, o, components, at))
            .collect();
        return candidates
            .iter()
            .find(|p| p.is_empty())
            .cloned()
            .unwrap_or_else(|| candidates.into_iter().flatten().collect());
    }
    match value {
        Value::Object(map) => {
            let mut problems = Vec::new();
            let properties = schema["properties"].as_object();
            for (key, item) in map {
                match properties.and_then(|p| p.get(key)) {
                    Some(property) => {
                        problems.extend(shape_problems(item, property, components, &format!("{at}/{key}")))
                    }
                    None => problems.push(format!("{at}/{key}: not in the schema")),
                }
            }
            for key in schema["required"].as_array().into_iter().flatten() {
                if !map.contains_key(key.as_str().unwrap_or_default()) {
                    problems.push(format!("{at}: required {key} missing"));
                }
            }
            problems
        }
        Value::Array(items) => items
            .iter()
            .enumerate()
            .flat_map(|(k, item)| shape_problems(item, &schema["items"], components, &format!("{at}/{k}")))
            .collect(),
        _ => vec![],
    }
}

fn resolve<'a>(schema: &'a Value, components: &'a HashMap<String, Value>) -> &'a Value {
    schema["$ref"]
        .as_str()
        .and_then(|r| components.get(r.trim_start_matches("#/components/schemas/")))
        .unwrap_or(schema)
}

fn assert_matches_its_schema(process: &dyn Process, results_schema: &str, output: &RunOutput) {
    let components = components(process);
    let schema = components
        .get(results_schema)
        .unwrap_or_else(|| panic!("{results_schema} not among {:?}", components.keys()));
    let problems = shape_problems(&output.document, schema, &components, "");
    assert!(problems.is_empty(), "{}: {problems:#?}", process.id());
    let declared: Vec<String> = process
        .outputs_description()
        .as_object()
        .expect("outputs object")
        .keys()
        .cloned()
        .collect();
    let mut written: Vec<String> = output.histories.iter().map(|h| h.name.clone()).collect();
    written.sort();
    assert_eq!(
        written,
        declared,
        "{}: histories written vs declared",
        process.id()
    );
}

#[test]
fn a_cantilever_results_document_is_what_its_schema_says() {
    let mut inputs = example("cantilever-impact.json");
    inputs["solver"]["duration"] = json!(0.02);
    inputs["contact"]["damping"] = json!(1.0); // a reference note
    let output = run(&CantileverImpact, &inputs);
    assert_matches_its_schema(&CantileverImpact, "CantileverResults", &output);
}

#[test]
fn a_bundle_results_document_is_what_its_schema_says_in_both_forms() {
    // The generator form (with its expansion) and the explicit form (without).
    let mut generated = example("bundle-local-closure.json");
    generated["solver"]["duration"] = json!(0.005);
    let output = run(&BundleDynamics, &generated);
    assert!(output.document.get("expansion").is_some());
    assert_matches_its_schema(&BundleDynamics, "BundleResults", &output);

    let explicit = json!({
        "pin": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                "elements": 10, "modes": 3},
        "pins": 2,
        "contacts": [{"left": "wall", "right": 0, "height": 1.0, "gap": 0.0, "stiffness": 1e5},
                     {"left": 0, "right": 1, "height": 1.0, "gap": 1e-4, "stiffness": 1e5}],
        "initial": {"tip_displacements": [-1e-3, 0.0]},
        "solver": {"duration": 0.01, "check": "none"}
    });
    let output = run(&BundleDynamics, &explicit);
    assert!(output.document.get("expansion").is_none());
    assert_eq!(output.document["contacts"][0]["left"], "wall");
    assert_eq!(output.document["contacts"][1]["right"], 1);
    assert_matches_its_schema(&BundleDynamics, "BundleResults", &output);
}

/// Every process of the registry, on its first shipped example cut to 2 ms: its results
/// document is what its schema says and its histories are the ones it declares.
#[test]
fn every_process_writes_what_its_schema_and_outputs_declare() {
    let registry = super::Registry::builtin();
    for process in registry.all() {
        let example = process
            .examples()
            .first()
            .unwrap_or_else(|| panic!("{} has no example", process.id()));
        let mut inputs = serde_json::from_str::<Value>(example.body).expect("JSON")["inputs"].clone();
        inputs["solver"]["duration"] = json!(0.002);
        let output = run(process.as_ref(), &inputs);
        // The results schema: the one the adapter gives its `warnings` member.
        let components = components(process.as_ref());
        let results = components
            .iter()
            .find(|(_, schema)| schema["allOf"][1]["properties"].get("warnings").is_some())
            .map(|(name, _)| name.clone())
            .unwrap_or_else(|| panic!("{}: no results schema", process.id()));
        assert_matches_its_schema(process.as_ref(), &results, &output);
    }
}

#[test]
fn the_shape_check_sees_an_unknown_and_a_missing_property() {
    let components = HashMap::new();
    let schema = json!({"type": "object", "required": ["a"], "properties": {"a": {"type": "number"}}});
    assert!(shape_problems(&json!({"a": 1}), &schema, &components, "").is_empty());
    assert_eq!(
        shape_problems(&json!({"a": 1, "b": 2}), &schema, &components, "").len(),
        1
    );
    assert_eq!(shape_problems(&json!({}), &schema, &components, "").len(), 1);
}

/// One ceiling for steps in every process, at the duration, with what set the step.
#[test]
fn too_many_steps_are_refused_at_the_duration_in_every_process() {
    let mut cantilever = example("cantilever-impact.json");
    cantilever["solver"]["time_step"] = json!(1e-9);
    cantilever["solver"]["duration"] = json!(0.5);
    let mut bundle = example("bundle-row17.json");
    bundle["solver"]["time_step"] = json!("auto");
    bundle["solver"]["tolerance"] = json!(1e-12);
    bundle["solver"]["duration"] = json!(10.0);
    for (process, inputs, note) in [
        (&CantileverImpact as &dyn Process, cantilever, false),
        (&BundleDynamics, bundle, true),
    ] {
        let refused = process.validate(&inputs).expect_err("too many steps");
        let at_duration: Vec<_> = refused
            .0
            .iter()
            .filter(|e| e.pointer == "/inputs/solver/duration")
            .collect();
        assert!(!at_duration.is_empty(), "{}: {refused:?}", process.id());
        assert!(
            at_duration
                .iter()
                .any(|e| e.detail.contains("time steps, above the limit of 5e7")),
            "{}: {refused:?}",
            process.id()
        );
        assert_eq!(
            at_duration.iter().any(|e| e.detail.contains("auto")),
            note,
            "{}: what set the step: {refused:?}",
            process.id()
        );
    }
}
