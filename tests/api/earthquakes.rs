//! Synthetic earthquakes through real HTTP: a sweep over seeds is a Monte Carlo campaign
//! over earthquakes (one row per seed, each seed its own record), and a bad target
//! spectrum is a 422 at its pointer before anything is queued.

use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{assert_problem, spawn_app_with_processes};

fn inputs() -> Value {
    let text = include_str!("../../examples/bundle-earthquake.json");
    let mut body: Value = serde_json::from_str(text).unwrap_or_default();
    body["inputs"]["bundle"]["pins"] = json!(2);
    body["inputs"]["solver"]["duration"] = json!(0.5);
    body["inputs"].take()
}

#[tokio::test]
async fn a_sweep_over_seeds_runs_one_earthquake_per_seed() {
    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await;
    let body = json!({"process": "bundle-dynamics", "inputs": inputs(),
        "axes": [{"pointer": "/excitation/base_acceleration/seed", "values": [1, 2, 1]}]});
    let id = app.create_sweep(body).await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(300))
        .await;
    let results = app.sweep_results(&id).await;
    let rows = results["rows"].as_array().cloned().unwrap_or_default();
    assert_eq!(rows.len(), 3, "{results}");
    let peak = |row: &Value| row["pins.0.max_abs_deflection"].as_f64().unwrap_or(f64::NAN);
    assert!(peak(&rows[0]) > 0.0, "{}", rows[0]);
    assert_eq!(peak(&rows[0]), peak(&rows[2]), "seed 1 twice, two results");
    assert_ne!(
        peak(&rows[0]),
        peak(&rows[1]),
        "seeds 1 and 2 gave the same result"
    );
}

#[tokio::test]
async fn an_unsorted_target_spectrum_is_refused_at_its_pointer() {
    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await;
    let mut inputs = inputs();
    inputs["excitation"]["base_acceleration"]["target"]["frequencies"] = json!([1.0, 6.67, 2.5, 33.0]);
    let response = app
        .post_execution("bundle-dynamics", &json!({"inputs": inputs}))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(
        problem["errors"][0]["pointer"], "/inputs/excitation/base_acceleration/target/frequencies/2",
        "{problem}"
    );
    let jobs = app.get_json("/jobs").await;
    assert_eq!(jobs["jobs"].as_array().map(Vec::len), Some(0), "{jobs}");
}
