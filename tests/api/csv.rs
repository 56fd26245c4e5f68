//! CSV for humans and machines (issue 20 item 6): a history's JSON form says what each
//! column is (name, unit, what it measures), `header=long` puts the same in the CSV
//! header while the short header keeps the names scripts index (`time,c0,c1`), and every
//! CSV the service writes (histories, their spectra, the impact table, sweep results, a
//! signal's samples and spectrum) writes its numbers the same way: the shortest text
//! that reads back as the same double, as the JSON documents write it.

use std::sync::Arc;
use std::time::Duration;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;

use crate::helpers::{TestApp, assert_problem, spawn_app_with_processes};

/// Height of every contact of the row (m).
const HEIGHT: f64 = 0.18;

/// Two short pins between the walls, in contact at [`HEIGHT`], one released.
fn row() -> Value {
    json!({"inputs": {
        "pin": {"length": 0.2, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "elements": 6, "modes": 3},
        "pins": 2,
        "contacts": [
            {"left": "wall", "right": 0, "height": HEIGHT, "gap": 1e-5, "stiffness": 2e5},
            {"left": 0, "right": 1, "height": HEIGHT, "gap": 1e-5, "stiffness": 2e5},
            {"left": 1, "right": "wall", "height": HEIGHT, "gap": 1e-5, "stiffness": 2e5}],
        "initial": {"tip_displacements": [1e-4, 0.0]},
        "solver": {"duration": 0.005, "check": "none"},
        "output": {"heights": [0.1, 0.2]}}})
}

async fn run(app: &TestApp, process: &str, body: &Value) -> String {
    let response = app.post_execution(process, body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let id = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status = app.wait_until_finished(&id).await;
    assert_eq!(status["status"], "successful", "{status}");
    id
}

async fn text(app: &TestApp, path: &str) -> String {
    let response = app.get(path).await;
    assert_eq!(response.status(), StatusCode::OK, "{path}");
    response.text().await.unwrap()
}

#[tokio::test]
async fn a_history_says_what_each_column_is_in_json_and_in_a_long_csv_header() {
    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await;
    let job = run(&app, "bundle-dynamics", &row()).await;

    let forces = app.get_json(&format!("/jobs/{job}/results/contact_forces")).await;
    let columns = forces["columns"].as_array().unwrap();
    let named: Vec<&str> = columns.iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(named, ["time", "c0", "c1", "c2"]);
    assert_eq!(columns[0]["unit"], "s");
    for (column, bodies) in columns[1..].iter().zip(["wall–p0", "p0–p1", "p1–wall"]) {
        assert_eq!(column["unit"], "N", "{column}");
        assert_eq!(
            column["description"],
            format!("contact {bodies} at {HEIGHT} m"),
            "{column}"
        );
    }
    let deflections = app.get_json(&format!("/jobs/{job}/results/displacements")).await;
    let p1 = deflections["columns"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "p1@0.1")
        .unwrap_or_else(|| panic!("no p1@0.1 column: {deflections}"));
    assert_eq!(p1["unit"], "m");
    assert!(
        p1["description"]
            .as_str()
            .unwrap()
            .starts_with("deflection of p1 at 0.1 m"),
        "{p1}"
    );
    let peaks = app
        .get_json(&format!("/jobs/{job}/results/contact_forces_peaks"))
        .await;
    assert!(
        peaks["columns"][1]["description"]
            .as_str()
            .unwrap()
            .contains("over each output interval")
    );

    // The short header is the names scripts index; the long one adds unit and meaning,
    // each cell starting with the name; the numbers are the same.
    let short = text(&app, &format!("/jobs/{job}/results/contact_forces?format=csv")).await;
    let long = text(
        &app,
        &format!("/jobs/{job}/results/contact_forces?format=csv&header=long"),
    )
    .await;
    let (short_header, short_body) = short.split_once('\n').unwrap();
    let (long_header, long_body) = long.split_once('\n').unwrap();
    assert_eq!(short_header, "time,c0,c1,c2");
    assert_eq!(long_body, short_body);
    let cells: Vec<&str> = long_header.split(',').collect();
    assert_eq!(cells[0], "time [s] time from the start of the run");
    assert_eq!(cells[1], format!("c0 [N] contact wall–p0 at {HEIGHT} m"));
    for (cell, name) in cells.iter().zip(short_header.split(',')) {
        assert_eq!(cell.split(' ').next(), Some(name));
    }
    // A chosen series keeps its description.
    let picked = text(
        &app,
        &format!("/jobs/{job}/results/contact_forces?format=csv&header=long&series=c2"),
    )
    .await;
    assert!(picked.starts_with(&format!(
        "time [s] time from the start of the run,c2 [N] contact p1–wall at {HEIGHT} m\n"
    )));

    let bad = app
        .get(&format!(
            "/jobs/{job}/results/contact_forces?format=csv&header=wide"
        ))
        .await;
    assert_problem(bad, StatusCode::BAD_REQUEST, "/invalid-query").await;
}

#[tokio::test]
async fn the_cantilever_histories_describe_both_solutions() {
    let app = spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |_| {}).await;
    let body = json!({"inputs": {
        "beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                 "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                 "elements": 8, "modes": 4},
        "solver": {"duration": 0.03, "check": "none"}, "reference": {"modes": 6}}});
    let job = run(&app, "cantilever-impact", &body).await;
    for (output, unit) in [("tip_displacement", "m"), ("contact_force", "N")] {
        let history = app.get_json(&format!("/jobs/{job}/results/{output}")).await;
        let columns = &history["columns"];
        assert_eq!(columns[1]["name"], "numerical");
        assert_eq!(columns[2]["name"], "reference");
        for column in &columns.as_array().unwrap()[1..] {
            assert_eq!(column["unit"], unit, "{column}");
        }
        assert!(
            columns[2]["description"]
                .as_str()
                .unwrap()
                .contains("semi-analytic reference")
        );
    }
}

/// Whether `cell` is a number written as the JSON documents write it: an integer, or
/// the shortest text that reads back as the same double.
fn canonical(cell: &str) -> bool {
    let integer = cell.strip_prefix('-').unwrap_or(cell);
    if !integer.is_empty() && integer.bytes().all(|b| b.is_ascii_digit()) {
        return true;
    }
    cell.parse::<f64>()
        .ok()
        .and_then(serde_json::Number::from_f64)
        .is_some_and(|n| n.to_string() == cell)
}

/// Every cell of `csv` below its header that reads as a number is written canonically;
/// at least `numbers` of them do.
fn assert_numbers_canonical(csv: &str, what: &str, numbers: usize) {
    let mut seen = 0;
    for line in csv.lines().skip(1) {
        for cell in line.split(',') {
            if cell.parse::<f64>().is_ok() {
                seen += 1;
                assert!(
                    canonical(cell),
                    "{what}: `{cell}` is not the shortest text of its number"
                );
            }
        }
    }
    assert!(seen >= numbers, "{what}: only {seen} numbers in\n{csv}");
}

#[tokio::test]
async fn every_csv_writes_its_numbers_the_same_way() {
    let app =
        spawn_app_with_processes(vec![Arc::new(BundleDynamics), Arc::new(CantileverImpact)], |_| {}).await;
    let job = run(&app, "bundle-dynamics", &row()).await;
    for output in ["contact_forces", "displacements_peaks"] {
        let csv = text(&app, &format!("/jobs/{job}/results/{output}?format=csv")).await;
        assert_numbers_canonical(&csv, output, 100);
        let spectrum = text(&app, &format!("/jobs/{job}/results/{output}/spectrum?format=csv")).await;
        assert_numbers_canonical(&spectrum, "a history's spectrum", 10);
    }
    let impacts = text(&app, &format!("/jobs/{job}/results/impacts?format=csv")).await;
    assert_numbers_canonical(&impacts, "the impact table", 10);

    let samples: String = (0..200)
        .map(|k| format!("{},{}\n", k as f64 / 1000.0, (k as f64 * 0.37).sin()))
        .collect();
    let signal = app
        .upload_signal(format!("time,acceleration\n{samples}"), "text/csv", "")
        .await;
    let id = signal["id"].as_str().unwrap();
    let samples = text(&app, &format!("/signals/{id}/samples?format=csv")).await;
    assert_numbers_canonical(&samples, "a signal's samples", 400);
    let spectrum = text(&app, &format!("/signals/{id}/spectrum?format=csv")).await;
    assert_numbers_canonical(&spectrum, "a signal's spectrum", 10);

    let inputs = json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                                 "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                                 "elements": 8, "modes": 4},
                        "solver": {"duration": 0.02, "check": "none"}, "reference": {"modes": 6}});
    let sweep = app
        .create_sweep(json!({"process": "cantilever-impact", "inputs": inputs,
                             "axes": [{"pointer": "/contact/rk", "values": [0.3, 1.0]}]}))
        .await;
    app.wait_for_sweep(&sweep, &["successful"], Duration::from_secs(60))
        .await;
    assert_numbers_canonical(&app.sweep_csv(&sweep).await, "sweep results", 20);
}
