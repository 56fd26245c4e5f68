//! `GET /jobs`: newest first, filters, keyset paging through `next` links.

use std::collections::HashSet;

use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{Backend, TestApp, on_both_backends, spawn_app_on};

on_both_backends!(
    jobs_are_listed_newest_first,
    jobs_can_be_filtered_by_status_and_process,
    paging_follows_next_links_through_every_job_once_even_while_jobs_arrive,
    next_links_keep_the_filters,
    sweep_runs_can_be_left_out_or_listed_alone
);

fn ids(page: &Value) -> Vec<String> {
    page["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["jobID"].as_str().unwrap().to_owned())
        .collect()
}

fn next_link(page: &Value) -> Option<String> {
    page["links"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["rel"] == "next")
        .map(|l| l["href"].as_str().unwrap().to_owned())
}

async fn queue_only(backend: Backend) -> TestApp {
    spawn_app_on(backend, |config| config.workers = 0).await
}

async fn jobs_are_listed_newest_first(backend: Backend) {
    let app = queue_only(backend).await;
    let mut submitted = Vec::new();
    for _ in 0..4 {
        submitted.push(app.submit(json!({"steps": 1})).await);
    }
    submitted.reverse();
    assert_eq!(ids(&app.get_json("/jobs").await), submitted);
}

async fn jobs_can_be_filtered_by_status_and_process(backend: Backend) {
    let app = queue_only(backend).await;
    let first = app.submit(json!({"steps": 1})).await;
    let second = app.submit(json!({"steps": 1})).await;
    app.delete(&format!("/jobs/{first}")).await;
    assert_eq!(
        ids(&app.get_json("/jobs?status=dismissed").await),
        vec![first.clone()]
    );
    assert_eq!(
        ids(&app.get_json("/jobs?status=accepted").await),
        vec![second.clone()]
    );
    assert_eq!(
        ids(&app.get_json("/jobs?status=accepted,dismissed").await),
        vec![second.clone(), first.clone()]
    );
    assert_eq!(
        ids(&app.get_json("/jobs?status=accepted&status=dismissed").await).len(),
        2
    );
    assert_eq!(ids(&app.get_json("/jobs?processID=count-steps").await).len(), 2);
    assert!(ids(&app.get_json("/jobs?processID=other").await).is_empty());
    assert!(ids(&app.get_json("/jobs?status=running").await).is_empty());
}

async fn paging_follows_next_links_through_every_job_once_even_while_jobs_arrive(backend: Backend) {
    let app = queue_only(backend).await;
    let mut submitted = Vec::new();
    for _ in 0..7 {
        submitted.push(app.submit(json!({"steps": 1})).await);
    }
    submitted.reverse();
    let mut seen = Vec::new();
    let mut page = app.get_json("/jobs?limit=3").await;
    let mut pages = 1;
    loop {
        let page_ids = ids(&page);
        assert!(page_ids.len() <= 3);
        seen.extend(page_ids);
        // A job submitted while paging must neither shift nor repeat older pages.
        app.submit(json!({"steps": 1})).await;
        match next_link(&page) {
            Some(next) => {
                assert!(next.contains("limit=3"), "{next}");
                page = app.get_json(&next).await;
                pages += 1;
            }
            None => break,
        }
    }
    assert_eq!(pages, 3);
    assert_eq!(seen, submitted);
    assert_eq!(seen.iter().collect::<HashSet<_>>().len(), 7);
}

async fn next_links_keep_the_filters(backend: Backend) {
    let app = queue_only(backend).await;
    let mut dismissed = Vec::new();
    for i in 0..5 {
        let job = app.submit(json!({"steps": 1})).await;
        if i % 2 == 0 {
            app.delete(&format!("/jobs/{job}")).await;
            dismissed.push(job);
        }
    }
    dismissed.reverse();
    let page = app.get_json("/jobs?status=dismissed&limit=2").await;
    let next = next_link(&page).expect("a second page");
    assert!(next.contains("status=dismissed"));
    let mut seen = ids(&page);
    let second = app.get_json(&next).await;
    seen.extend(ids(&second));
    assert!(next_link(&second).is_none());
    assert_eq!(seen, dismissed);
}

/// `inSweep=false` hides the runs of sweeps (what a person looking for their own jobs
/// wants), `inSweep=true` shows them alone; the `next` link keeps the filter.
async fn sweep_runs_can_be_left_out_or_listed_alone(backend: Backend) {
    let app = queue_only(backend).await;
    let before = app.submit(json!({"steps": 1})).await;
    let sweep = app
        .create_sweep(json!({"process": counting::ID, "inputs": {"steps": 1},
                             "axes": [{"pointer": "/steps", "values": [1, 2, 3]}]}))
        .await;
    let after = app.submit(json!({"steps": 1})).await;
    assert_eq!(ids(&app.get_json("/jobs").await).len(), 5);
    assert_eq!(
        ids(&app.get_json("/jobs?inSweep=false").await),
        vec![after.clone(), before.clone()]
    );
    let runs = app.get_json("/jobs?inSweep=true").await;
    assert_eq!(ids(&runs).len(), 3);
    assert!(
        runs["jobs"]
            .as_array()
            .unwrap()
            .iter()
            .all(|j| j["sweepID"] == sweep.as_str()),
        "{runs}"
    );
    let page = app.get_json("/jobs?inSweep=false&limit=1").await;
    assert_eq!(ids(&page), vec![after]);
    let next = next_link(&page).expect("a second page");
    assert!(next.contains("inSweep=false"), "{next}");
    assert_eq!(ids(&app.get_json(&next).await), vec![before]);
    let refused = app.get("/jobs?inSweep=maybe").await;
    assert_eq!(refused.status(), reqwest::StatusCode::BAD_REQUEST);
}
