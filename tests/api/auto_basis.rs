//! `modes: "auto"` and `elements: "auto"` over HTTP: the results say what was chosen and
//! why, the run's own probes then find the basis and the mesh within the bound the
//! choice met (10 × the tolerance), a given count is reported as given, and a bound no
//! mesh can meet is refused up front at `elements` with the numbers.

use reqwest::StatusCode;
use serde_json::{Value, json};

use crate::helpers::{Backend, TestApp, spawn_app_with_shipped_processes_on};

/// The public cantilever case, 0.05 s, without the step-halving check (cheap).
fn cantilever(beam: Value, tolerance: f64) -> Value {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/cantilever-impact.json"
    ))
    .unwrap();
    let mut body: Value = serde_json::from_str(&text).unwrap();
    for (key, value) in beam.as_object().unwrap() {
        body["inputs"]["beam"][key] = value.clone();
    }
    let solver = &mut body["inputs"]["solver"];
    solver["duration"] = json!(0.05);
    solver["check"] = json!("none");
    solver["time_step"] = json!("auto");
    solver["tolerance"] = json!(tolerance);
    body
}

async fn results_of(app: &TestApp, body: &Value) -> Value {
    app.results_of("cantilever-impact", body).await
}

#[tokio::test]
async fn auto_chooses_a_basis_and_mesh_that_the_runs_own_probes_find_within_the_bound() {
    let app = spawn_app_with_shipped_processes_on(Backend::Sqlite).await;
    let tolerance = 1e-3;
    let auto = results_of(
        &app,
        &cantilever(json!({"modes": "auto", "elements": "auto"}), tolerance),
    )
    .await;
    let basis = &auto["basis"];
    assert_eq!(
        basis["chosen_by"],
        json!({"modes": "auto", "elements": "auto"}),
        "{basis}"
    );
    let bound = 10.0 * tolerance;
    assert_eq!(basis["auto"]["target"].as_f64().unwrap(), bound);
    for key in ["estimated_basis_error", "estimated_mesh_error"] {
        let estimate = basis["auto"][key].as_f64().unwrap();
        assert!((0.0..=bound).contains(&estimate), "{key}: {basis}");
    }
    // The run probes the contacts that pushed, a subset of those the choice probed.
    let quality = &auto["quality"];
    for key in ["modal_truncation", "mesh"] {
        let estimate = quality[key]["estimated_peak_force_error"].as_f64().unwrap();
        assert!(estimate <= bound, "{key}: {quality}");
    }
    let modes = basis["modes"].as_u64().unwrap();
    let elements = basis["elements"].as_u64().unwrap();
    assert!(modes >= 1 && elements >= 40, "{basis}");

    // A looser bound never needs more.
    let loose = results_of(
        &app,
        &cantilever(json!({"modes": "auto", "elements": "auto"}), 1e-2),
    )
    .await;
    assert!(
        loose["basis"]["modes"].as_u64().unwrap() <= modes,
        "{}",
        loose["basis"]
    );

    // Given counts are reported as given, with no `auto` entry.
    let given = results_of(&app, &cantilever(json!({"modes": 5, "elements": 20}), tolerance)).await;
    assert_eq!(
        given["basis"]["chosen_by"],
        json!({"modes": "given", "elements": "given"})
    );
    assert_eq!(given["basis"]["auto"], Value::Null);
    assert_eq!(given["basis"]["elements"], 20);
}

#[tokio::test]
async fn a_bound_no_mesh_can_meet_is_refused_at_elements_with_the_numbers() {
    let app = spawn_app_with_shipped_processes_on(Backend::Sqlite).await;
    let body = cantilever(json!({"elements": "auto"}), 1e-9);
    let response = app.post_execution("cantilever-impact", &body).await;
    assert_eq!(response.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let problem: Value = response.json().await.unwrap();
    let text = problem.to_string();
    assert!(text.contains("/inputs/beam/elements"), "{text}");
    assert!(
        text.contains("no mesh up to") && text.contains("solver.tolerance"),
        "{text}"
    );

    // A word other than `auto` is named.
    let body = cantilever(json!({"modes": "many"}), 1e-3);
    let response = app.post_execution("cantilever-impact", &body).await;
    assert_eq!(response.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let text = response.text().await.unwrap();
    assert!(
        text.contains("/inputs/beam/modes") && text.contains("auto"),
        "{text}"
    );
}

/// `examples/bundle-row17-proven.json`: the 17-pin row with `modes` and `elements` at
/// `auto` (static correction on) under `exact_modal`, check included, is `good`: its
/// step, basis and mesh all checked. Central difference on the same inputs (its own
/// step, proven by its own check) is `good` too and finds the same peak contact force
/// within the verdict's bound for peaks (10 × the default tolerance). The shipped row17
/// (20 modes, no correction) is not `good`, and its peak is off by more than that bound.
#[tokio::test]
async fn the_proven_row17_example_is_good_and_right_where_the_shipped_basis_is_not() {
    let app = spawn_app_with_shipped_processes_on(Backend::Sqlite).await;
    let example = |name: &str| -> Value {
        let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    let peak = |results: &Value| {
        results["contacts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["max_force"].as_f64().unwrap())
            .fold(0.0, f64::max)
    };
    let proven_body = example("bundle-row17-proven.json");
    assert_eq!(proven_body["inputs"]["solver"]["scheme"], "exact_modal");
    let proven = app.results_of("bundle-dynamics", &proven_body).await;
    assert_eq!(proven["quality"]["verdict"], "good", "{}", proven["quality"]);
    assert_eq!(
        proven["basis"]["chosen_by"],
        json!({"modes": "auto", "elements": "auto"})
    );
    let mut explicit_body = proven_body.clone();
    explicit_body["inputs"]["solver"]["scheme"] = json!("central_difference");
    let explicit = app.results_of("bundle-dynamics", &explicit_body).await;
    assert_eq!(explicit["quality"]["verdict"], "good", "{}", explicit["quality"]);
    let bound = 10.0 * 1e-3;
    let (exact_peak, explicit_peak) = (peak(&proven), peak(&explicit));
    assert!(
        (exact_peak - explicit_peak).abs() <= bound * explicit_peak,
        "peak {exact_peak} N (exact_modal) vs {explicit_peak} N (central difference)"
    );
    assert!(
        proven["steps"].as_u64().unwrap() * 5 < explicit["steps"].as_u64().unwrap(),
        "steps {} (exact_modal) vs {} (central difference)",
        proven["steps"],
        explicit["steps"]
    );
    let shipped = app
        .results_of("bundle-dynamics", &example("bundle-row17.json"))
        .await;
    assert_ne!(shipped["quality"]["verdict"], "good", "{}", shipped["quality"]);
    let off = (peak(&shipped) - explicit_peak).abs() / explicit_peak;
    assert!(off > bound, "the shipped basis is off by {off}");
}
