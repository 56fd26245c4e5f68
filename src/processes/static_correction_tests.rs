//! The static correction (`beam.static_correction`, `pin.static_correction`) through the
//! processes: it makes few modes as accurate as many at a stiff contact (f_err against
//! the semi-analytic reference, peak force against the complete finite-element basis),
//! the results list the basis used, and bad inputs are refused at their pointer.

use std::ops::ControlFlow;

use serde_json::{Value, json};

use super::bundle_dynamics::BundleDynamics;
use super::cantilever_impact::CantileverImpact;
use super::{Process, RunOutput};

fn cantilever(rk: f64, elements: usize, modes: usize, correction: &str, duration: f64) -> Value {
    json!({
        "beam": {
            "length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
            "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
            "elements": elements, "modes": modes, "damping_ratio": 0.01,
            "static_correction": correction
        },
        "contact": {"rk": rk},
        "release": {"tip_displacement": 0.001},
        "solver": {"time_step": 1e-5, "duration": duration},
        "reference": {"modes": 30}
    })
}

fn run(process: &dyn Process, inputs: &Value) -> RunOutput {
    process.validate(inputs).expect("valid inputs");
    process
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .expect("run succeeds")
}

fn number(document: &Value, pointer: &str) -> f64 {
    document
        .pointer(pointer)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("no number at {pointer}"))
}

/// At Rk = 80 (BRIEF §7) the dropped modes' flexibility at the tip matters: 5 modes plus
/// the tip pseudo-mode reproduce the semi-analytic spectrum better than 10 modes alone.
#[test]
fn five_modes_with_the_correction_beat_ten_modes_without_at_rk_80() {
    let f_err = |modes, correction| {
        let output = run(&CantileverImpact, &cantilever(80.0, 40, modes, correction, 0.5));
        number(&output.document, "/comparison/f_err")
    };
    let (corrected, ten) = (f_err(5, "contacts"), f_err(10, "none"));
    assert!(
        corrected < ten,
        "f_err: 5 modes + correction {corrected:e} vs 10 modes without {ten:e} (expected lower)"
    );
}

/// Peak contact force at Rk = 80 on a 10-element beam, against the same model on its
/// complete basis (20 modes: the full finite-element solution, which both truncations
/// converge to). With the correction the error is smaller at every truncation and falls
/// faster as modes are added (the static flexibility at the contact is exact at once;
/// only the dynamic part of the dropped modes is missing).
#[test]
fn peak_contact_force_converges_faster_in_modes_with_the_correction() {
    let peak = |modes, correction| {
        let output = run(&CantileverImpact, &cantilever(80.0, 10, modes, correction, 0.2));
        number(&output.document, "/numerical/max_contact_force")
    };
    let full = peak(20, "none");
    let error = |modes, correction| ((peak(modes, correction) - full) / full).abs();
    let truncations = [2, 4, 8];
    let without: Vec<f64> = truncations.iter().map(|&m| error(m, "none")).collect();
    let with: Vec<f64> = truncations.iter().map(|&m| error(m, "contacts")).collect();
    for ((m, a), b) in truncations.iter().zip(&without).zip(&with) {
        assert!(
            b < a,
            "{m} modes: peak force error {b:e} with the correction vs {a:e} without (expected lower)"
        );
    }
    let (rate_without, rate_with) = (without[2] / without[0], with[2] / with[0]);
    assert!(
        rate_with < rate_without,
        "error reduction from 2 to 8 modes: ×{rate_with:e} with the correction vs ×{rate_without:e} without \
         (expected faster)"
    );
}

fn bundle(pin: Value) -> Value {
    let contact = |left: Value, right: Value, height: f64| json!({"left": left, "right": right, "height": height, "gap": 1e-4, "stiffness": 2e4});
    json!({
        "pin": pin,
        "pins": 2,
        "contacts": [
            contact(json!("wall"), json!(0), 0.6), contact(json!(0), json!(1), 0.6),
            contact(json!(1), json!("wall"), 0.6), contact(json!(0), json!(1), 1.0)
        ],
        "initial": {"tip_displacements": [1e-3, 0.0]},
        "solver": {"time_step": "auto", "duration": 0.02}
    })
}

fn pin(correction: &str) -> Value {
    json!({"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
           "elements": 20, "modes": 6, "damping_ratio": 0.01, "static_correction": correction})
}

/// The results list the basis: 6 modes, one pseudo-mode per distinct contact height
/// (0.6 m and 1 m, shared by both pins) above the last mode, the modal DOFs, and the
/// critical step with and without the pseudo-modes (shorter with them). `contacts` is
/// the default.
#[test]
fn results_list_the_basis_actually_used() {
    let mut default_pin = pin("contacts");
    default_pin.as_object_mut().unwrap().remove("static_correction");
    let output = run(&BundleDynamics, &bundle(default_pin));
    let basis = &output.document["basis"];
    assert_eq!(basis["static_correction"], "contacts", "default: {basis}");
    assert_eq!(basis["modes"], 6);
    assert_eq!(basis["correction_heights"], json!([0.6, 1.0]), "{basis}");
    assert_eq!(basis["cost"]["modal_dofs_per_pin"], 8, "{basis}");
    assert_eq!(basis["cost"]["modal_dofs"], 16, "{basis}");
    let last_mode = number(basis, "/mode_frequencies_hz/5");
    let first_pseudo = number(basis, "/pseudo_mode_frequencies_hz/0");
    assert!(
        first_pseudo > last_mode,
        "pseudo-mode {first_pseudo} Hz vs last mode {last_mode} Hz (expected above)"
    );
    let (critical, without) = (
        number(basis, "/cost/critical_time_step"),
        number(basis, "/cost/critical_time_step_without_correction"),
    );
    assert!(
        critical < without,
        "critical step {critical:e} with vs {without:e} s without"
    );
    assert_eq!(critical, number(&output.document, "/critical_time_step"));
    let displacements = output
        .histories
        .iter()
        .find(|h| h.name == "displacements")
        .unwrap();
    let columns: Vec<&str> = displacements.series.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(columns, ["p0", "p1"], "one tip deflection column per pin");

    let plain = run(&BundleDynamics, &bundle(pin("none")));
    let basis = &plain.document["basis"];
    assert_eq!(basis["static_correction"], "none");
    assert_eq!(basis["cost"]["modal_dofs_per_pin"], 6, "{basis}");
    assert_eq!(basis["pseudo_mode_frequencies_hz"], json!([]));
}

fn pointers(process: &dyn Process, inputs: &Value) -> Vec<String> {
    process
        .validate(inputs)
        .expect_err("invalid inputs")
        .0
        .into_iter()
        .map(|e| e.pointer)
        .collect()
}

/// An unknown correction name is refused at its own pointer, in both processes.
#[test]
fn an_unknown_correction_is_refused_at_its_pointer() {
    assert_eq!(
        pointers(&BundleDynamics, &bundle(pin("modes"))),
        ["/inputs/pin/static_correction"]
    );
    assert_eq!(
        pointers(&CantileverImpact, &cantilever(1.0, 10, 3, "everything", 0.1)),
        ["/inputs/beam/static_correction"]
    );
}

/// A free-free pin has no static response (singular stiffness): refused, naming the
/// supports.
#[test]
fn a_free_free_pin_is_refused_at_its_supports() {
    let mut free = pin("contacts");
    free["supports"] = json!({"foot": "free", "top": "free"});
    let errors = BundleDynamics
        .validate(&bundle(free))
        .expect_err("a free-free pin is refused")
        .0;
    assert!(
        errors.iter().any(|e| e.pointer == "/inputs/pin/supports"),
        "errors {errors:?} vs one at /inputs/pin/supports"
    );
}
