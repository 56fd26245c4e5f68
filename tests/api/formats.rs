//! Every table in every format (issue 33 item 4): one negotiator answers every route,
//! honouring the `format` parameter (or refusing, with the formats the route has) and
//! `Accept`'s quality values; the per-contact statistics are a table over HTTP, JSON and
//! CSV, the very table `chocmodal run --out` writes; bodies are compressed (gzip, zstd)
//! for clients that ask, and decode to the same bytes.

use std::io::Read;

use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{TestApp, assert_problem, spawn_app, spawn_app_with_shipped_processes_on};

/// Two short pins between the walls, one released: a run of a few hundred milliseconds.
fn row() -> Value {
    json!({"inputs": {
        "pin": {"length": 0.2, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "elements": 6, "modes": 3},
        "pins": 2,
        "contacts": [
            {"left": "wall", "right": 0, "height": 0.18, "gap": 1e-5, "stiffness": 2e5},
            {"left": 0, "right": 1, "height": 0.18, "gap": 1e-5, "stiffness": 2e5},
            {"left": 1, "right": "wall", "height": 0.18, "gap": 1e-5, "stiffness": 2e5}],
        "initial": {"tip_displacements": [1e-4, 0.0]},
        "solver": {"duration": 0.005, "check": "none"},
        "output": {"interval": 1e-4}}})
}

async fn run_row(app: &TestApp) -> String {
    let response = app.post_execution("bundle-dynamics", &row()).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let job = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    job
}

/// GET `path` with these headers: status, content type, `Content-Encoding`, body.
async fn fetch(
    app: &TestApp,
    path: &str,
    headers: &[(&str, &str)],
) -> (StatusCode, String, Option<String>, Vec<u8>) {
    let mut request = app.client.get(app.url(path));
    for (name, value) in headers {
        request = request.header(*name, *value);
    }
    let response = request.send().await.unwrap();
    let header = |name: &str| {
        response
            .headers()
            .get(name)
            .map(|v| v.to_str().unwrap().to_owned())
    };
    let (content_type, encoding) = (
        header("content-type").unwrap_or_default(),
        header("content-encoding"),
    );
    (
        response.status(),
        content_type,
        encoding,
        response.bytes().await.unwrap().to_vec(),
    )
}

#[tokio::test]
async fn accept_quality_values_choose_between_csv_and_json_on_every_table() {
    let app = spawn_shipped().await;
    let job = run_row(&app).await;
    for path in [
        format!("/jobs/{job}/results/contact_forces"),
        format!("/jobs/{job}/results/impacts"),
        format!("/jobs/{job}/results/contacts"),
    ] {
        for (accept, csv) in [
            ("text/csv;q=0.1, application/json", false),
            ("application/json;q=0.5, text/csv", true),
            ("text/csv", true),
            ("*/*", false),
            ("text/csv;q=0, */*", false),
        ] {
            let (status, content_type, _, body) = fetch(&app, &path, &[("accept", accept)]).await;
            assert_eq!(status, StatusCode::OK, "{path} with Accept: {accept}");
            let expected = if csv { "text/csv" } else { "application/json" };
            assert!(
                content_type.starts_with(expected),
                "{path} with Accept: {accept}: {content_type} instead of {expected}"
            );
            if !csv {
                serde_json::from_slice::<Value>(&body).unwrap_or_else(|e| panic!("{path} {accept}: {e}"));
            }
        }
        // The parameter wins over `Accept`, under either name.
        for query in ["?format=csv", "?f=csv"] {
            let (_, content_type, _, _) =
                fetch(&app, &format!("{path}{query}"), &[("accept", "application/json")]).await;
            assert!(
                content_type.starts_with("text/csv"),
                "{path}{query}: {content_type}"
            );
        }
        let response = app.get(&path).await;
        assert_eq!(response.headers()["vary"], "accept", "{path}");
    }
}

#[tokio::test]
async fn a_format_a_route_cannot_give_is_refused_naming_the_formats_it_has() {
    let app = spawn_shipped().await;
    let job = run_row(&app).await;
    // The results document is JSON only: `format=csv` no longer answers JSON in silence.
    let problem = assert_problem(
        app.get(&format!("/jobs/{job}/results?format=csv")).await,
        StatusCode::BAD_REQUEST,
        "/invalid-query",
    )
    .await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(detail.contains("`csv`") && detail.contains("`json`"), "{detail}");
    for path in [
        format!("/jobs/{job}/results/contacts?format=xml"),
        format!("/jobs/{job}/results/contact_forces?format=xml"),
        format!("/jobs/{job}?format=xml"),
        "/processes?format=csv".to_owned(),
        "/jobs?f=csv".to_owned(),
        format!("/jobs/{job}/results/contacts?format=csv&f=json"),
    ] {
        let problem = assert_problem(app.get(&path).await, StatusCode::BAD_REQUEST, "/invalid-query").await;
        if !path.contains("&f=") {
            assert!(
                problem["detail"].as_str().unwrap().contains("`json`"),
                "{path}: {problem}"
            );
        }
    }
    let problem = assert_problem(
        app.client
            .get(app.url(&format!("/jobs/{job}/results/contacts")))
            .header("accept", "application/xml")
            .send()
            .await
            .unwrap(),
        StatusCode::NOT_ACCEPTABLE,
        "/not-acceptable",
    )
    .await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(
        detail.contains("text/csv") && detail.contains("application/json"),
        "{detail}"
    );
    // The formats a route has are all served.
    let (status, content_type, _, _) = fetch(&app, &format!("/jobs/{job}?format=json"), &[]).await;
    assert_eq!(status, StatusCode::OK);
    assert!(content_type.starts_with("application/json"));
    let (status, content_type, _, _) = fetch(&app, "/jobs?f=html", &[]).await;
    assert_eq!(status, StatusCode::OK);
    assert!(content_type.starts_with("text/html"));
}

#[tokio::test]
async fn the_contact_statistics_are_a_table_in_json_and_csv_with_the_results_values() {
    let app = spawn_shipped().await;
    let job = run_row(&app).await;
    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    let contacts = results["contacts"].as_array().unwrap();
    let table = app.get_json(&format!("/jobs/{job}/results/contacts")).await;
    let columns: Vec<&str> = table["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(columns[0], "contact", "{columns:?}");
    for name in [
        "left",
        "right",
        "height",
        "gap",
        "max_force",
        "impacts",
        "impulse",
        "impact_statistics.rms_force",
    ] {
        assert!(columns.contains(&name), "no {name} in {columns:?}");
    }
    let records = table["contacts"].as_array().unwrap();
    assert_eq!(records.len(), contacts.len());
    let csv = String::from_utf8(
        fetch(&app, &format!("/jobs/{job}/results/contacts?format=csv"), &[])
            .await
            .3,
    )
    .unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, columns);
    let force_column = header.iter().position(|c| *c == "max_force").unwrap();
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len(), "row {k}: {line}");
        assert_eq!(cells[0], k.to_string());
        let max_force: f64 = cells[force_column].parse().unwrap();
        assert_eq!(
            max_force,
            contacts[k]["max_force"].as_f64().unwrap(),
            "contact {k}"
        );
        assert_eq!(records[k]["max_force"], contacts[k]["max_force"], "contact {k}");
        assert_eq!(records[k]["contact"], k);
    }
    // A run without a contact list has no such table.
    let counted = app.submit(json!({"steps": 3})).await;
    app.wait_until_finished(&counted).await;
    assert_problem(
        app.get(&format!("/jobs/{counted}/results/contacts")).await,
        StatusCode::NOT_FOUND,
        "/no-such-output",
    )
    .await;
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(bytes).read_to_end(&mut out).unwrap();
    out
}

#[tokio::test]
async fn compressed_bodies_decode_to_the_same_bytes_and_still_revalidate() {
    let app = spawn_shipped().await;
    let job = run_row(&app).await;
    for path in [
        format!("/jobs/{job}/results"),
        format!("/jobs/{job}/results/displacements?format=csv"),
        format!("/jobs/{job}/results/contacts?format=csv"),
        "/openapi.json".to_owned(),
        "/metrics".to_owned(),
    ] {
        let (status, plain_type, encoding, plain) = fetch(&app, &path, &[]).await;
        assert_eq!(status, StatusCode::OK, "{path}");
        assert_eq!(encoding, None, "{path}: no Accept-Encoding, no compression");
        let (status, content_type, encoding, gzipped) =
            fetch(&app, &path, &[("accept-encoding", "gzip")]).await;
        assert_eq!(status, StatusCode::OK, "{path}");
        assert_eq!(encoding.as_deref(), Some("gzip"), "{path}");
        assert_eq!(content_type, plain_type, "{path}");
        if path != "/metrics" {
            // (the metrics move between two scrapes)
            assert_eq!(gunzip(&gzipped), plain, "{path}: gzip");
            let (_, _, encoding, zstd_bytes) = fetch(&app, &path, &[("accept-encoding", "zstd")]).await;
            assert_eq!(encoding.as_deref(), Some("zstd"), "{path}");
            assert_eq!(zstd::decode_all(&zstd_bytes[..]).unwrap(), plain, "{path}: zstd");
            if path.contains("displacements") || path.contains("openapi") {
                assert!(
                    gzipped.len() < plain.len(),
                    "{path}: {} gzipped bytes for {}",
                    gzipped.len(),
                    plain.len()
                );
            }
        } else {
            let text = String::from_utf8(gunzip(&gzipped)).unwrap();
            assert!(text.contains("# TYPE"), "{text}");
        }
        // Quality values: gzip refused, zstd taken.
        let (_, _, encoding, _) = fetch(&app, &path, &[("accept-encoding", "gzip;q=0, zstd")]).await;
        assert_eq!(encoding.as_deref(), Some("zstd"), "{path}");
    }
    // A compressed representation has a weak tag, which revalidates.
    let path = format!("/jobs/{job}/results");
    let response = app
        .client
        .get(app.url(&path))
        .header("accept-encoding", "gzip")
        .send()
        .await
        .unwrap();
    let tag = response.headers()["etag"].to_str().unwrap().to_owned();
    assert!(tag.starts_with("W/\""), "{tag}");
    let again = app
        .client
        .get(app.url(&path))
        .header("accept-encoding", "gzip")
        .header("if-none-match", &tag)
        .send()
        .await
        .unwrap();
    assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
}

#[tokio::test]
async fn sample_times_are_written_as_the_decimals_k_times_the_interval() {
    let app = spawn_shipped().await;
    let job = run_row(&app).await;
    for output in ["displacements", "contact_forces"] {
        let csv = String::from_utf8(
            fetch(&app, &format!("/jobs/{job}/results/{output}?format=csv"), &[])
                .await
                .3,
        )
        .unwrap();
        let times: Vec<&str> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap())
            .collect();
        assert_eq!(times.len(), 51, "{output}: 0.005 s every 1e-4 s");
        for (k, text) in times.iter().enumerate() {
            let expected: f64 = format!("{k}e-4").parse().unwrap();
            assert_eq!(
                text.parse::<f64>().unwrap(),
                expected,
                "{output} sample {k}: {text}"
            );
            assert!(text.len() <= 6, "{output} sample {k} printed as {text}");
        }
    }
}

async fn spawn_shipped() -> TestApp {
    spawn_app_with_shipped_processes_on(crate::helpers::Backend::Sqlite).await
}

#[tokio::test]
async fn routes_without_a_table_keep_their_single_format() {
    let app = spawn_app().await;
    let job = app.submit(json!({"steps": 2})).await;
    app.wait_until_finished(&job).await;
    let (status, content_type, _, _) = fetch(
        &app,
        &format!("/jobs/{job}/results"),
        &[("accept", "text/csv;q=0.1, application/json")],
    )
    .await;
    assert_eq!(status, StatusCode::OK);
    assert!(content_type.starts_with("application/json"), "{content_type}");
    let (status, content_type, _, _) = fetch(&app, "/metrics", &[("accept", "text/plain")]).await;
    assert_eq!(status, StatusCode::OK);
    assert!(content_type.starts_with("text/plain"), "{content_type}");
}
