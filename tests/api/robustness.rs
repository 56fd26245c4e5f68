//! Malformed and hostile requests: unknown members refused at their pointer (inputs of
//! both processes, execution envelope, sweep bodies), numbers no double can hold,
//! nesting beyond the depth limit, slow clients, and the refusal to serve a
//! non-loopback address without tokens.

use std::sync::Arc;
use std::time::{Duration, Instant};

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::cantilever_impact::CantileverImpact;
use chocmodal::processes::{Process, Registry};
use chocmodal::service::auth::TokenTable;
use chocmodal::service::{Application, StartupError};
use reqwest::StatusCode;
use serde_json::{Value, json};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

use crate::helpers::{TestApp, assert_problem, spawn_app_with, spawn_app_with_processes, test_config};

fn example(name: &str) -> Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

async fn spawn_validating() -> TestApp {
    let processes: Vec<Arc<dyn Process>> = vec![Arc::new(CantileverImpact), Arc::new(BundleDynamics)];
    spawn_app_with_processes(processes, |config| config.workers = 0).await
}

/// The one error of a 422 problem.
async fn single_error(response: reqwest::Response, type_suffix: &str) -> (String, String) {
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, type_suffix).await;
    let errors = problem["errors"].as_array().unwrap();
    assert_eq!(errors.len(), 1, "{problem}");
    (
        errors[0]["pointer"].as_str().unwrap().to_owned(),
        errors[0]["detail"].as_str().unwrap().to_owned(),
    )
}

#[tokio::test]
async fn unknown_members_are_refused_at_their_pointer() {
    let app = spawn_validating().await;
    let cases = [
        ("cantilever-impact.json", "/inputs/beam/section", "inner_diamter"),
        ("cantilever-impact.json", "/inputs/solver", "timestep"),
        ("cantilever-impact.json", "", "input"),
        ("bundle-random-gaps.json", "/inputs/bundle/levels", "spacng"),
        (
            "bundle-random-gaps.json",
            "/inputs/bundle/gaps/distribution",
            "sigma",
        ),
        (
            "bundle-row17.json",
            "/inputs/excitation/base_acceleration",
            "amplitud",
        ),
    ];
    for (name, object, typo) in cases {
        let mut body = example(name);
        body.pointer_mut(object)
            .and_then(Value::as_object_mut)
            .unwrap_or_else(|| panic!("{name} has no object at {object}"))
            .insert(typo.into(), json!(1));
        let process = if name.starts_with("bundle") {
            "bundle-dynamics"
        } else {
            "cantilever-impact"
        };
        let (pointer, detail) =
            single_error(app.post_execution(process, &body).await, "/invalid-inputs").await;
        assert_eq!(pointer, format!("{object}/{typo}"), "{detail}");
        assert!(detail.contains("unknown"), "{detail}");
    }

    let mut sweep = example("sweep-gaps.json");
    sweep["axes"][0]["strides"] = json!(3);
    let (pointer, _) = single_error(app.post_sweep(&sweep).await, "/invalid-inputs").await;
    assert_eq!(pointer, "/axes/0/strides");
    let mut sweep = example("sweep-gaps.json");
    sweep["polcy"] = json!("continue");
    let (pointer, _) = single_error(app.post_sweep(&sweep).await, "/invalid-inputs").await;
    assert_eq!(pointer, "/polcy");
}

#[tokio::test]
async fn numbers_no_double_can_hold_are_refused_at_their_pointer() {
    let app = spawn_validating().await;
    let body = r#"{"inputs": {"beam": {"length": 1e400, "young_modulus": 2.1e11, "density": 7800.0,
        "section": {"type": "explicit", "area": 1e-5, "inertia": 1e-10}}}}"#;
    let (pointer, detail) = single_error(
        app.post_execution_raw("cantilever-impact", body).await,
        "/invalid-inputs",
    )
    .await;
    assert_eq!(pointer, "/inputs/beam/length");
    assert!(detail.contains("finite"), "{detail}");

    let sweep = r#"{"process": "cantilever-impact", "inputs": {},
        "axes": [{"pointer": "/contact/rk", "values": [1, -2e308, 1e-999]}]}"#;
    let response = app
        .client
        .post(app.url("/sweeps"))
        .header("content-type", "application/json")
        .body(sweep)
        .send()
        .await
        .unwrap();
    let (pointer, _) = single_error(response, "/invalid-inputs").await;
    assert_eq!(pointer, "/axes/0/values/1");

    // JSON has no NaN nor Infinity: not JSON at all.
    for text in ["NaN", "Infinity", "-Infinity"] {
        let body = format!(r#"{{"inputs": {{"steps": {text}}}}}"#);
        assert_problem(
            app.post_execution_raw("cantilever-impact", body).await,
            StatusCode::BAD_REQUEST,
            "/malformed-body",
        )
        .await;
    }
}

#[tokio::test]
async fn nesting_deeper_than_the_limit_is_a_400() {
    let app = spawn_validating().await;
    let deep = format!(
        r#"{{"inputs": {{"beam": {}1{}}}}}"#,
        "[".repeat(200),
        "]".repeat(200)
    );
    let problem = assert_problem(
        app.post_execution_raw("cantilever-impact", deep).await,
        StatusCode::BAD_REQUEST,
        "/malformed-body",
    )
    .await;
    assert!(problem["detail"].as_str().unwrap().contains("128"), "{problem}");
    // Within the limit, the nesting is simply a wrong type at its pointer.
    let shallow = format!(
        r#"{{"inputs": {{"beam": {}1{}}}}}"#,
        "[".repeat(100),
        "]".repeat(100)
    );
    let (pointer, _) = single_error(
        app.post_execution_raw("cantilever-impact", shallow).await,
        "/invalid-inputs",
    )
    .await;
    assert_eq!(pointer, "/inputs/beam");
}

/// Reads until the server closes the connection; returns what it sent.
async fn read_to_close(stream: &mut TcpStream, within: Duration) -> String {
    let mut received = Vec::new();
    tokio::time::timeout(within, stream.read_to_end(&mut received))
        .await
        .expect("the server closes the connection in time")
        .ok();
    String::from_utf8_lossy(&received).into_owned()
}

#[tokio::test]
async fn a_client_that_never_finishes_its_headers_is_disconnected() {
    let app = spawn_app_with(|config| config.header_read_timeout = Duration::from_millis(300)).await;
    let address = app.address.trim_start_matches("http://").to_owned();
    let mut stream = TcpStream::connect(&address).await.unwrap();
    let started = Instant::now();
    stream
        .write_all(b"GET /healthz HTTP/1.1\r\nHost: test\r\nX-Slow: ")
        .await
        .unwrap();
    read_to_close(&mut stream, Duration::from_secs(5)).await;
    let elapsed = started.elapsed();
    assert!(elapsed >= Duration::from_millis(250), "closed after {elapsed:?}");
    // Everyone else is still served.
    assert_eq!(app.get("/healthz").await.status(), StatusCode::OK);
}

#[tokio::test]
async fn a_client_that_never_finishes_its_body_gets_a_408() {
    let app = spawn_app_with(|config| config.request_timeout = Duration::from_millis(400)).await;
    let address = app.address.trim_start_matches("http://").to_owned();
    let mut stream = TcpStream::connect(&address).await.unwrap();
    stream
        .write_all(
            b"POST /processes/count-steps/execution HTTP/1.1\r\nHost: test\r\n\
              Content-Type: application/json\r\nContent-Length: 100\r\n\r\n{\"inputs\": ",
        )
        .await
        .unwrap();
    let mut received = vec![0u8; 4096];
    let read = tokio::time::timeout(Duration::from_secs(5), stream.read(&mut received))
        .await
        .expect("an answer in time")
        .unwrap();
    let answer = String::from_utf8_lossy(&received[..read]).into_owned();
    assert!(answer.starts_with("HTTP/1.1 408"), "{answer}");
    assert!(answer.contains("application/problem+json"), "{answer}");
}

#[tokio::test]
async fn a_non_loopback_address_needs_tokens_or_insecure() {
    let build = |auth: Option<TokenTable>, insecure: bool| async move {
        let data_dir = crate::helpers::TestStore::new(crate::helpers::Backend::Sqlite).await;
        let mut config = test_config(&data_dir);
        config.bind = "0.0.0.0:0".parse().unwrap();
        config.workers = 0;
        config.auth = auth;
        config.insecure = insecure;
        (Application::build(config, Registry::new(vec![])).await, data_dir)
    };
    let (refused, _dir) = build(None, false).await;
    match refused {
        Err(error @ StartupError::Insecure { .. }) => {
            let message = error.to_string();
            assert!(
                message.contains("--auth-file") && message.contains("--insecure"),
                "{message}"
            );
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
    let tokens = TokenTable::parse("alpha alpha-token-0123456789\n").unwrap();
    assert!(build(Some(tokens), false).await.0.is_ok());
    assert!(build(None, true).await.0.is_ok());
}
