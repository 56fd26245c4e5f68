//! The API stays responsive while every worker computes.

use std::time::{Duration, Instant};

use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::spawn_app_with;

#[tokio::test]
async fn the_api_answers_quickly_while_every_worker_is_busy() {
    let app = spawn_app_with(|config| config.workers = 2).await;
    // Two CPU-bound jobs (spinning 0.1 ms per step for up to 20 s), one per worker.
    let mut busy = Vec::new();
    for _ in 0..2 {
        busy.push(
            app.submit(json!({"steps": 200000, "step_ms": 0.1, "busy": true}))
                .await,
        );
    }
    for job in &busy {
        app.wait_for(job, &["running"], Duration::from_secs(5)).await;
    }
    let mut latencies = Vec::new();
    for _ in 0..20 {
        let started = Instant::now();
        let response = app
            .post_execution("count-steps", &json!({"inputs": {"steps": 1}}))
            .await;
        assert_eq!(response.status(), StatusCode::CREATED);
        assert_eq!(
            app.get(&format!("/jobs/{}", busy[0])).await.status(),
            StatusCode::OK
        );
        assert_eq!(app.get("/jobs?limit=50").await.status(), StatusCode::OK);
        latencies.push(started.elapsed());
    }
    for job in &busy {
        assert_eq!(app.status(job).await["status"], "running", "still computing");
        app.delete(&format!("/jobs/{job}")).await;
    }
    latencies.sort();
    let median = latencies[latencies.len() / 2];
    let worst = latencies[latencies.len() - 1];
    assert!(
        median < Duration::from_millis(100) && worst < Duration::from_millis(1000),
        "submit + status + list took median {median:?}, worst {worst:?}"
    );
}
