//! Point forces and tip releases of `hex-bundle-dynamics` as the process reads them: a
//! load along θ lands on the pin's x and y lines as cos θ and sin θ (exactly 0 and ±1
//! along the axes), a release on its two lines, every bad value is refused at its
//! pointer with the bound it broke, a force or a release counts as excitation, and the
//! `auto` step resolves a force's samples.

use serde_json::{Value, json};

use super::*;
use crate::processes::Process;
use crate::processes::hex_bundle_dynamics::HexBundleDynamics;
use crate::processes::warnings::WarningCode;

/// A 7-pin bundle of 0.6 m pins at rest: no base excitation.
fn inputs() -> Value {
    json!({
        "pin": {"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "static_correction": "none"},
        "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                   "wrapper_flat_to_flat": 0.0305},
        "contact": {"stiffness": 2e6, "damping": 20.0},
        "gaps": {"type": "uniform", "pin_pin": 5e-5, "pin_wall": 1e-4},
        "solver": {"duration": 0.01, "check": "none"},
        "output": {"interval": 1e-3}
    })
}

fn force(pin: usize, direction: Option<f64>) -> Value {
    let mut force = json!({"pin": pin, "height": 0.4, "time": [0.0, 0.01, 0.02],
                           "force": [0.0, 2.0, -1.0]});
    if let Some(direction) = direction {
        force["direction"] = json!(direction);
    }
    force
}

fn loads_of(inputs: &Value) -> PlaneLoads {
    let parsed: HexInputs = serde_json::from_value(inputs.clone()).expect("valid inputs");
    let mut errors = Vec::new();
    let loads = plane_loads(&parsed, &mut errors);
    assert_eq!(errors, vec![], "{inputs}");
    loads
}

/// Pointer and detail of every refusal.
fn errors(inputs: &Value) -> Vec<(String, String)> {
    HexBundleDynamics
        .validate(inputs)
        .expect_err("invalid")
        .0
        .into_iter()
        .map(|e| (e.pointer, e.detail))
        .collect()
}

#[test]
fn axis_directions_have_exact_factors() {
    for (degrees, expected) in [
        (0.0, (1.0, 0.0)),
        (90.0, (0.0, 1.0)),
        (180.0, (-1.0, 0.0)),
        (270.0, (0.0, -1.0)),
        (360.0, (1.0, 0.0)),
        (-90.0, (0.0, -1.0)),
        (450.0, (0.0, 1.0)),
        (-1e-300, (1.0, 0.0)),
    ] {
        assert_eq!(direction_factors(degrees), expected, "{degrees}°");
    }
    let radians = 37f64.to_radians();
    let (cos, sin) = direction_factors(37.0);
    assert_eq!((cos, sin), (radians.cos(), radians.sin()));
    assert_eq!(
        direction_factors(397.0),
        (cos, sin),
        "a turn more is the same angle"
    );
    let (cos, sin) = direction_factors(-37.0);
    assert!((cos - radians.cos()).abs() < 1e-15 && (sin + radians.sin()).abs() < 1e-15);
}

/// Pin p along x is line p, along y line 7 + p: a force along 37° is two line forces,
/// one along 90° or left at 0° loads its axis alone with the force as given; a release
/// (or an initial velocity) fills both lines of its pin and leaves the others straight
/// (or at rest).
#[test]
fn loads_land_on_the_pins_x_and_y_lines() {
    let mut inputs = inputs();
    inputs["excitation"] = json!({"point_forces": [force(3, Some(37.0)), force(5, Some(90.0)),
                                                   force(2, None), force(6, Some(-180.0))]});
    inputs["initial"] = json!({"tip_displacements": [{"pin": 4, "x": 1e-3, "y": -2e-4}],
                               "tip_velocities": [{"pin": 1, "x": -0.5, "y": 0.25}]});
    let loads = loads_of(&inputs);
    let given = [0.0, 2.0, -1.0];
    let (cos, sin) = (37f64.to_radians().cos(), 37f64.to_radians().sin());
    let lines: Vec<(usize, Vec<f64>)> = loads
        .point_forces
        .iter()
        .map(|f| {
            assert_eq!(f.height, 0.4);
            assert_eq!(f.force.time, [0.0, 0.01, 0.02]);
            (f.line, f.force.values.clone())
        })
        .collect();
    assert_eq!(
        lines,
        [
            (3, given.map(|f| cos * f).to_vec()),
            (10, given.map(|f| sin * f).to_vec()),
            (12, given.to_vec()),
            (2, given.to_vec()),
            (6, given.map(|f| -f).to_vec()),
        ]
    );
    let mut tips = vec![0.0; 14];
    (tips[4], tips[11]) = (1e-3, -2e-4);
    assert_eq!(loads.initial_tip_displacements, tips);
    let mut velocities = vec![0.0; 14];
    (velocities[1], velocities[8]) = (-0.5, 0.25);
    assert_eq!(loads.initial_tip_velocities, velocities);
    assert_eq!(
        loads_of(&self::inputs()),
        PlaneLoads::default(),
        "no load: no line force, no release (not 14 zeros)"
    );
}

#[test]
fn bad_loads_are_refused_at_their_pointers_with_the_bound() {
    let mut bad = inputs();
    bad["excitation"] = json!({"point_forces": [
        force(7, Some(10.0)),
        {"pin": 1, "height": 0.7, "time": [0.0, 0.01], "force": [1.0, 1.0]},
        {"pin": 1, "height": 0.3, "time": [0.0, 0.02, 0.01], "force": [1.0, 2.0]}
    ]});
    bad["initial"] = json!({"tip_displacements": [
        {"pin": 2, "x": 1e-3, "y": 0.0},
        {"pin": 9, "x": 1e-3, "y": 0.0},
        {"pin": 2, "x": 0.0, "y": 1e-3}
    ], "tip_velocities": [
        {"pin": 3, "x": 0.1, "y": 0.0},
        {"pin": 3, "x": 0.0, "y": 0.1},
        {"pin": 7, "x": 0.0, "y": 0.1}
    ]});
    let errors = errors(&bad);
    let pointers: Vec<&str> = errors.iter().map(|(p, _)| p.as_str()).collect();
    let expected = [
        ("/inputs/initial/tip_displacements/1/pin", "7 pins (0 to 6)"),
        (
            "/inputs/initial/tip_displacements/2/pin",
            "released twice (also by tip_displacements/0)",
        ),
        (
            "/inputs/initial/tip_velocities/1/pin",
            "given a velocity twice (also by tip_velocities/0)",
        ),
        ("/inputs/initial/tip_velocities/2/pin", "7 pins (0 to 6)"),
        ("/inputs/excitation/point_forces/0/pin", "7 pins (0 to 6)"),
        ("/inputs/excitation/point_forces/1/height", "0 to 0.6 m"),
        (
            "/inputs/excitation/point_forces/2/force",
            "as many samples as `time` (2 vs 3)",
        ),
        ("/inputs/excitation/point_forces/2/time/2", "strictly increasing"),
    ];
    assert_eq!(pointers, expected.map(|(p, _)| p), "{errors:?}");
    for ((_, detail), (pointer, bound)) in errors.iter().zip(expected) {
        assert!(detail.contains(bound), "{pointer}: {detail} (expected {bound})");
    }
}

/// Values no JSON number gives (the checks do not rely on the parser).
#[test]
fn non_finite_loads_are_refused_at_their_members() {
    let mut parsed: HexInputs = serde_json::from_value({
        let mut inputs = inputs();
        inputs["excitation"] = json!({"point_forces": [force(1, None)]});
        inputs["initial"] = json!({"tip_displacements": [{"pin": 2, "x": 0.0, "y": 0.0}]});
        inputs
    })
    .expect("valid inputs");
    parsed.excitation.point_forces[0].direction = f64::INFINITY;
    parsed.excitation.point_forces[0].height = f64::NAN;
    parsed.initial.tip_displacements[0].y = f64::NAN;
    let mut errors = Vec::new();
    let loads = plane_loads(&parsed, &mut errors);
    let pointers: Vec<&str> = errors.iter().map(|e| e.pointer.as_str()).collect();
    assert_eq!(
        pointers,
        [
            "/inputs/initial/tip_displacements/0/y",
            "/inputs/excitation/point_forces/0/height",
            "/inputs/excitation/point_forces/0/direction",
        ]
    );
    assert!(loads.point_forces.is_empty());
    assert!(loads.initial_tip_displacements.iter().all(|t| *t == 0.0));
}

/// A pin whose top is held has no tip-load shape: a release is refused at the list, as
/// for the row, and one of zeros is no release.
#[test]
fn a_tip_release_needs_a_free_top() {
    let mut inputs = inputs();
    inputs["pin"]["supports"] = json!({"foot": "clamped", "top": "pinned"});
    inputs["excitation"] = json!({"point_forces": [force(0, None)]});
    inputs["initial"] = json!({"tip_displacements": [{"pin": 0, "x": 0.0, "y": 0.0}]});
    HexBundleDynamics
        .validate(&inputs)
        .expect("a release of zeros on a held top");
    inputs["initial"]["tip_displacements"][0]["y"] = json!(1e-4);
    let errors = errors(&inputs);
    assert_eq!(errors.len(), 1, "{errors:?}");
    let (pointer, detail) = &errors[0];
    assert_eq!(pointer, "/inputs/initial/tip_displacements");
    assert!(
        detail.contains("free top") && detail.contains("pinned"),
        "{detail}"
    );
}

/// As for the row, a point force or a release moves the bundle: no `nothing_excites`.
#[test]
fn a_point_force_or_a_release_excites_the_bundle() {
    let excites = |inputs: &Value| {
        let validated = HexBundleDynamics.validate(inputs).expect("valid inputs");
        !validated
            .warnings
            .iter()
            .any(|w| w.code == WarningCode::NothingExcites)
    };
    assert!(!excites(&inputs()), "a bundle at rest, unloaded");
    let mut pushed = inputs();
    pushed["excitation"] = json!({"point_forces": [force(0, Some(45.0))]});
    assert!(excites(&pushed));
    let mut released = inputs();
    released["initial"] = json!({"tip_displacements": [{"pin": 6, "x": 0.0, "y": 1e-3}]});
    assert!(excites(&released));
}

/// The `auto` step resolves a point force's table: sampled every 2 µs, it sets a step
/// of at most 2 µs (the row's rule), the quality report naming the excitation.
#[test]
fn the_auto_step_resolves_a_point_forces_samples() {
    let mut inputs = inputs();
    inputs["solver"] = json!({"duration": 1e-3, "check": "none"});
    inputs["output"] = json!({"interval": 1e-4});
    let time: Vec<f64> = (0..=50).map(|k| k as f64 * 2e-6).collect();
    let force: Vec<f64> = time.iter().map(|t| 1e5 * t).collect();
    inputs["excitation"] = json!({"point_forces": [
        {"pin": 3, "height": 0.3, "direction": 200.0, "time": time, "force": force}]});
    let output = HexBundleDynamics
        .run(&inputs, &mut |_| std::ops::ControlFlow::Continue(()))
        .expect("runs");
    let document = &output.document;
    let step = document["time_step"].as_f64().unwrap();
    assert!(step <= 2e-6, "time step {step:e} s");
    assert_eq!(
        document["quality"]["time_step_limited_by"], "excitation",
        "{}",
        document["quality"]
    );
}
