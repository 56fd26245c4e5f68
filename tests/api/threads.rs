//! Threads inside one run (`solver.threads`): a worker's slots share as many cores as
//! there are slots. A run gets the free cores it asks for (and no more), the other slots
//! claim nothing while it holds them, and the results do not depend on the count.

use std::sync::Arc;
use std::time::Duration;

use chocmodal::processes::hex_bundle_dynamics::HexBundleDynamics;
use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::dashboard::execute;
use crate::helpers::{Backend, TestApp, on_both_backends, spawn_app_on, spawn_app_with_processes};

on_both_backends!(
    a_run_gets_the_cores_it_asks_for_and_the_other_slots_wait,
    a_run_gets_only_the_free_cores
);

const WITHIN: Duration = Duration::from_secs(30);

/// The `chocmodal_worker_threads` gauge of `/metrics`.
async fn worker_threads(app: &TestApp) -> i64 {
    let text = app.get("/metrics").await.text().await.unwrap();
    text.lines()
        .find_map(|line| line.strip_prefix("chocmodal_worker_threads "))
        .and_then(|value| value.trim().parse().ok())
        .expect("the gauge is exported")
}

/// Waits until `count` runs have started computing (a job is `running` from its claim,
/// a moment before).
async fn started(app: &TestApp, count: usize) {
    for _ in 0..600 {
        if app.probe.started() >= count {
            return;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    panic!("{count} runs did not start within 30 s");
}

/// Two slots, so two cores: a run asking for two takes both. A job queued meanwhile
/// stays queued although a slot is idle, and runs (on one thread) once the first is
/// dismissed.
async fn a_run_gets_the_cores_it_asks_for_and_the_other_slots_wait(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 2).await;
    // Minutes of work unless dismissed.
    let wide = app
        .submit(json!({"steps": 100000, "step_ms": 1, "solver": {"threads": 2}}))
        .await;
    app.wait_for(&wide, &["running"], WITHIN).await;
    started(&app, 1).await;
    assert_eq!(*app.probe.threads.lock().unwrap(), [2]);
    assert_eq!(worker_threads(&app).await, 2);

    let narrow = app.submit(json!({"steps": 2})).await;
    // Far longer than an idle slot takes to claim (an enqueue wakes it at once).
    tokio::time::sleep(Duration::from_millis(1500)).await;
    assert_eq!(app.status(&narrow).await["status"], "accepted", "no core is free");
    assert_eq!(app.probe.started(), 1);

    assert_eq!(
        app.delete(&format!("/jobs/{wide}")).await.status(),
        StatusCode::OK
    );
    assert_eq!(app.wait_until_finished(&narrow).await["status"], "successful");
    assert_eq!(*app.probe.threads.lock().unwrap(), [2, 1]);
    // Every core is handed back.
    let mut threads = worker_threads(&app).await;
    for _ in 0..100 {
        if threads == 0 {
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
        threads = worker_threads(&app).await;
    }
    assert_eq!(threads, 0);
}

/// A run asking for more threads than there are free cores runs on those it gets.
async fn a_run_gets_only_the_free_cores(backend: Backend) {
    let app = spawn_app_on(backend, |config| config.workers = 2).await;
    let long = app.submit(json!({"steps": 100000, "step_ms": 1})).await;
    app.wait_for(&long, &["running"], WITHIN).await;
    started(&app, 1).await;
    let wide = app.submit(json!({"steps": 2, "solver": {"threads": 8}})).await;
    assert_eq!(app.wait_until_finished(&wide).await["status"], "successful");
    assert_eq!(*app.probe.threads.lock().unwrap(), [1, 1]);
    assert_eq!(
        app.delete(&format!("/jobs/{long}")).await.status(),
        StatusCode::OK
    );
}

/// A 61-pin bundle rattling against its neighbours and the wrapper: 2 196 modal DOFs,
/// enough to share its steps.
fn bundle(threads: usize) -> Value {
    json!({"inputs": {
        "pin": {"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 24, "modes": 18, "static_correction": "none"},
        "bundle": {"rings": 4, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.15,
                   "wrapper_flat_to_flat": 0.0868},
        "contact": {"stiffness": 2e6, "damping": 20.0},
        "gaps": {"type": "uniform", "pin_pin": 1e-5, "pin_wall": 2e-5},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 80.0, "duration": 0.01},
                       "direction": 10.0},
        "solver": {"duration": 0.02, "check": "none", "threads": threads},
        "output": {"interval": 1e-3, "contacts": {"type": "all"}}
    }})
}

/// The results document of `process` run with `inputs` on one and on two threads (but
/// for the links to its histories, its provenance and the check's wall time) and its
/// contact forces, byte for byte.
async fn on_one_and_two_threads(
    app: &TestApp,
    process: &str,
    inputs: impl Fn(usize) -> Value,
) -> Vec<(Value, String)> {
    let mut documents = Vec::new();
    for threads in [1, 2] {
        let job = execute(app, process, &inputs(threads)).await;
        let status = app.wait_until_finished(&job).await;
        assert_eq!(status["status"], "successful", "{status}");
        let mut results = app.get_json(&format!("/jobs/{job}/results")).await;
        // The links to the histories name the job; the inputs (`solver.threads`) differ,
        // hence their hash.
        results.as_object_mut().unwrap().remove("outputs");
        results.as_object_mut().unwrap().remove("provenance");
        if let Some(check) = results.pointer_mut("/quality/step_halving") {
            check["seconds"] = json!(0.0);
        }
        let forces = app
            .get(&format!("/jobs/{job}/results/contact_forces"))
            .await
            .text()
            .await
            .unwrap();
        documents.push((results, forces));
    }
    assert!(
        documents[0] == documents[1],
        "{process}: one and two threads differ"
    );
    documents
}

/// The hex bundle on one and on two threads (its steps shared): the same results.
#[tokio::test]
async fn a_hex_bundle_gives_the_same_results_on_one_and_two_threads() {
    let app = spawn_app_with_processes(vec![Arc::new(HexBundleDynamics)], |config| config.workers = 2).await;
    let documents = on_one_and_two_threads(&app, "hex-bundle-dynamics", bundle).await;
    let impacts = documents[0].0["impacts"].as_u64().unwrap();
    assert!(impacts > 0, "the bundle rattles");
}

/// A row with its step check on one and on two threads (the run and the check's
/// repetition at once): the same results, the same verdict.
#[tokio::test]
async fn a_checked_row_gives_the_same_results_on_one_and_two_threads() {
    use chocmodal::processes::bundle_dynamics::BundleDynamics;
    let app = spawn_app_with_processes(vec![Arc::new(BundleDynamics)], |config| config.workers = 2).await;
    let row = |threads: usize| {
        json!({"inputs": {
            "pin": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                    "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085}},
            "bundle": {"pins": 3, "levels": [1.0], "stiffness": 1e6, "damping": 20.0,
                       "wall_gap": 1e-4, "pin_gap": 1e-4},
            "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 50.0, "duration": 0.01}},
            "solver": {"duration": 0.05, "threads": threads}
        }})
    };
    let documents = on_one_and_two_threads(&app, "bundle-dynamics", row).await;
    let results = &documents[0].0;
    assert!(
        results["impacts"].as_u64().unwrap() > 0,
        "the row rattles: {results}"
    );
    assert!(
        results["quality"]["step_halving"].is_object(),
        "checked: {}",
        results["quality"]
    );
}

/// Only large hex bundles share their steps: a row process or a small bundle asking for
/// threads is granted two cores where its check repeats the run (the run and the
/// repetition at once), one without a check: not cores it would leave idle.
#[test]
fn processes_are_granted_the_threads_they_can_use() {
    use chocmodal::processes::Process;
    use chocmodal::processes::bundle_dynamics::BundleDynamics;
    use chocmodal::processes::cantilever_impact::CantileverImpact;
    let asking = |threads: u64| json!({"solver": {"threads": threads}});
    let hex = |rings: u64, check: &str| json!({"bundle": {"rings": rings}, "pin": {"modes": 10}, "solver": {"threads": 4, "check": check}});
    // 217 pins of 10 modes: 4 340 modal DOFs, shared; 19 pins: 380, too few.
    assert_eq!(HexBundleDynamics.threads(&hex(8, "auto")), 4);
    assert_eq!(HexBundleDynamics.threads(&hex(8, "none")), 4);
    assert_eq!(HexBundleDynamics.threads(&hex(2, "auto")), 2);
    assert_eq!(HexBundleDynamics.threads(&hex(2, "none")), 1);
    assert!(
        HexBundleDynamics.threads(&bundle(4)["inputs"]) == 4,
        "the shared test bundle"
    );
    assert_eq!(HexBundleDynamics.threads(&json!({})), 1);
    assert_eq!(BundleDynamics.threads(&asking(4)), 2);
    assert_eq!(CantileverImpact.threads(&asking(4)), 2);
    assert_eq!(BundleDynamics.threads(&json!({})), 1);
    let unchecked = json!({"solver": {"threads": 4, "check": "none"}});
    assert_eq!(BundleDynamics.threads(&unchecked), 1);
    assert_eq!(CantileverImpact.threads(&unchecked), 1);
}
