//! The API keeps answering while every worker computes.
//!
//! Only the behaviour is tested here: with both workers spinning on CPU-bound jobs,
//! submissions, a status and the listing are all answered, and the workers stay busy
//! throughout. How fast they are answered is a measurement, not a test outcome (it
//! depends on the machine and its load): `scripts/load.sh` measures the latency
//! percentiles under the same saturation with a release build (see the README).

use std::time::Duration;

use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::spawn_app_with;

/// Far beyond any latency: only a request that hangs behind the workers exceeds it.
const HANG: Duration = Duration::from_secs(10);

#[tokio::test]
async fn the_api_answers_while_every_worker_is_busy() {
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
    for _ in 0..20 {
        let answered = tokio::time::timeout(HANG, async {
            let response = app
                .post_execution("count-steps", &json!({"inputs": {"steps": 1}}))
                .await;
            assert_eq!(response.status(), StatusCode::CREATED);
            assert_eq!(
                app.get(&format!("/jobs/{}", busy[0])).await.status(),
                StatusCode::OK
            );
            assert_eq!(app.get("/jobs?limit=50").await.status(), StatusCode::OK);
        })
        .await;
        assert!(
            answered.is_ok(),
            "submit + status + list not answered within {HANG:?} while the workers compute"
        );
    }
    for job in &busy {
        assert_eq!(app.status(job).await["status"], "running", "still computing");
        app.delete(&format!("/jobs/{job}")).await;
    }
}
