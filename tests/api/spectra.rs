//! What the dashboard reads besides the core API: the power spectrum of a history
//! (`/jobs/{id}/results/{output}/spectrum`), series picked by name in a history
//! (`?series=`), and a job's inputs (`/jobs/{id}/inputs`).
//!
//! The spectrum is the one-sided periodogram Γ of each series, normalized so that
//! Σ Γ Δf is the variance of the signal (Parseval), on the bins f_k = k/(nΔt); its
//! `comparison` is f_err = max_f |Γ_a − Γ_b| / max(max Γ_a, max Γ_b) between the first two
//! series, which for `cantilever-impact` must be the f_err of the results document.

use std::sync::Arc;

use chocmodal::processes::cantilever_impact::CantileverImpact;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{TestApp, assert_problem, spawn_app, spawn_app_with_processes};

fn numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

fn series<'a>(document: &'a Value, name: &str) -> &'a Value {
    document["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no series {name} in {}", document["output"]))
}

/// A finished `cantilever-impact` job of the public case over 0.1 s; its id and results.
pub(crate) async fn cantilever_job(app: &TestApp) -> (String, Value) {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/cantilever-impact.json"
    ))
    .unwrap();
    let mut body: Value = serde_json::from_str(&text).unwrap();
    body["inputs"]["solver"]["duration"] = json!(0.1);
    let response = app.post_execution("cantilever-impact", &body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let id = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    assert_eq!(app.wait_until_finished(&id).await["status"], "successful");
    let results = app.get_json(&format!("/jobs/{id}/results")).await;
    (id, results)
}

pub(crate) async fn spawn_with_cantilever() -> TestApp {
    spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |_| {}).await
}

#[tokio::test]
async fn the_tip_spectrum_satisfies_parseval_and_gives_the_f_err_of_the_results() {
    let app = spawn_with_cantilever().await;
    let (id, results) = cantilever_job(&app).await;
    let history = app
        .get_json(&format!("/jobs/{id}/results/tip_displacement"))
        .await;
    let spectrum = app
        .get_json(&format!("/jobs/{id}/results/tip_displacement/spectrum"))
        .await;

    let time = numbers(&history["time"]);
    let n = time.len();
    let dt = spectrum["sample_interval"].as_f64().unwrap();
    assert!((dt - 1e-5).abs() < 1e-15, "Δt = {dt}");
    assert_eq!(spectrum["samples"], n);
    let frequency = numbers(&spectrum["frequency"]);
    assert_eq!(frequency.len(), n / 2 + 1);
    assert_eq!(spectrum["total_points"], n / 2 + 1);
    for (k, f) in frequency.iter().enumerate().step_by(97) {
        let expected = k as f64 / (n as f64 * dt);
        assert!(
            (f - expected).abs() <= 1e-9 * expected.max(1.0),
            "f_{k} = {f}, expected {expected}"
        );
    }

    let mut peaks = Vec::new();
    for name in ["numerical", "reference"] {
        let values = numbers(&series(&history, name)["values"]);
        let mean = values.iter().sum::<f64>() / n as f64;
        let variance = values.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        let psd = numbers(&series(&spectrum, name)["values"]);
        let power: f64 = psd.iter().sum::<f64>() / (n as f64 * dt);
        assert!(
            (power - variance).abs() <= 1e-9 * variance,
            "{name}: Σ Γ Δf = {power:e}, variance {variance:e}"
        );
        peaks.push(psd);
    }
    let (a, b) = (&peaks[0], &peaks[1]);
    let (worst, difference) = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .enumerate()
        .fold((0, 0.0), |best, (k, d)| if d > best.1 { (k, d) } else { best });
    let top = a.iter().chain(b).fold(0.0_f64, |m, &x| m.max(x));
    let comparison = &spectrum["comparison"];
    assert_eq!(comparison["series"], json!(["numerical", "reference"]));
    let f_err = comparison["f_err"].as_f64().unwrap();
    let reported = results["comparison"]["f_err"].as_f64().unwrap();
    assert!(
        (f_err - reported).abs() <= 1e-12 * reported,
        "spectrum f_err {f_err:e}, results f_err {reported:e}"
    );
    assert!(
        (difference / top - reported).abs() <= 1e-9 * reported,
        "f_err from the served spectra {:e}, results {reported:e}",
        difference / top
    );
    assert_eq!(comparison["frequency"].as_f64().unwrap(), frequency[worst]);
}

#[tokio::test]
async fn a_spectrum_can_be_windowed_thinned_and_read_as_csv() {
    let app = spawn_with_cantilever().await;
    let (id, _) = cantilever_job(&app).await;
    let base = format!("/jobs/{id}/results/tip_displacement/spectrum");
    let window = app.get_json(&format!("{base}?f_min=10&f_max=50")).await;
    let frequency = numbers(&window["frequency"]);
    assert!(
        frequency.iter().all(|f| (10.0..=50.0).contains(f)),
        "{frequency:?}"
    );
    // Bins are 1/(nΔt) ≈ 10 Hz apart over 0.1 s.
    assert_eq!(frequency.len(), 4, "{frequency:?}");
    assert_eq!(window["thinned"], false);

    let thin = app.get_json(&format!("{base}?max_points=100")).await;
    assert!(thin["points"].as_u64().unwrap() <= 100);
    assert_eq!(thin["thinned"], true);
    let full = app.get_json(&base).await;
    let peak = |doc: &Value| {
        numbers(&series(doc, "numerical")["values"])
            .into_iter()
            .fold(0.0, f64::max)
    };
    assert_eq!(peak(&thin), peak(&full), "thinning keeps the spectral peak");

    let csv = app
        .get(&format!("{base}?format=csv&f_max=50&series=reference"))
        .await;
    assert_eq!(csv.headers()["content-type"], "text/csv; charset=utf-8");
    let text = csv.text().await.unwrap();
    assert_eq!(text.lines().next(), Some("frequency,reference"));
    assert_eq!(text.lines().count(), 1 + 6, "{text}");

    for query in [
        "f_max=abc",
        "max_points=1",
        "format=xml",
        "series=bogus",
        "colour=red",
    ] {
        assert_problem(
            app.get(&format!("{base}?{query}")).await,
            StatusCode::BAD_REQUEST,
            "invalid-query",
        )
        .await;
    }
    assert_problem(
        app.get(&format!("/jobs/{id}/results/nothing/spectrum")).await,
        StatusCode::NOT_FOUND,
        "no-such-output",
    )
    .await;
}

#[tokio::test]
async fn history_series_are_picked_by_name_in_the_order_asked() {
    let app = spawn_with_cantilever().await;
    let (id, _) = cantilever_job(&app).await;
    let path = format!("/jobs/{id}/results/contact_force");
    let both = app.get_json(&path).await;
    let picked = app.get_json(&format!("{path}?series=reference,numerical")).await;
    let names: Vec<&str> = picked["series"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["reference", "numerical"]);
    assert_eq!(series(&picked, "reference"), series(&both, "reference"));
    let csv = app
        .get(&format!("{path}?series=reference&format=csv"))
        .await
        .text()
        .await
        .unwrap();
    assert_eq!(csv.lines().next(), Some("time,reference"));
    let problem = assert_problem(
        app.get(&format!("{path}?series=c7")).await,
        StatusCode::BAD_REQUEST,
        "invalid-query",
    )
    .await;
    assert!(
        problem["detail"]
            .as_str()
            .unwrap()
            .contains("numerical, reference"),
        "{problem}"
    );
}

#[tokio::test]
async fn a_jobs_inputs_are_its_execution_request_ready_to_resubmit() {
    let app = spawn_app().await;
    let inputs = json!({"steps": 4, "step_ms": 0.5, "spikes": [[2, 3.0]]});
    let job = app.submit(inputs.clone()).await;
    let served = app.get_json(&format!("/jobs/{job}/inputs")).await;
    assert_eq!(served, json!({ "inputs": inputs }));
    app.wait_until_finished(&job).await;

    let again = app.post_execution("count-steps", &served).await;
    assert_eq!(again.status(), StatusCode::CREATED);
    let again = again.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status = app.wait_until_finished(&again).await;
    assert!(
        status["message"]
            .as_str()
            .unwrap()
            .contains(&format!("reused the results of job {job}")),
        "the same inputs are the same run: {status}"
    );
    assert_problem(
        app.get("/jobs/no-such-job/inputs").await,
        StatusCode::NOT_FOUND,
        "no-such-job",
    )
    .await;
}
