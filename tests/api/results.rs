//! A job runs to success; its results document and histories are served, windowed and
//! thinned; failures are problems; entity tags make polling cheap.

use std::time::Duration;

use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{Backend, assert_problem, on_both_backends, spawn_app, spawn_app_on};

on_both_backends!(
    a_job_runs_to_success_and_serves_its_results_and_histories,
    a_deterministic_failure_fails_at_once_without_retry,
    a_failed_job_keeps_the_progress_it_had_reached,
    a_panicking_process_fails_only_its_own_job
);

async fn a_job_runs_to_success_and_serves_its_results_and_histories(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let job = app.submit(json!({"steps": 50})).await;
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    assert_eq!(status["progress"], 100);
    assert!(status["finished"].is_string() && status["started"].is_string());
    assert!(
        status["links"]
            .as_array()
            .unwrap()
            .iter()
            .any(|l| l["href"] == format!("/jobs/{job}/results"))
    );

    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    assert_eq!(results["sum"], 50 * 51 / 2);
    let href = results["outputs"]["signal"]["href"].as_str().unwrap();
    assert_eq!(href, format!("/jobs/{job}/results/signal"));

    let csv_response = app.get(&format!("{href}?format=csv")).await;
    assert_eq!(csv_response.status(), StatusCode::OK);
    assert!(
        csv_response.headers()["content-type"]
            .to_str()
            .unwrap()
            .starts_with("text/csv")
    );
    let csv = csv_response.text().await.unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "time,value,square");
    assert_eq!(lines.len(), 51);
    let last: Vec<f64> = lines[50].split(',').map(|x| x.parse().unwrap()).collect();
    assert_eq!(last, vec![50.0 * 1e-3, (50.0f64 * 0.05).sin(), 2500.0]);

    let history = app.get_json(href).await;
    assert_eq!(history["output"], "signal");
    assert_eq!(history["points"], 50);
    assert_eq!(history["total_points"], 50);
    assert_eq!(history["series"][1]["name"], "square");
    assert_eq!(history["series"][1]["values"][49], 2500.0);

    let by_accept = app
        .client
        .get(app.url(href))
        .header("accept", "text/csv")
        .send()
        .await
        .unwrap();
    assert_eq!(by_accept.text().await.unwrap(), csv);
}

#[tokio::test]
async fn results_are_not_ready_while_the_job_runs() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 200, "step_ms": 10})).await;
    app.wait_for(&job, &["running"], Duration::from_secs(5)).await;
    let response = app.get(&format!("/jobs/{job}/results")).await;
    assert!(response.headers().contains_key("retry-after"));
    assert_problem(response, StatusCode::NOT_FOUND, "/result-not-ready").await;
    let output = app.get(&format!("/jobs/{job}/results/signal")).await;
    assert_problem(output, StatusCode::NOT_FOUND, "/result-not-ready").await;
    app.delete(&format!("/jobs/{job}")).await;
}

#[tokio::test]
async fn thinning_keeps_the_peaks_of_a_history() {
    let app = spawn_app().await;
    let job = app
        .submit(json!({"steps": 10000, "spikes": [[4321, 50.0], [777, -20.0], [9999, 30.0]]}))
        .await;
    app.wait_until_finished(&job).await;
    let thin = app
        .get_json(&format!("/jobs/{job}/results/signal?max_points=200"))
        .await;
    assert!(thin["thinned"].as_bool().unwrap());
    assert_eq!(thin["total_points"], 10000);
    let time: Vec<f64> = serde_json::from_value(thin["time"].clone()).unwrap();
    assert!(time.len() <= 200, "{} rows", time.len());
    assert!(time.windows(2).all(|w| w[0] < w[1]), "rows out of time order");
    let values: Vec<f64> = serde_json::from_value(thin["series"][0]["values"].clone()).unwrap();
    for peak in [50.0, -20.0, 30.0] {
        assert!(values.contains(&peak), "peak {peak} lost by thinning");
    }
    let csv = app
        .get(&format!("/jobs/{job}/results/signal?format=csv&max_points=200"))
        .await
        .text()
        .await
        .unwrap();
    assert!(csv.lines().count() <= 201);
    assert!(csv.contains(",50.0,"), "CSV keeps the 50 N spike");
}

#[tokio::test]
async fn a_time_window_selects_samples_between_t_start_and_t_end() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 1000})).await;
    app.wait_until_finished(&job).await;
    let window = app
        .get_json(&format!("/jobs/{job}/results/signal?t_start=0.1&t_end=0.2"))
        .await;
    let time: Vec<f64> = serde_json::from_value(window["time"].clone()).unwrap();
    assert!(time.iter().all(|t| (0.1..=0.2).contains(t)), "{time:?}");
    assert!((99..=101).contains(&time.len()), "{} samples", time.len());
}

#[tokio::test]
async fn an_unknown_output_is_a_404_problem() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&job).await;
    let response = app.get(&format!("/jobs/{job}/results/nothing")).await;
    assert_problem(response, StatusCode::NOT_FOUND, "/no-such-output").await;
}

/// A run that fails (a divergence) says where it stopped: its progress stays at the
/// percent it had reached, even when it fails between two heartbeats (no pause here:
/// the 60 steps before the failure take microseconds, far less than the 50 ms period).
async fn a_failed_job_keeps_the_progress_it_had_reached(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let job = app.submit(json!({"steps": 100, "fail_at": 61})).await;
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "failed", "{status}");
    assert_eq!(status["progress"], 60, "60 of 100 steps were done: {status}");
    let listed = app.get_json("/jobs?status=failed").await;
    assert_eq!(listed["jobs"][0]["progress"], 60, "{listed}");
}

async fn a_deterministic_failure_fails_at_once_without_retry(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let job = app.submit(json!({"steps": 10, "fail_at": 5})).await;
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "failed");
    assert!(
        status["message"].as_str().unwrap().contains("diverged at step 5"),
        "{status}"
    );
    let problem = assert_problem(
        app.get(&format!("/jobs/{job}/results")).await,
        StatusCode::UNPROCESSABLE_ENTITY,
        "/job-failed",
    )
    .await;
    assert_eq!(problem["detail"], "diverged at step 5");
    // Jobs are claimed oldest first: a retry of the failed job would start before a job
    // submitted after its failure.
    let later = app.submit(json!({"steps": 2})).await;
    assert_eq!(app.wait_until_finished(&later).await["status"], "successful");
    assert_eq!(
        *app.probe.runs.lock().unwrap(),
        [10, 2],
        "a deterministic failure is not retried"
    );
    assert_eq!(app.status(&job).await["status"], "failed");
    assert_eq!(app.queue.get("default", &job).await.unwrap().unwrap().attempt, 1);
}

async fn a_panicking_process_fails_only_its_own_job(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let crashing = app.submit(json!({"steps": 10, "panic_at": 3})).await;
    let healthy = app.submit(json!({"steps": 10})).await;
    assert_eq!(app.wait_until_finished(&crashing).await["status"], "failed");
    assert_eq!(app.wait_until_finished(&healthy).await["status"], "successful");
    let problem = assert_problem(
        app.get(&format!("/jobs/{crashing}/results")).await,
        StatusCode::INTERNAL_SERVER_ERROR,
        "/job-crashed",
    )
    .await;
    assert!(
        !problem["detail"].as_str().unwrap().contains("panics at step"),
        "no internals leak"
    );
    let after = app.submit(json!({"steps": 2})).await;
    assert_eq!(
        app.wait_until_finished(&after).await["status"],
        "successful",
        "workers survive"
    );
}

#[tokio::test]
async fn job_status_has_an_etag_and_answers_304_while_unchanged() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 5})).await;
    app.wait_until_finished(&job).await;
    let path = format!("/jobs/{job}");
    let first = app.get(&path).await;
    let etag = first.headers()["etag"].to_str().unwrap().to_owned();
    assert!(etag.starts_with('"'), "a strong tag: {etag}");
    assert!(
        !first.headers().contains_key("retry-after"),
        "finished: no Retry-After"
    );
    let again = app.get_if_none_match(&path, &etag).await;
    assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
    assert_eq!(again.headers()["etag"].to_str().unwrap(), etag);
    assert!(again.bytes().await.unwrap().is_empty());
    let stale = app.get_if_none_match(&path, "\"something-else\"").await;
    assert_eq!(stale.status(), StatusCode::OK);
}

#[tokio::test]
async fn a_job_not_finished_has_retry_after_and_a_changing_etag() {
    let app = spawn_app_with_one_worker().await;
    let job = app.submit(json!({"steps": 100, "step_ms": 20})).await;
    let first = app.get(&format!("/jobs/{job}")).await;
    assert!(first.headers().contains_key("retry-after"));
    let first_tag = first.headers()["etag"].to_str().unwrap().to_owned();
    let first_progress = first.json::<Value>().await.unwrap()["progress"].as_u64().unwrap();
    // Conditional polling answers 304 until the job moves on, then 200 with a new tag.
    let deadline = std::time::Instant::now() + Duration::from_secs(5);
    let changed = loop {
        let response = app.get_if_none_match(&format!("/jobs/{job}"), &first_tag).await;
        if response.status() == StatusCode::OK {
            break response;
        }
        assert_eq!(response.status(), StatusCode::NOT_MODIFIED);
        assert!(std::time::Instant::now() < deadline, "the job never progressed");
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_ne!(changed.headers()["etag"].to_str().unwrap(), first_tag);
    let later: Value = changed.json().await.unwrap();
    assert!(
        later["progress"].as_u64().unwrap() > first_progress || later["status"] != "accepted",
        "{later}"
    );
    app.delete(&format!("/jobs/{job}")).await;
}

async fn spawn_app_with_one_worker() -> crate::helpers::TestApp {
    crate::helpers::spawn_app_with(|config| config.workers = 1).await
}

#[tokio::test]
async fn finished_results_have_a_strong_etag_and_answer_304() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 20})).await;
    app.wait_until_finished(&job).await;
    for path in [
        format!("/jobs/{job}/results"),
        format!("/jobs/{job}/results/signal?format=csv"),
    ] {
        let first = app.get(&path).await;
        let etag = first.headers()["etag"].to_str().unwrap().to_owned();
        assert!(!etag.starts_with("W/"));
        let body: Vec<u8> = first.bytes().await.unwrap().to_vec();
        let again = app.get(&path).await;
        assert_eq!(again.headers()["etag"].to_str().unwrap(), etag, "stable tag");
        assert_eq!(again.bytes().await.unwrap().to_vec(), body);
        let conditional = app.get_if_none_match(&path, &etag).await;
        assert_eq!(conditional.status(), StatusCode::NOT_MODIFIED, "{path}");
    }
    let _: Value = app.get_json(&format!("/jobs/{job}/results")).await;
}
