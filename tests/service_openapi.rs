//! The committed OpenAPI document (`openapi/openapi.json`) is what the code generates.
//!
//! When the API changes, regenerate it with
//! `UPDATE_OPENAPI=1 cargo test --test service_openapi` and commit the result.

use std::path::PathBuf;

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
        "openapi/openapi.json is out of date with the code: regenerate it with \
         `UPDATE_OPENAPI=1 cargo test --test service_openapi` and commit it"
    );
}

#[test]
fn the_openapi_document_describes_every_route() {
    let document: serde_json::Value =
        serde_json::from_str(&chocmodal::service::http::openapi::json()).unwrap();
    let paths = document["paths"].as_object().unwrap();
    for route in [
        "/",
        "/conformance",
        "/openapi.json",
        "/healthz",
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
            "schema {schema} is missing"
        );
    }
}
