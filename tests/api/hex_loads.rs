//! Point forces and tip releases of `hex-bundle-dynamics` over HTTP, against physics.
//!
//! A pin of the bundle bends along x and y on the row's modal basis, the two directions
//! uncoupled while no contact closes. So in a bundle whose gaps never close, a pin pushed
//! (or released) along θ moves along θ exactly as the one-pin `bundle-dynamics` row
//! moves under the same load along x: x(t) = cos θ u(t), y(t) = sin θ u(t), the other
//! pins never moving. When the centre pin is plucked into its neighbours, the contacts
//! between pins push both equal and opposite (Newton's third law): the sum of the seven
//! pins' deflections feels no contact and swings as a lone pin released by the same tip
//! deflection, while the energy balance closes. Bad loads are refused with a 422 at
//! their pointers.

use std::sync::Arc;

use reqwest::StatusCode;
use serde_json::{Value, json};

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::hex_bundle_dynamics::HexBundleDynamics;

use crate::helpers::{TestApp, assert_problem, spawn_app_with_processes};

/// Fixed step (s) and duration (s) of every run, so that the row and the bundle take
/// the same steps.
const STEP: f64 = 2e-5;
const DURATION: f64 = 0.06;

async fn spawn() -> TestApp {
    spawn_app_with_processes(
        vec![Arc::new(BundleDynamics), Arc::new(HexBundleDynamics)],
        |_| {},
    )
    .await
}

/// The pin of both processes: 0.6 m, four modes, no static correction (the row has no
/// contact, the bundle's never close: the same basis).
fn pin() -> Value {
    json!({"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
           "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "damping_ratio": 0.01,
           "static_correction": "none"})
}

fn solver() -> Value {
    json!({"time_step": STEP, "duration": DURATION, "check": "none"})
}

/// Seven pins with gaps of `pin_pin` between clads and `pin_wall` to the wrapper (m).
fn bundle(pin_pin: f64, pin_wall: f64) -> Value {
    json!({"pin": pin(),
           "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                      "wrapper_flat_to_flat": 0.0305},
           "contact": {"stiffness": 2e5, "damping": 5.0},
           "gaps": {"type": "uniform", "pin_pin": pin_pin, "pin_wall": pin_wall},
           "solver": solver(),
           "output": {"interval": 1e-3, "contacts": {"type": "all"}}})
}

/// Seven pins whose gaps (2 cm) no load here closes.
fn open_bundle() -> Value {
    bundle(0.02, 0.02)
}

/// One pin alone: no wall, no contact.
fn lone_pin() -> Value {
    json!({"pin": pin(), "pins": 1, "contacts": [], "solver": solver(),
           "output": {"interval": 1e-3}})
}

/// A push at 0.4 m that reverses and stops at 30 ms (N along the force's direction).
fn push() -> Value {
    json!({"height": 0.4, "time": [0.0, 0.01, 0.02, 0.03], "force": [0.0, 0.5, -0.2, 0.0]})
}

/// Runs a job to success; its id.
async fn succeed(app: &TestApp, process: &str, inputs: Value) -> String {
    app.succeed(process, &json!({"inputs": inputs})).await
}

/// Runs a job to success; its results document and `displacements` history.
async fn run(app: &TestApp, process: &str, inputs: Value) -> (Value, Value) {
    let id = succeed(app, process, inputs).await;
    (
        app.get_json(&format!("/jobs/{id}/results")).await,
        app.get_json(&format!("/jobs/{id}/results/displacements")).await,
    )
}

/// The series `name` of a history document.
fn series(history: &Value, name: &str) -> Vec<f64> {
    history["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no series {name}"))["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

fn peak(values: &[f64]) -> f64 {
    values.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// Pin `pin` of the bundle moves along θ by the row's pin 0: its x and y tip histories
/// are cos θ and sin θ times the row's to 1e-9 of the row's peak; every other pin stays
/// exactly straight; the load's work is the row's.
fn assert_turned_row(
    what: &str,
    (bundle, history): &(Value, Value),
    row: &(Value, Value),
    pin: usize,
    degrees: f64,
) {
    let u = series(&row.1, "p0");
    let scale = peak(&u);
    assert!(scale > 1e-5, "{what}: the row's pin must move ({scale:e} m)");
    let (cos, sin) = (degrees.to_radians().cos(), degrees.to_radians().sin());
    let (x, y) = (
        series(history, &format!("p{pin}x")),
        series(history, &format!("p{pin}y")),
    );
    assert_eq!(x.len(), u.len(), "{what}: the same samples");
    for (k, u) in u.iter().enumerate() {
        for (axis, measured, expected) in [("x", x[k], cos * u), ("y", y[k], sin * u)] {
            assert!(
                (measured - expected).abs() <= 1e-9 * scale,
                "{what}, θ {degrees}°, sample {k}: {axis} measured {measured:e}, expected {expected:e}"
            );
        }
    }
    for other in (0..7).filter(|p| *p != pin) {
        for axis in ["x", "y"] {
            let name = format!("p{other}{axis}");
            assert_eq!(peak(&series(history, &name)), 0.0, "{what}: {name} moves");
        }
    }
    assert!(
        bundle["contacts"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["max_force"] == 0.0),
        "{what}: a contact closed"
    );
    let (work, expected) = (
        bundle["energy"]["external_work"].as_f64().unwrap(),
        row.0["energy"]["external_work"].as_f64().unwrap(),
    );
    let energy_scale = expected.abs() + row.0["energy"]["initial"].as_f64().unwrap();
    assert!(
        (work - expected).abs() <= 1e-9 * energy_scale,
        "{what}, θ {degrees}°: external work {work:e}, the row's {expected:e}"
    );
}

#[tokio::test]
async fn a_point_force_along_theta_moves_its_pin_along_theta_by_the_rows_response() {
    let app = spawn().await;
    let mut row = lone_pin();
    let mut force = push();
    force["pin"] = json!(0);
    row["excitation"] = json!({"point_forces": [force]});
    let row = run(&app, "bundle-dynamics", row).await;
    for degrees in [0.0, 37.0] {
        let mut hex = open_bundle();
        let mut force = push();
        force["pin"] = json!(3);
        force["direction"] = json!(degrees);
        hex["excitation"] = json!({"point_forces": [force]});
        let hex = run(&app, "hex-bundle-dynamics", hex).await;
        assert_turned_row("point force", &hex, &row, 3, degrees);
    }
}

#[tokio::test]
async fn a_tip_release_or_throw_along_theta_swings_its_pin_along_theta_like_the_row() {
    let app = spawn().await;
    let release = 1e-3;
    let mut row = lone_pin();
    row["initial"] = json!({"tip_displacements": [release]});
    let row = run(&app, "bundle-dynamics", row).await;
    for degrees in [0.0, 37.0] {
        let radians = f64::to_radians(degrees);
        let mut hex = open_bundle();
        hex["initial"] = json!({"tip_displacements": [
            {"pin": 5, "x": release * radians.cos(), "y": release * radians.sin()}]});
        let hex = run(&app, "hex-bundle-dynamics", hex).await;
        assert_turned_row("release", &hex, &row, 5, degrees);
    }
    // Thrown along θ from straight: the row's pin thrown at the same speed, turned.
    let speed = 0.05;
    let mut row = lone_pin();
    row["initial"] = json!({"tip_velocities": [speed]});
    let row = run(&app, "bundle-dynamics", row).await;
    for degrees in [0.0, 37.0] {
        let radians = f64::to_radians(degrees);
        let mut hex = open_bundle();
        hex["initial"] = json!({"tip_velocities": [
            {"pin": 5, "x": speed * radians.cos(), "y": speed * radians.sin()}]});
        let hex = run(&app, "hex-bundle-dynamics", hex).await;
        assert_turned_row("throw", &hex, &row, 5, degrees);
    }
}

/// The centre pin plucked by 0.1 mm toward pin 2 (at 60°) across 20 µm gaps: it starts
/// pressed into its neighbours (pin 2 among them), which it throws away, and rattles
/// between them. Pin–pin contacts push both pins equal and opposite, so the sum of the
/// seven pins' deflections is the lone pin's release by 0.1 mm along 60° (the wrapper,
/// 5 mm away, is never reached); the energy balance closes.
#[tokio::test]
async fn a_plucked_centre_pin_hits_its_neighbours_with_equal_and_opposite_forces() {
    let app = spawn().await;
    let release = 1e-4;
    let (cos, sin) = (60f64.to_radians().cos(), 60f64.to_radians().sin());
    let mut hex = bundle(2e-5, 5e-3);
    hex["initial"] = json!({"tip_displacements": [{"pin": 0, "x": release * cos, "y": release * sin}]});
    let mut row = lone_pin();
    row["initial"] = json!({"tip_displacements": [release]});
    let (results, history) = run(&app, "hex-bundle-dynamics", hex).await;
    let (_, lone) = run(&app, "bundle-dynamics", row).await;

    let contacts = results["contacts"].as_array().unwrap();
    let pair = |c: &Value| {
        let bodies = (c["wire_pin"].as_u64(), c["touched_pin"].as_u64());
        bodies == (Some(0), Some(2)) || bodies == (Some(2), Some(0))
    };
    let pair_impulse: f64 = contacts
        .iter()
        .filter(|c| pair(c))
        .map(|c| c["impulse"].as_f64().unwrap())
        .sum();
    assert!(pair_impulse > 0.0, "the centre pin must hit pin 2");
    assert!(
        contacts
            .iter()
            .filter(|c| c["touched_flat"].is_number())
            .all(|c| c["max_force"] == 0.0),
        "the wrapper must stay out of reach"
    );
    let moved = peak(&series(&history, "p2x")).max(peak(&series(&history, "p2y")));
    assert!(moved > 0.1 * release, "pin 2 is thrown: {moved:e} m");

    let u = series(&lone, "p0");
    let scale = peak(&u);
    let sum = |axis: &str| -> Vec<f64> {
        let columns: Vec<Vec<f64>> = (0..7).map(|p| series(&history, &format!("p{p}{axis}"))).collect();
        (0..u.len()).map(|k| columns.iter().map(|c| c[k]).sum()).collect()
    };
    for (axis, factor) in [("x", cos), ("y", sin)] {
        for (k, (total, u)) in sum(axis).iter().zip(&u).enumerate() {
            assert!(
                (total - factor * u).abs() <= 1e-9 * scale,
                "sum of the pins along {axis} at sample {k}: {total:e}, the lone pin's {:e}",
                factor * u
            );
        }
    }
    let energy = &results["energy"];
    assert!(energy["dissipated_contact"].as_f64().unwrap() > 0.0, "{energy}");
    let residual = results["quality"]["energy_residual"].as_f64().unwrap();
    assert!(residual < 1e-3, "energy residual {residual:e}: {energy}");
}

#[tokio::test]
async fn bad_point_forces_and_releases_are_refused_at_their_pointers() {
    let app = spawn().await;
    let mut hex = open_bundle();
    hex["initial"] = json!({"tip_displacements": [
        {"pin": 1, "x": 1e-3, "y": 0.0},
        {"pin": 7, "x": 1e-3, "y": 0.0},
        {"pin": 1, "x": 0.0, "y": 1e-3}]});
    hex["excitation"] = json!({"point_forces": [
        {"pin": 12, "height": 0.3, "time": [0.0, 0.01], "force": [0.0, 1.0]},
        {"pin": 0, "height": 0.61, "direction": 45.0, "time": [0.0, 0.01], "force": [0.0, 1.0]},
        {"pin": 0, "height": 0.3, "time": [0.01], "force": [1.0]},
        {"pin": 0, "height": 0.3, "time": [-0.01, 0.01], "force": [1.0, 0.0]}]});
    let response = app
        .post_execution("hex-bundle-dynamics", &json!({"inputs": hex}))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    let errors: Vec<(&str, &str)> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e["pointer"].as_str().unwrap(), e["detail"].as_str().unwrap()))
        .collect();
    for (pointer, reason) in [
        ("/inputs/initial/tip_displacements/1/pin", "7 pins"),
        ("/inputs/initial/tip_displacements/2/pin", "released twice"),
        ("/inputs/excitation/point_forces/0/pin", "7 pins"),
        ("/inputs/excitation/point_forces/1/height", "0 to 0.6 m"),
        ("/inputs/excitation/point_forces/2/time", "at least two samples"),
        ("/inputs/excitation/point_forces/3/time/0", "must not be negative"),
    ] {
        let found = errors.iter().find(|(p, _)| *p == pointer);
        let Some((_, detail)) = found else {
            panic!("no error at {pointer}: {errors:?}");
        };
        assert!(detail.contains(reason), "{pointer}: {detail} (expected {reason})");
    }
    assert_eq!(errors.len(), 6, "{errors:?}");

    let mut held = open_bundle();
    held["pin"]["supports"] = json!({"foot": "clamped", "top": "pinned"});
    held["initial"] = json!({"tip_displacements": [{"pin": 0, "x": 1e-3, "y": 0.0}]});
    let response = app
        .post_execution("hex-bundle-dynamics", &json!({"inputs": held}))
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
    assert_eq!(
        problem["errors"][0]["pointer"], "/inputs/initial/tip_displacements",
        "{problem}"
    );
    assert!(
        problem["errors"][0]["detail"]
            .as_str()
            .unwrap()
            .contains("free top"),
        "{problem}"
    );
}

/// Two horizontal components at once: with gaps that never close, every pin's x motion
/// is the lone pin's under the x component alone and its y motion the lone pin's under
/// the y component (the directions are uncoupled), and the `excitation` history gives
/// both components, as given, at every sample of the record and at the output times.
#[tokio::test]
async fn two_components_of_a_base_shock_move_the_pins_along_each_axis_as_the_row() {
    let app = spawn().await;
    let along_x = json!({"type": "half_sine", "amplitude": 30.0, "duration": 0.01});
    // A record sampled every 0.7 ms, off the output grid (1 ms).
    let times: Vec<f64> = (0..=40).map(|k| k as f64 * 7e-4).collect();
    let values: Vec<f64> = times
        .iter()
        .map(|t| 20.0 * (t * 400.0_f64).sin() * (1.0 - t / 0.028))
        .collect();
    let along_y = json!({"type": "table", "time": times, "acceleration": values});
    let mut inputs = open_bundle();
    inputs["excitation"] = json!({"base_acceleration_x": along_x, "base_acceleration_y": along_y});
    let id = succeed(&app, "hex-bundle-dynamics", inputs).await;
    let history = app.get_json(&format!("/jobs/{id}/results/displacements")).await;

    for (axis, signal) in [("x", &along_x), ("y", &along_y)] {
        let mut row = lone_pin();
        row["excitation"] = json!({"base_acceleration": signal});
        let (_, row_history) = run(&app, "bundle-dynamics", row).await;
        let u = series(&row_history, "p0");
        let scale = peak(&u);
        assert!(scale > 1e-6, "{axis}: the lone pin must move ({scale:e} m)");
        for pin in 0..7 {
            let moved = series(&history, &format!("p{pin}{axis}"));
            assert_eq!(moved.len(), u.len());
            for (k, (m, e)) in moved.iter().zip(&u).enumerate() {
                assert!(
                    (m - e).abs() <= 1e-9 * scale,
                    "pin {pin} along {axis}, sample {k}: {m:e} against the row's {e:e}"
                );
            }
        }
    }

    let excitation = app.get_json(&format!("/jobs/{id}/results/excitation")).await;
    let time: Vec<f64> = excitation["time"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    let (x, y) = (
        series(&excitation, "base_acceleration_x"),
        series(&excitation, "base_acceleration_y"),
    );
    for t in &times {
        assert!(
            time.iter().any(|s| (s - t).abs() < 1e-12),
            "the record's sample at {t} s is missing"
        );
    }
    for k in 0..=60 {
        let t = k as f64 * 1e-3;
        assert!(
            time.iter().any(|s| (s - t).abs() < 1e-12),
            "output time {t} s is missing"
        );
    }
    for (k, t) in time.iter().enumerate() {
        let exact_x = if *t <= 0.01 {
            30.0 * (std::f64::consts::PI * t / 0.01).sin()
        } else {
            0.0
        };
        assert!((x[k] - exact_x).abs() <= 1e-12 * 30.0, "x at {t} s: {}", x[k]);
        // Linear between the record's samples, 0 after the last.
        let j = times.partition_point(|s| s <= t);
        let exact_y = match j {
            0 => 0.0,
            j if j == times.len() => {
                if (t - times[j - 1]).abs() < 1e-15 {
                    values[j - 1]
                } else {
                    0.0
                }
            }
            j => {
                let w = (t - times[j - 1]) / (times[j] - times[j - 1]);
                values[j - 1] + w * (values[j] - values[j - 1])
            }
        };
        assert!(
            (y[k] - exact_y).abs() <= 1e-12 * 20.0,
            "y at {t} s: {} against {exact_y}",
            y[k]
        );
    }
}
