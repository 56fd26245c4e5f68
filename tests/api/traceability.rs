//! Traceability (issue 33 item 6): labels and a note given with a job come back in its
//! status and the job list, which filters on labels; bad ones are refused at their
//! pointers; every results document says which solver, which build and which inputs
//! (a hash of their canonical JSON) made it; the job list shows each job's verdict.

use reqwest::StatusCode;
use serde_json::{Value, json};
use sha2::{Digest, Sha256};

use crate::counting;
use crate::helpers::{
    Backend, TestApp, assert_problem, on_both_backends, spawn_app, spawn_app_on,
    spawn_app_with_shipped_processes_on,
};

on_both_backends!(
    labels_and_a_note_are_stored_with_the_job_returned_and_filtered_on,
    the_job_list_shows_the_verdict_of_each_successful_job,
    a_sweep_keeps_its_labels_and_note_and_the_sweep_list_filters_on_them,
    a_signal_keeps_the_labels_and_note_of_its_upload_and_the_signal_list_filters_on_them
);

/// Submits `count-steps` with this body; returns the job id.
async fn submit(app: &TestApp, body: Value) -> String {
    let response = app.post_execution(counting::ID, &body).await;
    assert_eq!(response.status(), StatusCode::CREATED, "{body}");
    let status: Value = response.json().await.unwrap();
    status["jobID"].as_str().unwrap().to_owned()
}

fn ids(list: &Value) -> Vec<String> {
    list["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["jobID"].as_str().unwrap().to_owned())
        .collect()
}

async fn labels_and_a_note_are_stored_with_the_job_returned_and_filtered_on(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let both = submit(
        &app,
        json!({"inputs": {"steps": 1}, "labels": ["handling-5g", "clad B, rev. C"], "note": "ticket 4512\nsecond line"}),
    )
    .await;
    let one = submit(&app, json!({"inputs": {"steps": 1}, "labels": ["handling-5g"]})).await;
    let none = submit(&app, json!({"inputs": {"steps": 1}})).await;
    let status = app.status(&both).await;
    assert_eq!(status["labels"], json!(["handling-5g", "clad B, rev. C"]));
    assert_eq!(status["note"], "ticket 4512\nsecond line");
    let status = app.status(&none).await;
    assert_eq!(status["labels"], json!([]));
    assert!(status.get("note").is_none(), "{status}");

    let listed = app.get_json("/jobs?label=handling-5g").await;
    assert_eq!(ids(&listed), [one.clone(), both.clone()]);
    assert_eq!(listed["jobs"][1]["note"], "ticket 4512\nsecond line");
    // Every label named; a comma is part of a label, not a separator.
    let listed = app
        .get_json("/jobs?label=handling-5g&label=clad%20B%2C%20rev.%20C")
        .await;
    assert_eq!(ids(&listed), [both.as_str()]);
    assert_eq!(
        ids(&app.get_json("/jobs?label=clad%20B").await),
        Vec::<String>::new()
    );
    assert_eq!(ids(&app.get_json("/jobs").await).len(), 3);
    // The next page keeps the filter.
    let page = app.get_json("/jobs?label=handling-5g&limit=1").await;
    let next = page["links"]
        .as_array()
        .unwrap()
        .iter()
        .find(|l| l["rel"] == "next")
        .unwrap()["href"]
        .as_str()
        .unwrap()
        .to_owned();
    assert_eq!(ids(&app.get_json(&next).await), [both.as_str()], "{next}");
    let bad = app.get(&format!("/jobs?label={}", "x".repeat(65))).await;
    assert_problem(bad, StatusCode::BAD_REQUEST, "/invalid-query").await;
}

#[tokio::test]
async fn bad_labels_and_notes_are_refused_at_their_pointers_and_nothing_is_queued() {
    let app = spawn_app().await;
    let response = app
        .post_execution(
            counting::ID,
            &json!({"inputs": {"steps": 1}, "labels": ["ok", 3, "", "x".repeat(65), "a\tb", "ok"],
                    "note": "n".repeat(2001)}),
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let pointers: Vec<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["pointer"].as_str().unwrap())
        .collect();
    assert_eq!(
        pointers,
        [
            "/labels/1",
            "/labels/2",
            "/labels/3",
            "/labels/4",
            "/labels/5",
            "/note"
        ],
        "{problem}"
    );
    for body in [
        json!({"inputs": {"steps": 1}, "labels": "one"}),
        json!({"inputs": {"steps": 1}, "labels": (0..21).map(|k| format!("l{k}")).collect::<Vec<_>>()}),
        json!({"inputs": {"steps": 1}, "note": {"text": "x"}}),
    ] {
        let response = app.post_execution(counting::ID, &body).await;
        assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    }
    // Bad inputs and bad labels are reported together.
    let response = app
        .post_execution(counting::ID, &json!({"inputs": {"steps": -1}, "labels": [1]}))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let pointers: Vec<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["pointer"].as_str().unwrap())
        .collect();
    assert!(
        pointers.contains(&"/inputs/steps") && pointers.contains(&"/labels/0"),
        "{problem}"
    );
    assert_eq!(ids(&app.get_json("/jobs").await).len(), 0);
}

fn sha256_hex(text: &str) -> String {
    Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[tokio::test]
async fn every_results_document_names_its_solver_build_and_inputs() {
    let app = spawn_app().await;
    // The same inputs written three ways (member order, spacing, `0` and `0.0`), then
    // one value changed.
    let texts = [
        r#"{"inputs": {"steps": 2, "step_ms": 0}}"#,
        r#"{"inputs":{"step_ms":0.0,"steps":2}}"#,
        r#"{ "inputs" : { "step_ms" : 0e0 , "steps" : 2 } }"#,
        r#"{"inputs": {"steps": 3, "step_ms": 0}}"#,
    ];
    let mut hashes = Vec::new();
    for text in texts {
        let response = app.post_execution_raw(counting::ID, text).await;
        assert_eq!(response.status(), StatusCode::CREATED, "{text}");
        let job = response.json::<Value>().await.unwrap()["jobID"]
            .as_str()
            .unwrap()
            .to_owned();
        app.wait_until_finished(&job).await;
        let results = app.get_json(&format!("/jobs/{job}/results")).await;
        let provenance = &results["provenance"];
        assert_eq!(provenance["solver"], "chocmodal");
        assert_eq!(provenance["solver_version"], env!("CARGO_PKG_VERSION"));
        match option_env!("CHOCMODAL_BUILD_COMMIT") {
            Some(commit) => assert_eq!(provenance["build"], commit),
            None => assert!(provenance["build"].is_null(), "{provenance}"),
        }
        hashes.push(provenance["inputs_sha256"].as_str().unwrap().to_owned());
    }
    // RFC 8785: members sorted, no whitespace, numbers in their shortest form.
    assert_eq!(hashes[0], sha256_hex(r#"{"step_ms":0,"steps":2}"#));
    assert_eq!(hashes[1], hashes[0]);
    assert_eq!(hashes[2], hashes[0]);
    assert_eq!(hashes[3], sha256_hex(r#"{"step_ms":0,"steps":3}"#));
    assert_ne!(hashes[3], hashes[0]);
}

#[tokio::test]
async fn a_build_from_a_git_checkout_names_its_commit() {
    // The package is built from its repository in development and in CI: the commit is
    // known, 40 hex digits (a source tarball has none, and says `null`).
    let in_checkout = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(".git")
        .exists();
    if in_checkout {
        let commit = option_env!("CHOCMODAL_BUILD_COMMIT");
        assert!(commit.is_some(), "build.rs records the commit of a checkout");
        let commit = commit.unwrap_or_default();
        assert_eq!(commit.len(), 40, "{commit}");
        assert!(commit.chars().all(|c| c.is_ascii_hexdigit()), "{commit}");
    }
}

async fn the_job_list_shows_the_verdict_of_each_successful_job(backend: Backend) {
    let app = spawn_app_with_shipped_processes_on(backend).await;
    let body = json!({"inputs": {
        "pin": {"length": 0.2, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "elements": 6, "modes": 3},
        "pins": 1,
        "contacts": [{"left": "wall", "right": 0, "height": 0.18, "gap": 1e-5, "stiffness": 2e5}],
        "initial": {"tip_displacements": [1e-4]},
        "solver": {"duration": 0.003, "check": "none"}},
        "labels": ["verdict"]});
    let response = app.post_execution("bundle-dynamics", &body).await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let job = response.json::<Value>().await.unwrap()["jobID"]
        .as_str()
        .unwrap()
        .to_owned();
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "successful", "{status}");
    let results = app.get_json(&format!("/jobs/{job}/results")).await;
    let verdict = results["quality"]["verdict"].as_str().unwrap();
    let listed = app.get_json("/jobs?label=verdict").await;
    assert_eq!(listed["jobs"][0]["verdict"], verdict, "{listed}");
    assert_eq!(status["verdict"], verdict);
    // Not successful (yet, or ever): no verdict.
    let running = app.submit(json!({"steps": 200, "step_ms": 10})).await;
    let status = app.status(&running).await;
    assert!(status.get("verdict").is_none(), "{status}");
    let dismissed = app.delete(&format!("/jobs/{job}")).await;
    assert_eq!(dismissed.status(), StatusCode::OK);
    let status = app.status(&job).await;
    assert!(
        status.get("verdict").is_none(),
        "a dismissed job has no results, hence no verdict: {status}"
    );
    app.delete(&format!("/jobs/{running}")).await;
}

fn sweep_ids(list: &Value) -> Vec<String> {
    list["sweeps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["sweepID"].as_str().unwrap().to_owned())
        .collect()
}

async fn a_sweep_keeps_its_labels_and_note_and_the_sweep_list_filters_on_them(backend: Backend) {
    let app = spawn_app_on(backend, |_| {}).await;
    let sweep = |labels: Value| {
        json!({"process": counting::ID, "inputs": {"steps": 1},
               "axes": [{"pointer": "/steps", "values": [1, 2]}],
               "labels": labels, "note": "calibration, rev. B"})
    };
    let labelled = app.create_sweep(sweep(json!(["calibration", "row17"]))).await;
    let other = app.create_sweep(sweep(json!(["row17"]))).await;
    let status = app.get_json(&format!("/sweeps/{labelled}")).await;
    assert_eq!(status["labels"], json!(["calibration", "row17"]));
    assert_eq!(status["note"], "calibration, rev. B");
    // The labels are the sweep's, not part of its definition.
    assert!(status["definition"].get("labels").is_none(), "{status}");
    assert_eq!(
        sweep_ids(&app.get_json("/sweeps?label=row17").await),
        [other.as_str(), labelled.as_str()]
    );
    assert_eq!(
        sweep_ids(&app.get_json("/sweeps?label=row17&label=calibration").await),
        [labelled.as_str()]
    );
    assert_eq!(
        sweep_ids(&app.get_json("/sweeps?label=none").await),
        Vec::<String>::new()
    );
    let response = app.post_sweep(&sweep(json!(["ok", ""]))).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/labels/1", "{problem}");
    assert_eq!(
        sweep_ids(&app.get_json("/sweeps").await).len(),
        2,
        "the refused sweep queued nothing"
    );
}

fn signal_ids(list: &Value) -> Vec<String> {
    list["signals"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["id"].as_str().unwrap().to_owned())
        .collect()
}

async fn a_signal_keeps_the_labels_and_note_of_its_upload_and_the_signal_list_filters_on_them(
    backend: Backend,
) {
    let app = spawn_app_on(backend, |_| {}).await;
    let record = "time,acceleration\n0,0\n0.01,1\n0.02,0\n";
    let labelled = app
        .upload_signal(
            record,
            "text/csv",
            "?label=el-centro&label=scaled%202%2C5&note=PEER%20NGA%20%236",
        )
        .await;
    assert_eq!(labelled["labels"], json!(["el-centro", "scaled 2,5"]));
    assert_eq!(labelled["note"], "PEER NGA #6");
    let id = labelled["id"].as_str().unwrap().to_owned();
    let plain = app.upload_signal(record, "text/csv", "").await;
    assert_eq!(plain["labels"], json!([]));
    assert_eq!(
        app.get_json(&format!("/signals/{id}")).await["labels"],
        labelled["labels"]
    );
    assert_eq!(
        signal_ids(&app.get_json("/signals?label=el-centro").await),
        [id.as_str()]
    );
    assert_eq!(
        signal_ids(&app.get_json("/signals?label=el-centro&label=other").await),
        Vec::<String>::new()
    );
    assert_eq!(signal_ids(&app.get_json("/signals").await).len(), 2);
    let refused = app.post_signal(record, "text/csv", "?label=").await;
    let problem = assert_problem(refused, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/labels/0", "{problem}");
    let refused = app.post_signal(record, "text/csv", "?colour=red").await;
    assert_problem(refused, StatusCode::BAD_REQUEST, "/invalid-query").await;
    assert_eq!(
        signal_ids(&app.get_json("/signals").await).len(),
        2,
        "nothing stored when refused"
    );
}
