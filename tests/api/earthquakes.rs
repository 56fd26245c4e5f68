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

fn numbers(value: &Value) -> Vec<f64> {
    (value.as_array().into_iter().flatten())
        .map(|v| v.as_f64().unwrap_or(f64::NAN))
        .collect()
}

/// The record a job was shaken by is one of its outputs: the `excitation` history holds
/// every sample the generator drew from the seed (the same request, generated here, gives
/// the same samples bit for bit), `generated_records` what it reached, and the spectrum
/// of the stored record, computed apart from the generator (another grid, the exact
/// oscillators of `physics::response_spectrum` on the samples the CSV serves), lies
/// within the tolerance of the target: here, by the route and by the test itself.
#[tokio::test]
async fn the_generated_record_is_an_output_whose_stored_spectrum_meets_its_target() {
    use chocmodal::physics::response_spectrum::{log_spaced, pseudo_acceleration};
    use chocmodal::physics::synthetic::{SpectrumCompatible, TargetSpectrum};

    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await;
    let inputs = inputs();
    let given = &inputs["excitation"]["base_acceleration"];
    let response = app
        .post_execution("bundle-dynamics", &json!({"inputs": inputs.clone()}))
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let created: Value = response.json().await.unwrap_or_default();
    let id = created["jobID"].as_str().unwrap_or_default().to_owned();
    let status = app.wait_until_finished(&id).await;
    assert_eq!(status["status"], "successful", "{status}");
    let results = app.get_json(&format!("/jobs/{id}/results")).await;

    let target = TargetSpectrum {
        frequencies: numbers(&given["target"]["frequencies"]),
        accelerations: numbers(&given["target"]["accelerations"]),
        damping: given["target"]["damping"].as_f64().unwrap(),
    };
    let request = SpectrumCompatible {
        target: target.clone(),
        duration: given["duration"].as_f64().unwrap(),
        strong_motion: given["strong_motion"].as_f64().unwrap(),
        rise: None,
        time_step: None,
        tolerance: 0.1,
        max_iterations: 40,
        seed: given["seed"].as_u64().unwrap(),
    };
    let record = request.generate().expect("the example's record");

    let generated = &results["generated_records"];
    assert_eq!(generated.as_array().map(Vec::len), Some(1), "{generated}");
    let generated = &generated[0];
    assert_eq!(generated["member"], "base_acceleration");
    assert_eq!(generated["seed"], request.seed);
    assert_eq!(generated["samples"], record.samples.len());
    assert_eq!(generated["time_step"], record.time_step);
    assert_eq!(generated["rounds"], record.iterations);
    assert_eq!(generated["max_deviation"], record.max_deviation);
    assert_eq!(generated["target"]["frequencies"], given["target"]["frequencies"]);
    let peak = record.samples.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    assert_eq!(generated["peak_acceleration"], peak);

    // The run lasts 0.5 s of the 12 s record; the history holds all of it.
    let csv = app
        .get(&format!("/jobs/{id}/results/excitation?format=csv"))
        .await
        .text()
        .await
        .unwrap_or_default();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time,base_acceleration"));
    let rows: Vec<(f64, f64)> = lines
        .map(|line| {
            let (t, a) = line.split_once(',').unwrap_or_default();
            (t.parse().unwrap_or(f64::NAN), a.parse().unwrap_or(f64::NAN))
        })
        .collect();
    let (time, stored): (Vec<f64>, Vec<f64>) = rows.into_iter().unzip();
    let table = record.table();
    for (t, a) in table.time.iter().zip(&table.values) {
        let at = time.iter().position(|s| (s - t).abs() <= 1e-12);
        let at = at.unwrap_or_else(|| panic!("the record's sample at {t} s is not in the history"));
        assert_eq!(stored[at], *a, "at {t} s");
    }

    // The stored record's spectrum against the target, apart from the generator: 300
    // log-spaced frequencies per decade of the band.
    let stored_record = chocmodal::physics::loads::Table {
        time: time.clone(),
        values: stored.clone(),
    };
    let (low, high) = target.band();
    let grid = log_spaced(low, high, (300.0 * (high / low).log10()).ceil() as usize);
    let spectrum = pseudo_acceleration(&stored_record, &grid, target.damping).unwrap();
    let worst = (spectrum.pseudo_acceleration.iter().zip(&grid))
        .map(|(psa, f)| (psa / target.at(*f) - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= request.tolerance,
        "the stored record deviates by {worst}"
    );

    // The route says the same, at the target's damping and band by default.
    let served = app
        .get_json(&format!(
            "/jobs/{id}/results/excitation/response_spectrum?series=base_acceleration"
        ))
        .await;
    let frequencies = numbers(&served["frequencies"]);
    assert_eq!(frequencies.first(), Some(&low), "{served}");
    assert_eq!(frequencies.last(), Some(&high), "{served}");
    assert_eq!(served["pseudo_acceleration"][0]["damping"], target.damping);
    assert_eq!(served["samples"], time.len());
    assert_eq!(served["peak_acceleration"], peak);
    let deviation = served["target"]["max_deviation"].as_f64().unwrap_or(f64::NAN);
    assert!(deviation <= request.tolerance, "{}", served["target"]);
    let wanted = numbers(&served["target"]["pseudo_acceleration"]);
    for (f, w) in frequencies.iter().zip(&wanted) {
        assert!((w / target.at(*f) - 1.0).abs() < 1e-12, "target at {f} Hz");
    }
    // Past the band the target is null; the CSV then has no target column.
    let wide = app
        .get_json(&format!(
            "/jobs/{id}/results/excitation/response_spectrum?f_min=0.5&f_max=50&points=20"
        ))
        .await;
    assert_eq!(wide["target"]["pseudo_acceleration"][0], Value::Null, "{wide}");
    assert!(wide["target"]["max_deviation"].as_f64().unwrap_or(f64::NAN) <= request.tolerance);
    let csv = |query: &str| {
        let app = &app;
        let url = format!("/jobs/{id}/results/excitation/response_spectrum?{query}format=csv");
        async move { app.get(&url).await.text().await.unwrap_or_default() }
    };
    assert!(csv("").await.starts_with("frequency,psa_0.05,target\n"));
    assert!(csv("f_max=50&").await.starts_with("frequency,psa_0.05\n"));
}
