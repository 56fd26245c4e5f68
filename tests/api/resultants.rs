//! The resultant contact force on each pin at each contact height (issue 33 item 1) over
//! HTTP: the vector sum of the contacts acting on the pin there, every step. A pin held
//! by two equal preloads carries none though each contact pushes K g; in a rattling row
//! and a wire-wrapped bundle a height with one contact gives that contact's peak, one with
//! several at most the sum of theirs, each pin's largest and the run's are the largest
//! of the lists; the per-pin and per-height tables (JSON and CSV) carry the results'
//! values; a process without pins has neither.

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

async fn results(app: &TestApp, process: &str, inputs: Value) -> (String, Value) {
    let response = app.post_execution(process, &json!({"inputs": inputs})).await;
    let status = response.status();
    let body: Value = response.json().await.unwrap();
    assert_eq!(status, StatusCode::CREATED, "{body}");
    let id = body["jobID"].as_str().unwrap().to_owned();
    let status = app.wait_until_finished(&id).await;
    assert_eq!(status["status"], "successful", "{status}");
    let document = app.get_json(&format!("/jobs/{id}/results")).await;
    (id, document)
}

fn number(value: &Value) -> f64 {
    value.as_f64().unwrap_or_else(|| panic!("not a number: {value}"))
}

#[tokio::test]
async fn a_pin_held_by_equal_preloads_carries_no_resultant_though_each_contact_pushes() {
    let app = spawn().await;
    let (stiffness, interference, height) = (2e5, 3e-5, 0.3);
    let contact = |left: Value, right: Value| json!({"left": left, "right": right, "height": height, "gap": -interference, "stiffness": stiffness});
    let inputs = json!({"pin": pin(), "pins": 1,
        "contacts": [contact(json!("wall"), json!(0)), contact(json!(0), json!("wall"))],
        "solver": {"duration": 0.01, "check": "none"}});
    let (_, document) = results(&app, "bundle-dynamics", inputs).await;
    let preload = stiffness * interference;
    for contact in document["contacts"].as_array().unwrap() {
        let force = number(&contact["max_force"]);
        assert!(
            (force - preload).abs() <= 1e-9 * preload,
            "{force} N, not K g = {preload} N"
        );
    }
    let resultants = document["pins"][0]["resultant_forces"].as_array().unwrap();
    assert_eq!(resultants.len(), 1, "{resultants:?}");
    assert_eq!(resultants[0]["height"], height);
    assert_eq!(resultants[0]["contacts"], 2);
    assert!(
        number(&resultants[0]["max_force"]) <= 1e-9 * preload,
        "{resultants:?}"
    );
    assert_eq!(document["pins"][0]["max_resultant_force"], resultants[0]);
    assert_eq!(document["max_resultant_force"]["pin"], 0);
}

/// Every pin's resultants against its contacts: `on_pin(contact, pin)` says whether a
/// contact acts on a pin.
fn check_resultants(document: &Value, on_pin: impl Fn(&Value, usize) -> bool) {
    let contacts = document["contacts"].as_array().unwrap();
    let (mut largest, mut several_closed) = (0.0_f64, 0);
    for (p, pin) in document["pins"].as_array().unwrap().iter().enumerate() {
        let list = pin["resultant_forces"].as_array().unwrap();
        let mut heights: Vec<f64> = (contacts.iter())
            .filter(|c| on_pin(c, p))
            .map(|c| number(&c["height"]))
            .collect();
        heights.sort_by(f64::total_cmp);
        heights.dedup();
        let listed: Vec<f64> = list.iter().map(|r| number(&r["height"])).collect();
        assert_eq!(
            listed, heights,
            "pin {p}: one entry per height with a contact, from the foot"
        );
        for resultant in list {
            let height = number(&resultant["height"]);
            let here: Vec<f64> = (contacts.iter())
                .filter(|c| on_pin(c, p) && number(&c["height"]) == height)
                .map(|c| number(&c["max_force"]))
                .collect();
            assert_eq!(resultant["contacts"], here.len(), "pin {p} at {height} m");
            let force = number(&resultant["max_force"]);
            if here.len() == 1 {
                // |F n| with |n| = 1 to rounding.
                assert!(
                    (force - here[0]).abs() <= 1e-12 * here[0],
                    "pin {p} at {height} m: a lone contact's resultant {force} N is its peak {} N",
                    here[0]
                );
            } else {
                let sum: f64 = here.iter().sum();
                assert!(
                    force <= sum * (1.0 + 1e-12),
                    "pin {p} at {height} m: {force} N above {sum} N"
                );
                if here.iter().all(|f| (force - f).abs() > 1e-9 * f.max(1e-30)) {
                    several_closed += 1;
                }
            }
        }
        let max = list.iter().map(|r| number(&r["max_force"])).fold(0.0, f64::max);
        assert_eq!(number(&pin["max_resultant_force"]["max_force"]), max, "pin {p}");
        largest = largest.max(max);
    }
    assert!(
        largest > 0.0,
        "no contact ever closed: the test shakes too little"
    );
    assert_eq!(number(&document["max_resultant_force"]["max_force"]), largest);
    let pin = document["max_resultant_force"]["pin"].as_u64().unwrap() as usize;
    assert_eq!(
        number(&document["pins"][pin]["max_resultant_force"]["max_force"]),
        largest
    );
    eprintln!("heights where several contacts closed together made the resultant: {several_closed}");
}

#[tokio::test]
async fn a_rattling_rows_resultants_are_bounded_by_its_contacts_and_tabulated() {
    let app = spawn().await;
    let inputs = json!({"pin": pin(),
        "bundle": {"pins": 3, "levels": [0.3, 0.6], "stiffness": 2e5, "damping": 2.0,
                   "wall_gap": 1e-4, "pin_gap": 5e-5},
        "initial": {"tip_displacements": [1e-3, -1e-3, 1e-3]},
        "solver": {"duration": 0.04, "check": "none"},
        "output": {"interval": 1e-3}});
    let (id, document) = results(&app, "bundle-dynamics", inputs).await;
    let body_is = |side: &Value, p: usize| side.as_u64() == Some(p as u64);
    check_resultants(&document, |c, p| {
        body_is(&c["left"], p) || body_is(&c["right"], p)
    });
    check_tables(&app, &id, &document).await;
}

#[tokio::test]
async fn a_wire_wrapped_bundles_resultants_are_bounded_by_its_wires_and_tabulated() {
    let app = spawn().await;
    let inputs = json!({"pin": pin(),
        "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                   "wrapper_flat_to_flat": 0.0305},
        "contact": {"stiffness": 2e5, "damping": 2.0},
        "gaps": {"type": "uniform", "pin_pin": 0.0, "pin_wall": 0.0},
        "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 30.0, "cycles": 2},
                       "direction": 30.0},
        "solver": {"duration": 0.04, "check": "none"},
        "output": {"interval": 1e-3}});
    let (id, document) = results(&app, "hex-bundle-dynamics", inputs).await;
    check_resultants(&document, |c, p| c["wire_pin"] == p || c["touched_pin"] == p);
    check_tables(&app, &id, &document).await;

    // A process without pins has neither table.
    let cantilever = json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                    "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                    "elements": 10, "modes": 4},
           "contact": {"rk": 1.0}, "solver": {"duration": 0.02, "check": "none"}});
    let (id, _) = results(&app, "cantilever-impact", cantilever).await;
    for table in ["pins", "resultants"] {
        assert_problem(
            app.get(&format!("/jobs/{id}/results/{table}")).await,
            StatusCode::NOT_FOUND,
            "/no-such-output",
        )
        .await;
    }
}

/// The CSV of `path` as a header and rows of cells.
async fn csv(app: &TestApp, path: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let response = app.get(path).await;
    assert_eq!(response.status(), StatusCode::OK);
    assert!(
        response.headers()["content-type"]
            .to_str()
            .unwrap()
            .starts_with("text/csv")
    );
    let text = response.text().await.unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(str::to_owned).collect::<Vec<_>>());
    (lines.next().unwrap(), lines.collect())
}

/// The per-pin and per-height tables, JSON and CSV, carry the results' values.
async fn check_tables(app: &TestApp, id: &str, document: &Value) {
    let pins = document["pins"].as_array().unwrap();
    let table = app.get_json(&format!("/jobs/{id}/results/pins")).await;
    let records = table["pins"].as_array().unwrap();
    assert_eq!(records.len(), pins.len());
    let (header, rows) = csv(app, &format!("/jobs/{id}/results/pins?format=csv")).await;
    assert_eq!(rows.len(), pins.len());
    let column = |name: &str| {
        header
            .iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no {name}"))
    };
    for (p, (pin, (record, row))) in pins.iter().zip(records.iter().zip(&rows)).enumerate() {
        for (name, value) in [
            ("pin", &pin["pin"]),
            ("bending.stress", &pin["bending"]["stress"]),
            ("bending.height", &pin["bending"]["height"]),
            (
                "max_resultant_force.max_force",
                &pin["max_resultant_force"]["max_force"],
            ),
            (
                "max_resultant_force.height",
                &pin["max_resultant_force"]["height"],
            ),
        ] {
            assert_eq!(&record[name], value, "pin {p}: {name}");
            assert_eq!(
                row[column(name)].parse::<f64>().unwrap(),
                number(value),
                "pin {p}: {name}"
            );
        }
    }
    let expected: Vec<(u64, &Value)> = (pins.iter())
        .flat_map(|pin| {
            let p = pin["pin"].as_u64().unwrap();
            pin["resultant_forces"]
                .as_array()
                .unwrap()
                .iter()
                .map(move |r| (p, r))
        })
        .collect();
    let table = app.get_json(&format!("/jobs/{id}/results/resultants")).await;
    assert_eq!(
        table["columns"],
        json!(["pin", "contacts", "height", "max_force", "time"])
    );
    let records = table["resultants"].as_array().unwrap();
    let (header, rows) = csv(app, &format!("/jobs/{id}/results/resultants?format=csv")).await;
    assert_eq!(header, ["pin", "contacts", "height", "max_force", "time"]);
    assert_eq!((records.len(), rows.len()), (expected.len(), expected.len()));
    for ((record, row), (p, resultant)) in records.iter().zip(&rows).zip(&expected) {
        assert_eq!(record["pin"], *p);
        for (k, name) in ["contacts", "height", "max_force", "time"].iter().enumerate() {
            assert_eq!(&record[*name], &resultant[*name], "pin {p}: {name}");
            assert_eq!(
                row[k + 1].parse::<f64>().unwrap(),
                number(&resultant[*name]),
                "pin {p}: {name}"
            );
        }
    }
}
