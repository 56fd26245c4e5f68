//! The shipped processes end to end over HTTP: the public cantilever case runs as a
//! job and serves the same physics as the CLI (results blocks, CSV histories with
//! numerical and reference columns), and bad physics inputs come back as 422 with the
//! pointer of the field at fault.

use std::sync::Arc;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;

use crate::helpers::{TestApp, spawn_app_with_processes};

async fn spawn_with_real_processes() -> TestApp {
    spawn_app_with_processes(vec![Arc::new(CantileverImpact), Arc::new(BundleDynamics)], |_| {}).await
}

fn cantilever_body(duration: f64) -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/cantilever-impact.json"
    ))
    .unwrap();
    let mut body: Value = serde_json::from_str(&text).unwrap();
    body["inputs"]["solver"]["duration"] = json!(duration);
    body
}

#[tokio::test]
async fn the_public_cantilever_case_runs_as_a_job_and_serves_its_histories() {
    let app = spawn_with_real_processes().await;
    let response = app
        .post_execution("cantilever-impact", &cantilever_body(0.1))
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let job: Value = response.json().await.unwrap();
    let id = job["jobID"].as_str().unwrap().to_owned();
    let status = app.wait_until_finished(&id).await;
    assert_eq!(status["status"], "successful", "{status}");

    let results = app.get_json(&format!("/jobs/{id}/results")).await;
    // First impact of the public case (BRIEF §7) on both sides.
    for block in ["numerical", "reference"] {
        let first = results[block]["first_impact_time"].as_f64().unwrap();
        assert!((first - 0.0253717).abs() < 1e-6, "{block} first impact {first}");
    }
    assert_eq!(results["comparison"]["agrees"], true);
    let href = results["outputs"]["tip_displacement"]["href"].as_str().unwrap();
    assert_eq!(href, format!("/jobs/{id}/results/tip_displacement"));

    let csv = app.get(&format!("{href}?format=csv")).await.text().await.unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time,numerical,reference"));
    assert_eq!(lines.count(), 10_001, "one row per 1e-5 s step over 0.1 s");
    let forces = app
        .get_json(&format!("/jobs/{id}/results/contact_force?max_points=200"))
        .await;
    let numerical = forces["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == "numerical")
        .unwrap();
    let peak = numerical["values"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(Value::as_f64)
        .fold(0.0, f64::max);
    let expected = results["numerical"]["max_contact_force"].as_f64().unwrap();
    assert_eq!(peak, expected, "thinning keeps the force peak");
}

#[tokio::test]
async fn a_time_step_above_the_critical_one_is_a_422_naming_the_field() {
    let app = spawn_with_real_processes().await;
    let mut body = cantilever_body(0.1);
    body["inputs"]["solver"]["time_step"] = json!(1e-3);
    let response = app.post_execution("cantilever-impact", &body).await;
    assert_eq!(response.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let problem: Value = response.json().await.unwrap();
    assert_eq!(problem["errors"][0]["pointer"], "/inputs/solver/time_step");
    assert!(
        problem["errors"][0]["detail"]
            .as_str()
            .unwrap()
            .contains("critical")
    );
}

#[tokio::test]
async fn a_bundle_job_serves_contact_forces_by_contact_column() {
    let app = spawn_with_real_processes().await;
    let body = json!({"inputs": {
        "pin": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                "elements": 10, "modes": 4},
        "bundle": {"pins": 2, "levels": [1.0], "stiffness": 1e4, "wall_gap": 1e-4, "pin_gap": 1e-4},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 30.0, "duration": 0.01}},
        "solver": {"duration": 0.05}}});
    let response = app.post_execution("bundle-dynamics", &body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let id = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    assert_eq!(app.wait_until_finished(&id).await["status"], "successful");
    let csv = app
        .get(&format!("/jobs/{id}/results/contact_forces?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    assert_eq!(csv.lines().next(), Some("time,c0,c1,c2"));
    let results = app.get_json(&format!("/jobs/{id}/results")).await;
    assert_eq!(results["expansion"]["contacts"].as_array().unwrap().len(), 3);
}

/// `solver.scheme: "exact_modal"` on the public cantilever case: the run agrees with the
/// semi-analytic reference (first impact and the comparison's verdict), reports no
/// critical step (the scheme has no stability limit: null), and takes a step far longer
/// than the case's explicit one (its contact, not the top of its basis, sets it).
#[tokio::test]
async fn the_exact_modal_scheme_agrees_with_the_reference_on_the_public_cantilever_case() {
    let app = spawn_with_real_processes().await;
    let mut body = cantilever_body(0.1);
    body["inputs"]["solver"]["scheme"] = json!("exact_modal");
    body["inputs"]["solver"]["time_step"] = json!("auto");
    let results = app.results_of("cantilever-impact", &body).await;
    // The step is a few milliseconds here (a soft contact): the first impact is
    // interpolated within it.
    let numerical = &results["numerical"];
    let (first, step) = (
        numerical["first_impact_time"].as_f64().unwrap(),
        numerical["time_step"].as_f64().unwrap(),
    );
    assert!(
        (first - 0.0253717).abs() < 0.05 * step,
        "first impact {first} (step {step})"
    );
    assert_eq!(results["comparison"]["agrees"], true, "{}", results["comparison"]);
    let error = results["comparison"]["f_err"].as_f64().unwrap();
    assert!(error < 1e-3, "f_err {error}");
    assert!(
        numerical["steps"].as_u64().unwrap() < 1000,
        "{}",
        numerical["steps"]
    );
    assert!(results["numerical"]["critical_time_step"].is_null());
    assert!(results["basis"]["cost"]["critical_time_step"].is_null());
}

/// The hexagonal bundle under `exact_modal`: the shipped 7-pin case runs (no critical
/// step: null) to central difference's peak contact force within the verdict's bound
/// for peaks (10 × the tolerance); with friction (the fretting example) the scheme is
/// refused with a 422 at the scheme, naming friction.
#[tokio::test]
async fn the_exact_modal_scheme_runs_the_hexagonal_bundle_and_refuses_friction_at_the_scheme() {
    use chocmodal::processes::hex_bundle_dynamics::HexBundleDynamics;
    let app = spawn_app_with_processes(vec![Arc::new(HexBundleDynamics)], |_| {}).await;
    let example = |name: &str| -> Value {
        let path = format!("{}/examples/{name}.json", env!("CARGO_MANIFEST_DIR"));
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    let mut peaks = Vec::new();
    for scheme in ["central_difference", "exact_modal"] {
        let mut body = example("hex7-loads");
        body["inputs"]["solver"]["scheme"] = json!(scheme);
        body["inputs"]["solver"]["time_step"] = json!("auto");
        body["inputs"]["solver"]["duration"] = json!(0.03);
        body["inputs"]["solver"]["check"] = json!("none");
        let results = app.results_of("hex-bundle-dynamics", &body).await;
        if scheme == "exact_modal" {
            assert!(
                results["critical_time_step"].is_null(),
                "{}",
                results["critical_time_step"]
            );
        }
        let peak = results["contacts"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|c| c["max_force"].as_f64())
            .fold(0.0, f64::max);
        peaks.push(peak);
    }
    assert!(peaks[0] > 0.0);
    assert!((peaks[1] - peaks[0]).abs() <= 1e-2 * peaks[0], "{peaks:?}");

    let mut body = example("hex7-fretting");
    body["inputs"]["solver"]["scheme"] = json!("exact_modal");
    let response = app.post_execution("hex-bundle-dynamics", &body).await;
    assert_eq!(response.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let problem: Value = response.json().await.unwrap();
    let errors = problem["errors"].as_array().unwrap();
    assert!(
        errors
            .iter()
            .any(|e| e["pointer"] == "/inputs/solver/scheme"
                && e["detail"].as_str().unwrap().contains("friction")),
        "{problem}"
    );
}
