//! `cantilever-impact` against physics: the public check values of BRIEF §7, the limits
//! Rk → 0 and gap > release amplitude, and validation that names every bad field.

use std::ops::ControlFlow;

use serde_json::{Value, json};

use super::*;
use crate::processes::{Process, RunOutput};

fn default_inputs() -> Value {
    json!({
        "beam": {
            "length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
            "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
            "elements": 40, "modes": 10, "damping_ratio": 0.01
        },
        "contact": {"rk": 1.0, "gap": 0.0, "damping": 0.0},
        "release": {"tip_displacement": 0.001},
        "solver": {"scheme": "central_difference", "time_step": 1e-5, "duration": 0.5},
        "reference": {"modes": 30}
    })
}

fn run(inputs: &Value) -> RunOutput {
    CantileverImpact.validate(inputs).expect("valid inputs");
    CantileverImpact
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .expect("run succeeds")
}

fn pointers(inputs: &Value) -> Vec<String> {
    CantileverImpact
        .validate(inputs)
        .expect_err("invalid inputs")
        .0
        .into_iter()
        .map(|e| e.pointer)
        .collect()
}

fn relative(measured: f64, expected: f64) -> f64 {
    (measured - expected).abs() / expected.abs()
}

/// BRIEF §7, Rk = 1: reference first impact 0.0253717 s, 6 impacts, peak 0.071491 N; the
/// numerical scheme (40 elements, 10 modes, CD, Δt = 1e-5 s) agrees with f_err ≈ 7e-5.
#[test]
fn default_case_reproduces_the_public_values() {
    let output = run(&default_inputs());
    let doc = &output.document;
    let reference = &doc["reference"];
    let first = reference["first_impact_time"].as_f64().unwrap();
    assert!(
        relative(first, 0.0253717) < 2e-6,
        "reference first impact {first} vs 0.0253717 s"
    );
    assert_eq!(reference["impacts"], 6);
    let peak = reference["max_contact_force"].as_f64().unwrap();
    assert!(
        relative(peak, 0.071491) < 1e-5,
        "reference peak {peak} vs 0.071491 N"
    );
    let f1 = reference["contact_frequencies_hz"][0].as_f64().unwrap();
    assert!(
        relative(f1, 13.6088) < 1e-5,
        "clamped-spring f1 {f1} vs 13.6088 Hz"
    );

    let numerical = &doc["numerical"];
    assert_eq!(numerical["impacts"], 6);
    let numerical_peak = numerical["max_contact_force"].as_f64().unwrap();
    assert!(
        relative(numerical_peak, peak) < 1e-3,
        "numerical peak {numerical_peak} vs reference {peak}"
    );
    let f_err = doc["comparison"]["f_err"].as_f64().unwrap();
    assert!(f_err > 1e-6 && f_err < 2e-4, "f_err {f_err} vs public ≈ 7e-5");
    assert_eq!(doc["comparison"]["agrees"], true);
    let critical = numerical["critical_time_step"].as_f64().unwrap();
    let omega_10 = 2.0 * std::f64::consts::PI * numerical["frequencies_hz"][9].as_f64().unwrap();
    assert!(
        critical < 2.0 / omega_10,
        "the contact spring can only shorten the critical step"
    );

    let names: Vec<&str> = output.histories.iter().map(|h| h.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "tip_displacement",
            "contact_force",
            "tip_displacement_peaks",
            "contact_force_peaks",
            "impacts"
        ]
    );
    assert_eq!(
        output.histories[0].time.len(),
        50_001,
        "every step of 0.5 s at 1e-5 s"
    );
}

/// BRIEF §7, Rk = 80: 12 impacts and a peak force of 0.515569 N on a 1e-5 s grid (the
/// continuous peak is 0.5155710 N); f_err ≈ 2e-3.
#[test]
fn stiff_spring_case_reproduces_the_public_values() {
    let mut inputs = default_inputs();
    inputs["contact"]["rk"] = json!(80.0);
    let output = run(&inputs);
    let reference = &output.document["reference"];
    assert_eq!(reference["impacts"], 12);
    let peak = reference["max_contact_force"].as_f64().unwrap();
    assert!(
        relative(peak, 0.515569) < 1e-5,
        "reference peak {peak} vs 0.515569 N"
    );
    let f_err = output.document["comparison"]["f_err"].as_f64().unwrap();
    assert!(f_err > 5e-4 && f_err < 5e-3, "f_err {f_err} vs public ≈ 2e-3");
}

/// Rk → 0: no spring, free damped vibration on both sides: no impact, and the two tip
/// histories agree closely (only modal truncation and Δt differ).
#[test]
fn zero_stiffness_is_free_vibration() {
    let mut inputs = default_inputs();
    inputs["contact"]["rk"] = json!(0.0);
    let output = run(&inputs);
    assert_eq!(output.document["numerical"]["impacts"], 0);
    assert_eq!(output.document["reference"]["impacts"], 0);
    let f_err = output.document["comparison"]["f_err"].as_f64().unwrap();
    assert!(f_err < 1e-4, "free vibration f_err {f_err}");
}

/// A gap larger than the release amplitude can never be closed (the motion decays).
#[test]
fn gap_beyond_release_amplitude_gives_no_impact() {
    let mut inputs = default_inputs();
    inputs["contact"]["gap"] = json!(1.5e-3);
    let output = run(&inputs);
    assert_eq!(output.document["numerical"]["impacts"], 0);
    assert_eq!(output.document["reference"]["impacts"], 0);
    let min_tip = output.document["numerical"]["min_tip_displacement"]
        .as_f64()
        .unwrap();
    assert!(min_tip > -1.5e-3 && min_tip < -0.8e-3, "lowest tip {min_tip} m");
}

/// A gap shifts the first impact later: the tip must travel u₀ + g instead of u₀.
#[test]
fn gap_delays_the_first_impact_on_both_sides() {
    let mut inputs = default_inputs();
    inputs["contact"]["gap"] = json!(2e-4);
    let output = run(&inputs);
    let numerical = output.document["numerical"]["first_impact_time"]
        .as_f64()
        .unwrap();
    let reference = output.document["reference"]["first_impact_time"]
        .as_f64()
        .unwrap();
    assert!(reference > 0.0253717, "gap must delay the impact: {reference}");
    assert!(
        relative(numerical, reference) < 1e-4,
        "numerical {numerical} vs reference {reference}"
    );
}

#[test]
fn defaults_fill_everything_but_geometry_and_material() {
    let inputs = json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
        "section": {"type": "explicit", "area": 1.4923e-5, "inertia": 1.6198e-10}}});
    assert!(CantileverImpact.validate(&inputs).is_ok());
    assert_eq!(pointers(&json!({})), ["/inputs/beam"], "beam is required");
    let errors = CantileverImpact
        .validate(&json!({"beam": {"length": 1.0}}))
        .unwrap_err()
        .0;
    assert_eq!(errors[0].pointer, "/inputs/beam/young_modulus");
    assert_eq!(errors[0].detail, "is required");
}

#[test]
fn invalid_inputs_name_each_field() {
    let mut inputs = default_inputs();
    inputs["contact"]["stiffness"] = json!(100.0);
    inputs["reference"]["modes"] = json!(61);
    inputs["beam"]["section"]["inner_diameter"] = json!(0.011);
    inputs["beam"]["elements"] = json!(0);
    inputs["contact"]["gap"] = json!(-1.0);
    assert_eq!(
        pointers(&inputs),
        [
            "/inputs/beam/section/inner_diameter",
            "/inputs/beam/elements",
            "/inputs/contact/stiffness",
            "/inputs/contact/gap",
            "/inputs/reference/modes"
        ]
    );
}

/// The contact's values are checked by the model's own validation (issue 17), with the
/// beam's problems and at the members the user wrote: a given stiffness at
/// `contact/stiffness`, one derived from a negative `rk` once at `contact/rk`, and none
/// when only the beam it scales is wrong.
#[test]
fn the_models_problems_come_with_the_beams_at_the_contact_members() {
    let mut inputs = default_inputs();
    inputs["beam"]["modes"] = json!(0);
    inputs["contact"] = json!({"stiffness": -5.0, "gap": -1e-3, "damping": -1.0});
    assert_eq!(
        pointers(&inputs),
        [
            "/inputs/beam/modes",
            "/inputs/contact/gap",
            "/inputs/contact/stiffness",
            "/inputs/contact/damping"
        ]
    );
    let mut inputs = default_inputs();
    inputs["contact"]["rk"] = json!(-2.0);
    let errors = CantileverImpact.validate(&inputs).unwrap_err().0;
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].pointer, "/inputs/contact/rk");
    assert!(
        errors[0].detail.contains("-2"),
        "the value given: {}",
        errors[0].detail
    );
    let mut inputs = default_inputs();
    inputs["beam"]["young_modulus"] = json!(-2.1e11);
    assert_eq!(pointers(&inputs), ["/inputs/beam/young_modulus"]);
    // The tip release needs a free top: the supports are the cause, named once.
    let mut inputs = default_inputs();
    inputs["beam"]["supports"] = json!({"foot": "clamped", "top": "pinned"});
    assert_eq!(pointers(&inputs), ["/inputs/beam/supports"]);
}

#[test]
fn unknown_and_mistyped_fields_are_refused_with_their_pointer() {
    let mut inputs = default_inputs();
    inputs["solver"]["time_stpe"] = json!(1e-5);
    assert_eq!(pointers(&inputs), ["/inputs/solver/time_stpe"]);
    let mut inputs = default_inputs();
    inputs["beam"]["modes"] = json!("ten");
    assert_eq!(pointers(&inputs), ["/inputs/beam/modes"]);
    let mut inputs = default_inputs();
    inputs["solver"]["time_step"] = json!("fast");
    assert_eq!(pointers(&inputs), ["/inputs/solver/time_step"]);
}

#[test]
fn modes_beyond_the_mesh_are_refused() {
    let mut inputs = default_inputs();
    inputs["beam"]["elements"] = json!(2);
    inputs["beam"]["modes"] = json!(10);
    let errors = CantileverImpact.validate(&inputs).unwrap_err().0;
    assert_eq!(errors[0].pointer, "/inputs/beam/modes");
    assert!(
        errors[0].detail.contains("between 1 and 4"),
        "{}",
        errors[0].detail
    );
}

/// A step above the critical step (contact included) is refused before running, with a
/// message naming both values; "auto" runs at a fraction of it.
#[test]
fn time_step_above_critical_is_refused_and_auto_is_stable() {
    let mut inputs = default_inputs();
    inputs["solver"]["time_step"] = json!(2e-4);
    let errors = CantileverImpact.validate(&inputs).unwrap_err().0;
    assert_eq!(errors[0].pointer, "/inputs/solver/time_step");
    assert!(
        errors[0].detail.contains("2e-4") && errors[0].detail.contains("critical"),
        "{}",
        errors[0].detail
    );

    inputs["solver"]["time_step"] = json!("auto");
    inputs["solver"]["duration"] = json!(0.1);
    let output = run(&inputs);
    let numerical = &output.document["numerical"];
    let ratio = numerical["time_step"].as_f64().unwrap() / numerical["critical_time_step"].as_f64().unwrap();
    assert!(
        ratio <= crate::physics::integrate::step_size::STABILITY_FRACTION,
        "auto step / critical step = {ratio}"
    );
    let quality = &output.document["quality"];
    assert_eq!(quality["verdict"], "good", "{quality:#}");
}

/// Tchamwa–Wielgosz runs the same case (first order, dissipative) and still agrees.
#[test]
fn tchamwa_scheme_agrees_with_the_reference() {
    let mut inputs = default_inputs();
    inputs["solver"]["scheme"] = json!("tchamwa");
    inputs["solver"]["phi"] = json!(1.05);
    let output = run(&inputs);
    let f_err = output.document["comparison"]["f_err"].as_f64().unwrap();
    assert!(f_err < 0.2, "f_err {f_err}");
    let mut inputs = default_inputs();
    inputs["solver"]["phi"] = json!(1.1);
    assert_eq!(
        pointers(&inputs),
        ["/inputs/solver/phi"],
        "phi only applies to tchamwa"
    );
}

/// `auto` on the paper's cantilever, soft (Rk = 1) and stiff (Rk = 80) spring: the energy
/// balance closes within the default tolerance and the peak contact force is within 1 %
/// (10 × the tolerance) of its Δt → 0 limit, extrapolated (second order) from runs at
/// Δt/10 and Δt/20; the verdict is good. The contact force peaks, sampled or not, reach
/// the reported maximum.
#[test]
fn auto_is_accurate_on_the_cantilever() {
    for rk in [1.0, 80.0] {
        let mut inputs = default_inputs();
        inputs["contact"]["rk"] = json!(rk);
        inputs["solver"]["duration"] = json!(0.2);
        inputs["solver"]["time_step"] = json!("auto");
        inputs["output"] = json!({"interval": 1e-3});
        let output = run(&inputs);
        let doc = &output.document;
        let quality = &doc["quality"];
        assert_eq!(quality["verdict"], "good", "Rk {rk}: {quality:#}");
        let residual = quality["energy_residual"].as_f64().unwrap();
        assert!(residual <= 1e-3, "Rk {rk}: energy residual {residual:e}");
        let dt = doc["numerical"]["time_step"].as_f64().unwrap();
        let peak_at = |step: f64| {
            let mut fine = inputs.clone();
            fine["solver"]["time_step"] = json!(step);
            fine["solver"]["check"] = json!("none");
            run(&fine).document["numerical"]["max_contact_force"]
                .as_f64()
                .unwrap()
        };
        let (fine, finer) = (peak_at(dt / 10.0), peak_at(dt / 20.0));
        let limit = finer + (finer - fine) / 3.0;
        let peak = doc["numerical"]["max_contact_force"].as_f64().unwrap();
        assert!(
            relative(peak, limit) <= 1e-2,
            "Rk {rk}: peak force {peak} N vs Δt → 0 limit {limit} N"
        );
        let peaks = output
            .histories
            .iter()
            .find(|h| h.name == "contact_force_peaks")
            .unwrap();
        let envelope = peaks.series[0].1.iter().fold(0.0f64, |m, f| m.max(*f));
        assert_eq!(envelope, peak, "Rk {rk}: envelope maximum vs max_contact_force");
        assert_eq!(doc["numerical"]["output_interval"], 1e-3);
    }
}

/// Bad solver settings are refused at their pointers: a tolerance outside (0, 1), a check
/// that is not one of the names.
#[test]
fn bad_tolerance_and_check_are_refused_at_their_pointers() {
    for tolerance in [json!(0.0), json!(-1e-3), json!(1.0), json!(2.0)] {
        let mut inputs = default_inputs();
        inputs["solver"]["tolerance"] = tolerance.clone();
        assert_eq!(
            pointers(&inputs),
            ["/inputs/solver/tolerance"],
            "tolerance {tolerance}"
        );
    }
    let mut inputs = default_inputs();
    inputs["solver"]["check"] = json!("richardson");
    let errors = CantileverImpact.validate(&inputs).unwrap_err().0;
    assert_eq!(errors[0].pointer, "/inputs/solver/check");
    assert!(errors[0].detail.contains("step_halving"), "{}", errors[0].detail);
}

/// A cantilever thrown toward its spring (tip velocity −0.05 m/s from a 0.5 mm release):
/// the numerical model and the semi-analytic reference, which takes the same velocity
/// field v ψ(x) exactly, agree (f_err within the default case's order), and the throw
/// reaches the spring sooner than the release alone; thrown away from it, later.
#[test]
fn a_thrown_cantilever_agrees_with_its_reference() {
    let first_impact = |velocity: f64| {
        let mut inputs = default_inputs();
        inputs["release"] = json!({"tip_displacement": 0.0005, "tip_velocity": velocity});
        let output = run(&inputs);
        let doc = &output.document;
        let f_err = doc["comparison"]["f_err"].as_f64().unwrap();
        assert!(f_err < 2e-4, "v = {velocity} m/s: f_err {f_err}");
        assert_eq!(doc["comparison"]["agrees"], true);
        assert_eq!(doc["numerical"]["impacts"], doc["reference"]["impacts"]);
        doc["reference"]["first_impact_time"].as_f64().unwrap()
    };
    let (toward, at_rest, away) = (first_impact(-0.05), first_impact(0.0), first_impact(0.05));
    assert!(
        toward < at_rest && at_rest < away,
        "{toward} s, {at_rest} s, {away} s"
    );
    let mut inputs = default_inputs();
    inputs["beam"]["supports"] = json!({"foot": "clamped", "top": "pinned"});
    inputs["release"] = json!({"tip_displacement": 0.0, "tip_velocity": 0.1});
    assert!(
        pointers(&inputs).contains(&"/inputs/beam/supports".to_owned()),
        "{:?}",
        pointers(&inputs)
    );
}
