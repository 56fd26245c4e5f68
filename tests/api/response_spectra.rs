//! `GET /jobs/{id}/results/{output}/response_spectrum`: the pseudo-acceleration response
//! spectrum of a point of the model, from one column of a displacement history.
//!
//! The acceleration is the second divided difference of the stored displacement
//! (full resolution), the oscillators those of a signal's spectrum: the document must be
//! exactly `physics::response_spectrum` of `physics::acceleration` of the history the
//! CSV serves, its `peak_acceleration` the largest |second difference|. Only displacement
//! histories have one (a force history is a 404 that says why), and a bad column or
//! query is a 400.

use std::sync::Arc;

use chocmodal::physics::acceleration::acceleration_of_displacement;
use chocmodal::physics::response_spectrum::{log_spaced, pseudo_acceleration};
use chocmodal::processes::cantilever_impact::CantileverImpact;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{assert_problem, spawn_app, spawn_app_with_processes};
use crate::spectra::{cantilever_job, spawn_with_cantilever};

fn numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .unwrap_or_else(|| panic!("not an array: {value}"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// The columns `time` and `name` of a history served as CSV (full resolution).
fn csv_columns(text: &str, name: &str) -> (Vec<f64>, Vec<f64>) {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|line| {
            let cells: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
            (cells[0], cells[column])
        })
        .unzip()
}

#[tokio::test]
async fn a_displacement_column_has_the_spectrum_of_its_second_differences() {
    let app = spawn_with_cantilever().await;
    let (job, _) = cantilever_job(&app).await;
    let csv = app
        .get(&format!("/jobs/{job}/results/tip_displacement?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    let (time, displacement) = csv_columns(&csv, "reference");
    let record = acceleration_of_displacement(&time, &displacement).unwrap();
    let frequencies = log_spaced(2.0, 500.0, 40);

    let document = app
        .get_json(&format!(
            "/jobs/{job}/results/tip_displacement/response_spectrum?series=reference&damping=0.02,0.05&f_min=2&f_max=500&points=40"
        ))
        .await;
    assert_eq!(document["output"], "tip_displacement");
    assert_eq!(document["series"], "reference");
    assert_eq!(document["samples"], time.len() - 2);
    assert_eq!(numbers(&document["frequencies"]), frequencies);
    let peak = record.values.iter().fold(0.0_f64, |peak, a| peak.max(a.abs()));
    assert_eq!(document["peak_acceleration"], peak);
    let interval = (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64;
    assert_eq!(document["sample_interval"], interval);
    for (k, damping) in [0.02, 0.05].into_iter().enumerate() {
        let expected = pseudo_acceleration(&record, &frequencies, damping).unwrap();
        let served = &document["pseudo_acceleration"][k];
        assert_eq!(served["damping"], damping);
        assert_eq!(
            numbers(&served["values"]),
            expected.pseudo_acceleration,
            "ξ = {damping}: the served spectrum is the physics' of the stored history"
        );
    }

    // The first column by default, and the CSV form of the same numbers.
    let default = app
        .get_json(&format!("/jobs/{job}/results/tip_displacement/response_spectrum"))
        .await;
    assert_eq!(default["series"], "numerical");
    assert_eq!(numbers(&default["frequencies"]).len(), 200);
    let text = app
        .get(&format!(
            "/jobs/{job}/results/tip_displacement/response_spectrum?series=reference&damping=0.05&f_min=2&f_max=500&points=40&format=csv"
        ))
        .await
        .text()
        .await
        .unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("frequency,psa_0.05"));
    let column: Vec<f64> = lines
        .map(|line| line.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(column, numbers(&document["pseudo_acceleration"][1]["values"]));
}

#[tokio::test]
async fn only_displacement_and_acceleration_histories_have_a_response_spectrum() {
    let app = spawn_with_cantilever().await;
    let (job, _) = cantilever_job(&app).await;
    for output in ["contact_force", "tip_displacement_peaks", "impacts"] {
        let problem = assert_problem(
            app.get(&format!("/jobs/{job}/results/{output}/response_spectrum"))
                .await,
            StatusCode::NOT_FOUND,
            "/no-such-output",
        )
        .await;
        assert!(
            problem["detail"]
                .as_str()
                .unwrap()
                .contains("only displacement and acceleration histories have a response spectrum"),
            "{problem}"
        );
    }
    for query in [
        "series=nothing",
        "series=numerical,reference",
        "damping=1.5",
        "f_min=0",
        "points=1",
        "dampnig=0.05",
    ] {
        assert_problem(
            app.get(&format!(
                "/jobs/{job}/results/tip_displacement/response_spectrum?{query}"
            ))
            .await,
            StatusCode::BAD_REQUEST,
            "/invalid-query",
        )
        .await;
    }
    assert_problem(
        app.get("/jobs/nope/results/tip_displacement/response_spectrum")
            .await,
        StatusCode::NOT_FOUND,
        "/no-such-job",
    )
    .await;
}

/// A process that declares no kind for its histories (the counting test process) offers
/// no response spectrum, and a job still running has no result yet.
#[tokio::test]
async fn an_undeclared_or_unfinished_history_has_none() {
    let app = spawn_app().await;
    let finished = app.submit(json!({"steps": 20})).await;
    app.wait_until_finished(&finished).await;
    let problem = assert_problem(
        app.get(&format!("/jobs/{finished}/results/signal/response_spectrum"))
            .await,
        StatusCode::NOT_FOUND,
        "/no-such-output",
    )
    .await;
    assert!(
        problem["detail"]
            .as_str()
            .unwrap()
            .contains("has no displacement or acceleration history `signal`"),
        "{problem}"
    );

    // No worker: the job stays queued.
    let app = spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |config| config.workers = 0).await;
    let body = serde_json::from_str::<Value>(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/cantilever-impact.json"
        ))
        .unwrap(),
    )
    .unwrap();
    let response = app.post_execution("cantilever-impact", &body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let job = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    assert_problem(
        app.get(&format!("/jobs/{job}/results/tip_displacement/response_spectrum"))
            .await,
        StatusCode::NOT_FOUND,
        "/result-not-ready",
    )
    .await;
}
