//! The served schema is the contract: what `GET /processes/{id}` says of each input, its
//! bounds and its default, is what validation enforces.
//!
//! For every process, the schema of its inputs is read from the process description the
//! service serves (`Process::inputs_description`, the `inputs` of `GET /processes/{id}`)
//! and walked alongside small valid example inputs ([`examples`]). At every member of
//! every object they hold:
//! - a number with a `minimum`/`maximum` (exclusive or not) is set to the last value the
//!   bound allows, which validation must not refuse at the member's pointer (it may
//!   refuse a consequence elsewhere: a 1 µm beam makes a 1e-5 s step unstable, refused
//!   at the step), then to the first value it excludes (the next double, or the next
//!   integer), which validation must refuse at the member's pointer: a 422 there;
//! - a member with a `default` is left out, then given as its default: both are
//!   accepted, and both runs give the same results document (which echoes the inputs
//!   as run) and the same histories.
//!
//! Validation is `Process::validate_with`, which the execution route calls (and then
//! the service's own cost ceilings, not an input's bound). Every place of the schema
//! with a bound or a default must be reached by some example, so a new field is
//! covered as soon as it exists (or the test says which example to extend). Every member
//! has a description, without the developers' notes of the code (`serde`, rustdoc links).

mod examples;
mod walk;

use std::collections::BTreeSet;
use std::ops::ControlFlow;

use chocmodal::processes::signal_input::SignalLibrary;
use chocmodal::processes::{CostLimits, FieldError, Process, Registry};
use chocmodal::sweep::admission::{self, AdmissionLimits, Refusal};
use chocmodal::sweep::spec::SweepError;
use serde_json::{Value, json};

use walk::Site;

/// The inputs schema a process's description serves: an object of the described
/// inputs, those with `minOccurs` 1 required.
fn served_schema(process: &dyn Process) -> Value {
    let inputs = process.inputs_description();
    let mut properties = serde_json::Map::new();
    let mut required = Vec::new();
    for (name, input) in inputs.as_object().expect("an inputs object") {
        properties.insert(name.clone(), input["schema"].clone());
        if input["minOccurs"] == 1 {
            required.push(Value::from(name.as_str()));
        }
    }
    json!({"type": "object", "properties": properties, "required": required})
}

/// What validation says of a request: accepted, or its refusals.
type Validate = Box<dyn Fn(&Value) -> Result<(), Vec<FieldError>>>;
/// What a request gives once accepted, which leaving a default out must not change.
type Outcome = Box<dyn Fn(&Value) -> Result<Value, String>>;

/// A schema, the validation it must agree with, and the disagreements found.
struct Contract {
    name: String,
    schema: Value,
    /// Pointer of the walked value in the request body (`/inputs` for a process).
    at: &'static str,
    validate: Validate,
    outcome: Outcome,
    failures: Vec<String>,
}

impl Contract {
    /// A process: its served inputs schema against `Process::validate_with` (what the
    /// execution route calls), defaults judged by the results document and histories.
    fn process(id: &str, library: SignalLibrary) -> Self {
        let process = Registry::builtin().get(id).expect("a built-in process");
        let library = std::sync::Arc::new(library);
        let (validating, validating_library) = (process.clone(), library.clone());
        Self {
            name: id.to_owned(),
            schema: served_schema(process.as_ref()),
            at: "/inputs",
            validate: Box::new(move |inputs| {
                validating
                    .validate_with(inputs, &validating_library)
                    .map(|_| ())
                    .map_err(|invalid| invalid.0)
            }),
            // The results as run; the wall-clock time of the step-halving check is no result.
            outcome: Box::new(move |inputs| {
                let mut output = process
                    .run_with(inputs, &library, &mut |_| ControlFlow::Continue(()))
                    .map_err(|e| e.to_string())?;
                if let Some(check) = output.document.pointer_mut("/quality/step_halving") {
                    check["seconds"] = Value::Null;
                }
                let histories: Vec<String> = output.histories.iter().map(|h| h.to_csv()).collect();
                Ok(json!({"document": output.document, "histories": histories}))
            }),
            failures: Vec::new(),
        }
    }

    /// The sweep request: its schema in the served OpenAPI document against admission
    /// (what `POST /sweeps` calls), defaults judged by the definition stored and the
    /// runs generated.
    fn sweep() -> Self {
        let document: Value =
            serde_json::from_str(&chocmodal::service::http::openapi::json()).expect("the OpenAPI document");
        let components = &document["components"]["schemas"];
        let limits = AdmissionLimits {
            max_runs: chocmodal::service::config::DEFAULT_MAX_SWEEP_RUNS,
            cost: CostLimits::default(),
        };
        let admit = move |body: &Value| {
            admission::admit(body, &Registry::builtin(), &limits, &SignalLibrary::default())
        };
        Self {
            name: "POST /sweeps".to_owned(),
            schema: walk::inlined(&components["SweepRequest"], components),
            at: "",
            validate: Box::new(move |body| {
                admit(body).map(|_| ()).map_err(|refusal| match refusal {
                    Refusal::Request(SweepError::Invalid(errors)) => errors,
                    Refusal::InvalidRuns(runs) | Refusal::TooCostly { runs, .. } => runs.errors,
                    other => vec![FieldError::new("", format!("{other:?}"))],
                })
            }),
            outcome: Box::new(move |body| {
                let admitted = admit(body).map_err(|refusal| format!("{refusal:?}"))?;
                let runs: Vec<&Value> = admitted.runs.iter().map(|run| &run.inputs).collect();
                Ok(json!({"definition": admitted.spec.definition(), "runs": runs}))
            }),
            failures: Vec::new(),
        }
    }

    fn refusals(&mut self, inputs: &Value) -> Vec<FieldError> {
        // A panic is a refusal at the whole body that names it, and a failure.
        let validated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (self.validate)(inputs)));
        match validated {
            Ok(Ok(())) => Vec::new(),
            Ok(Err(errors)) => errors,
            Err(_) => {
                self.fail(format!("validation panics on {inputs}"));
                vec![FieldError::new(self.at, "validation panicked")]
            }
        }
    }

    fn fail(&mut self, message: String) {
        self.failures.push(format!("{}: {message}", self.name));
    }

    /// Each bound of the number at `site`: the last value it allows is not refused at the
    /// member (unless a rule with other inputs, which its description states, sets a
    /// higher floor: [`FLOORS`]), the first value it excludes is.
    fn check_bounds(&mut self, example: &Value, site: &Site) {
        let floor = FLOORS
            .iter()
            .find(|(place, _)| site.location.ends_with(place))
            .map(|(_, rule)| *rule);
        if let Some(rule) = floor
            && !site.description.contains(rule)
        {
            self.fail(format!(
                "{}'s description does not state its floor ({rule})",
                site.location
            ));
        }
        for (keyword, inside, outside) in bound_cases(&site.schema) {
            let at = site
                .pointer
                .strip_prefix(self.at)
                .expect("a pointer into the walked value");
            let at_member = |e: &FieldError| {
                e.pointer == site.pointer || e.pointer.starts_with(&format!("{}/", site.pointer))
            };
            let refused: Vec<FieldError> = match floor.is_some() && keyword == "exclusiveMinimum" {
                true => Vec::new(),
                false => self
                    .refusals(&walk::with(example, at, inside.clone()))
                    .into_iter()
                    .filter(at_member)
                    .collect(),
            };
            if !refused.is_empty() {
                self.fail(format!(
                    "{} = {inside} is allowed by its {keyword} but refused: {refused:?}",
                    site.pointer
                ));
            }
            let refusals = self.refusals(&walk::with(example, at, outside.clone()));
            if !refusals.iter().any(at_member) {
                self.fail(format!(
                    "{} = {outside} is beyond its {keyword} but not refused there (refusals: {refusals:?})",
                    site.pointer
                ));
            }
        }
    }

    /// The member at `site` left out and given as its default: both accepted, the same
    /// results document and histories.
    fn check_default(&mut self, example: &Value, site: &Site) {
        let default = site.schema["default"].clone();
        let at = site
            .pointer
            .strip_prefix(self.at)
            .expect("a pointer into the walked value");
        let omitted = walk::without(example, at);
        let explicit = walk::with(example, at, default.clone());
        for (inputs, how) in [(&omitted, "left out"), (&explicit, "given as its default")] {
            let refusals = self.refusals(inputs);
            if !refusals.is_empty() {
                self.fail(format!(
                    "{} {how} ({default}) is refused: {refusals:?}",
                    site.pointer
                ));
                return;
            }
        }
        match ((self.outcome)(&omitted), (self.outcome)(&explicit)) {
            (Ok(left_out), Ok(given)) if left_out == given => {}
            (Ok(left_out), Ok(given)) => self.fail(format!(
                "{} left out and given as its default ({default}) differ: {}",
                site.pointer,
                first_difference(&left_out, &given, "")
            )),
            (left_out, given) => self.fail(format!(
                "{} left out or given as its default ({default}) fails: {left_out:?} / {given:?}",
                site.pointer
            )),
        }
    }

    /// Walks every example; checks each bound and default once, at the first example
    /// reaching its place; then that every place with one was reached.
    fn check(&mut self, examples: &[Value]) {
        let schema = self.schema.clone();
        let (mut bounds_checked, mut defaults_checked) = (BTreeSet::new(), BTreeSet::new());
        for example in examples {
            let refusals = self.refusals(example);
            assert!(refusals.is_empty(), "example refused: {refusals:?}\n{example}");
            let mut sites = Vec::new();
            walk::sites(&schema, example, self.at, "", &mut sites);
            // A bound is checked where the example gives the member (in the context its
            // cross-field rules allow), a default wherever the member's object is.
            for site in sites {
                if site.present
                    && !bound_cases(&site.schema).is_empty()
                    && bounds_checked.insert(site.location.clone())
                {
                    self.check_bounds(example, &site);
                }
                if site.schema.get("default").is_some() && defaults_checked.insert(site.member.clone()) {
                    self.check_default(example, &site);
                }
            }
        }
        // Every place with a bound or a default was checked; every member is described.
        let mut places = Vec::new();
        walk::locations(&schema, "", &mut places);
        for walk::Place {
            location,
            schema: place,
            alternative,
        } in &places
        {
            if !bound_cases(place).is_empty() && !bounds_checked.contains(location) {
                self.fail(format!(
                    "{location} has a bound that no example gives it: extend the examples"
                ));
            }
            if !alternative {
                if place.get("default").is_some() && !defaults_checked.contains(location) {
                    self.fail(format!(
                        "{location} has a default no example reaches: extend the examples"
                    ));
                }
                self.check_description(location, place);
            }
        }
    }

    /// A member's description: present, and for users (no serde, no rustdoc links).
    fn check_description(&mut self, location: &str, place: &Value) {
        let name = location.rsplit('/').next().unwrap_or_default();
        let is_tag = name.starts_with("type") && place["enum"].as_array().is_some_and(|e| e.len() == 1);
        if name.starts_with('*') || is_tag {
            return;
        }
        match place["description"].as_str() {
            None | Some("") => self.fail(format!("{location} has no description")),
            Some(text) if text.contains("serde") || text.contains("[`") => {
                self.fail(format!("{location}'s description is a developer's note: {text}"))
            }
            Some(_) => {}
        }
    }

    fn assert_agrees(self) {
        assert!(
            self.failures.is_empty(),
            "the served schema and validation disagree ({}):\n{}",
            self.failures.len(),
            self.failures.join("\n")
        );
    }
}

/// Numbers whose exclusive minimum is necessary but not sufficient: a rule with other
/// inputs refuses the values just above it (a pitch below the clad and wire diameters),
/// or the computation cannot reach them (a spectrum's tolerance). Their descriptions
/// must state the rule (the text here); the value at the bound is still refused at the
/// member.
const FLOORS: [(&str, &str); 6] = [
    ("/levels<object>/spacing", "tell the levels apart"),
    ("/bundle/pitch", "≥ D + d_w"),
    ("/bundle/wire_lead", "≥ 6 beam element lengths"),
    ("/bundle/wrapper_flat_to_flat", "≥ √3·n·P + D + 2·d_w"),
    (
        "<spectrum_compatible>/tolerance",
        "a record that cannot reach it is refused",
    ),
    ("/target/frequencies/*", "at least 2/strong_motion"),
];

fn is_number(schema: &Value) -> bool {
    walk::types(schema)
        .iter()
        .any(|t| *t == "number" || *t == "integer")
}

/// For each bound of a numeric schema: its keyword, the last value it allows and the
/// first it excludes (the next double; the next integer for integers).
fn bound_cases(schema: &Value) -> Vec<(&'static str, Value, Value)> {
    if !is_number(schema) {
        return Vec::new();
    }
    let integer = !walk::types(schema).contains(&"number");
    let value = |x: f64| match integer {
        true => json!(x as i64),
        false => json!(x),
    };
    let step_up = |x: f64| if integer { x + 1.0 } else { x.next_up() };
    let step_down = |x: f64| if integer { x - 1.0 } else { x.next_down() };
    let mut cases = Vec::new();
    for keyword in ["minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"] {
        let Some(bound) = schema[keyword].as_f64() else {
            continue;
        };
        let (inside, outside) = match keyword {
            "minimum" => (bound, step_down(bound)),
            "exclusiveMinimum" => (step_up(bound), bound),
            "maximum" => (bound, step_up(bound)),
            _ => (step_down(bound), bound),
        };
        cases.push((keyword, value(inside), value(outside)));
    }
    cases
}

/// Where two documents first differ, for the failure message.
fn first_difference(a: &Value, b: &Value, at: &str) -> String {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for key in x.keys().chain(y.keys()) {
                if x.get(key) != y.get(key) {
                    return match (x.get(key), y.get(key)) {
                        (Some(p), Some(q)) => first_difference(p, q, &format!("{at}/{key}")),
                        (p, q) => format!("{at}/{key}: {p:?} vs {q:?}"),
                    };
                }
            }
            format!("{at}: equal")
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find(|(_, (p, q))| p != q)
            .map(|(i, (p, q))| first_difference(p, q, &format!("{at}/{i}")))
            .unwrap_or_else(|| format!("{at}: equal")),
        _ => format!("{at}: {a} vs {b}"),
    }
}

#[test]
fn the_cantilever_schema_states_the_bounds_and_defaults_validation_enforces() {
    let mut contract = Contract::process("cantilever-impact", SignalLibrary::default());
    contract.check(&examples::cantilever());
    contract.assert_agrees();
}

#[test]
fn the_bundle_schema_states_the_bounds_and_defaults_validation_enforces() {
    let mut contract = Contract::process("bundle-dynamics", examples::signals());
    contract.check(&examples::bundle());
    contract.assert_agrees();
}

#[test]
fn the_hex_bundle_schema_states_the_bounds_and_defaults_validation_enforces() {
    let mut contract = Contract::process("hex-bundle-dynamics", examples::signals());
    contract.check(&examples::hex());
    contract.assert_agrees();
}

#[test]
fn the_sweep_request_schema_states_the_bounds_and_defaults_admission_enforces() {
    let mut contract = Contract::sweep();
    contract.check(&examples::sweeps());
    contract.assert_agrees();
}
