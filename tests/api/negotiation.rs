//! Content negotiation: a browser asking for `/`, `/jobs`, `/jobs/{id}`, `/sweeps` or
//! `/sweeps/{id}` gets the dashboard's HTML page (with the resource's status), while
//! JSON clients (`application/json`, `*/*`, or no `Accept`) get the same JSON bytes as
//! ever; `?f=json` and `?f=html` override `Accept`. The dashboard's assets are embedded.

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::Registry;

use crate::helpers::{TestApp, spawn_app, spawn_app_with_processes};

const BROWSER: &str = "text/html,application/xhtml+xml,application/xml;q=0.9,image/avif,image/webp,*/*;q=0.8";

async fn fetch(app: &TestApp, path: &str, accept: Option<&str>) -> (StatusCode, String, String, Vec<u8>) {
    let mut request = app.client.get(app.url(path));
    if let Some(accept) = accept {
        request = request.header("accept", accept);
    }
    let response = request.send().await.unwrap();
    let header = |name: &str| {
        response
            .headers()
            .get(name)
            .map(|v| v.to_str().unwrap().to_owned())
            .unwrap_or_default()
    };
    let (content_type, vary) = (header("content-type"), header("vary"));
    (
        response.status(),
        content_type,
        vary,
        response.bytes().await.unwrap().to_vec(),
    )
}

/// The paths with a page, for a service holding one finished job and one sweep.
async fn paths_with_pages(app: &TestApp) -> Vec<String> {
    let job = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&job).await;
    let sweep = app
        .create_sweep(json!({"process": "count-steps", "inputs": {"steps": 2},
                             "axes": [{"pointer": "/steps", "values": [1, 2]}]}))
        .await;
    // Everything ended, so that every representation stays the same between requests.
    app.wait_for_sweep(&sweep, &["successful"], std::time::Duration::from_secs(20))
        .await;
    vec![
        "/".into(),
        "/jobs".into(),
        format!("/jobs/{job}"),
        "/sweeps".into(),
        format!("/sweeps/{sweep}"),
    ]
}

#[tokio::test]
async fn json_clients_get_the_same_json_whatever_they_accept() {
    let app = spawn_app().await;
    for path in paths_with_pages(&app).await {
        let (status, content_type, vary, plain) = fetch(&app, &path, None).await;
        assert_eq!(status, StatusCode::OK, "{path}");
        assert!(
            content_type.starts_with("application/json"),
            "{path}: {content_type}"
        );
        assert_eq!(vary, "accept", "{path}");
        serde_json::from_slice::<Value>(&plain).unwrap_or_else(|e| panic!("{path}: {e}"));
        for accept in ["application/json", "*/*", "application/json, text/html;q=0.9"] {
            let (status, content_type, _, body) = fetch(&app, &path, Some(accept)).await;
            assert_eq!(status, StatusCode::OK, "{path} with {accept}");
            assert!(
                content_type.starts_with("application/json"),
                "{path} with {accept}"
            );
            // Job lists carry times that do not change once the job ended: same bytes.
            assert_eq!(body, plain, "{path} with Accept: {accept}");
        }
        let (_, content_type, _, body) = fetch(&app, &format!("{path}?f=json"), Some(BROWSER)).await;
        assert!(content_type.starts_with("application/json"), "{path}?f=json");
        assert_eq!(body, plain, "{path}?f=json");
    }
}

#[tokio::test]
async fn browsers_get_the_dashboard_page_of_each_resource() {
    let app = spawn_app().await;
    for (path, page) in paths_with_pages(&app)
        .await
        .into_iter()
        .zip(["home", "jobs", "job", "sweeps", "sweep"])
    {
        for (accept, query) in [(Some(BROWSER), ""), (None, "?f=html")] {
            let (status, content_type, vary, body) = fetch(&app, &format!("{path}{query}"), accept).await;
            let body = String::from_utf8(body).unwrap();
            assert_eq!(status, StatusCode::OK, "{path}{query}");
            assert_eq!(content_type, "text/html; charset=utf-8", "{path}{query}");
            assert_eq!(vary, "accept");
            assert!(body.starts_with("<!doctype html>"), "{path}: {body}");
            assert!(body.contains(&format!("data-page=\"{page}\"")), "{path}: {body}");
            assert!(body.contains("/ui/assets/app.js"), "{path}");
        }
    }
}

#[tokio::test]
async fn the_page_of_a_missing_job_or_a_bad_query_has_the_status_of_the_json_answer() {
    let app = spawn_app().await;
    for (path, expected) in [
        ("/jobs/no-such-job", StatusCode::NOT_FOUND),
        ("/sweeps/no-such-sweep", StatusCode::NOT_FOUND),
        ("/jobs?status=done", StatusCode::BAD_REQUEST),
    ] {
        let (status, content_type, _, _) = fetch(&app, path, Some(BROWSER)).await;
        assert_eq!(status, expected, "{path}");
        assert!(content_type.starts_with("text/html"), "{path}: {content_type}");
        let (status, content_type, _, _) = fetch(&app, path, None).await;
        assert_eq!(status, expected, "{path}");
        assert_eq!(content_type, "application/problem+json", "{path}");
    }
    // Routes without a page answer JSON even to a browser.
    let (_, content_type, _, _) = fetch(&app, "/processes", Some(BROWSER)).await;
    assert!(content_type.starts_with("application/json"), "{content_type}");
}

#[tokio::test]
async fn the_dashboard_assets_and_examples_are_served_from_the_binary() {
    let app = spawn_app_with_processes(Registry::builtin().all().to_vec(), |_| {}).await;
    for (path, content_type) in [
        ("/ui/assets/app.js", "text/javascript; charset=utf-8"),
        ("/ui/assets/plot.js", "text/javascript; charset=utf-8"),
        ("/ui/assets/style.css", "text/css; charset=utf-8"),
        ("/ui/submit", "text/html; charset=utf-8"),
    ] {
        let (status, served, _, body) = fetch(&app, path, None).await;
        assert_eq!(status, StatusCode::OK, "{path}");
        assert_eq!(served, content_type, "{path}");
        assert!(!body.is_empty(), "{path}");
    }
    let examples = app.get_json("/ui/examples.json").await;
    let files: Vec<&str> = examples
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["file"].as_str().unwrap())
        .collect();
    assert!(files.contains(&"cantilever-impact.json") && files.contains(&"sweep-calibration.json"));
    // A server offers the examples of its own processes only.
    let without = spawn_app().await.get_json("/ui/examples.json").await;
    assert_eq!(without, json!([]), "the test processes have no example");
    let (status, content_type, _, _) = fetch(&app, "/ui/assets/missing.js", None).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert_eq!(content_type, "application/problem+json");
}
