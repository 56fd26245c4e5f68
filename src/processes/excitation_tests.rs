//! Base-acceleration kinds through a process (`bundle-dynamics`): the transport and
//! handling pulses reach the pins as the closed form says, and bad parameters are a 422
//! at their pointer naming the bound.

use std::ops::ControlFlow;

use serde_json::{Value, json};

use super::bundle_dynamics::BundleDynamics;
use super::{Process, RunOutput};

const LENGTH: f64 = 1.0;
const YOUNG_MODULUS: f64 = 2.1e11;
const DENSITY: f64 = 7800.0;
const OUTER: f64 = 0.010;
const INNER: f64 = 0.009;

fn pin() -> Value {
    json!({"length": LENGTH, "young_modulus": YOUNG_MODULUS, "density": DENSITY,
           "section": {"type": "tube", "outer_diameter": OUTER, "inner_diameter": INNER},
           "elements": 20, "modes": 8, "damping_ratio": 0.05})
}

/// One free-standing pin (no contact) under `excitation`, run for `duration` (s).
fn lone_pin(excitation: Value, duration: f64) -> Value {
    json!({"pin": pin(), "pins": 1, "contacts": [],
           "excitation": {"base_acceleration": excitation},
           "solver": {"duration": duration, "check": "none"}})
}

fn run(inputs: &Value) -> RunOutput {
    BundleDynamics.validate(inputs).unwrap_or_else(|e| panic!("{e}"));
    BundleDynamics
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .unwrap_or_else(|e| panic!("{e}"))
}

fn errors(inputs: &Value) -> Vec<(String, String)> {
    match BundleDynamics.validate(inputs) {
        Ok(_) => panic!("inputs accepted: {inputs}"),
        Err(invalid) => invalid.0.into_iter().map(|e| (e.pointer, e.detail)).collect(),
    }
}

/// Tip deflection of the pin at the last output time.
fn final_tip_deflection(output: &RunOutput) -> f64 {
    let displacements = output
        .histories
        .iter()
        .find(|h| h.name == "displacements")
        .unwrap_or_else(|| panic!("no displacements history"));
    *displacements.series[0].1.last().unwrap_or(&f64::NAN)
}

// A pulse far longer than the pin's first period (0.1 s) is followed quasi-statically:
// in the wrapper frame the pin carries the uniform load q = −ρA a(t), so at the
// haversine's peak (t = T/2, a = A) the tip deflects by the cantilever's static
// w = q L⁴ / (8 E I). The smooth haversine leaves a dynamic error of order
// (period / T)² and the 5 % damping keeps it small: 1 % tolerance.
#[test]
fn a_long_haversine_bends_the_pin_by_the_static_deflection_at_its_peak() {
    let (amplitude, duration) = (20.0, 4.0);
    let output = run(&lone_pin(
        json!({"type": "haversine", "amplitude": amplitude, "duration": duration}),
        duration / 2.0,
    ));
    let area = std::f64::consts::PI / 4.0 * (OUTER * OUTER - INNER * INNER);
    let inertia = std::f64::consts::PI / 64.0 * (OUTER.powi(4) - INNER.powi(4));
    let expected = -DENSITY * area * amplitude * LENGTH.powi(4) / (8.0 * YOUNG_MODULUS * inertia);
    let measured = final_tip_deflection(&output);
    assert!(
        (measured - expected).abs() < 0.01 * expected.abs(),
        "tip at the haversine's peak: {measured:e} m, expected static {expected:e} m"
    );
}

// Same for the trapezoid's plateau: once the (slow) rise is over the pin sits at the
// static deflection of the plateau's acceleration, and the work of the base on it is
// positive.
#[test]
fn a_slow_trapezoid_holds_the_static_deflection_on_its_plateau() {
    let amplitude = -15.0;
    let output = run(&lone_pin(
        json!({"type": "trapezoid", "amplitude": amplitude, "rise": 2.0, "plateau": 2.0, "fall": 0.5}),
        3.5,
    ));
    let area = std::f64::consts::PI / 4.0 * (OUTER * OUTER - INNER * INNER);
    let inertia = std::f64::consts::PI / 64.0 * (OUTER.powi(4) - INNER.powi(4));
    let expected = -DENSITY * area * amplitude * LENGTH.powi(4) / (8.0 * YOUNG_MODULUS * inertia);
    let measured = final_tip_deflection(&output);
    assert!(
        (measured - expected).abs() < 0.01 * expected.abs(),
        "tip on the plateau: {measured:e} m, expected static {expected:e} m"
    );
}

// A short sawtooth does work on the pin and the run ends with a finite, non-zero
// response (it reached the integrator).
#[test]
fn a_sawtooth_shakes_the_pin() {
    let output = run(&lone_pin(
        json!({"type": "terminal_peak_sawtooth", "amplitude": 300.0, "duration": 0.011}),
        0.1,
    ));
    let work = output.document["energy"]["external_work"]
        .as_f64()
        .unwrap_or(f64::NAN);
    assert!(work > 0.0, "external work {work}");
    assert!(final_tip_deflection(&output).abs() > 0.0);
}

#[test]
fn bad_pulse_parameters_are_refused_at_their_pointer_with_the_bound() {
    let found = errors(&lone_pin(
        json!({"type": "haversine", "amplitude": 10.0, "duration": -0.01}),
        0.1,
    ));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "/inputs/excitation/base_acceleration/duration");
    assert!(found[0].1.contains("positive"), "{}", found[0].1);

    let found = errors(&lone_pin(
        json!({"type": "trapezoid", "amplitude": 10.0, "rise": 0.001, "plateau": -0.002, "fall": 0.001}),
        0.1,
    ));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "/inputs/excitation/base_acceleration/plateau");
    assert!(found[0].1.contains("must not be negative"), "{}", found[0].1);

    let found = errors(&lone_pin(
        json!({"type": "terminal_peak_sawtooth", "amplitude": 10.0}),
        0.1,
    ));
    assert_eq!(
        found,
        [(
            "/inputs/excitation/base_acceleration/duration".to_owned(),
            "is required".to_owned()
        )]
    );

    let found = errors(&lone_pin(
        json!({"type": "trapezoid", "amplitude": 10.0, "rise": 0.0, "plateau": 0.0, "fall": 0.0}),
        0.1,
    ));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "/inputs/excitation/base_acceleration/plateau");
}

/// A Eurocode 8 type 1 shape (a_g = 3 m/s²) over 1–33 Hz, a 12 s record.
fn earthquake(seed: u64) -> Value {
    json!({"type": "spectrum_compatible",
           "target": {"frequencies": [1.0, 2.5, 6.67, 33.0], "accelerations": [3.0, 7.5, 7.5, 3.9]},
           "duration": 12.0, "strong_motion": 6.0, "seed": seed})
}

// A synthetic earthquake is an excitation like any other: the same seed gives the same
// results document (the record is the same bit for bit), another seed another one.
#[test]
fn a_spectrum_compatible_earthquake_shakes_the_pin_reproducibly() {
    let first = run(&lone_pin(earthquake(5), 3.0));
    let again = run(&lone_pin(earthquake(5), 3.0));
    let other = run(&lone_pin(earthquake(6), 3.0));
    assert_eq!(first.document, again.document, "same seed, different results");
    assert_eq!(first.histories, again.histories, "same seed, different histories");
    assert_ne!(
        first.document["pins"], other.document["pins"],
        "seeds 5 and 6 shook the pin the same way"
    );
    let work = first.document["energy"]["external_work"]
        .as_f64()
        .unwrap_or(f64::NAN);
    assert!(work > 0.0, "external work {work}");
}

#[test]
fn a_bad_target_spectrum_is_refused_at_its_pointer() {
    let mut bad = earthquake(1);
    bad["target"]["frequencies"] = json!([1.0, 6.67, 2.5, 33.0]);
    bad["target"]["accelerations"] = json!([3.0, -7.5, 7.5, 3.9]);
    let found = errors(&lone_pin(bad, 1.0));
    let pointers: Vec<&str> = found.iter().map(|(p, _)| p.as_str()).collect();
    assert_eq!(
        pointers,
        [
            "/inputs/excitation/base_acceleration/target/frequencies/2",
            "/inputs/excitation/base_acceleration/target/accelerations/1"
        ],
        "{found:?}"
    );
    assert!(found[0].1.contains("strictly increasing"), "{}", found[0].1);
    assert!(found[1].1.contains("positive"), "{}", found[1].1);

    let mut bad = earthquake(1);
    bad["strong_motion"] = json!(12.0);
    let found = errors(&lone_pin(bad, 1.0));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "/inputs/excitation/base_acceleration/strong_motion");

    let mut bad = earthquake(1);
    bad["seed"] = json!(-3);
    let found = errors(&lone_pin(bad, 1.0));
    assert_eq!(found.len(), 1, "{found:?}");
    // serde buffers a tagged object, losing the member's path: the pointer names the
    // object and the detail the value refused.
    assert!(
        found[0].0.starts_with("/inputs/excitation/base_acceleration"),
        "{found:?}"
    );
    assert!(found[0].1.contains("-3"), "{found:?}");

    let mut bad = earthquake(1);
    bad["magnitude"] = json!(7);
    let found = errors(&lone_pin(bad, 1.0));
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "/inputs/excitation/base_acceleration/magnitude");
}

// Sweeps check their axis pointers against the inputs schema: the seed must be in it.
#[test]
fn the_seed_is_in_the_inputs_schema() {
    let schema = BundleDynamics.inputs_schema().unwrap_or_default();
    let text = schema.to_string();
    assert!(
        text.contains("\"strong_motion\""),
        "no strong_motion in the schema"
    );
    assert!(text.contains("\"seed\""), "no seed in the schema");
    assert!(
        text.contains("spectrum_compatible"),
        "no spectrum_compatible type"
    );
}

/// The shipped shock and earthquake examples are valid.
#[test]
fn the_shock_and_earthquake_examples_are_valid() {
    for name in ["bundle-haversine.json", "bundle-earthquake.json"] {
        let path = format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let body: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
        if let Err(invalid) = BundleDynamics.validate(&body["inputs"]) {
            panic!("{name}: {invalid}");
        }
    }
}

/// A record shared by the stored-signal tests: a 30 m/s² half-sine of 0.2 s sampled
/// every millisecond.
fn stored_record() -> (Vec<f64>, Vec<f64>) {
    let time: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-3).collect();
    let values = time
        .iter()
        .map(|t| 30.0 * (std::f64::consts::PI * t / 0.2).sin())
        .collect();
    (time, values)
}

fn library_with(key: &str, time: &[f64], values: &[f64]) -> super::signal_input::SignalLibrary {
    use super::signal_input::{SignalLibrary, SignalSource};
    let mut library = SignalLibrary::new(SignalSource::Stored);
    library.insert(
        key,
        std::sync::Arc::new(crate::physics::loads::Table {
            time: time.to_vec(),
            values: values.to_vec(),
        }),
    );
    library
}

// A stored signal is the table it holds times its scale: the same run as the inline
// table of −2 × the record, bit for bit. Without the record (an unknown id) it is a 422
// at the id; a scale that would overflow the record is a 422 at the scale.
#[test]
fn a_stored_signal_is_its_table_times_its_scale() {
    let (time, values) = stored_record();
    let library = library_with("rec", &time, &values);
    let by_reference = lone_pin(json!({"type": "signal", "id": "rec", "scale": -2.0}), 0.3);
    let scaled: Vec<f64> = values.iter().map(|a| -2.0 * a).collect();
    let inline = lone_pin(
        json!({"type": "table", "time": time, "acceleration": scaled}),
        0.3,
    );
    BundleDynamics
        .validate_with(&by_reference, &library)
        .unwrap_or_else(|e| panic!("{e}"));
    let stored = BundleDynamics
        .run_with(&by_reference, &library, &mut |_| ControlFlow::Continue(()))
        .unwrap_or_else(|e| panic!("{e}"));
    let pasted = run(&inline);
    assert!(final_tip_deflection(&pasted).abs() > 0.0);
    assert_eq!(stored.document, pasted.document);
    assert_eq!(stored.histories, pasted.histories);

    let unknown = errors(&by_reference);
    assert_eq!(
        unknown[0].0, "/inputs/excitation/base_acceleration/id",
        "{unknown:?}"
    );
    let huge = lone_pin(json!({"type": "signal", "id": "rec", "scale": 1e307}), 0.3);
    let refused = BundleDynamics.validate_with(&huge, &library).unwrap_err().0;
    assert_eq!(
        refused[0].pointer, "/inputs/excitation/base_acceleration/scale",
        "{refused:?}"
    );
}

// The hexagonal bundle takes a stored signal as either component of its excitation;
// an unknown id is refused at that component's pointer.
#[test]
fn the_hexagonal_bundle_takes_a_stored_signal_as_a_component() {
    use super::hex_bundle_dynamics::HexBundleDynamics;
    let (time, values) = stored_record();
    let library = library_with("rec", &time, &values);
    let inputs = json!({
        "pin": {"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "static_correction": "none"},
        "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                   "wrapper_flat_to_flat": 0.0305},
        "contact": {"stiffness": 2e6, "damping": 20.0},
        "gaps": {"type": "uniform", "pin_pin": 5e-5, "pin_wall": 1e-4},
        "excitation": {"base_acceleration_y": {"type": "signal", "id": "rec"}},
        "solver": {"duration": 0.01, "check": "none"}
    });
    HexBundleDynamics
        .validate_with(&inputs, &library)
        .unwrap_or_else(|e| panic!("{e}"));
    let refused = HexBundleDynamics.validate(&inputs).unwrap_err().0;
    assert_eq!(
        refused[0].pointer, "/inputs/excitation/base_acceleration_y/id",
        "{refused:?}"
    );
}
