//! A result's quality verdict where users look: a `poor` or `doubtful` job stays
//! `successful` but its status message says so with the reasons (also when its results
//! are reused), and a sweep's rows carry the verdict and the numeric quality fields,
//! its aggregates the count of poor runs per axis value and in total.
//!
//! The runs are made poor and doubtful from the verdict's own definition
//! (`docs/accuracy.md`): steps per period of the fastest motion are 2π / (ω_max Δt);
//! fewer than 8 is `poor`; without the step-halving check, 8 to 15 is `doubtful` (unless
//! something else is poor: the energy residual only is at a tolerance of 0.1 when it
//! exceeds 1). So a first run's step times its `steps_per_contact_period` / N gives N
//! steps per period. Central difference is stable up to π steps per period, so N = 5 and
//! N = 10 both run.

use std::time::Duration;

use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{Backend, TestApp, on_both_backends, spawn_app_with_shipped_processes_on};

/// The public cantilever case, 0.05 s, without the step-halving check (cheap).
fn cantilever(time_step: Option<f64>) -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/cantilever-impact.json"
    ))
    .unwrap();
    let mut body: Value = serde_json::from_str(&text).unwrap();
    let solver = &mut body["inputs"]["solver"];
    solver["duration"] = json!(0.05);
    solver["check"] = json!("none");
    solver["time_step"] = time_step.map_or(json!("auto"), |dt| json!(dt));
    body
}

async fn execute(app: &TestApp, body: &Value) -> String {
    let response = app.post_execution("cantilever-impact", body).await;
    let code = response.status();
    let status: Value = response.json().await.unwrap();
    assert_eq!(code, StatusCode::CREATED, "{status}");
    status["jobID"].as_str().unwrap().to_owned()
}

/// Runs `body` to its end; returns its status and results.
async fn run(app: &TestApp, body: &Value) -> (Value, Value) {
    let id = execute(app, body).await;
    let status = app
        .wait_for(&id, &["successful", "failed"], Duration::from_secs(60))
        .await;
    assert_eq!(status["status"], "successful", "{status}");
    let results = app.get_json(&format!("/jobs/{id}/results")).await;
    (status, results)
}

fn reasons(results: &Value) -> Vec<&str> {
    results["quality"]["reasons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_str().unwrap())
        .collect()
}

/// The step that gives `steps` steps per period of the fastest motion, from a run's
/// results (steps per period scale as 1/Δt).
fn step_for(results: &Value, steps: f64) -> f64 {
    let time_step = results["numerical"]["time_step"].as_f64().unwrap();
    let per_period = results["quality"]["steps_per_contact_period"].as_f64().unwrap();
    time_step * per_period / steps
}

async fn a_poor_or_doubtful_job_stays_successful_and_its_message_gives_the_verdict_and_reasons(
    backend: Backend,
) {
    let app = spawn_app_with_shipped_processes_on(backend).await;
    let (status, auto) = run(&app, &cantilever(None)).await;
    let verdict = auto["quality"]["verdict"].as_str().unwrap();
    // Without the step-halving check the step's error is not measured: never `good`.
    assert_ne!(verdict, "good", "{}", auto["quality"]);
    if verdict == "unchecked" {
        assert!(
            reasons(&auto).iter().any(|r| r.contains("solver.check")),
            "an unchecked verdict says what was not checked: {}",
            auto["quality"]
        );
    }
    let expected = match verdict {
        "good" => "finished".to_owned(),
        other => format!("finished; quality {other}: {}", reasons(&auto).join("; ")),
    };
    assert_eq!(status["message"], expected.as_str(), "{}", auto["quality"]);

    let poor = cantilever(Some(step_for(&auto, 5.0)));
    let (status, results) = run(&app, &poor).await;
    assert_eq!(results["quality"]["verdict"], "poor", "{}", results["quality"]);
    let reasons_poor = reasons(&results).join("; ");
    assert!(!reasons_poor.is_empty());
    assert_eq!(
        status["message"],
        format!("finished; quality poor: {reasons_poor}").as_str()
    );
    let job = status["jobID"].as_str().unwrap().to_owned();
    let listed = app.get_json("/jobs?status=successful").await;
    let row = listed["jobs"]
        .as_array()
        .unwrap()
        .iter()
        .find(|j| j["jobID"] == job.as_str())
        .expect("the poor job is listed as successful");
    assert_eq!(row["message"], status["message"]);

    // The same inputs again: the results are reused, and so is their verdict.
    let (status, _) = run(&app, &poor).await;
    assert_eq!(
        status["message"],
        format!("finished: reused the results of job {job}; quality poor: {reasons_poor}").as_str()
    );

    let mut doubtful = cantilever(Some(step_for(&auto, 10.0)));
    doubtful["inputs"]["solver"]["tolerance"] = json!(0.1);
    let (status, results) = run(&app, &doubtful).await;
    assert_eq!(
        results["quality"]["verdict"], "doubtful",
        "{}",
        results["quality"]
    );
    assert_eq!(
        status["message"],
        format!("finished; quality doubtful: {}", reasons(&results).join("; ")).as_str()
    );
}

on_both_backends!(a_poor_or_doubtful_job_stays_successful_and_its_message_gives_the_verdict_and_reasons);

#[tokio::test]
async fn sweep_rows_carry_the_verdict_and_the_aggregates_count_poor_runs_per_axis_value() {
    let app = spawn_app_with_shipped_processes_on(Backend::Sqlite).await;
    let (_, auto) = run(&app, &cantilever(None)).await;
    let fine = auto["numerical"]["time_step"].as_f64().unwrap();
    let coarse = step_for(&auto, 5.0);
    let id = app
        .create_sweep(json!({
            "process": "cantilever-impact",
            "inputs": cantilever(Some(fine))["inputs"],
            "axes": [
                {"pointer": "/solver/time_step", "values": [fine, coarse]},
                {"pointer": "/release/tip_displacement", "values": [0.001, 0.002]}
            ]
        }))
        .await;
    app.wait_for_sweep(&id, &["successful"], Duration::from_secs(60))
        .await;
    let results = app.sweep_results(&id).await;
    let columns: Vec<&str> = results["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    for column in [
        "quality.verdict",
        "quality.energy_residual",
        "quality.time_step_over_critical",
        "quality.steps_per_contact_period",
        "quality.tolerance",
    ] {
        assert!(columns.contains(&column), "no {column} in {columns:?}");
    }
    let rows = results["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for row in rows {
        let over = row["/solver/time_step"].as_f64().unwrap()
            / row["numerical.critical_time_step"].as_f64().unwrap();
        let shown = row["quality.time_step_over_critical"].as_f64().unwrap();
        assert!(
            (shown - over).abs() <= 1e-12 * over,
            "Δt/Δt_c {shown}, expected {over}"
        );
        if row["/solver/time_step"].as_f64() == Some(coarse) {
            assert_eq!(row["quality.verdict"], "poor", "{row:?}");
        }
    }
    let poor_where = |pointer: &str, value: &Value| {
        rows.iter()
            .filter(|r| &r[pointer] == value && r["quality.verdict"] == "poor")
            .count()
    };

    let quality = &results["aggregates"]["quality"];
    let total_poor = rows.iter().filter(|r| r["quality.verdict"] == "poor").count();
    assert!(total_poor >= 2, "both coarse runs are poor");
    assert_eq!(quality["runs"], 4, "{quality}");
    assert_eq!(quality["poor"], total_poor, "{quality}");
    let counted: u64 = ["good", "unchecked", "doubtful", "poor"]
        .iter()
        .map(|v| quality[v].as_u64().unwrap())
        .sum();
    assert_eq!(counted, 4, "{quality}");
    // The runs have no step-halving check: none is good, and the fine ones are unchecked
    // unless something else is wrong with them.
    assert_eq!(quality["good"], 0, "{quality}");
    let unchecked = rows
        .iter()
        .filter(|r| r["quality.verdict"] == "unchecked")
        .count();
    assert_eq!(quality["unchecked"], unchecked, "{quality}");
    let by_axis = quality["by_axis"].as_array().unwrap();
    assert_eq!(by_axis.len(), 2, "{quality}");
    for axis in by_axis {
        let pointer = axis["axis"].as_str().unwrap();
        let values = axis["values"].as_array().unwrap();
        assert_eq!(values.len(), 2, "{axis}");
        for entry in values {
            assert_eq!(entry["runs"], 2, "{axis}");
            assert_eq!(entry["poor"], poor_where(pointer, &entry["value"]), "{axis}");
        }
    }
    let coarse_entry = by_axis[0]["values"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["value"].as_f64() == Some(coarse))
        .unwrap();
    assert_eq!(coarse_entry["poor"], 2, "{coarse_entry}");

    let csv = app.sweep_csv(&id).await;
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let at = header.iter().position(|c| *c == "quality.verdict").unwrap();
    let poor_cells = csv
        .lines()
        .skip(1)
        .filter(|line| line.split(',').nth(at) == Some("poor"))
        .count();
    assert_eq!(poor_cells, total_poor);
}
