//! The self-contained JSON schema of a process's inputs, as `GET /processes/{id}` serves
//! it (the OGC `inputs` description), and the OpenAPI schemas the processes share.
//!
//! utoipa writes a member whose type is a named schema as a reference, with the member's
//! own documentation beside it (`{"$ref", "description", "default"}`). Inlining the
//! reference keeps what is written at the member over what the type says in general:
//! `pin` is "the pin shared by the whole row", not "a uniform, slender Euler–Bernoulli
//! beam", and `damping_ratio` keeps its default. An optional member (`oneOf` of its type
//! and `null`) is described at the member, as any other.
//!
//! The schema is the contract: `tests/schema_contract` checks each bound and default it
//! states against validation.

use serde_json::Value;
use utoipa::openapi::schema::{ArrayBuilder, ObjectBuilder, OneOfBuilder, Type};
use utoipa::openapi::{RefOr, Schema};
use utoipa::{PartialSchema, ToSchema};

use super::common_inputs::{DampingInput, SolverDefaults, SolverInput, TimeStepInput};
use crate::physics::beam::MAX_ELEMENTS;

/// A self-contained JSON schema of `T`: component references inlined, the keywords
/// written beside a reference kept over the component's.
pub fn schema_of<T: ToSchema>() -> Value {
    let mut components = Vec::new();
    T::schemas(&mut components);
    let components: std::collections::HashMap<String, Value> = components
        .into_iter()
        .map(|(name, schema)| (name, serde_json::to_value(schema).unwrap_or_default()))
        .collect();
    let mut root = serde_json::to_value(T::schema()).unwrap_or_default();
    inline_references(&mut root, &components, 0);
    root
}

fn inline_references(value: &mut Value, components: &std::collections::HashMap<String, Value>, depth: usize) {
    const PREFIX: &str = "#/components/schemas/";
    match value {
        Value::Object(map) => {
            if let Some(Value::String(reference)) = map.get("$ref")
                && let Some(name) = reference.strip_prefix(PREFIX)
                && let Some(Value::Object(component)) = components.get(name)
                && depth < 32
            {
                let mut inlined = component.clone();
                for (key, keyword) in map.iter().filter(|(key, _)| *key != "$ref") {
                    inlined.insert(key.clone(), keyword.clone());
                }
                *value = Value::Object(inlined);
                inline_references(value, components, depth + 1);
                return;
            }
            for child in map.values_mut() {
                inline_references(child, components, depth);
            }
            describe_optional(map);
        }
        Value::Array(items) => items
            .iter_mut()
            .for_each(|v| inline_references(v, components, depth)),
        _ => {}
    }
}

/// An optional member written as `oneOf` its type and `null`: the description of its
/// type's alternative (the member's own documentation) also at the member.
fn describe_optional(map: &mut serde_json::Map<String, Value>) {
    if map.contains_key("description") {
        return;
    }
    let Some(Value::Array(options)) = map.get("oneOf") else {
        return;
    };
    let mut typed = options.iter().filter(|o| o["type"] != "null");
    if let (Some(only), None) = (typed.next(), typed.next())
        && let Some(description) = only.get("description").cloned()
    {
        map.insert("description".into(), description);
    }
}

/// OGC `inputs` description from the schema of the whole inputs object: one entry per
/// top-level property, with its title, description, schema and occurrence.
pub fn ogc_inputs(schema: &Value) -> Value {
    let required: Vec<&str> = schema["required"]
        .as_array()
        .map(|r| r.iter().filter_map(|v| v.as_str()).collect())
        .unwrap_or_default();
    let mut inputs = serde_json::Map::new();
    if let Some(properties) = schema["properties"].as_object() {
        for (name, property) in properties {
            inputs.insert(
                name.clone(),
                serde_json::json!({
                    "title": name,
                    "description": property.get("description").cloned().unwrap_or_default(),
                    "schema": property,
                    "minOccurs": if required.contains(&name.as_str()) { 1 } else { 0 },
                    "maxOccurs": 1,
                }),
            );
        }
    }
    Value::Object(inputs)
}

/// The schema of a process's `solver` block: [`SolverInput`]'s, self-contained, with the
/// process's defaults for the step and the duration (and the member's description and
/// default, which utoipa leaves to the function that writes the schema).
pub fn solver_schema(defaults: SolverDefaults) -> RefOr<Schema> {
    let mut schema = schema_of::<SolverInput>();
    schema["description"] = "Explicit integration: scheme, time step, duration, accuracy.".into();
    schema["default"] = serde_json::json!({});
    let properties = &mut schema["properties"];
    properties["time_step"]["default"] = match defaults.time_step {
        TimeStepInput::Seconds(seconds) => seconds.into(),
        TimeStepInput::Keyword(_) => "auto".into(),
    };
    properties["duration"]["default"] = defaults.duration.into();
    serde_json::from_value(schema).expect("a JSON schema read back as one")
}

/// The `solver` schema of the processes that step `auto` over 0.2 s by default.
pub fn auto_solver_schema() -> RefOr<Schema> {
    solver_schema(SolverDefaults::AUTO)
}

/// A number ≥ 0 (the items of a list of gaps, times, heights).
#[derive(Debug, ToSchema)]
#[schema(minimum = 0.0)]
#[allow(dead_code)] // a schema only: the lists are read as numbers and checked
pub struct NonNegativeNumber(f64);

/// A number > 0 (the items of a list of levels, frequencies).
#[derive(Debug, ToSchema)]
#[schema(exclusive_minimum = 0.0)]
#[allow(dead_code)] // a schema only: the lists are read as numbers and checked
pub struct PositiveNumber(f64);

/// A damping ratio's bounds: in [0, 1).
fn damping_ratio() -> ObjectBuilder {
    ObjectBuilder::new()
        .schema_type(Type::Number)
        .minimum(Some(0.0))
        .exclusive_maximum(Some(1.0))
}

impl PartialSchema for DampingInput {
    fn schema() -> RefOr<Schema> {
        OneOfBuilder::new()
            .item(damping_ratio().description(Some("The ratio of every mode (dimensionless).")))
            .item(
                ArrayBuilder::new()
                    .items(damping_ratio())
                    .min_items(Some(1))
                    .description(Some(
                        "The ratio of each mode, in order (dimensionless); a shorter list repeats its last value.",
                    )),
            )
            .description(Some(
                "Modal damping ratio (dimensionless, in [0, 1)): a number for every mode, or a list, one per mode.",
            ))
            .into()
    }
}

impl ToSchema for DampingInput {}

impl PartialSchema for TimeStepInput {
    fn schema() -> RefOr<Schema> {
        OneOfBuilder::new()
            .item(
                ObjectBuilder::new()
                    .schema_type(Type::Number)
                    .exclusive_minimum(Some(0.0))
                    .description(Some("A time step (s).")),
            )
            .item(
                ObjectBuilder::new()
                    .schema_type(Type::String)
                    .enum_values(Some(["auto"]))
                    .description(Some(
                        "`auto`: the longest step meeting `tolerance`, within stability, a whole \
                         number of steps per output interval.",
                    )),
            )
            .description(Some("A time step in seconds, or `\"auto\"`."))
            .into()
    }
}

impl ToSchema for TimeStepInput {}

/// A count (`integer`: its bounds and description) or `"auto"`, the `what` it chooses;
/// `noun` names the count in the member's description.
fn count_or_auto(integer: ObjectBuilder, what: &str, noun: &str) -> RefOr<Schema> {
    let auto = ObjectBuilder::new()
        .schema_type(Type::String)
        .enum_values(Some(["auto"]))
        .description(Some(format!(
            "`auto`: the {what} whose impact probes put the peak contact force within 10 × \
             `solver.tolerance` (docs/accuracy.md)."
        )));
    OneOfBuilder::new()
        .item(integer.schema_type(Type::Integer).minimum(Some(1.0)))
        .item(auto)
        .description(Some(format!("A number of {noun} (count), or `\"auto\"`.")))
        .into()
}

/// The schema of `elements`: a count from 1 to 400, or `"auto"`.
#[derive(Debug)]
#[allow(dead_code)] // a schema only: read as a `CountInput`
pub struct ElementsInput;

impl PartialSchema for ElementsInput {
    fn schema() -> RefOr<Schema> {
        count_or_auto(
            ObjectBuilder::new()
                .maximum(Some(MAX_ELEMENTS as f64))
                .description(Some("Elements (count).")),
            "coarsest mesh, doubling from 40 up to 200,",
            "elements",
        )
    }
}

impl ToSchema for ElementsInput {}

/// The schema of `modes`: a count from 1, or `"auto"`.
#[derive(Debug)]
#[allow(dead_code)] // a schema only: read as a `CountInput`
pub struct ModesInput;

impl PartialSchema for ModesInput {
    fn schema() -> RefOr<Schema> {
        count_or_auto(
            ObjectBuilder::new().description(Some("Modes (count), at most the free DOFs of the mesh.")),
            "fewest modes",
            "modes",
        )
    }
}

impl ToSchema for ModesInput {}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_members_own_keywords_win_over_its_types() {
        let components = [(
            "Beam".to_owned(),
            json!({"type": "object", "description": "A beam.", "properties": {}}),
        )]
        .into_iter()
        .collect();
        let mut schema = json!({"properties": {
            "pin": {"$ref": "#/components/schemas/Beam", "description": "The pin."},
            "plain": {"$ref": "#/components/schemas/Beam"},
            "optional": {"oneOf": [{"$ref": "#/components/schemas/Beam", "description": "Maybe."},
                                   {"type": "null"}]}}});
        inline_references(&mut schema, &components, 0);
        assert_eq!(schema["properties"]["pin"]["description"], "The pin.");
        assert_eq!(schema["properties"]["pin"]["type"], "object");
        assert_eq!(schema["properties"]["plain"]["description"], "A beam.");
        assert_eq!(schema["properties"]["optional"]["description"], "Maybe.");
    }
}
