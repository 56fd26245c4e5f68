//! Cost ceilings (422 `too-costly` naming the fields that drive the cost, the estimate
//! and the limit; every run of a sweep), the per-tenant limit on queued jobs (429 with
//! `Retry-After`), the wall-time limit of a job, and the cap on history responses.

use std::time::Duration;

use chocmodal::processes::{CostLimits, Registry};
use chocmodal::service::auth::TokenTable;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{
    Backend, TestApp, assert_problem, on_both_backends, spawn_app_on, spawn_app_with,
    spawn_app_with_processes,
};

on_both_backends!(a_tenant_with_a_full_queue_gets_a_429_with_retry_after_and_the_others_do_not);

fn example(name: &str) -> Value {
    let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The real processes, no workers (nothing accepted here needs to run).
async fn spawn_validating(limits: CostLimits) -> TestApp {
    spawn_app_with_processes(Registry::builtin().all().to_vec(), move |config| {
        config.workers = 0;
        config.limits = limits;
    })
    .await
}

fn pointers(problem: &Value) -> Vec<String> {
    problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["pointer"].as_str().unwrap().to_owned())
        .collect()
}

#[tokio::test]
async fn a_run_above_the_work_ceiling_is_a_422_naming_the_fields_the_estimate_and_the_limit() {
    let app = spawn_validating(CostLimits {
        max_work: 1e6,
        ..CostLimits::default()
    })
    .await;
    // 1 s / 1e-5 s = 1e5 steps of 10 modes, the tip pseudo-mode of the (default) static
    // correction and 1 contact, run once and again at half the step by the step-halving
    // check (3 × the steps): 3.6e6 updates, over 1e6.
    let mut body = example("cantilever-impact.json");
    body["inputs"]["solver"]["duration"] = json!(1.0);
    let response = app.post_execution("cantilever-impact", &body).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/too-costly").await;
    let pointers = pointers(&problem);
    for field in [
        "/inputs/solver/duration",
        "/inputs/solver/time_step",
        "/inputs/beam/modes",
    ] {
        assert!(pointers.contains(&field.to_owned()), "{field} missing: {problem}");
    }
    let exceeded = &problem["exceeded"][0];
    assert_eq!(exceeded["quantity"], "work");
    assert_eq!(exceeded["limit"], 1e6);
    let estimate = exceeded["estimate"].as_f64().unwrap();
    let expected = 3.0 * 1.0 / 1e-5 * 12.0;
    assert!(
        (estimate - expected).abs() < 1e-6 * expected,
        "estimate {estimate}, expected {expected}"
    );
    assert!(
        problem["detail"].as_str().unwrap().contains("1.000e6"),
        "{problem}"
    );

    // A twentieth of the duration passes (validated, queued).
    body["inputs"]["solver"]["duration"] = json!(0.05);
    assert_eq!(
        app.post_execution("cantilever-impact", &body).await.status(),
        StatusCode::CREATED
    );
}

#[tokio::test]
async fn histories_above_the_ceiling_point_at_the_output_interval() {
    let app = spawn_validating(CostLimits {
        max_history_values: 1e5,
        ..CostLimits::default()
    })
    .await;
    // row17: 0.2 s sampled every 1e-4 s is 2001 samples of 1 + 180 columns twice (the
    // forces and their peaks) and of 1 + 17 three times (the deflections, their peaks and
    // the bending moments), and the per-impact table's default 100 000 rows of 10 values
    // and the two count series a truncated table keeps with them (180 contacts could make
    // more in its ~10⁵ steps).
    let body = example("bundle-row17.json");
    let response = app.post_execution("bundle-dynamics", &body).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/too-costly").await;
    let pointers = pointers(&problem);
    assert!(
        pointers.contains(&"/inputs/output/interval".to_owned()),
        "{problem}"
    );
    assert!(
        pointers.contains(&"/inputs/solver/duration".to_owned()),
        "{problem}"
    );
    assert_eq!(problem["exceeded"][0]["quantity"], "history_values");
    assert_eq!(
        problem["exceeded"][0]["estimate"],
        2001.0 * (2.0 * 181.0 + 3.0 * 18.0) + 1e5 * 12.0
    );
}

#[tokio::test]
async fn the_shipped_examples_pass_the_default_ceilings() {
    let app = spawn_validating(CostLimits::default()).await;
    let registry = Registry::builtin();
    for process in registry.all() {
        for example in process.examples() {
            let body: Value = serde_json::from_str(example.body).unwrap();
            let response = app.post_execution(process.id(), &body).await;
            assert_eq!(response.status(), StatusCode::CREATED, "{}", example.file);
        }
    }
    for name in ["sweep-calibration.json", "sweep-gaps.json"] {
        let response = app.post_sweep(&example(name)).await;
        assert_eq!(response.status(), StatusCode::CREATED, "{name}");
    }
}

#[tokio::test]
async fn a_sweep_with_a_run_above_a_ceiling_is_refused_naming_the_run() {
    let app = spawn_app_with(|config| {
        config.workers = 0;
        config.limits.max_work = 1000.0;
    })
    .await;
    let response = app
        .post_sweep(&json!({"process": counting::ID, "inputs": {"steps": 10},
                            "axes": [{"pointer": "/steps", "values": [10, 500, 5000]}],
                            "invalid_runs": "record"}))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/too-costly").await;
    assert_eq!(pointers(&problem), ["/runs/2/inputs/steps"], "{problem}");
    assert!(
        problem["errors"][0]["detail"]
            .as_str()
            .unwrap()
            .contains("/steps = 5000"),
        "{problem}"
    );
    assert!(problem["detail"].as_str().unwrap().contains("run 2"), "{problem}");
    assert_eq!(app.get_json("/jobs").await["jobs"], json!([]), "nothing queued");
}

async fn a_tenant_with_a_full_queue_gets_a_429_with_retry_after_and_the_others_do_not(backend: Backend) {
    let tokens = TokenTable::parse("alpha alpha-token-0123456789\nbeta beta-token-0123456789\n").unwrap();
    let app = spawn_app_on(backend, |config| {
        config.workers = 0;
        config.auth = Some(tokens);
        config.max_queued_jobs = Some(2);
    })
    .await;
    let post = |token: &'static str, path: &'static str, body: Value| {
        app.client
            .post(app.url(path))
            .bearer_auth(token)
            .header("content-type", "application/json")
            .body(body.to_string())
            .send()
    };
    let execute = "/processes/count-steps/execution";
    let job = json!({"inputs": {"steps": 3}});
    for _ in 0..2 {
        let response = post("alpha-token-0123456789", execute, job.clone())
            .await
            .unwrap();
        assert_eq!(response.status(), StatusCode::CREATED);
    }
    let response = post("alpha-token-0123456789", execute, job.clone())
        .await
        .unwrap();
    let retry_after: u64 = response.headers()["retry-after"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!(retry_after >= 1);
    let problem = assert_problem(response, StatusCode::TOO_MANY_REQUESTS, "/too-many-queued-jobs").await;
    assert!(
        problem["detail"].as_str().unwrap().contains("2 queued"),
        "{problem}"
    );

    // Another tenant has its own queue: one job, then a sweep of two runs does not fit.
    let response = post("beta-token-0123456789", execute, job.clone()).await.unwrap();
    assert_eq!(response.status(), StatusCode::CREATED);
    let sweep = json!({"process": counting::ID, "inputs": {"steps": 3},
                       "axes": [{"pointer": "/steps", "values": [3, 4]}]});
    let response = post("beta-token-0123456789", "/sweeps", sweep).await.unwrap();
    assert_problem(response, StatusCode::TOO_MANY_REQUESTS, "/too-many-queued-jobs").await;
    let listed = app
        .client
        .get(app.url("/sweeps"))
        .bearer_auth("beta-token-0123456789")
        .send()
        .await
        .unwrap();
    assert_eq!(listed.json::<Value>().await.unwrap()["sweeps"], json!([]));
}

#[tokio::test]
async fn a_job_over_the_wall_time_limit_fails_with_a_message() {
    let app = spawn_app_with(|config| config.max_job_time = Some(Duration::from_millis(300))).await;
    let job = app.submit(json!({"steps": 200, "step_ms": 20})).await;
    let status = app.wait_until_finished(&job).await;
    assert_eq!(status["status"], "failed", "{status}");
    let message = status["message"].as_str().unwrap();
    assert!(message.contains("wall-time limit"), "{message}");
    let problem = assert_problem(
        app.get(&format!("/jobs/{job}/results")).await,
        StatusCode::UNPROCESSABLE_ENTITY,
        "/job-time-limit",
    )
    .await;
    assert!(problem["detail"].as_str().unwrap().contains("0.3 s"), "{problem}");
    assert_eq!(app.probe.cancelled.load(std::sync::atomic::Ordering::SeqCst), 1);
    // A short job is untouched by the limit.
    let quick = app.submit(json!({"steps": 5})).await;
    assert_eq!(app.wait_until_finished(&quick).await["status"], "successful");
}

#[tokio::test]
async fn history_responses_are_thinned_to_the_cap_whatever_is_asked() {
    let app = spawn_app_with(|config| config.max_history_points = 100).await;
    let job = app.submit(json!({"steps": 1000, "spikes": [[437, 90.0]]})).await;
    app.wait_until_finished(&job).await;
    for query in ["", "?max_points=5000", "?max_points=60"] {
        let history = app.get_json(&format!("/jobs/{job}/results/signal{query}")).await;
        let points = history["points"].as_u64().unwrap();
        let cap = if query.ends_with("60") { 60 } else { 100 };
        assert!(points <= cap && points > 10, "{query}: {points} points");
        assert_eq!(history["thinned"], true);
        assert_eq!(history["total_points"], 1000);
        let values = history["series"][0]["values"].as_array().unwrap();
        assert!(
            values.contains(&json!(90.0)),
            "{query}: the spike was thinned away"
        );
    }
    let csv = app
        .get(&format!("/jobs/{job}/results/signal?format=csv"))
        .await
        .text()
        .await
        .unwrap();
    assert!(csv.lines().count() <= 101, "{} lines", csv.lines().count());
    // A window within the cap is served whole.
    let window = app
        .get_json(&format!("/jobs/{job}/results/signal?t_start=0.1&t_end=0.15"))
        .await;
    assert_eq!(window["points"], 51);
    assert_eq!(window["thinned"], false);
}

#[tokio::test]
async fn a_per_impact_table_above_the_ceiling_points_at_its_rows() {
    let app = spawn_validating(CostLimits {
        max_history_values: 1e6,
        ..CostLimits::default()
    })
    .await;
    // The cantilever's histories hold 12 values a sample: 1001 samples at 1e-4 s over
    // 0.1 s. A table of up to 10⁵ rows (one impact every two of its 10⁴ steps at most:
    // 5000 rows) stays within 10⁶ values; its histories too.
    let mut body = example("cantilever-impact.json");
    body["inputs"]["solver"]["duration"] = json!(0.1);
    body["inputs"]["output"] = json!({"interval": 1e-4});
    assert_eq!(
        app.post_execution("cantilever-impact", &body).await.status(),
        StatusCode::CREATED
    );
    // Over 10 s, 10⁶ steps could make 5·10⁵ impacts: 10⁵ rows kept, each with its 10
    // values and the 2 counts of a truncated table, plus the histories: refused, at the
    // table's size among the drivers.
    body["inputs"]["solver"]["duration"] = json!(10.0);
    body["inputs"]["output"] = json!({"interval": 1e-2});
    let response = app.post_execution("cantilever-impact", &body).await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/too-costly").await;
    assert!(
        pointers(&problem).contains(&"/inputs/output/impacts/max_rows".to_owned()),
        "{problem}"
    );
    assert_eq!(problem["exceeded"][0]["estimate"], 12.0 * 1001.0 + 12.0 * 1e5);
    // Fewer rows fit.
    body["inputs"]["output"]["impacts"] = json!({"max_rows": 1000});
    assert_eq!(
        app.post_execution("cantilever-impact", &body).await.status(),
        StatusCode::CREATED
    );
}
