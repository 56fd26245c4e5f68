//! The SQLite settings really apply, and retention deletes old finished jobs (both backends).

use std::sync::Arc;
use std::time::{Duration, Instant};

use chocmodal::service::clock::ManualClock;
use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::{Backend, assert_problem, on_both_backends, spawn_app, spawn_app_on};

#[tokio::test]
async fn every_connection_uses_wal_a_busy_timeout_and_foreign_keys() {
    let app = spawn_app().await;
    let sqlite = app.queue.database().as_sqlite().unwrap();
    // Hold several connections at once so that the pool has to open more than one.
    let mut connections = Vec::new();
    for _ in 0..3 {
        connections.push(sqlite.acquire().await.unwrap());
    }
    for connection in &mut connections {
        let journal_mode: String = sqlx::query_scalar("PRAGMA journal_mode")
            .fetch_one(&mut **connection)
            .await
            .unwrap();
        let busy_timeout: i64 = sqlx::query_scalar("PRAGMA busy_timeout")
            .fetch_one(&mut **connection)
            .await
            .unwrap();
        let foreign_keys: i64 = sqlx::query_scalar("PRAGMA foreign_keys")
            .fetch_one(&mut **connection)
            .await
            .unwrap();
        let synchronous: i64 = sqlx::query_scalar("PRAGMA synchronous")
            .fetch_one(&mut **connection)
            .await
            .unwrap();
        assert_eq!(journal_mode, "wal");
        assert_eq!(busy_timeout, 10_000);
        assert_eq!(foreign_keys, 1);
        assert_eq!(synchronous, 1, "NORMAL");
    }
}

on_both_backends!(retention_deletes_finished_jobs_and_their_histories);

async fn retention_deletes_finished_jobs_and_their_histories(backend: Backend) {
    let clock = Arc::new(ManualClock::starting_now());
    let app = spawn_app_on(backend, |config| {
        config.clock = clock.clone();
        config.retention = Some(Duration::from_secs(30 * 86_400));
    })
    .await;
    let old = app.submit(json!({"steps": 10})).await;
    app.wait_until_finished(&old).await;
    assert!(
        app.queue
            .history("default", &old, "signal")
            .await
            .unwrap()
            .is_some()
    );
    clock.advance(Duration::from_secs(20 * 86_400));
    let recent = app.submit(json!({"steps": 10})).await;
    app.wait_until_finished(&recent).await;
    clock.advance(Duration::from_secs(11 * 86_400));
    // The next maintenance pass (every 100 ms) finds the old job past retention; once it
    // is gone, that pass has also judged the recent one.
    let deadline = Instant::now() + Duration::from_secs(10);
    while app.get(&format!("/jobs/{old}")).await.status() != StatusCode::NOT_FOUND {
        assert!(
            Instant::now() < deadline,
            "retention never deleted the 31-day-old job"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }

    assert_problem(
        app.get(&format!("/jobs/{old}")).await,
        StatusCode::NOT_FOUND,
        "/no-such-job",
    )
    .await;
    assert!(
        app.queue
            .history("default", &old, "signal")
            .await
            .unwrap()
            .is_none(),
        "histories go with their job"
    );
    assert_eq!(app.status(&recent).await["status"], "successful");
}
