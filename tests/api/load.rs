//! Load figures (ignored by default; run in release-like profile, on an idle machine):
//!
//! ```sh
//! cargo test --test api load -- --ignored --nocapture --test-threads 1
//! ```
//!
//! 1. Submission latency at a steady 200 requests/s for 5 s while every worker computes
//!    a CPU-bound job (target: p99 under 20 ms).
//! 2. Throughput: 1000 small jobs queued at once, then completed by `--workers` = cores.

use std::sync::Arc;
use std::time::{Duration, Instant};

use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::spawn_app_with;

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    sorted[((sorted.len() as f64 - 1.0) * p).round() as usize]
}

#[tokio::test(flavor = "multi_thread")]
#[ignore = "load figures; run explicitly"]
async fn load_submission_latency_at_200_per_second_while_workers_are_busy() {
    let workers = chocmodal::service::config::default_workers();
    let app = Arc::new(spawn_app_with(|config| config.workers = workers).await);
    let mut busy = Vec::new();
    for _ in 0..workers {
        busy.push(
            app.submit(json!({"steps": 1000000, "step_ms": 0.1, "busy": true}))
                .await,
        );
    }
    for job in &busy {
        app.wait_for(job, &["running"], Duration::from_secs(5)).await;
    }
    // Jobs stay queued behind the busy ones: this measures the API, not the workers.
    let mut ticker = tokio::time::interval(Duration::from_millis(5));
    let mut tasks = tokio::task::JoinSet::new();
    for _ in 0..1000 {
        ticker.tick().await;
        let app = app.clone();
        tasks.spawn(async move {
            let started = Instant::now();
            let response = app
                .post_execution("count-steps", &json!({"inputs": {"steps": 1}}))
                .await;
            assert_eq!(response.status(), StatusCode::CREATED);
            started.elapsed()
        });
    }
    let mut latencies = Vec::new();
    while let Some(latency) = tasks.join_next().await {
        latencies.push(latency.unwrap());
    }
    latencies.sort();
    println!(
        "submissions at 200/s with {workers} busy workers: p50 {:?}, p90 {:?}, p99 {:?}, max {:?}",
        percentile(&latencies, 0.5),
        percentile(&latencies, 0.9),
        percentile(&latencies, 0.99),
        latencies[latencies.len() - 1]
    );
    for job in &busy {
        app.delete(&format!("/jobs/{job}")).await;
    }
}

#[tokio::test(flavor = "multi_thread")]
#[ignore = "load figures; run explicitly"]
async fn load_a_thousand_small_jobs_complete() {
    let workers = chocmodal::service::config::default_workers();
    let app = Arc::new(spawn_app_with(|config| config.workers = workers).await);
    let started = Instant::now();
    let mut jobs = Vec::new();
    for _ in 0..1000 {
        jobs.push(app.submit(json!({"steps": 1000})).await);
    }
    let submitted = started.elapsed();
    loop {
        let done = app.get_json("/jobs?status=successful&limit=1000").await["jobs"]
            .as_array()
            .unwrap()
            .len();
        if done == jobs.len() {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(300),
            "only {done} of 1000 jobs done"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let total = started.elapsed();
    println!(
        "1000 small jobs with {workers} workers: submitted in {submitted:?}, all done in {total:?} \
         ({:.0} jobs/s)",
        1000.0 / total.as_secs_f64()
    );
}
