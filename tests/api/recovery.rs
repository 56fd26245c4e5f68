//! Jobs survive lost workers and restarts: expired leases go back to the queue, a job
//! that keeps losing its worker fails with a clear message, stale workers cannot write,
//! and a graceful shutdown either finishes running jobs or hands them back.

use std::sync::Arc;
use std::time::Duration;

use chocmodal::service::clock::ManualClock;
use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::{Backend, assert_problem, on_both_backends, spawn_app_in, spawn_app_on};

on_both_backends!(
    a_job_left_running_by_a_dead_worker_is_requeued_at_startup_and_completes,
    a_job_whose_worker_keeps_dying_fails_with_a_clear_message,
    expired_leases_are_recovered_periodically_once_the_clock_passes_them,
    a_worker_that_lost_its_lease_can_neither_heartbeat_nor_write_results,
    a_job_survives_a_server_restart,
    a_graceful_shutdown_lets_a_running_job_finish_within_the_grace_period
);

/// Long enough that the periodic pass never runs during a test.
const NO_MAINTENANCE: Duration = Duration::from_secs(3600);

async fn a_job_left_running_by_a_dead_worker_is_requeued_at_startup_and_completes(backend: Backend) {
    let clock = Arc::new(ManualClock::starting_now());
    let before = spawn_app_on(backend, |config| {
        config.workers = 0;
        config.maintenance_interval = NO_MAINTENANCE;
        config.clock = clock.clone();
    })
    .await;
    let job = before.submit(json!({"steps": 20})).await;
    // A worker claims the job with a lease that expires at once, then dies.
    let claimed = before.queue.claim("dead-worker", Duration::ZERO).await.unwrap();
    assert_eq!(claimed.unwrap().lease.job_id, job);
    assert_eq!(before.status(&job).await["status"], "running");
    let store = before.stop().await;
    clock.advance(Duration::from_millis(1));

    let after = spawn_app_in(store, |config| {
        config.workers = 1;
        config.clock = clock.clone();
    })
    .await;
    let status = after.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    assert_eq!(
        after.queue.get("default", &job).await.unwrap().unwrap().attempt,
        2
    );
    let metrics = after.get("/metrics").await.text().await.unwrap();
    assert!(metrics.contains("chocmodal_jobs_rescued_total 1"), "{metrics}");
}

async fn a_job_whose_worker_keeps_dying_fails_with_a_clear_message(backend: Backend) {
    let clock = Arc::new(ManualClock::starting_now());
    let app = spawn_app_on(backend, |config| {
        config.workers = 0;
        config.max_attempts = 2;
        config.maintenance_interval = NO_MAINTENANCE;
        config.clock = clock.clone();
    })
    .await;
    let job = app.submit(json!({"steps": 20})).await;
    for dead in ["first-dead-worker", "second-dead-worker"] {
        assert!(app.queue.claim(dead, Duration::ZERO).await.unwrap().is_some());
        clock.advance(Duration::from_millis(1));
        app.queue.recover_expired(2).await.unwrap();
    }
    let status = app.status(&job).await;
    assert_eq!(status["status"], "failed", "{status}");
    assert!(
        status["message"]
            .as_str()
            .unwrap()
            .contains("worker was lost 2 times"),
        "{status}"
    );
    let problem = assert_problem(
        app.get(&format!("/jobs/{job}/results")).await,
        StatusCode::INTERNAL_SERVER_ERROR,
        "/job-abandoned",
    )
    .await;
    assert!(problem["detail"].as_str().unwrap().contains("not retried again"));
    assert!(
        app.queue
            .claim("live-worker", Duration::from_secs(30))
            .await
            .unwrap()
            .is_none()
    );
    assert_eq!(app.probe.started(), 0);
}

async fn expired_leases_are_recovered_periodically_once_the_clock_passes_them(backend: Backend) {
    let clock = Arc::new(ManualClock::starting_now());
    let before = spawn_app_on(backend, |config| {
        config.workers = 0;
        config.clock = clock.clone();
    })
    .await;
    let job = before.submit(json!({"steps": 5})).await;
    before
        .queue
        .claim("stalled-worker", Duration::from_secs(30))
        .await
        .unwrap();
    let store = before.stop().await;

    let app = spawn_app_in(store, |config| {
        config.workers = 1;
        config.clock = clock.clone();
    })
    .await;
    // What the periodic pass does at the manual clock's (unchanged) time: nothing.
    let recovered = app.queue.recover_expired(3).await.unwrap();
    assert!(
        recovered.requeued.is_empty() && recovered.failed.is_empty(),
        "the lease still holds: {recovered:?}"
    );
    assert_eq!(
        app.status(&job).await["status"],
        "running",
        "the lease still holds"
    );
    assert_eq!(app.probe.started(), 0);

    clock.advance(Duration::from_secs(31));
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    assert_eq!(app.probe.started(), 1);
}

async fn a_worker_that_lost_its_lease_can_neither_heartbeat_nor_write_results(backend: Backend) {
    let clock = Arc::new(ManualClock::starting_now());
    let app = spawn_app_on(backend, |config| {
        config.workers = 0;
        config.clock = clock.clone();
        config.maintenance_interval = NO_MAINTENANCE;
    })
    .await;
    let job = app.submit(json!({"steps": 5})).await;
    let lease = Duration::from_secs(30);
    let stale = app.queue.claim("stalled", lease).await.unwrap().unwrap().lease;
    clock.advance(Duration::from_secs(31));
    assert_eq!(
        app.queue.recover_expired(3).await.unwrap().requeued,
        vec![job.clone()]
    );
    let fresh = app.queue.claim("healthy", lease).await.unwrap().unwrap().lease;
    assert_eq!(fresh.attempt, 2);

    assert!(!app.queue.heartbeat(&stale, Some(50), lease).await.unwrap());
    assert!(!app.queue.is_held(&stale).await.unwrap());
    let problem = chocmodal::problem::Problem::job_failed("stale");
    assert!(!app.queue.fail(&stale, &problem, None).await.unwrap());
    assert!(
        !app.queue
            .complete(&stale, &json!({"stale": true}), &[])
            .await
            .unwrap()
    );
    assert!(!app.queue.hand_back(&stale).await.unwrap());

    assert!(app.queue.heartbeat(&fresh, Some(50), lease).await.unwrap());
    assert!(
        app.queue
            .complete(&fresh, &json!({"fresh": true}), &[])
            .await
            .unwrap()
    );
    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    assert_eq!(results, json!({"fresh": true}));
}

async fn a_job_survives_a_server_restart(backend: Backend) {
    let before = spawn_app_on(backend, |config| {
        config.workers = 1;
        config.shutdown_grace = Duration::from_millis(200);
    })
    .await;
    let job = before.submit(json!({"steps": 1500, "step_ms": 1})).await;
    before.wait_for(&job, &["running"], Duration::from_secs(5)).await;
    let store = before.stop().await;

    let after = spawn_app_in(store, |config| config.workers = 0).await;
    let record = after.queue.get("default", &job).await.unwrap().unwrap();
    assert_eq!(record.status.as_str(), "accepted", "handed back to the queue");
    assert_eq!(record.attempt, 0, "a hand-back does not count as a lost worker");
    let store = after.stop().await;

    let restarted = spawn_app_in(store, |config| config.workers = 1).await;
    let status = restarted.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    let results = restarted.get_json(&format!("/jobs/{job}/results")).await;
    assert_eq!(results["sum"], 1500 * 1501 / 2);
}

async fn a_graceful_shutdown_lets_a_running_job_finish_within_the_grace_period(backend: Backend) {
    let before = spawn_app_on(backend, |config| {
        config.workers = 1;
        config.shutdown_grace = Duration::from_secs(10);
    })
    .await;
    let job = before.submit(json!({"steps": 300, "step_ms": 1})).await;
    before.wait_for(&job, &["running"], Duration::from_secs(5)).await;
    let store = before.stop().await;

    let after = spawn_app_in(store, |config| config.workers = 0).await;
    assert_eq!(after.status(&job).await["status"], "successful");
}
