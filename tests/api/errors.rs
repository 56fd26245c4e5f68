//! Every error is an RFC 9457 problem document with the right status.

use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::{assert_problem, spawn_app, spawn_app_with};

#[tokio::test]
async fn invalid_inputs_are_a_422_with_a_pointer_per_field_and_never_reach_a_worker() {
    let app = spawn_app().await;
    let response = app
        .post_execution(
            "count-steps",
            &json!({"inputs": {"steps": 0, "step_ms": -1, "stpes": 3}}),
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let pointers: Vec<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["pointer"].as_str().unwrap())
        .collect();
    for pointer in ["/inputs/steps", "/inputs/step_ms", "/inputs/stpes"] {
        assert!(pointers.contains(&pointer), "{pointer} missing from {problem}");
    }
    assert!(problem["errors"][0]["detail"].is_string());
    let jobs = app.get_json("/jobs").await;
    assert_eq!(jobs["jobs"].as_array().unwrap().len(), 0, "no job is created");
    assert_eq!(app.probe.started(), 0);
}

#[tokio::test]
async fn a_body_without_inputs_is_a_422_pointing_at_inputs() {
    let app = spawn_app().await;
    let response = app.post_execution("count-steps", &json!({"input": {}})).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/input");
}

#[tokio::test]
async fn malformed_json_is_a_400_problem() {
    let app = spawn_app().await;
    let response = app
        .post_execution_raw("count-steps", "{\"inputs\": {\"steps\": 3,}")
        .await;
    assert_problem(response, StatusCode::BAD_REQUEST, "/malformed-body").await;
}

#[tokio::test]
async fn a_body_that_is_not_declared_as_json_is_a_415_problem() {
    let app = spawn_app().await;
    let response = app
        .client
        .post(app.url("/processes/count-steps/execution"))
        .header("content-type", "text/plain")
        .body("{\"inputs\": {\"steps\": 3}}")
        .send()
        .await
        .unwrap();
    assert_problem(
        response,
        StatusCode::UNSUPPORTED_MEDIA_TYPE,
        "/unsupported-media-type",
    )
    .await;
}

#[tokio::test]
async fn a_body_over_the_limit_is_a_413_problem() {
    let app = spawn_app_with(|config| config.max_body_bytes = 1024).await;
    let padding = "x".repeat(4096);
    let response = app
        .post_execution(
            "count-steps",
            &json!({"inputs": {"steps": 3, "padding": padding}}),
        )
        .await;
    assert_problem(response, StatusCode::PAYLOAD_TOO_LARGE, "/payload-too-large").await;
}

#[tokio::test]
async fn executing_an_unknown_process_is_a_404_problem_even_with_a_bad_body() {
    let app = spawn_app().await;
    let response = app.post_execution_raw("no-such", "not json").await;
    assert_problem(response, StatusCode::NOT_FOUND, "/no-such-process").await;
}

#[tokio::test]
async fn an_unknown_job_is_a_404_problem_everywhere() {
    let app = spawn_app().await;
    for path in ["/jobs/nope", "/jobs/nope/results", "/jobs/nope/results/signal"] {
        assert_problem(app.get(path).await, StatusCode::NOT_FOUND, "/no-such-job").await;
    }
    assert_problem(
        app.delete("/jobs/nope").await,
        StatusCode::NOT_FOUND,
        "/no-such-job",
    )
    .await;
}

#[tokio::test]
async fn an_unknown_route_is_a_404_problem() {
    let app = spawn_app().await;
    assert_problem(app.get("/nowhere").await, StatusCode::NOT_FOUND, "/not-found").await;
}

#[tokio::test]
async fn a_wrong_method_is_a_405_problem_that_says_what_is_allowed() {
    let app = spawn_app().await;
    let response = app.client.put(app.url("/jobs")).send().await.unwrap();
    let allow = response.headers()["allow"].to_str().unwrap().to_owned();
    assert!(allow.contains("GET"), "Allow: {allow}");
    assert_problem(response, StatusCode::METHOD_NOT_ALLOWED, "/method-not-allowed").await;
}

#[tokio::test]
async fn bad_query_parameters_are_400_problems() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&job).await;
    for path in [
        "/jobs?limit=0".to_owned(),
        "/jobs?status=done".to_owned(),
        "/jobs?colour=blue".to_owned(),
        format!("/jobs/{job}/results/signal?max_points=1"),
        format!("/jobs/{job}/results/signal?format=xml"),
        format!("/jobs/{job}/results/signal?t_start=soon"),
        format!("/jobs/{job}/results/signal?colour=blue"),
    ] {
        assert_problem(app.get(&path).await, StatusCode::BAD_REQUEST, "/invalid-query").await;
    }
}

#[tokio::test]
async fn a_server_fault_is_a_500_problem_that_reveals_no_internals() {
    let app = spawn_app().await;
    // Make every database access fail.
    app.queue.database().close().await;
    let problem = assert_problem(
        app.get("/jobs").await,
        StatusCode::INTERNAL_SERVER_ERROR,
        "/internal",
    )
    .await;
    let detail = problem["detail"].as_str().unwrap().to_lowercase();
    assert!(
        !detail.contains("pool") && !detail.contains("sqlite"),
        "{problem}"
    );
    let health = app.get("/healthz").await;
    assert_eq!(health.status(), StatusCode::SERVICE_UNAVAILABLE);
}
