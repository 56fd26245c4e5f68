//! Margins over HTTP (docs/margins.md): `output.allowables` turns each contact's peak
//! force and each pin's largest bending stress into utilisation ratios. Checked from the
//! runs' own numbers by the definitions, never against a past run:
//!
//! - utilisation × allowable = the peak the same document reports (contact force,
//!   outer-fibre stress), per contact and per pin;
//! - a pin's contact utilisation is the largest of the contacts it takes part in, its
//!   utilisation the larger of that and its stress's; the run's worst is the largest;
//! - without allowables every utilisation is null, and with them nothing else in the
//!   document changes (allowables report, they do not act);
//! - the per-contact table (JSON and CSV) and the sweep aggregates carry them;
//! - a non-positive allowable, a family the process has not, an allowable given twice
//!   or a stress without a diameter: 422 at the member.

use std::time::Duration;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::Registry;

use crate::helpers::{TestApp, assert_problem, spawn_app_with_processes};

async fn spawn() -> TestApp {
    spawn_app_with_processes(Registry::builtin().all().to_vec(), |_| {}).await
}

fn pin() -> Value {
    json!({"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
           "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "damping_ratio": 0.01})
}

/// A row of three pins between two walls, released toward each other, contacts at two
/// levels, with `output`.
fn row(output: Value) -> Value {
    json!({"pin": pin(),
           "bundle": {"pins": 3, "levels": [0.3, 0.6], "stiffness": 2e5, "damping": 2.0,
                      "wall_gap": 1e-4, "pin_gap": 5e-5},
           "initial": {"tip_displacements": [1e-3, -1e-3, 1e-3]},
           "solver": {"duration": 0.04, "check": "none"},
           "output": output})
}

/// Seven wire-wrapped pins shaken against each other and the wrapper, with `output`.
fn hex(output: Value) -> Value {
    json!({"pin": pin(),
           "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                      "wrapper_flat_to_flat": 0.0305},
           "contact": {"stiffness": 2e5, "damping": 2.0},
           "gaps": {"type": "uniform", "pin_pin": 0.0, "pin_wall": 0.0},
           "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 30.0, "cycles": 2},
                          "direction": 30.0},
           "solver": {"duration": 0.04, "check": "none"},
           "output": output})
}

fn cantilever(output: Value) -> Value {
    json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                    "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                    "elements": 20, "modes": 6},
           "contact": {"rk": 1.0},
           "solver": {"duration": 0.1},
           "reference": {"modes": 10},
           "output": output})
}

async fn submit(app: &TestApp, process: &str, inputs: Value) -> String {
    let response = app.post_execution(process, &json!({"inputs": inputs})).await;
    let status = response.status();
    let body: Value = response.json().await.unwrap();
    assert_eq!(status, StatusCode::CREATED, "{body}");
    let id = body["jobID"].as_str().unwrap().to_owned();
    let status = app.wait_until_finished(&id).await;
    assert_eq!(status["status"], "successful", "{status}");
    id
}

async fn results(app: &TestApp, process: &str, inputs: Value) -> Value {
    let id = submit(app, process, inputs).await;
    app.get_json(&format!("/jobs/{id}/results")).await
}

/// The problem's (pointer, detail) pairs, sorted by pointer.
async fn refused(app: &TestApp, process: &str, inputs: Value) -> Vec<(String, String)> {
    let response = app.post_execution(process, &json!({"inputs": inputs})).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let mut errors: Vec<(String, String)> = (problem["errors"].as_array().unwrap().iter())
        .map(|e| {
            (
                e["pointer"].as_str().unwrap().to_owned(),
                e["detail"].as_str().unwrap().to_owned(),
            )
        })
        .collect();
    errors.sort();
    errors
}

fn number(value: &Value, what: &str) -> f64 {
    value
        .as_f64()
        .unwrap_or_else(|| panic!("{what} is not a number: {value}"))
}

/// `measured` is `expected` to 1e-12 relative.
fn close(measured: f64, expected: f64, what: &str) {
    assert!(
        (measured - expected).abs() <= 1e-12 * expected.abs().max(1e-300),
        "{what}: measured {measured}, expected {expected}"
    );
}

/// Every margin member of a bundle's document set to null: what the document would be
/// without allowables.
fn without_margins(document: &Value) -> Value {
    let mut document = document.clone();
    for contact in document["contacts"].as_array_mut().unwrap() {
        contact["allowable_force"] = Value::Null;
        contact["utilisation"] = Value::Null;
    }
    for pin in document["pins"].as_array_mut().unwrap() {
        for member in ["stress_utilisation", "contact_utilisation", "utilisation"] {
            pin[member] = Value::Null;
        }
    }
    for member in ["max_utilisation", "max_stress_utilisation", "worst_utilisation"] {
        document[member] = Value::Null;
    }
    // The links name the job, and the provenance hashes the inputs, which differ.
    let members = document.as_object_mut().unwrap();
    members.remove("outputs");
    members.remove("provenance");
    document
}

/// The bundle document's margins follow from its peaks: per contact (with its family's
/// allowable `allowable(contact)`), per pin (its contacts by `on_pin`), and the run.
fn check_bundle_margins(
    document: &Value,
    allowable: impl Fn(&Value) -> f64,
    stress: f64,
    on_pin: impl Fn(&Value, u64) -> bool,
) {
    let contacts = document["contacts"].as_array().unwrap();
    let mut worst_contact = (f64::NEG_INFINITY, 0);
    for (k, contact) in contacts.iter().enumerate() {
        let expected = allowable(contact);
        assert_eq!(
            number(&contact["allowable_force"], "allowable_force"),
            expected,
            "{contact}"
        );
        let utilisation = number(&contact["utilisation"], "utilisation");
        close(
            utilisation * expected,
            number(&contact["max_force"], "max_force"),
            &format!("c{k}: utilisation × allowable"),
        );
        if utilisation > worst_contact.0 {
            worst_contact = (utilisation, k);
        }
    }
    let mut worst_stress = (f64::NEG_INFINITY, 0);
    for pin in document["pins"].as_array().unwrap() {
        let p = pin["pin"].as_u64().unwrap();
        let stress_utilisation = number(&pin["stress_utilisation"], "stress_utilisation");
        close(
            stress_utilisation * stress,
            number(&pin["bending"]["stress"], "bending.stress"),
            &format!("pin {p}: stress utilisation × allowable"),
        );
        if stress_utilisation > worst_stress.0 {
            worst_stress = (stress_utilisation, p as usize);
        }
        let of_contacts = (contacts.iter())
            .filter(|c| on_pin(c, p))
            .map(|c| number(&c["utilisation"], "utilisation"))
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(of_contacts.is_finite(), "pin {p} takes part in contacts");
        assert_eq!(
            number(&pin["contact_utilisation"], "contact_utilisation"),
            of_contacts,
            "{pin}"
        );
        assert_eq!(
            number(&pin["utilisation"], "utilisation"),
            of_contacts.max(stress_utilisation),
            "{pin}"
        );
    }
    let run = &document["max_utilisation"];
    assert_eq!(run["contact"], worst_contact.1, "{run}");
    assert_eq!(number(&run["utilisation"], "max_utilisation"), worst_contact.0);
    let run_stress = &document["max_stress_utilisation"];
    let max_bending = &document["max_bending"];
    for member in ["pin", "height", "time", "stress"] {
        assert_eq!(
            run_stress[member], max_bending[member],
            "{run_stress} is at {max_bending}"
        );
    }
    assert_eq!(
        number(&run_stress["allowable_stress"], "allowable_stress"),
        stress
    );
    assert_eq!(
        number(&run_stress["utilisation"], "stress utilisation"),
        worst_stress.0,
        "{run_stress}"
    );
    assert_eq!(
        number(&document["worst_utilisation"], "worst_utilisation"),
        worst_contact.0.max(worst_stress.0)
    );
}

#[tokio::test]
async fn a_rows_utilisations_times_their_allowables_give_its_peaks_and_nothing_else_changes() {
    let app = spawn().await;
    let (pin_pin, pin_wall, stress) = (3.0, 5.0, 2e7);
    let allowables = json!({"contact_force": {"pin_pin": pin_pin, "pin_wall": pin_wall}, "stress": stress});
    let with = results(&app, "bundle-dynamics", row(json!({"allowables": allowables}))).await;
    let wall = |c: &Value| c["left"] == "wall" || c["right"] == "wall";
    check_bundle_margins(
        &with,
        |c| if wall(c) { pin_wall } else { pin_pin },
        stress,
        |c, p| c["left"] == p || c["right"] == p,
    );
    assert!(
        with["contacts"]
            .as_array()
            .unwrap()
            .iter()
            .any(|c| number(&c["max_force"], "max_force") > 0.0),
        "the released pins must touch: {with}"
    );

    let bare = results(&app, "bundle-dynamics", row(json!({}))).await;
    for contact in bare["contacts"].as_array().unwrap() {
        assert!(
            contact["utilisation"].is_null() && contact["allowable_force"].is_null(),
            "{contact}"
        );
    }
    for pin in bare["pins"].as_array().unwrap() {
        assert!(
            pin["utilisation"].is_null() && pin["stress_utilisation"].is_null(),
            "{pin}"
        );
    }
    assert!(bare["worst_utilisation"].is_null() && bare["max_stress_utilisation"].is_null());
    assert_eq!(
        without_margins(&with),
        without_margins(&bare),
        "allowables change nothing but the margins"
    );
}

#[tokio::test]
async fn the_contact_table_carries_each_contacts_allowable_and_utilisation_in_json_and_csv() {
    let app = spawn().await;
    let allowables = json!({"contact_force": 4.0});
    let id = submit(&app, "bundle-dynamics", row(json!({"allowables": allowables}))).await;
    let document = app.get_json(&format!("/jobs/{id}/results")).await;
    let contacts = document["contacts"].as_array().unwrap();
    let table = app.get_json(&format!("/jobs/{id}/results/contacts")).await;
    let records = table["contacts"].as_array().unwrap();
    assert_eq!(records.len(), contacts.len());
    for (record, contact) in records.iter().zip(contacts) {
        assert_eq!(record["allowable_force"], 4.0, "{record}");
        assert_eq!(record["utilisation"], contact["utilisation"], "{record}");
    }
    let csv = app
        .get(&format!("/jobs/{id}/results/contacts?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|c| *c == name)
            .unwrap_or_else(|| panic!("{name} in {header:?}"))
    };
    let (force, allowable, utilisation) = (
        column("max_force"),
        column("allowable_force"),
        column("utilisation"),
    );
    for (line, contact) in lines.zip(contacts) {
        let cells: Vec<&str> = line.split(',').collect();
        let parse = |k: usize| cells[k].parse::<f64>().unwrap_or_else(|e| panic!("{line}: {e}"));
        assert_eq!(parse(allowable), 4.0);
        assert_eq!(parse(force), number(&contact["max_force"], "max_force"));
        close(parse(utilisation) * parse(allowable), parse(force), line);
    }

    // Without allowables the table has no such columns (a null is no value).
    let bare = submit(&app, "bundle-dynamics", row(json!({}))).await;
    let table = app.get_json(&format!("/jobs/{bare}/results/contacts")).await;
    let columns: Vec<&str> = table["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert!(
        !columns.contains(&"utilisation") && !columns.contains(&"allowable_force"),
        "{columns:?}"
    );
}

#[tokio::test]
async fn a_hexagonal_bundles_pins_take_the_utilisations_of_their_wires_and_clads() {
    let app = spawn().await;
    let (force, stress) = (2.0, 1e7);
    let document = results(
        &app,
        "hex-bundle-dynamics",
        hex(json!({"interval": 1e-3, "allowables": {"contact_force": force, "stress": stress}})),
    )
    .await;
    check_bundle_margins(
        &document,
        |_| force,
        stress,
        |c, p| c["wire_pin"] == p || c["touched_pin"] == p,
    );

    // One family only: the other's contacts have none, and the run's worst is among those given.
    let document = results(
        &app,
        "hex-bundle-dynamics",
        hex(json!({"interval": 1e-3, "allowables": {"contact_force": {"pin_wall": force}}})),
    )
    .await;
    for contact in document["contacts"].as_array().unwrap() {
        let on_wall = contact["touched_pin"].is_null();
        assert_eq!(contact["allowable_force"].is_null(), !on_wall, "{contact}");
        assert_eq!(contact["utilisation"].is_null(), !on_wall, "{contact}");
    }
    let worst = document["max_utilisation"]["contact"].as_u64().unwrap() as usize;
    assert!(document["contacts"][worst]["touched_pin"].is_null());
    assert!(document["max_stress_utilisation"].is_null());
    assert_eq!(
        document["worst_utilisation"],
        document["max_utilisation"]["utilisation"]
    );
}

#[tokio::test]
async fn the_cantilevers_tip_contact_and_beam_report_their_utilisations() {
    let app = spawn().await;
    let (force, stress) = (0.05, 1e6);
    let document = results(
        &app,
        "cantilever-impact",
        cantilever(json!({"allowables": {"contact_force": force, "stress": stress}})),
    )
    .await;
    let numerical = &document["numerical"];
    assert_eq!(numerical["allowable_force"], force);
    let utilisation = number(&numerical["utilisation"], "utilisation");
    close(
        utilisation * force,
        number(&numerical["max_contact_force"], "max_contact_force"),
        "utilisation × allowable",
    );
    let bending = &numerical["max_bending"];
    let by_stress = &numerical["max_stress_utilisation"];
    assert_eq!(by_stress["stress"], bending["stress"]);
    assert_eq!(by_stress["height"], bending["height"]);
    let stress_utilisation = number(&by_stress["utilisation"], "stress utilisation");
    close(
        stress_utilisation * stress,
        number(&bending["stress"], "max_bending.stress"),
        "stress utilisation × allowable",
    );
    assert_eq!(
        number(&numerical["worst_utilisation"], "worst"),
        utilisation.max(stress_utilisation)
    );

    let bare = results(&app, "cantilever-impact", cantilever(json!({}))).await;
    for member in [
        "allowable_force",
        "utilisation",
        "max_stress_utilisation",
        "worst_utilisation",
    ] {
        assert!(
            bare["numerical"][member].is_null(),
            "{member}: {}",
            bare["numerical"]
        );
    }
}

#[tokio::test]
async fn bad_allowables_are_refused_at_their_members_with_the_reason() {
    let app = spawn().await;
    let errors = refused(
        &app,
        "bundle-dynamics",
        row(json!({"allowables": {"contact_force": {"pin_pin": 0.0, "pin_wall": -2.0}, "stress": -1.0}})),
    )
    .await;
    let pointers: Vec<&str> = errors.iter().map(|(p, _)| p.as_str()).collect();
    assert_eq!(
        pointers,
        [
            "/inputs/output/allowables/contact_force/pin_pin",
            "/inputs/output/allowables/contact_force/pin_wall",
            "/inputs/output/allowables/stress",
        ],
        "{errors:?}"
    );
    assert!(
        errors.iter().all(|(_, detail)| detail.contains("> 0")),
        "{errors:?}"
    );

    // A family the process has not.
    let errors = refused(
        &app,
        "hex-bundle-dynamics",
        hex(json!({"allowables": {"contact_force": {"walls": 5.0}}})),
    )
    .await;
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].0.starts_with("/inputs/output/allowables/contact_force"),
        "{errors:?}"
    );
    assert!(
        errors[0].1.contains("pin_pin") && errors[0].1.contains("pin_wall"),
        "{errors:?}"
    );
    let errors = refused(
        &app,
        "cantilever-impact",
        cantilever(json!({"allowables": {"contact_force": {"pin_pin": 5.0}}})),
    )
    .await;
    assert_eq!(
        errors[0].0, "/inputs/output/allowables/contact_force",
        "{errors:?}"
    );

    // Given twice: by the family's law and here.
    let mut twice = row(json!({"allowables": {"contact_force": {"pin_wall": 5.0}}}));
    twice["bundle"]["wall_law"] = json!({"allowable_force": 6.0});
    let errors = refused(&app, "bundle-dynamics", twice).await;
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].0, "/inputs/output/allowables/contact_force/pin_wall");
    assert!(
        errors[0].1.contains("/inputs/bundle/wall_law/allowable_force"),
        "{errors:?}"
    );
    // ... while another family's law is no conflict.
    let mut other = row(json!({"allowables": {"contact_force": {"pin_pin": 5.0}}}));
    other["bundle"]["wall_law"] = json!({"allowable_force": 6.0});
    let document = results(&app, "bundle-dynamics", other).await;
    for contact in document["contacts"].as_array().unwrap() {
        let wall = contact["left"] == "wall" || contact["right"] == "wall";
        assert_eq!(
            contact["allowable_force"],
            if wall { 6.0 } else { 5.0 },
            "{contact}"
        );
    }

    // A stress with no outer fibre to find it at.
    let mut explicit = row(json!({"allowables": {"stress": 1e8}}));
    explicit["pin"]["section"] = json!({"type": "explicit", "area": 1.7153e-5, "inertia": 1.8338e-10});
    let errors = refused(&app, "bundle-dynamics", explicit).await;
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].0, "/inputs/output/allowables/stress");
    assert!(errors[0].1.contains("diameter"), "{errors:?}");
}

#[tokio::test]
async fn a_random_sweep_aggregates_the_worst_utilisation_of_its_runs() {
    let app = spawn().await;
    let mut body: Value = serde_json::from_str(include_str!("../../examples/sweep-gaps.json")).unwrap();
    body["samples"] = json!(3);
    body["inputs"]["solver"]["duration"] = json!(0.02);
    body["inputs"]["output"]["allowables"] = json!({"contact_force": 2.0, "stress": 5e7});
    let id = app.create_sweep(body).await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(180))
        .await;
    let results = app.sweep_results(&id).await;
    let rows = results["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    let mut worst = Vec::new();
    for row in rows {
        let contact = number(&row["max_utilisation.utilisation"], "max_utilisation.utilisation");
        close(
            contact * 2.0,
            number(&row["max_contact_force.force"], "max_contact_force.force"),
            "worst contact",
        );
        let stress = number(
            &row["max_stress_utilisation.utilisation"],
            "max_stress_utilisation.utilisation",
        );
        close(
            stress * 5e7,
            number(&row["max_bending.stress"], "max_bending.stress"),
            "worst stress",
        );
        let run = number(&row["worst_utilisation"], "worst_utilisation");
        assert_eq!(run, contact.max(stress), "{row}");
        worst.push(run);
    }
    let statistics = &results["aggregates"]["statistics"][0]["metrics"]["worst_utilisation"];
    assert_eq!(statistics["count"], 3, "{statistics}");
    assert_eq!(
        number(&statistics["max"], "max"),
        worst.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    );
    assert_eq!(
        number(&statistics["min"], "min"),
        worst.iter().copied().fold(f64::INFINITY, f64::min)
    );
}
