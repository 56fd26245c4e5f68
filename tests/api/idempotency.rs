//! `Idempotency-Key` on job, sweep and signal creation, over HTTP on both backends: a
//! retry with the same key and request gets the same resource (same id, `201`, same
//! `Location`) and creates nothing; the same key with another request is a 422 naming
//! the header; keys are per tenant, and a key goes with its resource when it is deleted.
//! Concurrent retries of one key create one resource.

use reqwest::{Response, StatusCode};
use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{Backend, TestApp, assert_problem, on_both_backends, spawn_app_on};

on_both_backends!(
    a_retried_submission_with_the_same_key_creates_one_job,
    concurrent_retries_of_one_key_create_one_job,
    a_retried_sweep_with_the_same_key_creates_one_sweep,
    a_retried_signal_upload_with_the_same_key_stores_one_signal_until_it_is_deleted,
    keys_belong_to_their_tenant
);

const HEADER: &str = "Idempotency-Key";

/// What a creation answered: status, `Location`, whether it was a replay, and the body.
struct Answer {
    status: StatusCode,
    location: Option<String>,
    replayed: bool,
    body: Value,
}

async fn answer(response: Response) -> Answer {
    let status = response.status();
    let header = |name: &str| {
        response
            .headers()
            .get(name)
            .map(|v| v.to_str().unwrap().to_owned())
    };
    let location = header("location");
    let replayed = header("idempotent-replayed").as_deref() == Some("true");
    Answer {
        status,
        location,
        replayed,
        body: response.json().await.unwrap(),
    }
}

async fn execute_with_key(app: &TestApp, key: &str, body: &str, token: Option<&str>) -> Response {
    let mut request = app
        .client
        .post(app.url(&format!("/processes/{}/execution", counting::ID)))
        .header("content-type", "application/json")
        .header(HEADER, key)
        .body(body.to_owned());
    if let Some(token) = token {
        request = request.bearer_auth(token);
    }
    request.send().await.unwrap()
}

async fn job_ids(app: &TestApp) -> Vec<String> {
    let list = app.get_json("/jobs?limit=1000").await;
    list["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|job| job["jobID"].as_str().unwrap().to_owned())
        .collect()
}

async fn a_retried_submission_with_the_same_key_creates_one_job(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let first = answer(
        execute_with_key(
            &app,
            "order-17",
            r#"{"inputs": {"steps": 3, "step_ms": 1}}"#,
            None,
        )
        .await,
    )
    .await;
    assert_eq!(first.status, StatusCode::CREATED, "{}", first.body);
    assert!(!first.replayed);
    let id = first.body["jobID"].as_str().unwrap().to_owned();
    assert_eq!(first.location.as_deref(), Some(format!("/jobs/{id}").as_str()));

    // The same request (members in another order, other spacing) after the first ran.
    app.wait_until_finished(&id).await;
    let retry =
        answer(execute_with_key(&app, "order-17", r#"{"inputs":{"step_ms":1,"steps":3}}"#, None).await).await;
    assert_eq!(retry.status, StatusCode::CREATED, "{}", retry.body);
    assert!(retry.replayed, "a replay says so");
    assert_eq!(retry.body["jobID"], id.as_str(), "{}", retry.body);
    assert_eq!(retry.location, first.location);
    assert_eq!(
        retry.body["status"], "successful",
        "the job as it is now: {}",
        retry.body
    );
    assert_eq!(job_ids(&app).await, vec![id.clone()], "one job, not two");
    assert_eq!(app.probe.started(), 1, "it ran once");

    // The same key with another body: refused, naming the header, nothing queued.
    let other = execute_with_key(&app, "order-17", r#"{"inputs": {"steps": 4}}"#, None).await;
    let problem = assert_problem(other, StatusCode::UNPROCESSABLE_ENTITY, "/idempotency-key-reused").await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(
        detail.contains("Idempotency-Key") && detail.contains("order-17") && detail.contains(&id),
        "{detail}"
    );
    assert_eq!(job_ids(&app).await.len(), 1);

    // Another key: another job.
    let fresh = answer(
        execute_with_key(
            &app,
            "order-18",
            r#"{"inputs": {"steps": 3, "step_ms": 1}}"#,
            None,
        )
        .await,
    )
    .await;
    assert_eq!(fresh.status, StatusCode::CREATED);
    assert_ne!(fresh.body["jobID"], id.as_str());
    assert_eq!(job_ids(&app).await.len(), 2);

    // A malformed key is a 400 naming the header.
    let bad = execute_with_key(&app, "two words", r#"{"inputs": {"steps": 3}}"#, None).await;
    let problem = assert_problem(bad, StatusCode::BAD_REQUEST, "/invalid-header").await;
    assert!(
        problem["detail"].as_str().unwrap().contains("Idempotency-Key"),
        "{problem}"
    );
    assert_eq!(job_ids(&app).await.len(), 2);
}

async fn concurrent_retries_of_one_key_create_one_job(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let body = r#"{"inputs": {"steps": 2}}"#;
    let mut sent = tokio::task::JoinSet::new();
    for _ in 0..6 {
        let request = app
            .client
            .post(app.url(&format!("/processes/{}/execution", counting::ID)))
            .header("content-type", "application/json")
            .header(HEADER, "burst")
            .body(body);
        sent.spawn(async move { request.send().await.unwrap() });
    }
    let mut ids = Vec::new();
    while let Some(response) = sent.join_next().await {
        let answer = answer(response.unwrap()).await;
        assert_eq!(answer.status, StatusCode::CREATED, "{}", answer.body);
        ids.push(answer.body["jobID"].as_str().unwrap().to_owned());
    }
    ids.sort();
    ids.dedup();
    assert_eq!(ids.len(), 1, "every retry got the same job: {ids:?}");
    assert_eq!(job_ids(&app).await, ids);
}

async fn a_retried_sweep_with_the_same_key_creates_one_sweep(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let body = json!({"process": counting::ID, "inputs": {"steps": 1},
        "axes": [{"pointer": "/steps", "values": [1, 2, 3]}]});
    let post = |body: Value| {
        app.client
            .post(app.url("/sweeps"))
            .header("content-type", "application/json")
            .header(HEADER, "sweep-1")
            .body(body.to_string())
            .send()
    };
    let first = answer(post(body.clone()).await.unwrap()).await;
    assert_eq!(first.status, StatusCode::CREATED, "{}", first.body);
    let id = first.body["sweepID"].as_str().unwrap().to_owned();
    let retry = answer(post(body.clone()).await.unwrap()).await;
    assert_eq!(retry.status, StatusCode::CREATED, "{}", retry.body);
    assert!(retry.replayed);
    assert_eq!(retry.body["sweepID"], id.as_str());
    assert_eq!(retry.location, first.location);
    let sweeps = app.get_json("/sweeps").await;
    assert_eq!(sweeps["sweeps"].as_array().unwrap().len(), 1, "{sweeps}");
    assert_eq!(job_ids(&app).await.len(), 3, "three runs, not six");

    let mut other = body;
    other["axes"][0]["values"] = json!([1, 2]);
    let refused = post(other).await.unwrap();
    assert_problem(
        refused,
        StatusCode::UNPROCESSABLE_ENTITY,
        "/idempotency-key-reused",
    )
    .await;
    // A job submission may not reuse a sweep's key either.
    let crossed = execute_with_key(&app, "sweep-1", r#"{"inputs": {"steps": 1}}"#, None).await;
    let problem = assert_problem(
        crossed,
        StatusCode::UNPROCESSABLE_ENTITY,
        "/idempotency-key-reused",
    )
    .await;
    assert!(problem["detail"].as_str().unwrap().contains("sweep"), "{problem}");
    assert_eq!(job_ids(&app).await.len(), 3);
}

async fn a_retried_signal_upload_with_the_same_key_stores_one_signal_until_it_is_deleted(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let upload = |csv: &'static str| {
        app.client
            .post(app.url("/signals"))
            .header("content-type", "text/csv")
            .header(HEADER, "record-A")
            .body(csv)
            .send()
    };
    let csv = "time,acceleration\n0,0\n0.01,1.5\n0.02,-0.5\n";
    let first = answer(upload(csv).await.unwrap()).await;
    assert_eq!(first.status, StatusCode::CREATED, "{}", first.body);
    let id = first.body["id"].as_str().unwrap().to_owned();
    let retry = answer(upload(csv).await.unwrap()).await;
    assert_eq!(retry.status, StatusCode::CREATED, "{}", retry.body);
    assert!(retry.replayed);
    assert_eq!(retry.body["id"], id.as_str());
    assert_eq!(retry.location, Some(format!("/signals/{id}")));
    let list = app.get_json("/signals").await;
    assert_eq!(list["signals"].as_array().unwrap().len(), 1, "{list}");

    let other = upload("time,acceleration\n0,0\n0.01,2.5\n").await.unwrap();
    assert_problem(other, StatusCode::UNPROCESSABLE_ENTITY, "/idempotency-key-reused").await;

    // The key lives as long as its signal: once deleted, the key is free again.
    assert_eq!(
        app.delete(&format!("/signals/{id}")).await.status(),
        StatusCode::NO_CONTENT
    );
    let again = answer(upload(csv).await.unwrap()).await;
    assert_eq!(again.status, StatusCode::CREATED, "{}", again.body);
    assert!(!again.replayed);
    assert_ne!(again.body["id"], id.as_str(), "a new signal");
}

async fn keys_belong_to_their_tenant(backend: Backend) {
    const ALPHA: &str = "alpha-token-0123456789";
    const BETA: &str = "beta-token-9876543210";
    let tokens =
        chocmodal::service::auth::TokenTable::parse(&format!("alpha {ALPHA}\nbeta {BETA}\n")).unwrap();
    let app = spawn_app_on(backend, |config| config.auth = Some(tokens)).await;
    let body = r#"{"inputs": {"steps": 1}}"#;
    let alpha = answer(execute_with_key(&app, "shared-key", body, Some(ALPHA)).await).await;
    let beta = answer(execute_with_key(&app, "shared-key", body, Some(BETA)).await).await;
    assert_eq!(
        (alpha.status, beta.status),
        (StatusCode::CREATED, StatusCode::CREATED)
    );
    assert!(!beta.replayed, "another tenant's key is another key");
    assert_ne!(alpha.body["jobID"], beta.body["jobID"]);
    // And a tenant's other body under the same key is refused for that tenant only.
    let refused = execute_with_key(&app, "shared-key", r#"{"inputs": {"steps": 2}}"#, Some(BETA)).await;
    assert_problem(
        refused,
        StatusCode::UNPROCESSABLE_ENTITY,
        "/idempotency-key-reused",
    )
    .await;
}
