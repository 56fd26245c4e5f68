//! `DELETE /jobs/{id}`: a queued job never runs, a running job stops within a second,
//! a finished job loses its results.

use std::time::{Duration, Instant};

use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{Backend, assert_problem, on_both_backends, spawn_app_on};

on_both_backends!(
    a_dismissed_queued_job_never_runs,
    a_dismissed_running_job_stops_within_a_second,
    dismissing_a_finished_job_deletes_its_results
);

async fn a_dismissed_queued_job_never_runs(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 0).await;
    let job = app.submit(json!({"steps": 3})).await;
    let response = app.delete(&format!("/jobs/{job}")).await;
    assert_eq!(response.status(), StatusCode::OK);
    let status: Value = response.json().await.unwrap();
    assert_eq!(status["status"], "dismissed");
    assert!(status["finished"].is_string());
    let claimed = app
        .queue
        .claim("a-worker", Duration::from_secs(30))
        .await
        .unwrap();
    assert!(claimed.is_none(), "a dismissed job cannot be claimed");
    assert_eq!(app.status(&job).await["status"], "dismissed");
    assert_eq!(app.probe.started(), 0);
}

async fn a_dismissed_running_job_stops_within_a_second(backend: Backend) {
    // One worker: the next job can only run once it is done with the dismissed one.
    let app = spawn_app_on(backend, |config| config.workers = 1).await;
    // 100 000 steps of 1 ms: minutes of work unless cancelled.
    let job = app.submit(json!({"steps": 100000, "step_ms": 1})).await;
    app.wait_for(&job, &["running"], Duration::from_secs(5)).await;
    tokio::time::sleep(Duration::from_millis(100)).await;
    let dismissed_at = Instant::now();
    let response = app.delete(&format!("/jobs/{job}")).await;
    assert_eq!(response.status(), StatusCode::OK);
    let status: Value = response.json().await.unwrap();
    assert_eq!(status["status"], "dismissed");
    loop {
        if let Some(stopped_at) = *app.probe.cancelled_at.lock().unwrap() {
            let took = stopped_at.saturating_duration_since(dismissed_at);
            assert!(took < Duration::from_secs(1), "stopped after {took:?}");
            break;
        }
        assert!(
            dismissed_at.elapsed() < Duration::from_secs(1),
            "the run did not stop within a second"
        );
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    let next = app.submit(json!({"steps": 2})).await;
    assert_eq!(
        app.wait_until_finished(&next).await["status"],
        "successful",
        "the worker is free again"
    );
    // The only worker has run `next`, so it has long returned from the dismissed run,
    // final write (refused or not) included.
    let status = app.status(&job).await;
    assert_eq!(
        status["status"], "dismissed",
        "the stopped worker does not overwrite the dismissal"
    );
    assert_problem(
        app.get(&format!("/jobs/{job}/results")).await,
        StatusCode::NOT_FOUND,
        "/job-dismissed",
    )
    .await;
}

async fn dismissing_a_finished_job_deletes_its_results(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let job = app.submit(json!({"steps": 10})).await;
    app.wait_until_finished(&job).await;
    assert_eq!(app.delete(&format!("/jobs/{job}")).await.status(), StatusCode::OK);
    assert_problem(
        app.get(&format!("/jobs/{job}/results/signal")).await,
        StatusCode::NOT_FOUND,
        "/job-dismissed",
    )
    .await;
    assert!(
        app.queue
            .history("default", &job, "signal")
            .await
            .unwrap()
            .is_none()
    );
    let again = app.delete(&format!("/jobs/{job}")).await;
    assert_eq!(again.status(), StatusCode::OK, "dismissing twice is harmless");
}
