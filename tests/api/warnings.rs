//! Inputs that explain themselves (issue 20), over HTTP with the shipped processes:
//! plausibility warnings for the mistakes engineers make (a diameter or a length in mm,
//! gaps meaning mm, nothing exciting the model) in the 201 body, the job status (after
//! a restart too) and the results, none for the shipped examples, and none with
//! `"warnings": "off"`; every missing member in one 422 with the value errors; and
//! values that make the physics impossible refused at their own field, with the bound.

use std::sync::Arc;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::{Process, Registry};

use crate::helpers::{
    TestApp, TestStore, assert_problem, spawn_app_in_with_processes, spawn_app_with_processes,
};

fn shipped() -> Vec<Arc<dyn Process>> {
    Registry::builtin().all().to_vec()
}

/// The shipped processes without workers: submissions are only validated and queued.
async fn spawn_idle() -> TestApp {
    spawn_app_with_processes(shipped(), |config| config.workers = 0).await
}

fn example(name: &str) -> Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).expect("example")).expect("JSON")
}

/// The shipped process whose examples include the file `name`.
fn process_of(name: &str) -> String {
    let registry = Registry::builtin();
    let owner = registry
        .all()
        .iter()
        .find(|p| p.examples().iter().any(|e| e.file == name));
    owner
        .unwrap_or_else(|| panic!("{name} is no process's example"))
        .id()
        .to_owned()
}

/// Submits `inputs` to `process`: the 201 body.
async fn accepted(app: &TestApp, process: &str, inputs: &Value) -> Value {
    let response = app.post_execution(process, &json!({ "inputs": inputs })).await;
    let status = response.status();
    let body: Value = response.json().await.unwrap();
    assert_eq!(status, StatusCode::CREATED, "{process}: {body}");
    body
}

/// Submits `inputs` to `process`: the 422 problem's errors as (pointer, detail).
async fn refused(app: &TestApp, process: &str, inputs: &Value) -> Vec<(String, String)> {
    let response = app.post_execution(process, &json!({ "inputs": inputs })).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["pointer"].as_str().unwrap().to_owned(),
                e["detail"].as_str().unwrap().to_owned(),
            )
        })
        .collect()
}

/// (code, pointer) of each warning.
fn warnings(body: &Value) -> Vec<(String, String)> {
    body["warnings"]
        .as_array()
        .unwrap_or_else(|| panic!("a warnings list: {body}"))
        .iter()
        .map(|w| {
            assert!(w["message"].as_str().is_some_and(|m| !m.is_empty()), "{w}");
            (
                w["code"].as_str().unwrap().to_owned(),
                w["pointer"].as_str().unwrap().to_owned(),
            )
        })
        .collect()
}

fn has(warnings: &[(String, String)], code: &str, pointer: &str) -> bool {
    warnings.iter().any(|(c, p)| c == code && p == pointer)
}

/// The message of the warning with `code` in a 201 body.
fn message_of(body: &Value, code: &str) -> String {
    let warning = body["warnings"]
        .as_array()
        .and_then(|all| all.iter().find(|w| w["code"] == code));
    let message = warning.and_then(|w| w["message"].as_str());
    message
        .unwrap_or_else(|| panic!("no {code} warning: {body}"))
        .to_owned()
}

/// The first frequency (Hz) of a clamped-free tube: λ₁² √(EI/m) / (2π L²), λ₁ = 1.875104.
fn clamped_free_first_frequency(
    length: f64,
    young_modulus: f64,
    density: f64,
    outer: f64,
    inner: f64,
) -> f64 {
    let pi = std::f64::consts::PI;
    let area = pi / 4.0 * (outer.powi(2) - inner.powi(2));
    let inertia = pi / 64.0 * (outer.powi(4) - inner.powi(4));
    1.875104_f64.powi(2) * (young_modulus * inertia / (density * area)).sqrt() / (2.0 * pi * length.powi(2))
}

/// The number printed right before `unit` in `message` (`... 6538.2 Hz ...`).
fn number_before(message: &str, unit: &str) -> f64 {
    let end = message
        .find(&format!(" {unit}"))
        .unwrap_or_else(|| panic!("{unit} in {message}"));
    let start = message[..end].rfind(' ').map_or(0, |i| i + 1);
    message[start..end]
        .parse()
        .unwrap_or_else(|_| panic!("a number before {unit} in {message}"))
}

#[tokio::test]
async fn the_shipped_examples_get_no_warning() {
    let app = spawn_idle().await;
    let mut checked = 0;
    for entry in std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/examples")).unwrap() {
        let entry = entry.unwrap();
        // Record files and the jobs that read them (`chocmodal run`) live in subfolders.
        if entry.file_type().unwrap().is_dir() {
            continue;
        }
        let name = entry.file_name().into_string().unwrap();
        // Only the JSON requests: examples/ also holds the Python client's notebook.
        if !name.ends_with(".json") {
            continue;
        }
        let body = example(&name);
        // A sweep's base inputs are a complete request of its process.
        let (process, inputs) = match body["process"].as_str() {
            Some(process) => (process.to_owned(), body["inputs"].clone()),
            None => (process_of(&name), body["inputs"].clone()),
        };
        let status = accepted(&app, &process, &inputs).await;
        assert_eq!(warnings(&status), [], "{name}: {status}");
        checked += 1;
    }
    assert!(checked >= 12, "{checked} examples");
}

/// The mistakes of the issue, each on a sensible bundle (`examples/bundle-sine-auto.json`:
/// 7 pins of 1.2 m, D = 9.7 mm, shaken at 10 Hz).
#[tokio::test]
async fn unit_slips_each_get_a_warning_at_the_field_at_fault() {
    let app = spawn_idle().await;
    let base = example("bundle-sine-auto.json")["inputs"].clone();
    assert_eq!(warnings(&accepted(&app, "bundle-dynamics", &base).await), []);
    let pin = &base["pin"];
    let (length, modulus, density) = (
        pin["length"].as_f64().unwrap(),
        pin["young_modulus"].as_f64().unwrap(),
        pin["density"].as_f64().unwrap(),
    );

    // Diameters in mm: L/D = 0.12, and a first frequency 1000 times the pin's.
    let mut mm = base.clone();
    // A pin 1000 times stiffer needs 1000 times the steps: keep them under the ceiling.
    mm["solver"] = json!({"duration": 0.1, "check": "none"});
    mm["pin"]["section"] = json!({"type": "tube", "outer_diameter": 9.7, "inner_diameter": 8.5});
    let status = accepted(&app, "bundle-dynamics", &mm).await;
    let found = warnings(&status);
    assert!(
        has(&found, "slenderness", "/inputs/pin/section/outer_diameter"),
        "{status}"
    );
    let frequency = status["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|w| w["code"] == "first_frequency")
        .unwrap_or_else(|| panic!("a first frequency warning: {status}"));
    let expected = clamped_free_first_frequency(length, modulus, density, 9.7, 8.5);
    let printed = number_before(frequency["message"].as_str().unwrap(), "Hz");
    assert!(
        expected > 1000.0 && (printed - expected).abs() < 1e-4 * expected,
        "first frequency printed {printed} Hz, Euler–Bernoulli gives {expected} Hz"
    );

    // The length in mm: L/D = 1.2e5, and the run lasts a millionth of a first period.
    let mut long = base.clone();
    long["pin"]["length"] = json!(length * 1000.0);
    let found = warnings(&accepted(&app, "bundle-dynamics", &long).await);
    assert!(has(&found, "slenderness", "/inputs/pin/length"), "{found:?}");
    assert!(
        has(&found, "short_duration", "/inputs/solver/duration"),
        "{found:?}"
    );

    // Gaps of 0.1 meaning mm: 10 times the pin diameter, in both generator fields.
    let mut gaps = base.clone();
    gaps["bundle"]["wall_gap"] = json!(0.1);
    gaps["bundle"]["pin_gap"] = json!(0.1);
    let found = warnings(&accepted(&app, "bundle-dynamics", &gaps).await);
    assert!(
        has(&found, "gap_over_diameter", "/inputs/bundle/wall_gap"),
        "{found:?}"
    );
    assert!(
        has(&found, "gap_over_diameter", "/inputs/bundle/pin_gap"),
        "{found:?}"
    );

    // No excitation at all.
    let mut still = base.clone();
    still.as_object_mut().unwrap().remove("excitation");
    let found = warnings(&accepted(&app, "bundle-dynamics", &still).await);
    assert_eq!(
        found,
        [("nothing_excites".to_owned(), "/inputs/excitation".to_owned())]
    );

    // The modulus in MPa.
    let mut soft = base.clone();
    soft["pin"]["young_modulus"] = json!(modulus / 1e6);
    let found = warnings(&accepted(&app, "bundle-dynamics", &soft).await);
    assert!(
        has(&found, "soft_material", "/inputs/pin/young_modulus"),
        "{found:?}"
    );

    // An explicit contact list: the gap of each contact at its own pointer.
    let explicit = json!({
        "pin": base["pin"], "pins": 1,
        "contacts": [{"left": "wall", "right": 0, "height": 1.2, "gap": 1e-4, "stiffness": 1e6},
                     {"left": 0, "right": "wall", "height": 1.2, "gap": 0.1, "stiffness": 1e6}],
        "initial": {"tip_displacements": [1e-3]}
    });
    let found = warnings(&accepted(&app, "bundle-dynamics", &explicit).await);
    assert_eq!(
        found,
        [(
            "gap_over_diameter".to_owned(),
            "/inputs/contacts/1/gap".to_owned()
        )]
    );

    // Every one of them, turned off.
    let mut off = mm.clone();
    off["warnings"] = json!("off");
    assert_eq!(warnings(&accepted(&app, "bundle-dynamics", &off).await), []);
}

#[tokio::test]
async fn a_cantilever_released_from_rest_is_warned_in_its_status_its_results_and_after_a_restart() {
    let store = TestStore::new(crate::helpers::Backend::Sqlite).await;
    let app = spawn_app_in_with_processes(store, shipped(), |_| {}).await;
    let mut inputs = example("cantilever-impact.json")["inputs"].clone();
    inputs["release"]["tip_displacement"] = json!(0.0);
    inputs["solver"]["duration"] = json!(0.01);
    inputs["solver"]["check"] = json!("none");
    let created = accepted(&app, "cantilever-impact", &inputs).await;
    let expected = [(
        "nothing_excites".to_owned(),
        "/inputs/release/tip_displacement".to_owned(),
    )];
    assert_eq!(warnings(&created), expected);
    let id = created["jobID"].as_str().unwrap().to_owned();
    let finished = app.wait_until_finished(&id).await;
    assert_eq!(finished["status"], "successful", "{finished}");
    assert_eq!(warnings(&finished), expected);
    let results = app.get_json(&format!("/jobs/{id}/results")).await;
    assert_eq!(warnings(&results), expected);
    assert_eq!(results["numerical"]["max_contact_force"], 0.0, "nothing moved");

    let store = app.stop().await;
    let app = spawn_app_in_with_processes(store, shipped(), |_| {}).await;
    assert_eq!(warnings(&app.status(&id).await), expected, "after a restart");
}

#[tokio::test]
async fn every_missing_member_comes_in_one_422_with_the_value_errors() {
    let app = spawn_idle().await;
    let errors = refused(&app, "cantilever-impact", &json!({"beam": {"length": 1}})).await;
    let required: Vec<&str> = errors
        .iter()
        .filter(|(_, detail)| detail == "is required")
        .map(|(pointer, _)| pointer.as_str())
        .collect();
    assert_eq!(
        required,
        [
            "/inputs/beam/young_modulus",
            "/inputs/beam/density",
            "/inputs/beam/section"
        ],
        "{errors:?}"
    );

    // With value errors elsewhere, and nothing said about the members that are missing
    // but that they are.
    let inputs = json!({"beam": {"length": -1.0, "section": {"type": "tube", "outer_diameter": 0.01},
                                 "elements": 0},
                        "solver": {"duration": -1.0}});
    let errors = refused(&app, "cantilever-impact", &inputs).await;
    for pointer in [
        "/inputs/beam/young_modulus",
        "/inputs/beam/density",
        "/inputs/beam/section/inner_diameter",
    ] {
        let at: Vec<_> = errors.iter().filter(|(p, _)| p == pointer).collect();
        assert_eq!(at.len(), 1, "{pointer}: {errors:?}");
        assert_eq!(at[0].1, "is required", "{pointer}: {errors:?}");
    }
    for pointer in [
        "/inputs/beam/length",
        "/inputs/beam/elements",
        "/inputs/solver/duration",
    ] {
        assert!(
            errors.iter().any(|(p, d)| p == pointer && d != "is required"),
            "{pointer}: {errors:?}"
        );
    }

    // A bundle contact missing two members, with a value error in another.
    let mut bundle = example("bundle-row17.json")["inputs"].clone();
    bundle["contacts"][3] = json!({"left": 2, "height": 0.9});
    bundle["contacts"][5]["stiffness"] = json!(-1.0);
    let errors = refused(&app, "bundle-dynamics", &bundle).await;
    for (pointer, detail) in [
        ("/inputs/contacts/3/right", Some("is required")),
        ("/inputs/contacts/3/stiffness", Some("is required")),
        ("/inputs/contacts/5/stiffness", None),
    ] {
        assert!(
            errors
                .iter()
                .any(|(p, d)| p == pointer && detail.is_none_or(|detail| d == detail)),
            "{pointer}: {errors:?}"
        );
    }
}

/// Values that make the physics impossible are refused at their own field, with the
/// bound, instead of failing later somewhere else.
#[tokio::test]
async fn impossible_values_are_refused_at_their_field_with_the_bound() {
    use chocmodal::physics::beam::PLAUSIBLE_RANGES;
    let app = spawn_idle().await;
    let base = example("cantilever-impact.json")["inputs"].clone();
    let bound = |field: &str| {
        PLAUSIBLE_RANGES
            .iter()
            .find(|r| r.0 == field)
            .map(|r| (chocmodal::physics::number(r.1), chocmodal::physics::number(r.2)))
            .unwrap()
    };
    for (field, value) in [
        ("length", 1e308),
        ("young_modulus", 1e308),
        ("young_modulus", 1e-300),
    ] {
        let mut inputs = base.clone();
        inputs["beam"][field] = json!(value);
        let errors = refused(&app, "cantilever-impact", &inputs).await;
        let pointer = format!("/inputs/beam/{field}");
        let (low, high) = bound(field);
        assert!(
            errors
                .iter()
                .any(|(p, d)| *p == pointer && d.contains(&low) && d.contains(&high)),
            "{field} = {value:e}: {errors:?}"
        );
        assert!(
            errors.iter().all(|(p, _)| *p == pointer),
            "only {pointer} is at fault: {errors:?}"
        );
    }

    let mut inputs = base.clone();
    inputs["solver"]["duration"] = json!(1e308);
    let errors = refused(&app, "cantilever-impact", &inputs).await;
    assert!(
        errors.iter().any(|(p, _)| p == "/inputs/solver/duration"),
        "{errors:?}"
    );
    assert!(
        errors.iter().all(|(p, _)| p != "/inputs/solver/time_step"),
        "{errors:?}"
    );

    // In a bundle too: the step count is the duration's fault, not the step's, the
    // modes' or the pins' (its work and history ceilings only restate it).
    let mut bundle = example("bundle-sine-auto.json")["inputs"].clone();
    bundle["solver"]["duration"] = json!(1e308);
    let errors = refused(&app, "bundle-dynamics", &bundle).await;
    assert!(
        !errors.is_empty() && errors.iter().all(|(p, _)| p == "/inputs/solver/duration"),
        "{errors:?}"
    );

    // Numbers at sensible precision: 0.1 + 0.2 m is "0.3 m".
    let mut inputs = base.clone();
    inputs["beam"]["section"] = json!({"type": "tube", "outer_diameter": 0.1 + 0.2, "inner_diameter": 0.5});
    let errors = refused(&app, "cantilever-impact", &inputs).await;
    let (_, detail) = errors
        .iter()
        .find(|(p, _)| p == "/inputs/beam/section/inner_diameter")
        .unwrap_or_else(|| panic!("{errors:?}"));
    assert!(
        detail.contains("(0.3 m)") && !detail.contains("0.30000000000000004"),
        "{detail}"
    );
}

/// A sweep's runs carry the warnings of their own inputs in their status, and a sweep
/// over an odd range on purpose turns them off in its base inputs.
#[tokio::test]
async fn sweep_runs_show_their_warnings_unless_the_base_inputs_turn_them_off() {
    let app = spawn_idle().await;
    let mut body = example("sweep-calibration.json");
    body["inputs"]["release"]["tip_displacement"] = json!(0.0);
    body["axes"] = json!([{"pointer": "/contact/rk", "values": [1.0, 10.0]}]);
    let id = app.create_sweep(body.clone()).await;
    let jobs = app.get_json("/jobs").await;
    let runs: Vec<&Value> = jobs["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|job| job["sweepID"] == id.as_str())
        .collect();
    assert_eq!(runs.len(), 2, "{jobs}");
    for run in runs {
        assert_eq!(
            warnings(run),
            [(
                "nothing_excites".to_owned(),
                "/inputs/release/tip_displacement".to_owned()
            )],
            "{run}"
        );
    }

    body["inputs"]["warnings"] = json!("off");
    let quiet = app.create_sweep(body).await;
    let jobs = app.get_json("/jobs").await;
    let runs: Vec<&Value> = jobs["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|job| job["sweepID"] == quiet.as_str())
        .collect();
    assert_eq!(runs.len(), 2, "{jobs}");
    assert!(runs.iter().all(|run| warnings(run).is_empty()), "{runs:?}");
}

/// The hexagonal bundle with its default static correction: a pseudo-mode per contact
/// level (24 here, a level every H/12, two per element) stiffer than every eigenmode makes the critical
/// step many times smaller: a warning at `pin/static_correction` saying by how much;
/// none under `exact_modal` (whose step the pseudo-modes do not bound), none with the
/// correction off (the shipped hex217 example checks that side).
#[tokio::test]
async fn a_static_correction_that_shrinks_the_step_is_flagged_with_its_cost() {
    let app = spawn_idle().await;
    let mut inputs = example("hex217.json")["inputs"].clone();
    inputs["bundle"]["rings"] = json!(1);
    inputs["bundle"]["wrapper_flat_to_flat"] = json!(0.0305);
    inputs["pin"]["length"] = json!(0.6);
    inputs["bundle"]["wire_lead"] = json!(0.3);
    inputs["pin"]["elements"] = json!(24);
    inputs["pin"]["static_correction"] = json!("contacts");
    let body = accepted(&app, "hex-bundle-dynamics", &inputs).await;
    let found = warnings(&body);
    assert!(
        has(
            &found,
            "costly_static_correction",
            "/inputs/pin/static_correction"
        ),
        "{body}"
    );
    let message = message_of(&body, "costly_static_correction");
    let ratio = number_before(&message, "times smaller");
    assert!(ratio > 4.0, "{message}");
    // Under `exact_modal` the pseudo-modes cost no step: no warning.
    inputs["solver"]["scheme"] = json!("exact_modal");
    inputs["solver"]["time_step"] = json!("auto");
    let body = accepted(&app, "hex-bundle-dynamics", &inputs).await;
    assert!(
        !has(
            &warnings(&body),
            "costly_static_correction",
            "/inputs/pin/static_correction"
        ),
        "{body}"
    );
    inputs["solver"]["scheme"] = json!("central_difference");
    inputs["pin"]["static_correction"] = json!("none");
    let body = accepted(&app, "hex-bundle-dynamics", &inputs).await;
    assert!(!has(
        &warnings(&body),
        "costly_static_correction",
        "/inputs/pin/static_correction"
    ));
}

/// A run shorter than its earthquake record: a warning at `solver/duration` giving the
/// record's end (the spectrum-compatible record of 12 s, run for 2 s); none once the run
/// covers it, and none for a point force held past the end (sdnl104c's table).
#[tokio::test]
async fn a_run_that_ends_before_its_record_is_flagged_with_the_record_end() {
    let app = spawn_idle().await;
    let mut inputs = example("bundle-earthquake.json")["inputs"].clone();
    let record_end = inputs["excitation"]["base_acceleration"]["duration"]
        .as_f64()
        .unwrap();
    inputs["solver"]["duration"] = json!(record_end / 6.0);
    let body = accepted(&app, "bundle-dynamics", &inputs).await;
    let found = warnings(&body);
    assert!(
        has(&found, "excitation_outlasts_run", "/inputs/solver/duration"),
        "{body}"
    );
    let message = message_of(&body, "excitation_outlasts_run");
    assert!(message.contains(&format!("({record_end} s)")), "{message}");
    inputs["solver"]["duration"] = json!(record_end);
    let body = accepted(&app, "bundle-dynamics", &inputs).await;
    assert!(
        !has(
            &warnings(&body),
            "excitation_outlasts_run",
            "/inputs/solver/duration"
        ),
        "{body}"
    );
    let held = example("sdnl104c.json")["inputs"].clone();
    let body = accepted(&app, &process_of("sdnl104c.json"), &held).await;
    assert!(
        !has(
            &warnings(&body),
            "excitation_outlasts_run",
            "/inputs/solver/duration"
        ),
        "{body}"
    );
}
