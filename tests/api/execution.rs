//! Submitting jobs: 201 + Location + statusInfo, progress, concurrency.

use std::time::Duration;

use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{Backend, on_both_backends, spawn_app_on};

on_both_backends!(
    execution_returns_201_with_location_and_the_job_status,
    progress_is_reported_while_a_job_runs,
    two_hundred_concurrent_submissions_all_land,
    queued_jobs_run_oldest_first
);

async fn execution_returns_201_with_location_and_the_job_status(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 0).await;
    let response = app
        .post_execution("count-steps", &json!({"inputs": {"steps": 3}}))
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let location = response.headers()["location"].to_str().unwrap().to_owned();
    let status: Value = response.json().await.unwrap();
    let job = status["jobID"].as_str().unwrap();
    assert_eq!(location, format!("/jobs/{job}"));
    assert_eq!(status["processID"], "count-steps");
    assert_eq!(status["type"], "process");
    assert_eq!(status["status"], "accepted");
    assert_eq!(status["progress"], 0);
    assert!(status["created"].as_str().unwrap().ends_with('Z'));
    assert_eq!(status["links"][0]["href"], location);
    assert_eq!(app.status(job).await["status"], "accepted");
}

async fn progress_is_reported_while_a_job_runs(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let job = app.submit(json!({"steps": 100, "step_ms": 15})).await;
    let mut seen = Vec::new();
    let mut estimated = 0;
    loop {
        let status = app.status(&job).await;
        let progress = status["progress"].as_u64().unwrap();
        if status["status"] == "successful" {
            assert_eq!(progress, 100);
            assert!(status.get("estimatedFinish").is_none(), "{status}");
            break;
        }
        // While it runs with 1 to 99 % done, the estimated finish extrapolates the
        // pace so far: the 100 steps sleep 15 ms each, so never before 1.5 s after the
        // start (the stored percent is rounded down, the time taken is at least the
        // sleeps, less a millisecond of each time's rounding), and not absurdly later.
        if status["status"] == "running" && (1..100).contains(&progress) {
            let at = |member: &str| {
                let text = status[member]
                    .as_str()
                    .unwrap_or_else(|| panic!("no {member}: {status}"));
                time::OffsetDateTime::parse(text, &time::format_description::well_known::Rfc3339).unwrap()
            };
            let ahead = (at("estimatedFinish") - at("started")).as_seconds_f64();
            assert!(
                (1.35..60.0).contains(&ahead),
                "finish {ahead} s after the start: {status}"
            );
            estimated += 1;
        } else {
            assert!(status.get("estimatedFinish").is_none(), "{status}");
        }
        seen.push(progress);
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert!(estimated > 0, "no estimated finish seen: {seen:?}");
    assert!(
        seen.iter().any(|p| (1..100).contains(p)),
        "no intermediate progress seen: {seen:?}"
    );
    assert!(
        seen.windows(2).all(|w| w[0] <= w[1]),
        "progress went backwards: {seen:?}"
    );
}

async fn two_hundred_concurrent_submissions_all_land(backend: Backend) {
    let app = std::sync::Arc::new(spawn_app_on(backend, |config| config.workers = 0).await);
    let mut tasks = tokio::task::JoinSet::new();
    for _ in 0..20 {
        let app = app.clone();
        tasks.spawn(async move {
            let mut statuses = Vec::new();
            for _ in 0..10 {
                let response = app
                    .post_execution("count-steps", &json!({"inputs": {"steps": 1}}))
                    .await;
                statuses.push(response.status());
            }
            statuses
        });
    }
    let mut created = 0;
    while let Some(statuses) = tasks.join_next().await {
        for status in statuses.unwrap() {
            assert_eq!(status, StatusCode::CREATED);
            created += 1;
        }
    }
    assert_eq!(created, 200);
    let jobs = app.get_json("/jobs?limit=1000").await;
    assert_eq!(jobs["jobs"].as_array().unwrap().len(), 200);
}

async fn queued_jobs_run_oldest_first(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 1).await;
    let mut jobs = Vec::new();
    for steps in [11, 12, 13, 14] {
        jobs.push(app.submit(json!({"steps": steps, "step_ms": 2})).await);
    }
    for job in &jobs {
        assert_eq!(app.wait_until_finished(job).await["status"], "successful");
    }
    assert_eq!(*app.probe.runs.lock().unwrap(), vec![11, 12, 13, 14]);
}

/// OGC API – Processes clients (OWSLib) send `Prefer: respond-async` and expect to be
/// told it was applied; `respond-sync` is not, but the answer is a job all the same.
#[tokio::test]
async fn prefer_respond_async_is_applied_and_respond_sync_still_gets_a_job() {
    let app = spawn_app_on(Backend::Sqlite, |config| config.workers = 0).await;
    for (prefer, applied) in [
        (Some("respond-async"), Some("respond-async")),
        (Some("wait=10, respond-async"), Some("respond-async")),
        (Some("respond-sync"), None),
        (None, None),
    ] {
        let mut request = app
            .client
            .post(app.url("/processes/count-steps/execution"))
            .header("content-type", "application/json")
            .body(json!({"inputs": {"steps": 3}}).to_string());
        if let Some(prefer) = prefer {
            request = request.header("prefer", prefer);
        }
        let response = request.send().await.unwrap();
        assert_eq!(response.status(), StatusCode::CREATED, "Prefer: {prefer:?}");
        let header = response
            .headers()
            .get("preference-applied")
            .map(|v| v.to_str().unwrap().to_owned());
        assert_eq!(header.as_deref(), applied, "Prefer: {prefer:?}");
    }
}
