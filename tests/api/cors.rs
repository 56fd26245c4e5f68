//! Cross-origin requests from a browser (`--cors-origin`): a preflight from an allowed
//! origin is answered without a token even when tokens are required, the API's answers
//! (a 401 too) name the origin and expose the headers a script reads; another origin is
//! never named; without the setting nothing changes (no CORS headers, `OPTIONS` a 405).

use chocmodal::service::auth::TokenTable;
use chocmodal::service::http::cors::CorsOrigin;
use reqwest::{Method, Response, StatusCode};
use serde_json::json;

use crate::counting;
use crate::helpers::{TestApp, spawn_app, spawn_app_with};

const DASHBOARD: &str = "https://dash.example.com";
const TOKEN: &str = "cors-token-0123456789";

async fn spawn_with_tokens_and_origins(origins: &[&str]) -> TestApp {
    let origins: Vec<CorsOrigin> = origins.iter().map(|origin| origin.parse().unwrap()).collect();
    spawn_app_with(|config| {
        config.auth = Some(TokenTable::parse(&format!("team {TOKEN}\n")).unwrap());
        config.cors_origins = origins;
    })
    .await
}

/// A browser's preflight of a `POST` with a token and a JSON body, from `origin`.
async fn preflight(app: &TestApp, path: &str, origin: &str) -> Response {
    app.client
        .request(Method::OPTIONS, app.url(path))
        .header("origin", origin)
        .header("access-control-request-method", "POST")
        .header("access-control-request-headers", "authorization,content-type")
        .send()
        .await
        .unwrap()
}

fn header<'a>(response: &'a Response, name: &str) -> Option<&'a str> {
    response.headers().get(name).map(|v| v.to_str().unwrap())
}

/// The comma-separated values of a header, lower case.
fn listed(response: &Response, name: &str) -> Vec<String> {
    header(response, name)
        .unwrap_or_default()
        .split(',')
        .map(|item| item.trim().to_ascii_lowercase())
        .filter(|item| !item.is_empty())
        .collect()
}

#[tokio::test]
async fn a_preflight_from_an_allowed_origin_is_answered_without_a_token() {
    let app = spawn_with_tokens_and_origins(&[DASHBOARD, "http://localhost:5173"]).await;
    let execution = format!("/processes/{}/execution", counting::ID);

    let response = preflight(&app, &execution, DASHBOARD).await;
    assert!(response.status().is_success(), "{}", response.status());
    assert_eq!(header(&response, "access-control-allow-origin"), Some(DASHBOARD));
    let methods = listed(&response, "access-control-allow-methods");
    for method in ["get", "post", "delete"] {
        assert!(methods.iter().any(|m| m == method), "{method} not in {methods:?}");
    }
    let headers = listed(&response, "access-control-allow-headers");
    for name in ["authorization", "content-type", "accept", "if-none-match"] {
        assert!(headers.iter().any(|h| h == name), "{name} not in {headers:?}");
    }

    // The request itself: its answer names the origin and lets the script read Location.
    let response = app
        .client
        .post(app.url(&execution))
        .header("origin", DASHBOARD)
        .bearer_auth(TOKEN)
        .json(&json!({"inputs": {"steps": 1}}))
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::CREATED);
    assert_eq!(header(&response, "access-control-allow-origin"), Some(DASHBOARD));
    let exposed = listed(&response, "access-control-expose-headers");
    for name in ["location", "etag", "retry-after", "www-authenticate"] {
        assert!(exposed.iter().any(|h| h == name), "{name} not in {exposed:?}");
    }

    // A refusal is readable by the page too; the token is still required.
    let response = app
        .client
        .get(app.url("/jobs"))
        .header("origin", "http://localhost:5173")
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::UNAUTHORIZED);
    assert_eq!(
        header(&response, "access-control-allow-origin"),
        Some("http://localhost:5173")
    );
}

#[tokio::test]
async fn another_origin_is_never_allowed() {
    let app = spawn_with_tokens_and_origins(&[DASHBOARD]).await;
    let response = preflight(&app, "/jobs", "https://evil.example.com").await;
    assert_eq!(header(&response, "access-control-allow-origin"), None);

    let response = app
        .client
        .get(app.url("/jobs"))
        .header("origin", "https://evil.example.com")
        .bearer_auth(TOKEN)
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::OK);
    assert_eq!(header(&response, "access-control-allow-origin"), None);
}

#[tokio::test]
async fn a_star_allows_every_origin() {
    let app = spawn_with_tokens_and_origins(&["*"]).await;
    let response = preflight(&app, "/sweeps", "https://anywhere.example.org").await;
    assert!(response.status().is_success(), "{}", response.status());
    assert_eq!(header(&response, "access-control-allow-origin"), Some("*"));
}

#[tokio::test]
async fn without_origins_there_are_no_cors_headers_and_options_is_refused() {
    let app = spawn_app().await;
    let response = preflight(&app, "/jobs", DASHBOARD).await;
    assert_eq!(response.status(), StatusCode::METHOD_NOT_ALLOWED);
    let cors_headers = |response: &Response| -> Vec<String> {
        response
            .headers()
            .keys()
            .map(|name| name.as_str().to_owned())
            .filter(|name| name.starts_with("access-control-"))
            .collect()
    };
    assert_eq!(cors_headers(&response), Vec::<String>::new());

    let response = app
        .client
        .get(app.url("/jobs"))
        .header("origin", DASHBOARD)
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::OK);
    assert_eq!(cors_headers(&response), Vec::<String>::new());
}
