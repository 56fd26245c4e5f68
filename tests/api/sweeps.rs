//! Sweeps through real HTTP with the `count-steps` process: expansion (grid, Monte
//! Carlo, Latin hypercube), validation before queueing, dismissal, results rows and
//! aggregates, reuse of identical runs, and fairness towards single jobs.

use std::sync::Arc;
use std::time::{Duration, Instant};

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{
    Backend, TestApp, assert_problem, on_both_backends, spawn_app, spawn_app_on, spawn_app_with_processes,
};

on_both_backends!(
    a_grid_runs_every_cell_once_and_tabulates_axes_then_metrics,
    dismissing_a_sweep_dismisses_its_queued_and_running_runs,
    a_failed_run_of_a_fail_fast_sweep_dismisses_the_rest_and_fails_the_sweep,
    identical_runs_are_computed_once_across_single_jobs_and_sweeps,
    single_jobs_submitted_after_a_big_sweep_do_not_wait_for_it,
    sweeps_are_listed_newest_first_with_paging_and_unknown_ones_are_404
);

impl TestApp {
    pub async fn post_sweep(&self, body: &Value) -> reqwest::Response {
        self.client
            .post(self.url("/sweeps"))
            .header("content-type", "application/json")
            .body(body.to_string())
            .send()
            .await
            .unwrap()
    }

    /// Submits a sweep of `count-steps`; returns its id.
    pub async fn create_sweep(&self, body: Value) -> String {
        let response = self.post_sweep(&body).await;
        let code = response.status();
        let location = response
            .headers()
            .get("location")
            .map(|l| l.to_str().unwrap().to_owned());
        let status: Value = response.json().await.unwrap();
        assert_eq!(code, StatusCode::CREATED, "{status}");
        let location = location.expect("a Location header");
        let id = status["sweepID"].as_str().unwrap().to_owned();
        assert_eq!(location, format!("/sweeps/{id}"));
        id
    }

    /// Polls the sweep until its status is one of `wanted`.
    pub async fn wait_for_sweep(&self, id: &str, wanted: &[&str], within: Duration) -> Value {
        let deadline = Instant::now() + within;
        loop {
            let status = self.get_json(&format!("/sweeps/{id}")).await;
            if wanted.contains(&status["status"].as_str().unwrap_or_default()) {
                return status;
            }
            assert!(
                Instant::now() < deadline,
                "sweep {id} did not reach {wanted:?}: {status}"
            );
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }

    pub async fn sweep_results(&self, id: &str) -> Value {
        self.get_json(&format!("/sweeps/{id}/results")).await
    }

    /// The results table of a sweep as CSV (`format=csv`).
    pub async fn sweep_csv(&self, id: &str) -> String {
        let response = self.get(&format!("/sweeps/{id}/results?format=csv")).await;
        assert_eq!(response.status(), StatusCode::OK);
        response.text().await.unwrap()
    }
}

fn sweep(inputs: Value, axes: Value) -> Value {
    json!({"process": counting::ID, "inputs": inputs, "axes": axes})
}

/// The `columns` of a sweep's results table, in order.
fn column_names(results: &Value) -> Vec<&str> {
    results["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect()
}

fn column(results: &Value, name: &str) -> Vec<f64> {
    results["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| row[name].as_f64().unwrap_or_else(|| panic!("{name} in {row}")))
        .collect()
}

async fn a_grid_runs_every_cell_once_and_tabulates_axes_then_metrics(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let id = app
        .create_sweep(sweep(
            json!({"steps": 1, "step_ms": 0.0}),
            json!([{"pointer": "/steps", "values": [1, 2, 3]}, {"pointer": "/step_ms", "linspace": [0.0, 1.0, 2]}]),
        ))
        .await;
    let status = app
        .wait_for_sweep(&id, &["successful"], Duration::from_secs(20))
        .await;
    assert_eq!(status["runs"], 6);
    assert_eq!(status["counts"]["successful"], 6, "{status}");
    assert_eq!(status["progress"], 100);

    let results = app.sweep_results(&id).await;
    let columns = column_names(&results);
    assert_eq!(
        columns,
        ["run", "job", "status", "/steps", "/step_ms", "steps", "sum"]
    );
    let rows = results["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    let cells: Vec<(i64, f64)> = rows
        .iter()
        .map(|r| (r["/steps"].as_i64().unwrap(), r["/step_ms"].as_f64().unwrap()))
        .collect();
    assert_eq!(
        cells,
        [(1, 0.0), (1, 1.0), (2, 0.0), (2, 1.0), (3, 0.0), (3, 1.0)]
    );
    for row in rows {
        let n = row["/steps"].as_i64().unwrap();
        assert_eq!(row["sum"], n * (n + 1) / 2, "{row}");
    }

    // Each run is an ordinary job that links to its sweep.
    let job = app.status(rows[0]["job"].as_str().unwrap()).await;
    assert_eq!(job["sweepID"], id.as_str());
    assert!(
        job["links"]
            .as_array()
            .unwrap()
            .iter()
            .any(|l| l["href"] == format!("/sweeps/{id}") && l["rel"] == "up"),
        "{job}"
    );
    let runs = app.get_json(&format!("/jobs?sweepID={id}&limit=100")).await;
    assert_eq!(runs["jobs"].as_array().unwrap().len(), 6);

    let csv = app.get(&format!("/sweeps/{id}/results?format=csv")).await;
    assert_eq!(csv.status(), StatusCode::OK);
    let text = csv.text().await.unwrap();
    assert!(
        text.starts_with("run,job,status,/steps,/step_ms,steps,sum\n0,"),
        "{text}"
    );
    assert_eq!(text.lines().count(), 7);

    let list = app.get_json("/sweeps?limit=1").await;
    assert_eq!(list["sweeps"][0]["sweepID"], id.as_str());
}

#[tokio::test]
async fn the_same_seed_draws_the_same_monte_carlo_parameters() {
    let app = spawn_app().await;
    let body = |seed: u64| {
        json!({"process": counting::ID, "inputs": {"steps": 1}, "samples": 8, "seed": seed,
               "axes": [{"pointer": "/step_ms", "uniform": [0.0, 2.0]}]})
    };
    let mut drawn = Vec::new();
    for seed in [11, 11, 12] {
        let id = app.create_sweep(body(seed)).await;
        app.wait_for_sweep(&id, &["successful"], Duration::from_secs(20))
            .await;
        let values = column(&app.sweep_results(&id).await, "/step_ms");
        assert_eq!(values.len(), 8);
        assert!(values.iter().all(|v| (0.0..2.0).contains(v)), "{values:?}");
        drawn.push(values);
    }
    assert_eq!(drawn[0], drawn[1], "same seed, same draws");
    assert_ne!(drawn[0], drawn[2], "another seed, other draws");
}

#[tokio::test]
async fn a_latin_hypercube_hits_each_stratum_once_per_axis() {
    let app = spawn_app().await;
    let samples = 20;
    let id = app
        .create_sweep(json!({"process": counting::ID, "design": "latin_hypercube", "samples": samples, "seed": 5,
            "inputs": {"steps": 1, "spikes": [[1, 0.0]]},
            "axes": [{"pointer": "/step_ms", "uniform": [0.0, 1.0]}, {"pointer": "/spikes/0/1", "uniform": [10.0, 20.0]}]}))
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(20))
        .await;
    let results = app.sweep_results(&id).await;
    for (name, low, high) in [("/step_ms", 0.0, 1.0), ("/spikes/0/1", 10.0, 20.0)] {
        let mut strata: Vec<usize> = column(&results, name)
            .iter()
            .map(|v| ((v - low) / (high - low) * samples as f64).floor() as usize)
            .collect();
        strata.sort_unstable();
        assert_eq!(strata, (0..samples).collect::<Vec<_>>(), "strata of {name}");
    }
}

#[tokio::test]
async fn an_invalid_run_is_named_by_run_and_pointer_and_nothing_is_queued() {
    let app = spawn_app().await;
    let response = app
        .post_sweep(&sweep(
            json!({"steps": 1}),
            json!([{"pointer": "/steps", "values": [1, 2, 0, 5]}]),
        ))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let errors = problem["errors"].as_array().unwrap();
    assert_eq!(errors.len(), 1, "{problem}");
    assert_eq!(errors[0]["pointer"], "/runs/2/inputs/steps");
    assert!(
        errors[0]["detail"].as_str().unwrap().contains("/steps = 0"),
        "{problem}"
    );

    let response = app
        .post_sweep(&sweep(
            json!({"steps": 1}),
            json!([{"pointer": "/steps", "linspace": [1, 2]}]),
        ))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/axes/0/linspace");

    let response = app
        .post_sweep(&sweep(
            json!({"steps": 1}),
            json!([{"pointer": "/steps", "linspace": [1, 10000, 10000]},
                                                      {"pointer": "/step_ms", "values": [0, 1]}]),
        ))
        .await;
    assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/sweep-too-large").await;

    let response = app
        .post_sweep(&json!({"process": "no-such", "inputs": {}, "axes": [{"pointer": "/a", "values": [1]}]}))
        .await;
    assert_problem(response, StatusCode::NOT_FOUND, "/no-such-process").await;

    assert_eq!(app.get_json("/jobs").await["jobs"], json!([]));
    assert_eq!(app.get_json("/sweeps").await["sweeps"], json!([]));
}

/// A typo in an axis pointer (`/contact/rkk`) would make every run fail on an unknown
/// input: the sweep is refused up front, at the axis, naming the valid members.
#[tokio::test]
async fn an_axis_pointer_that_names_no_input_is_refused_before_any_run_is_queued() {
    let app = spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |_| {}).await;
    let mut body: Value =
        serde_json::from_str(include_str!("../../examples/sweep-calibration.json")).unwrap();
    body["axes"][0]["pointer"] = json!("/contact/rkk");
    let response = app.post_sweep(&body).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(
        problem["errors"],
        json!([{"pointer": "/axes/0/pointer",
                "detail": "no input `rkk` under /contact; valid: damping, gap, law, rk, stiffness"}]),
        "{problem}"
    );
    assert_eq!(app.get_json("/jobs").await["jobs"], json!([]));
    assert_eq!(app.get_json("/sweeps").await["sweeps"], json!([]));
}

/// The base inputs' own problems come in the same 422 as a refused axis pointer, not
/// once it is fixed.
#[tokio::test]
async fn a_refused_axis_pointer_and_the_base_inputs_problems_come_in_one_422() {
    let app = spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |_| {}).await;
    let mut body: Value =
        serde_json::from_str(include_str!("../../examples/sweep-calibration.json")).unwrap();
    body["axes"][0]["pointer"] = json!("/contact/rkk");
    body["inputs"]["beam"]["density"] = json!(-1.0);
    body["inputs"]["beam"]
        .as_object_mut()
        .unwrap()
        .remove("young_modulus");
    let response = app.post_sweep(&body).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let pointers: Vec<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["pointer"].as_str().unwrap())
        .collect();
    for pointer in [
        "/axes/0/pointer",
        "/runs/0/inputs/beam/density",
        "/runs/0/inputs/beam/young_modulus",
    ] {
        assert!(pointers.contains(&pointer), "{pointer}: {problem}");
    }
    assert_eq!(app.get_json("/sweeps").await["sweeps"], json!([]));
}

async fn dismissing_a_sweep_dismisses_its_queued_and_running_runs(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let id = app
        .create_sweep(sweep(
            json!({"steps": 400, "step_ms": 10.0}),
            json!([{"pointer": "/steps", "values": [400, 401, 402, 403, 404, 405]}]),
        ))
        .await;
    let deadline = Instant::now() + Duration::from_secs(10);
    while app.get_json(&format!("/sweeps/{id}")).await["counts"]["running"] != 2 {
        assert!(Instant::now() < deadline, "the runs never started");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let response = app.delete(&format!("/sweeps/{id}")).await;
    assert_eq!(response.status(), StatusCode::OK);
    let status: Value = response.json().await.unwrap();
    assert_eq!(status["status"], "dismissed");
    assert_eq!(status["counts"]["dismissed"], 6, "{status}");

    let deadline = Instant::now() + Duration::from_secs(3);
    while app.probe.cancelled.load(std::sync::atomic::Ordering::SeqCst) < 2 {
        assert!(Instant::now() < deadline, "running runs did not stop");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    // Runs are claimed oldest first: had a dismissed run stayed claimable, it would
    // start before the single run of a sweep created after it.
    let later = app
        .create_sweep(sweep(
            json!({"steps": 7}),
            json!([{"pointer": "/steps", "values": [7]}]),
        ))
        .await;
    app.wait_for_sweep(&later, &["successful"], Duration::from_secs(20))
        .await;
    let runs = app.probe.runs.lock().unwrap().clone();
    assert_eq!(runs.len(), 3, "no dismissed run may start: {runs:?}");
    assert_eq!(runs[2], 7, "no dismissed run may start: {runs:?}");
}

async fn a_failed_run_of_a_fail_fast_sweep_dismisses_the_rest_and_fails_the_sweep(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 1).await;
    let mut body = sweep(
        json!({"steps": 1, "fail_at": 4}),
        json!([{"pointer": "/steps", "values": [3, 4, 5, 6]}]),
    );
    body["policy"] = json!("fail_fast");
    let id = app.create_sweep(body).await;
    let status = app
        .wait_for_sweep(&id, &["failed"], Duration::from_secs(20))
        .await;
    let deadline = Instant::now() + Duration::from_secs(5);
    let mut status = status;
    while status["counts"]["accepted"] != 0 || status["counts"]["running"] != 0 {
        assert!(Instant::now() < deadline, "{status}");
        status = app.get_json(&format!("/sweeps/{id}")).await;
    }
    assert_eq!(
        status["counts"],
        json!({"accepted": 0, "running": 0, "successful": 1, "failed": 1, "dismissed": 2})
    );
    let results = app.sweep_results(&id).await;
    let statuses: Vec<&str> = results["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["status"].as_str().unwrap())
        .collect();
    assert_eq!(statuses, ["successful", "failed", "dismissed", "dismissed"]);
}

/// Under the `continue` policy every run ends: the sweep is `successful` only when none
/// failed, `partial` when some did (the failed count in its status and in the list),
/// `failed` when all did. `count-steps` fails at step `fail_at`, so the runs of 4 or more
/// steps fail and the run of 3 does not.
#[tokio::test]
async fn a_sweep_whose_runs_failed_is_partial_or_failed_not_successful() {
    let app = spawn_app().await;
    let partial = app
        .create_sweep(sweep(
            json!({"steps": 1, "fail_at": 4}),
            json!([{"pointer": "/steps", "values": [3, 4, 5, 6]}]),
        ))
        .await;
    let failed = app
        .create_sweep(sweep(
            json!({"steps": 1, "fail_at": 4}),
            json!([{"pointer": "/steps", "values": [4, 5]}]),
        ))
        .await;
    let finished = ["successful", "partial", "failed", "dismissed"];
    let status = app
        .wait_for_sweep(&partial, &finished, Duration::from_secs(20))
        .await;
    assert_eq!(status["status"], "partial", "{status}");
    assert_eq!(
        status["counts"],
        json!({"accepted": 0, "running": 0, "successful": 1, "failed": 3, "dismissed": 0})
    );
    assert_eq!(status["progress"], 100);
    assert!(status["finished"].is_string(), "{status}");
    assert_eq!(app.sweep_results(&partial).await["status"], "partial");

    let status = app
        .wait_for_sweep(&failed, &finished, Duration::from_secs(20))
        .await;
    assert_eq!(status["status"], "failed", "{status}");
    assert_eq!(status["counts"]["failed"], 2, "{status}");
    assert_eq!(status["counts"]["successful"], 0, "{status}");

    let list = app.get_json("/sweeps").await;
    let listed: Vec<(&str, &Value)> = list["sweeps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["status"].as_str().unwrap(), &s["counts"]["failed"]))
        .collect();
    assert_eq!(listed, [("failed", &json!(2)), ("partial", &json!(3))]);
}

/// `Accept: text/csv` without `format` gives the table as CSV, the same bytes as
/// `format=csv`; JSON stays the default, wins when listed first, and `format` overrides
/// `Accept`. The response varies with `Accept`.
#[tokio::test]
async fn sweep_results_honour_accept_text_csv() {
    let app = spawn_app().await;
    let id = app
        .create_sweep(sweep(
            json!({"steps": 1}),
            json!([{"pointer": "/steps", "values": [1, 2]}]),
        ))
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(20))
        .await;
    let path = format!("/sweeps/{id}/results");
    let get = |query: &'static str, accept: Option<&'static str>| {
        let mut request = app.client.get(app.url(&format!("{path}{query}")));
        if let Some(accept) = accept {
            request = request.header("accept", accept);
        }
        async move {
            let response = request.send().await.unwrap();
            assert_eq!(response.status(), StatusCode::OK);
            let vary = response
                .headers()
                .get("vary")
                .map(|v| v.to_str().unwrap().to_lowercase());
            assert_eq!(vary.as_deref(), Some("accept"));
            let content_type = response.headers()["content-type"].to_str().unwrap().to_owned();
            (content_type, response.text().await.unwrap())
        }
    };
    let (explicit_type, explicit) = get("?format=csv", None).await;
    assert!(explicit_type.starts_with("text/csv"), "{explicit_type}");
    for accept in [
        "text/csv",
        "text/csv, application/json;q=0.5",
        "text/csv;q=0.9, */*;q=0.1",
    ] {
        let (content_type, body) = get("", Some(accept)).await;
        assert!(
            content_type.starts_with("text/csv"),
            "Accept {accept}: {content_type}"
        );
        assert_eq!(body, explicit, "Accept {accept}");
    }
    assert!(explicit.starts_with("run,job,status,/steps,"), "{explicit}");
    assert_eq!(explicit.lines().count(), 3, "a header and two runs: {explicit}");
    for (query, accept) in [
        ("", None),
        ("", Some("application/json, text/csv")),
        ("?format=json", Some("text/csv")),
    ] {
        let (content_type, body) = get(query, accept).await;
        assert_eq!(content_type, "application/json", "{query} {accept:?}");
        let document: Value = serde_json::from_str(&body).unwrap();
        assert_eq!(document["rows"].as_array().unwrap().len(), 2);
    }
}

#[tokio::test]
async fn monte_carlo_aggregates_match_the_law_and_the_rows() {
    let app = spawn_app().await;
    let samples = 400;
    let id = app
        .create_sweep(
            json!({"process": counting::ID, "inputs": {"steps": 1}, "samples": samples, "seed": 2026,
            "axes": [{"pointer": "/step_ms", "uniform": [0.0, 1.0]}]}),
        )
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(60))
        .await;
    let results = app.sweep_results(&id).await;
    let statistics = &results["aggregates"]["statistics"];
    assert_eq!(
        statistics.as_array().unwrap().len(),
        1,
        "one cell without list axes"
    );
    let drawn = &statistics[0]["metrics"]["/step_ms"];
    assert_eq!(drawn["count"], samples);

    // Against the law: U(0, 1) has mean 1/2 and standard deviation 1/√12.
    let (mean, std) = (drawn["mean"].as_f64().unwrap(), drawn["std"].as_f64().unwrap());
    let standard_error = (1.0 / 12.0f64).sqrt() / (samples as f64).sqrt();
    assert!(
        (mean - 0.5).abs() < 4.0 * standard_error,
        "mean {mean}, expected 0.5 ± {}",
        4.0 * standard_error
    );
    assert!(
        (std - (1.0 / 12.0f64).sqrt()).abs() < 0.03,
        "std {std}, expected {}",
        (1.0 / 12.0f64).sqrt()
    );

    // Against the rows, computed by hand.
    let values = column(&results, "/step_ms");
    let by_hand_mean = values.iter().sum::<f64>() / values.len() as f64;
    let by_hand_std =
        (values.iter().map(|v| (v - by_hand_mean).powi(2)).sum::<f64>() / (values.len() - 1) as f64).sqrt();
    assert!((mean - by_hand_mean).abs() < 1e-12 && (std - by_hand_std).abs() < 1e-12);
    let (min, max) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    assert_eq!(
        (drawn["min"].as_f64().unwrap(), drawn["max"].as_f64().unwrap()),
        (min, max)
    );
    let sum = &statistics[0]["metrics"]["sum"];
    assert_eq!(
        (sum["mean"].as_f64(), sum["std"].as_f64(), sum["q95"].as_f64()),
        (Some(1.0), Some(0.0), Some(1.0))
    );

    // The Wilks 95 %/95 % bound of 400 runs: the values above the 95 % quantile are
    // binomial (400, 0.05), mean 20, standard deviation 4.36, so the rank from the top
    // that is at or above it with 95 % confidence is about 20 − 1.645 × 4.36 ≈ 13; the
    // bound is that order statistic of the rows.
    let rank = drawn["bound_95_95_rank"].as_u64().unwrap() as usize;
    assert!((11..=14).contains(&rank), "rank {rank}");
    let mut sorted = values.clone();
    sorted.sort_by(f64::total_cmp);
    assert_eq!(drawn["bound_95_95"].as_f64(), Some(sorted[sorted.len() - rank]));
}

async fn identical_runs_are_computed_once_across_single_jobs_and_sweeps(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 1).await;
    let single = app.submit(json!({"steps": 7})).await;
    app.wait_until_finished(&single).await;
    assert_eq!(app.probe.started(), 1);

    let id = app
        .create_sweep(sweep(
            json!({"steps": 1}),
            json!([{"pointer": "/steps", "values": [7, 8, 8]}]),
        ))
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(20))
        .await;
    assert_eq!(
        *app.probe.runs.lock().unwrap(),
        [7, 8],
        "7 reused from the single job, the second 8 from the first"
    );

    let results = app.sweep_results(&id).await;
    assert_eq!(column(&results, "sum"), [28.0, 36.0, 36.0]);
    let reused = results["rows"][0]["job"].as_str().unwrap();
    let status = app.status(reused).await;
    assert!(status["message"].as_str().unwrap().contains(&single), "{status}");
    let document = app.get_json(&format!("/jobs/{reused}/results")).await;
    assert_eq!(
        document["outputs"]["signal"]["href"],
        format!("/jobs/{reused}/results/signal")
    );
    let history = app
        .get(&format!("/jobs/{reused}/results/signal?format=csv"))
        .await;
    assert_eq!(history.status(), StatusCode::OK);
    assert_eq!(
        history.text().await.unwrap().lines().count(),
        8,
        "header and 7 steps, copied"
    );
}

async fn single_jobs_submitted_after_a_big_sweep_do_not_wait_for_it(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 1).await;
    let steps: Vec<u64> = (10..30).collect();
    let id = app
        .create_sweep(sweep(
            json!({"steps": 10, "step_ms": 5.0}),
            json!([{"pointer": "/steps", "values": steps}]),
        ))
        .await;
    while app.probe.started() == 0 {
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    let single = app.submit(json!({"steps": 3, "step_ms": 5.0})).await;
    app.wait_until_finished(&single).await;
    let runs = app.probe.runs.lock().unwrap().clone();
    let position = runs.iter().position(|n| *n == 3).unwrap();
    assert!(
        position <= 2,
        "the single job ran after {position} sweep runs: {runs:?}"
    );
    let sweep = app.get_json(&format!("/sweeps/{id}")).await;
    assert_ne!(sweep["status"], "successful", "{sweep}");
    app.delete(&format!("/sweeps/{id}")).await;
}

/// A small calibration grid on the real cantilever case (0.1 s of motion): the paper's
/// trend holds, the valid region shrinks as Rk and Δt grow. A stiff contact lowers the
/// critical time step, so the coarse steps of the stiffest contact are beyond it:
/// recorded as failed runs (`invalid_runs: record`), not valid. The softest contact
/// with the finest step is valid, and validity never reappears when Rk or Δt grows
/// along a row or column of the map.
#[tokio::test]
async fn a_calibration_grid_maps_validity_shrinking_as_rk_and_time_step_grow() {
    let app = spawn_app_with_processes(vec![Arc::new(CantileverImpact)], |_| {}).await;
    let mut body: Value =
        serde_json::from_str(include_str!("../../examples/sweep-calibration.json")).unwrap();
    body["inputs"]["solver"]["duration"] = json!(0.1);
    // The modes alone: with the static correction (the default) the tip pseudo-mode
    // shortens the critical step below 1e-5 s at Rk = 1e6, leaving that row without a
    // valid step (docs/static-correction.md); this test is about the map's shape.
    body["inputs"]["beam"]["static_correction"] = json!("none");
    body["axes"] = json!([
        {"pointer": "/contact/rk", "logspace": [1.0, 1e6, 3]},
        {"pointer": "/solver/time_step", "values": [1e-5, 3e-5, 1e-4]}
    ]);
    let id = app.create_sweep(body).await;
    let status = app
        .wait_for_sweep(&id, &["partial"], Duration::from_secs(120))
        .await;
    assert!(
        status["counts"]["failed"].as_i64().unwrap() >= 1,
        "the runs beyond the critical step failed, so the sweep is partial: {status}"
    );
    let results = app.sweep_results(&id).await;
    assert_eq!(results["status"], "partial");
    let calibration = &results["aggregates"]["calibration"];
    let valid: Vec<bool> = calibration["cells"]
        .as_array()
        .unwrap()
        .iter()
        .map(|cell| cell["valid"].as_bool().unwrap())
        .collect();
    assert_eq!(valid.len(), 9, "{calibration}");
    let at = |rk: usize, dt: usize| valid[rk * 3 + dt];
    assert!(
        at(0, 0),
        "the softest contact with the finest step is valid: {calibration}"
    );
    assert!(
        !at(2, 2),
        "the stiffest contact with the coarsest step is not: {calibration}"
    );
    for rk in 0..3 {
        for dt in 0..3 {
            if rk + 1 < 3 && at(rk + 1, dt) {
                assert!(
                    at(rk, dt),
                    "valid at a stiffer contact but not a softer one: {calibration}"
                );
            }
            if dt + 1 < 3 && at(rk, dt + 1) {
                assert!(
                    at(rk, dt),
                    "valid at a coarser step but not a finer one: {calibration}"
                );
            }
        }
    }
    let cheapest = &calibration["cheapest"][0];
    assert_eq!(cheapest["axis"], "/solver/time_step");
    let largest: Vec<f64> = cheapest["choices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|choice| choice["value"].as_f64().unwrap())
        .collect();
    assert_eq!(largest.len(), 3, "one choice per Rk: {calibration}");
    assert!(
        largest.windows(2).all(|w| w[1] <= w[0]),
        "the largest valid step shrinks as Rk grows: {largest:?}"
    );
    let failed = &results["rows"][8];
    assert_eq!(failed["status"], "failed", "beyond the critical step: {failed}");
    let problem = app
        .get(&format!("/jobs/{}/results", failed["job"].as_str().unwrap()))
        .await;
    let problem = assert_problem(problem, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/inputs/solver/time_step");
}

async fn sweeps_are_listed_newest_first_with_paging_and_unknown_ones_are_404(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let mut ids = Vec::new();
    for steps in [1, 2, 3] {
        ids.push(
            app.create_sweep(sweep(
                json!({"steps": 1}),
                json!([{"pointer": "/steps", "values": [steps]}]),
            ))
            .await,
        );
    }
    let first = app.get_json("/sweeps?limit=2").await;
    let listed: Vec<&str> = first["sweeps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["sweepID"].as_str().unwrap())
        .collect();
    assert_eq!(listed, [ids[2].as_str(), ids[1].as_str()]);
    let next = first["links"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["rel"] == "next")
        .expect("a next link");
    let second = app.get_json(next["href"].as_str().unwrap()).await;
    assert_eq!(second["sweeps"][0]["sweepID"], ids[0].as_str());
    assert!(
        second["links"]
            .as_array()
            .unwrap()
            .iter()
            .all(|l| l["rel"] != "next")
    );

    for path in ["/sweeps/nope", "/sweeps/nope/results"] {
        assert_problem(app.get(path).await, StatusCode::NOT_FOUND, "/no-such-sweep").await;
    }
    assert_problem(
        app.delete("/sweeps/nope").await,
        StatusCode::NOT_FOUND,
        "/no-such-sweep",
    )
    .await;
    for path in [
        "/sweeps?limit=0".to_owned(),
        format!("/sweeps/{}/results?format=xml", ids[0]),
    ] {
        assert_problem(app.get(&path).await, StatusCode::BAD_REQUEST, "/invalid-query").await;
    }
}

/// Random gap states on a small real bundle: the seed of the gap generator is the
/// random axis (integers, since the base holds one), and every run's table row carries
/// the peak force overall and per contact, with statistics over the campaign.
#[tokio::test]
async fn a_random_gap_campaign_tabulates_peak_forces_per_contact() {
    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |_| {}).await;
    let mut body: Value = serde_json::from_str(include_str!("../../examples/sweep-gaps.json")).unwrap();
    body["samples"] = json!(3);
    body["inputs"]["solver"]["duration"] = json!(0.02);
    let id = app.create_sweep(body).await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(120))
        .await;
    let results = app.sweep_results(&id).await;
    let columns = column_names(&results);
    for expected in [
        "/bundle/gaps/seed",
        "max_contact_force.force",
        "impacts",
        "contacts.0.max_force",
        "contacts.7.max_force",
        "impact_summary.impacts",
        "contacts.7.impact_statistics.impacts_per_second",
        "contacts.7.impact_statistics.max_impact_energy",
        "contacts.7.impact_statistics.mean_duration",
    ] {
        assert!(columns.contains(&expected), "{expected} missing from {columns:?}");
    }
    let rows = results["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    for row in rows {
        assert!(row["/bundle/gaps/seed"].is_u64(), "seeds are integers: {row}");
        let peak = row["max_contact_force.force"].as_f64().unwrap();
        let largest = (0..8)
            .map(|k| row[format!("contacts.{k}.max_force")].as_f64().unwrap())
            .fold(0.0, f64::max);
        assert_eq!(
            peak, largest,
            "the overall peak is the largest contact peak: {row}"
        );
        let counted: f64 = (0..8)
            .map(|k| {
                row[format!("contacts.{k}.impact_statistics.impacts")]
                    .as_f64()
                    .unwrap()
            })
            .sum();
        assert_eq!(row["impact_summary.impacts"].as_f64(), Some(counted), "{row}");
        assert_eq!(row["impacts"].as_f64(), Some(counted), "{row}");
    }
    let statistics = &results["aggregates"]["statistics"][0]["metrics"];
    assert!(
        statistics.get("/bundle/gaps/seed").is_none(),
        "no statistics of a seed: {statistics}"
    );
    let csv = app.sweep_csv(&id).await;
    let seeds: Vec<String> = rows
        .iter()
        .map(|row| row["/bundle/gaps/seed"].to_string())
        .collect();
    for (line, seed) in csv.lines().skip(1).zip(&seeds) {
        let cell = line.split(',').nth(3).unwrap();
        assert_eq!(cell, seed, "the seed column of the CSV, as an integer: {line}");
    }
    let force = &statistics["max_contact_force.force"];
    assert_eq!(force["count"], 3, "{force}");
    assert!(force["min"].as_f64().unwrap() <= force["q50"].as_f64().unwrap());
    assert!(force["q50"].as_f64().unwrap() <= force["max"].as_f64().unwrap());
}
