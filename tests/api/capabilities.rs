//! Landing page, conformance, processes, health, metrics and the OpenAPI document.

use std::path::PathBuf;

use reqwest::StatusCode;
use serde_json::json;

use crate::helpers::{assert_problem, spawn_app};

#[tokio::test]
async fn the_landing_page_links_to_processes_jobs_and_the_api_definition() {
    let app = spawn_app().await;
    let page = app.get_json("/").await;
    let hrefs: Vec<&str> = page["links"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["href"].as_str().unwrap())
        .collect();
    for href in ["/processes", "/jobs", "/sweeps", "/conformance", "/openapi.json"] {
        assert!(hrefs.contains(&href), "{href} missing from {hrefs:?}");
    }
}

#[tokio::test]
async fn the_landing_page_is_html_for_a_browser() {
    let app = spawn_app().await;
    let response = app
        .client
        .get(app.url("/"))
        .header("accept", "text/html,application/xhtml+xml,*/*;q=0.8")
        .send()
        .await
        .unwrap();
    assert!(
        response.headers()["content-type"]
            .to_str()
            .unwrap()
            .starts_with("text/html")
    );
    assert!(response.text().await.unwrap().contains("<a href=\"/processes\">"));
}

#[tokio::test]
async fn conformance_claims_core_job_list_and_dismiss() {
    let app = spawn_app().await;
    let conformance = app.get_json("/conformance").await;
    let classes = conformance["conformsTo"].as_array().unwrap();
    for class in [
        "conf/core",
        "conf/job-list",
        "conf/dismiss",
        "conf/ogc-process-description",
    ] {
        assert!(
            classes.iter().any(|c| c.as_str().unwrap().ends_with(class)),
            "{class} missing"
        );
    }
    // The API definition is OpenAPI 3.1: the 3.0 class is not claimed.
    assert!(
        !classes
            .iter()
            .any(|c| c.as_str().unwrap().ends_with("conf/oas30")),
        "{classes:?}"
    );
}

#[tokio::test]
async fn the_process_list_shows_every_registered_process() {
    let app = spawn_app().await;
    let list = app.get_json("/processes").await;
    let process = &list["processes"][0];
    assert_eq!(process["id"], "count-steps");
    assert_eq!(process["title"], "Count steps");
    assert_eq!(process["jobControlOptions"], json!(["async-execute", "dismiss"]));
    assert_eq!(process["links"][0]["href"], "/processes/count-steps");
}

#[tokio::test]
async fn a_process_description_includes_its_inputs_and_outputs() {
    let app = spawn_app().await;
    let description = app.get_json("/processes/count-steps").await;
    assert_eq!(description["id"], "count-steps");
    assert_eq!(description["inputs"]["steps"]["schema"]["type"], "integer");
    assert!(description["outputs"]["signal"].is_object());
}

#[tokio::test]
async fn an_unknown_process_is_a_404_problem() {
    let app = spawn_app().await;
    assert_problem(
        app.get("/processes/nope").await,
        StatusCode::NOT_FOUND,
        "/no-such-process",
    )
    .await;
}

#[tokio::test]
async fn the_health_check_answers_ok_and_the_readiness_check_ready() {
    let app = spawn_app().await;
    assert_eq!(
        app.get_json("/healthz").await,
        json!({"status": "ok", "writable": true})
    );
    assert_eq!(app.get_json("/readyz").await, json!({"status": "ready"}));
}

#[tokio::test]
async fn metrics_count_jobs_by_status_and_requests_by_route() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&job).await;
    app.get(&format!("/jobs/{job}")).await;
    let response = app.get("/metrics").await;
    assert_eq!(response.status(), StatusCode::OK);
    assert!(
        response.headers()["content-type"]
            .to_str()
            .unwrap()
            .starts_with("text/plain")
    );
    let text = response.text().await.unwrap();
    for line in [
        "chocmodal_jobs{status=\"successful\"} 1",
        "chocmodal_jobs{status=\"accepted\"} 0",
        "chocmodal_job_duration_seconds_count{outcome=\"successful\",process=\"count-steps\"} 1",
        "chocmodal_job_queue_wait_seconds_count{process=\"count-steps\"} 1",
        "chocmodal_jobs_rescued_total 0",
        "chocmodal_http_requests_total{method=\"GET\",route=\"/jobs/{jobId}\",status=\"200\"}",
        "chocmodal_http_requests_total{method=\"POST\",route=\"/processes/{processId}/execution\",status=\"201\"} 1",
    ] {
        assert!(text.contains(line), "`{line}` missing from\n{text}");
    }
}

#[tokio::test]
async fn the_openapi_document_is_served() {
    let app = spawn_app().await;
    let document = app.get_json("/openapi.json").await;
    assert!(document["paths"]["/processes/{processId}/execution"]["post"].is_object());
}

/// The committed `openapi/openapi.json` is what the code generates. After changing the
/// API, regenerate it with `UPDATE_OPENAPI=1 cargo test --test api openapi` and commit it.
#[test]
fn the_committed_openapi_document_matches_the_code() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("openapi/openapi.json");
    let generated = chocmodal::service::http::openapi::json();
    if std::env::var_os("UPDATE_OPENAPI").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "openapi/openapi.json is out of date: regenerate it with \
         `UPDATE_OPENAPI=1 cargo test --test api openapi` and commit it"
    );
}

#[test]
fn the_openapi_document_describes_every_route_and_problem_schema() {
    let document: serde_json::Value =
        serde_json::from_str(&chocmodal::service::http::openapi::json()).unwrap();
    let paths = document["paths"].as_object().unwrap();
    for route in [
        "/",
        "/conformance",
        "/openapi.json",
        "/healthz",
        "/readyz",
        "/metrics",
        "/processes",
        "/processes/{processId}",
        "/processes/{processId}/execution",
        "/jobs",
        "/jobs/{jobId}",
        "/jobs/{jobId}/results",
        "/jobs/{jobId}/results/{output}",
    ] {
        assert!(
            paths.contains_key(route),
            "{route} is missing from the OpenAPI document"
        );
    }
    assert!(document["paths"]["/jobs/{jobId}"]["delete"].is_object());
    for schema in [
        "Problem",
        "FieldError",
        "StatusInfo",
        "JobList",
        "HistoryDocument",
    ] {
        assert!(
            document["components"]["schemas"][schema].is_object(),
            "schema {schema} missing"
        );
    }
}

/// Jobs computed to success are counted by their quality verdict: the verdict their
/// results carry.
#[tokio::test]
async fn metrics_count_computed_jobs_by_their_verdict() {
    let app = crate::helpers::spawn_app_with_processes(
        vec![std::sync::Arc::new(
            chocmodal::processes::cantilever_impact::CantileverImpact,
        )],
        |_| {},
    )
    .await;
    let response = app
        .post_execution(
            "cantilever-impact",
            &json!({"inputs": {"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.01, "inner_diameter": 0.009},
                "elements": 10, "modes": 3}, "solver": {"duration": 0.02}}}),
        )
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let job = response.json::<serde_json::Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    let verdict = results["quality"]["verdict"].as_str().expect("a verdict");
    let text = app.get("/metrics").await.text().await.unwrap();
    let line =
        format!("chocmodal_job_verdicts_total{{process=\"cantilever-impact\",verdict=\"{verdict}\"}} 1");
    assert!(text.contains(&line), "`{line}` missing from\n{text}");
}
