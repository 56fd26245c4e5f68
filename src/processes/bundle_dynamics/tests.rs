//! `bundle-dynamics` against physics: a one-pin row is the cantilever case, mirror
//! symmetric inputs give mirror symmetric responses, pin–pin forces act equally and
//! oppositely (the energy balance closes only then), the generator form expands as the
//! explicit one, and validation names every bad field.

use std::ops::ControlFlow;

use serde_json::{Value, json};

use super::*;
use crate::processes::cantilever_impact::CantileverImpact;
use crate::processes::{Process, RunOutput};

fn pin() -> Value {
    json!({"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
           "elements": 20, "modes": 8, "damping_ratio": 0.01})
}

fn run(inputs: &Value) -> RunOutput {
    BundleDynamics.validate(inputs).expect("valid inputs");
    BundleDynamics
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .expect("run succeeds")
}

fn pointers(inputs: &Value) -> Vec<String> {
    BundleDynamics
        .validate(inputs)
        .expect_err("invalid")
        .0
        .into_iter()
        .map(|e| e.pointer)
        .collect()
}

fn series<'a>(history: &'a History, name: &str) -> &'a [f64] {
    &history
        .series
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .1
}

/// A row of one pin with a wall contact at its tip is the cantilever-impact model: the
/// numerical peak force, impacts and first impact must be identical.
#[test]
fn one_pin_row_reproduces_the_cantilever_numerical_result() {
    let beam = json!({"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
        "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009}, "elements": 40, "modes": 10});
    let stiffness = 3.0 * 2.1e11 * std::f64::consts::PI / 64.0 * (0.01f64.powi(4) - 0.009f64.powi(4));
    let cantilever = CantileverImpact
        .run(
            &json!({"beam": beam, "contact": {"stiffness": stiffness}, "solver": {"duration": 0.2}}),
            &mut |_| ControlFlow::Continue(()),
        )
        .unwrap();
    let bundle = run(&json!({"pin": beam, "pins": 1,
        "contacts": [{"left": "wall", "right": 0, "height": 1.0, "stiffness": stiffness}],
        "initial": {"tip_displacements": [1e-3]},
        "solver": {"time_step": 1e-5, "duration": 0.2}}));
    let numerical = &cantilever.document["numerical"];
    let contact = &bundle.document["contacts"][0];
    assert_eq!(contact["impacts"], numerical["impacts"]);
    assert_eq!(contact["max_force"], numerical["max_contact_force"]);
    assert_eq!(contact["first_impact_time"], numerical["first_impact_time"]);
}

/// Two pins between two walls, released in opposite directions with mirrored contacts:
/// the mirror image about the centre line is the same motion, so w₀ = −w₁ and the two
/// wall contacts carry identical forces at every instant.
#[test]
fn mirror_symmetric_inputs_give_mirror_symmetric_forces() {
    let contact = |left: Value, right: Value, h: f64| {
        json!({"left": left, "right": right, "height": h, "gap": 1e-4,
                                                             "stiffness": 5e4, "damping": 1.0})
    };
    let inputs = json!({"pin": pin(), "pins": 2,
        "contacts": [contact(json!("wall"), json!(0), 1.0), contact(json!(0), json!(1), 1.0), contact(json!(1), json!("wall"), 1.0),
                     contact(json!("wall"), json!(0), 0.5), contact(json!(0), json!(1), 0.5), contact(json!(1), json!("wall"), 0.5)],
        "initial": {"tip_displacements": [-1e-3, 1e-3]},
        "solver": {"time_step": 2e-6, "duration": 0.1}, "output": {"interval": 1e-4}});
    let output = run(&inputs);
    let forces = &output.histories[0];
    let displacements = &output.histories[1];
    let (left_wall, right_wall) = (series(forces, "c0"), series(forces, "c2"));
    let peak = left_wall.iter().copied().fold(0.0, f64::max);
    assert!(peak > 0.0, "the walls must be hit");
    for (a, b) in left_wall.iter().zip(right_wall) {
        assert!((a - b).abs() <= 1e-9 * peak, "wall forces {a} vs {b}");
    }
    for (a, b) in series(displacements, "p0")
        .iter()
        .zip(series(displacements, "p1"))
    {
        assert!((a + b).abs() <= 1e-12, "mirror deflections {a} vs {b}");
    }
}

/// Two pins that only touch each other, undamped: the contact force is internal. It
/// conserves the energy only if it acts equally and oppositely on both pins (its work
/// is then −F δ̇, stored in the contact spring).
#[test]
fn pin_to_pin_forces_are_equal_and_opposite() {
    let mut pin = pin();
    pin["damping_ratio"] = json!(0.0);
    let inputs = json!({"pin": pin, "pins": 2,
        "contacts": [{"left": 0, "right": 1, "height": 1.0, "gap": 0.0, "stiffness": 2e4},
                     {"left": 0, "right": 1, "height": 0.6, "gap": 2e-4, "stiffness": 2e4}],
        "initial": {"tip_displacements": [-1e-3, 5e-4]},
        "solver": {"time_step": 2e-6, "duration": 0.1}});
    let output = run(&inputs);
    assert!(output.document["impacts"].as_u64().unwrap() > 2);
    let residual = output.document["energy"]["relative_residual"].as_f64().unwrap();
    assert!(residual < 1e-4, "energy residual {residual}");
}

/// The generator form expands level by level (wall–0, 0–1, …, n−1–wall) and gives the
/// same run as its explicit expansion.
#[test]
fn generator_form_matches_its_explicit_expansion() {
    let generated = json!({"pin": pin(), "bundle": {"pins": 3, "levels": {"first": 0.5, "spacing": 0.5, "count": 2},
        "stiffness": 1e5, "damping": 2.0, "wall_gap": 1e-4, "pin_gap": 5e-5,
        "gaps": {"type": "random", "seed": 7, "distribution": {"type": "uniform", "low": 2e-5, "high": 1e-4}}},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 30.0, "duration": 0.01}},
        "solver": {"duration": 0.05}});
    let output = run(&generated);
    let expansion = &output.document["expansion"];
    assert_eq!(expansion["contacts"].as_array().unwrap().len(), 8);
    assert_eq!(expansion["contacts"][0]["left"], "wall");
    assert_eq!(expansion["contacts"][3]["right"], "wall");
    assert_eq!(expansion["contacts"][4]["height"], 1.0);
    let explicit = json!({"pin": pin(), "pins": 3, "contacts": expansion["contacts"],
        "excitation": generated["excitation"], "solver": generated["solver"]});
    let again = run(&explicit);
    assert_eq!(again.document["contacts"], output.document["contacts"]);
    assert!(
        output.document["impacts"].as_u64().unwrap() > 0,
        "the shock must close gaps"
    );
}

/// A damped row shaken by the base: the energy balance (kinetic + strain + contact +
/// dissipated − base work = initial) closes to a small fraction.
#[test]
fn energy_balance_closes_under_base_excitation() {
    let inputs = json!({"pin": pin(), "bundle": {"pins": 4, "levels": [0.5, 1.0], "stiffness": 5e4, "damping": 5.0,
        "wall_gap": 1e-4, "pin_gap": 1e-4},
        "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 15.0, "cycles": 3}},
        "solver": {"time_step": 2e-6, "duration": 0.3}});
    let output = run(&inputs);
    let energy = &output.document["energy"];
    assert!(energy["external_work"].as_f64().unwrap() > 0.0);
    let residual = energy["relative_residual"].as_f64().unwrap();
    assert!(residual < 1e-3, "energy residual {residual}: {energy}");
}

#[test]
fn invalid_inputs_name_each_field() {
    let inputs = json!({"pin": pin(), "pins": 2,
        "contacts": [{"left": "wall", "right": 2, "height": 1.2, "stiffness": 1e4},
                     {"left": 0, "right": 0, "height": 0.5, "stiffness": -1.0}],
        "initial": {"tip_displacements": [1e-3]},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 1.0, "duration": 0.0}}});
    assert_eq!(
        pointers(&inputs),
        [
            "/inputs/contacts/0/right",
            "/inputs/contacts/0/height",
            "/inputs/contacts/1/right",
            "/inputs/contacts/1/stiffness",
            "/inputs/initial/tip_displacements",
            "/inputs/excitation/base_acceleration/duration"
        ]
    );
    let both = json!({"pin": pin(), "pins": 2, "bundle": {"pins": 2, "levels": [1.0], "stiffness": 1.0, "wall_gap": 0.0, "pin_gap": 0.0}});
    assert_eq!(pointers(&both), ["/inputs/pins"]);
    let bad_left = json!({"pin": pin(), "pins": 1, "contacts": [{"left": "floor", "right": 0, "height": 1.0, "stiffness": 1.0}]});
    assert_eq!(pointers(&bad_left), ["/inputs/contacts/0/left"]);
}

/// The model is checked by physics (`Model::validate`, `Settings::validate`) with the
/// pin's own problems, in one refusal, each at the member the user wrote: an invalid pin
/// does not hide the contacts', the loads' or the recorded heights' problems.
#[test]
fn an_invalid_pin_does_not_hide_the_models_problems() {
    let mut bad_pin = pin();
    bad_pin["modes"] = json!(0);
    let inputs = json!({"pin": bad_pin, "pins": 2,
        "contacts": [{"left": "wall", "right": 3, "height": 1.0, "stiffness": 1e4, "gap": -1e-4}],
        "initial": {"tip_displacements": [1e-3, 0.0, 0.0]},
        "excitation": {
            "base_acceleration": {"type": "table", "time": [0.0, 0.01, 0.005], "acceleration": [0.0, 1.0]},
            "point_forces": [{"pin": 5, "height": 2.0, "time": [0.0, 0.01], "force": [0.0, 1.0]}]},
        "output": {"heights": [0.5, 1.5]}});
    assert_eq!(
        pointers(&inputs),
        [
            "/inputs/pin/modes",
            "/inputs/contacts/0/right",
            "/inputs/contacts/0/gap",
            "/inputs/initial/tip_displacements",
            "/inputs/excitation/base_acceleration/acceleration",
            "/inputs/excitation/base_acceleration/time/2",
            "/inputs/excitation/point_forces/0/pin",
            "/inputs/excitation/point_forces/0/height",
            "/inputs/output/heights/1",
        ]
    );
}

/// Heights within the pin cannot be checked against an invalid length: the length is
/// refused, the heights are not, the rest still is.
#[test]
fn an_invalid_length_refuses_the_length_not_every_height() {
    let mut bad_pin = pin();
    bad_pin["length"] = json!(-1.0);
    let inputs = json!({"pin": bad_pin, "pins": 1,
        "contacts": [{"left": "wall", "right": 0, "height": 0.5, "stiffness": -1.0}]});
    assert_eq!(
        pointers(&inputs),
        ["/inputs/pin/length", "/inputs/contacts/0/stiffness"]
    );
}

/// A release from the static tip-load shape needs a free top; a row without pins is
/// refused at its pin count, not at every contact that names a pin.
#[test]
fn a_tip_release_needs_a_free_top_and_a_row_needs_pins() {
    let mut clamped_top = pin();
    clamped_top["supports"] = json!({"foot": "clamped", "top": "clamped"});
    let contacts = json!([{"left": "wall", "right": 0, "height": 0.5, "stiffness": 1e4},
                          {"left": 0, "right": "wall", "height": 0.5, "stiffness": 1e4}]);
    let released = json!({"pin": clamped_top, "pins": 1, "contacts": contacts,
        "initial": {"tip_displacements": [1e-3]}});
    assert_eq!(pointers(&released), ["/inputs/initial/tip_displacements"]);
    let at_rest = json!({"pin": clamped_top, "pins": 1, "contacts": contacts,
        "initial": {"tip_displacements": [0.0]}, "solver": {"duration": 0.001}});
    assert!(BundleDynamics.validate(&at_rest).is_ok());
    let no_pins = json!({"pin": pin(), "pins": 0, "contacts": contacts});
    assert_eq!(pointers(&no_pins), ["/inputs/pins"]);
    let too_many = json!({"pin": pin(), "pins": MAX_PINS + 1, "contacts": contacts});
    assert_eq!(
        pointers(&too_many),
        ["/inputs/pins"],
        "no pointer into an absent `bundle`"
    );
}

/// The shipped benchmark example is valid and describes 17 pins and 180 contacts.
#[test]
fn row17_example_is_the_benchmark_case() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/bundle-row17.json")).unwrap();
    let body: Value = serde_json::from_str(&text).unwrap();
    let inputs = &body["inputs"];
    assert!(BundleDynamics.validate(inputs).is_ok());
    assert_eq!(inputs["contacts"].as_array().unwrap().len(), 180);
    for name in [
        "bundle-random-gaps.json",
        "bundle-local-closure.json",
        "bundle-sine-auto.json",
    ] {
        let text =
            std::fs::read_to_string(format!("{}/examples/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
        let body: Value = serde_json::from_str(&text).unwrap();
        assert!(BundleDynamics.validate(&body["inputs"]).is_ok(), "{name}");
    }
}

/// Row17 (issue 15): samples every 0.1 ms miss the peaks of impacts that last a fraction
/// of that, but every envelope's maximum is the reported maximum exactly: column c<k> of
/// `contact_forces_peaks` reaches contact k's `max_force`, column p<p> of
/// `displacements_peaks` pin p's peak tip deflection, and no sample exceeds its peak.
/// Samples are at exactly k × 0.1 ms.
#[test]
fn row17_envelopes_reach_the_reported_maxima_that_samples_miss() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/bundle-row17.json")).unwrap();
    let mut body: Value = serde_json::from_str(&text).unwrap();
    body["inputs"]["solver"]["check"] = json!("none");
    let output = run(&body["inputs"]);
    let doc = &output.document;
    let history = |name: &str| output.histories.iter().find(|h| h.name == name).unwrap();
    let (forces, force_peaks) = (history("contact_forces"), history("contact_forces_peaks"));
    let largest = |values: &[f64]| values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut missed = 0;
    for (k, contact) in doc["contacts"].as_array().unwrap().iter().enumerate() {
        let max_force = contact["max_force"].as_f64().unwrap();
        assert_eq!(force_peaks.series[k].0, format!("c{k}"));
        assert_eq!(largest(&force_peaks.series[k].1), max_force, "contact {k}");
        missed += usize::from(largest(&forces.series[k].1) < max_force);
        for (sample, peak) in forces.series[k].1.iter().zip(&force_peaks.series[k].1) {
            assert!(
                sample <= peak,
                "contact {k}: sample {sample} N above its peak {peak} N"
            );
        }
    }
    assert!(missed > 10, "only {missed} contacts had a peak between samples");
    let overall = doc["max_contact_force"]["force"].as_f64().unwrap();
    assert_eq!(
        overall,
        force_peaks
            .series
            .iter()
            .map(|(_, v)| largest(v))
            .fold(0.0, f64::max)
    );
    let (displacements, displacement_peaks) = (history("displacements"), history("displacements_peaks"));
    for (p, pin) in doc["pins"].as_array().unwrap().iter().enumerate() {
        let peak = pin["peak_deflections"][0]["deflection"].as_f64().unwrap();
        assert_eq!(pin["peak_deflections"][0]["height"], 1.8);
        let column = &displacement_peaks.series[p].1;
        assert_eq!(largest(column), peak.abs(), "pin {p}");
        assert!(
            column.contains(&peak),
            "pin {p}: the signed peak {peak} is in its column"
        );
        for (w, peak) in displacements.series[p].1.iter().zip(column) {
            assert!(
                w.abs() <= peak.abs(),
                "pin {p}: sample {w} m above its peak {peak} m"
            );
        }
    }
    assert_eq!(doc["output_interval"], 1e-4);
    for (k, t) in forces.time.iter().enumerate() {
        assert_eq!(
            *t,
            format!("{k}e-4").parse::<f64>().unwrap(),
            "sample {k}: k × 1e-4 as a decimal"
        );
    }
    assert_eq!(force_peaks.time, forces.time);
}

/// Walls given the feet's acceleration move with the feet: the same results.
#[test]
fn walls_given_the_feet_motion_move_with_them() {
    let base = json!({"type": "half_sine", "amplitude": 40.0, "duration": 0.01});
    let row = |excitation: Value| {
        json!({"pin": pin(), "bundle": {"pins": 3, "levels": [0.5, 1.0], "wall_gap": 1e-4, "pin_gap": 1e-4, "stiffness": 2e4, "damping": 2.0},
               "excitation": excitation, "solver": {"duration": 0.05, "check": "none"}})
    };
    let still = run(&row(json!({"base_acceleration": base})));
    let moving = run(&row(
        json!({"base_acceleration": base, "wall_acceleration": base}),
    ));
    let one = run(&row(
        json!({"base_acceleration": base, "left_wall_acceleration": base}),
    ));
    assert_eq!(still.document["contacts"], moving.document["contacts"]);
    let responses = crate::processes::excitation_record::responses;
    assert_eq!(responses(&still.histories), responses(&moving.histories));
    assert_eq!(responses(&still.histories), responses(&one.histories));
}

/// Opposite motions of the two walls, the feet still: the row answers as its own
/// mirror image (the first pin's deflection is minus the last's, the two wall contacts
/// at a level carry the same force).
#[test]
fn opposite_wall_motions_give_a_mirror_symmetric_row() {
    let inputs = json!({"pin": pin(), "bundle": {"pins": 2, "levels": [1.0], "wall_gap": 5e-5, "pin_gap": 5e-5, "stiffness": 2e4, "damping": 2.0},
        "excitation": {
            "left_wall_acceleration": {"type": "sine", "amplitude": 30.0, "frequency": 25.0, "cycles": 2.0},
            "right_wall_acceleration": {"type": "sine", "amplitude": -30.0, "frequency": 25.0, "cycles": 2.0}},
        "solver": {"duration": 0.1, "check": "none"}});
    let result = run(&inputs);
    let contacts = result.document["contacts"].as_array().unwrap();
    let wall = |side: &str| {
        contacts
            .iter()
            .position(|c| c[side] == "wall")
            .unwrap_or_else(|| panic!("a contact with the {side} wall"))
    };
    let (left, right) = (wall("left"), wall("right"));
    let forces = result
        .histories
        .iter()
        .find(|h| h.name == "contact_forces")
        .expect("forces");
    let (l, r) = (
        series(forces, &format!("c{left}")),
        series(forces, &format!("c{right}")),
    );
    let top = l.iter().fold(0.0_f64, |m, f| m.max(*f));
    assert!(top > 0.0, "the walls must hit the pins");
    for (a, b) in l.iter().zip(r) {
        assert!((a - b).abs() <= 1e-9 * top, "{a} vs {b}");
    }
}

#[test]
fn wall_motions_are_exclusive_and_checked() {
    let signal = json!({"type": "half_sine", "amplitude": 1.0, "duration": 0.01});
    let row = |excitation: Value| {
        json!({"pin": pin(), "bundle": {"pins": 2, "levels": [1.0], "wall_gap": 1e-4, "pin_gap": 1e-4, "stiffness": 2e4},
               "excitation": excitation, "solver": {"duration": 0.02}})
    };
    assert_eq!(
        pointers(&row(
            json!({"wall_acceleration": signal, "right_wall_acceleration": signal})
        )),
        ["/inputs/excitation/right_wall_acceleration"]
    );
    assert_eq!(
        pointers(&row(
            json!({"wall_acceleration": {"type": "half_sine", "amplitude": 1.0, "duration": -1.0}})
        )),
        ["/inputs/excitation/wall_acceleration/duration"]
    );
    // Pins held at both ends have their top support on the walls: one motion for both.
    let mut held = row(json!({"left_wall_acceleration": signal}));
    held["pin"]["supports"] = json!({"foot": "clamped", "top": "pinned"});
    assert_eq!(pointers(&held), ["/inputs/excitation/left_wall_acceleration"]);
}

#[test]
fn its_columns_name_their_bodies_heights_and_units() {
    let row_document = serde_json::json!({"contacts": [
        {"left": "wall", "right": 0, "height": 0.18},
        {"left": 0, "right": 1, "height": 0.18}]});
    let force = column_of("contact_forces", "c0", &row_document).unwrap();
    assert_eq!(force.long_header(), "c0 [N] contact wall–p0 at 0.18 m");
    assert_eq!(
        column_of("contact_forces", "c1", &row_document)
            .unwrap()
            .description
            .unwrap(),
        "contact p0–p1 at 0.18 m"
    );
    assert!(column_of("contact_forces", "c2", &row_document).is_none());
    let tip = column_of("displacements", "p1", &row_document).unwrap();
    assert_eq!(tip.unit.as_deref(), Some("m"));
    assert!(
        tip.description
            .unwrap()
            .starts_with("deflection of p1 at its tip")
    );
    let mid = column_of("displacements_peaks", "p1@0.9", &row_document).unwrap();
    assert!(mid.description.unwrap().starts_with("deflection of p1 at 0.9 m"));
}

/// A tip force brought on slowly to a pin damped at 0.9 of critical bends it as statics says:
/// M = F (L − z) along the height (the wall contact, 1 m away, never closes: its static
/// correction puts the tip's static shape in the basis, which the Hermite elements hold
/// exactly), σ = M c / I and ε = σ / E at the outer fibre, the worst at the clamped foot;
/// the moment history at the foot settles on F L.
#[test]
fn a_slow_tip_force_bends_the_pin_as_statics_says() {
    let (force, length) = (0.05, 1.0);
    let mut pin = pin();
    pin["damping_ratio"] = json!(0.9);
    pin["modes"] = json!(4);
    let output = run(&json!({"pin": pin, "pins": 1,
        "contacts": [{"left": 0, "right": "wall", "height": length, "gap": 1.0, "stiffness": 1e3}],
        "excitation": {"point_forces": [{"pin": 0, "height": length, "time": [0.0, 1.0, 10.0],
                                         "force": [0.0, force, force]}]},
        "output": {"heights": [0.0, 0.5], "interval": 1e-3},
        "solver": {"duration": 1.6, "check": "none"}}));
    let document = &output.document;
    let (outer, inner) = (0.010f64, 0.009f64);
    let inertia = std::f64::consts::PI / 64.0 * (outer.powi(4) - inner.powi(4));
    let envelope = document["bending_envelope"].as_array().unwrap();
    assert_eq!(envelope.len(), 21, "one entry per node");
    for entry in envelope {
        let z = entry["height"].as_f64().unwrap();
        let moment = entry["moment"].as_f64().unwrap();
        let exact = force * (length - z);
        assert!(
            (moment - exact).abs() <= 1e-4 * force * length,
            "M at {z} m: {moment:e} vs {exact:e}"
        );
        let stress = entry["stress"].as_f64().unwrap();
        assert!((stress - moment * outer / 2.0 / inertia).abs() <= 1e-9 * stress.abs().max(1.0));
        let strain = entry["strain"].as_f64().unwrap();
        assert!((strain - stress / 2.1e11).abs() <= 1e-12 * strain.abs().max(1e-12));
    }
    let worst = &document["max_bending"];
    assert_eq!(worst["height"], 0.0);
    assert_eq!(worst["pin"], 0);
    assert_eq!(document["pins"][0]["bending"], *worst);
    let moments = output
        .histories
        .iter()
        .find(|h| h.name == "bending_moments")
        .unwrap();
    let foot = series(moments, "p0@0").last().unwrap();
    assert!((foot - force * length).abs() <= 1e-6 * force * length, "{foot}");
    let middle = series(moments, "p0@0.5").last().unwrap();
    assert!(
        (middle - 0.5 * force * length).abs() <= 1e-6 * force * length,
        "{middle}"
    );
}

/// With an output height at every node, the largest |moment| of the histories is the
/// envelope's largest (the same samples, the same places).
#[test]
fn the_envelope_holds_the_largest_moment_of_the_histories() {
    let heights: Vec<f64> = (0..=10).map(|n| n as f64 * 0.1).collect();
    let mut pin = pin();
    pin["elements"] = json!(10);
    let output = run(&json!({"pin": pin, "pins": 2,
        "contacts": [{"left": "wall", "right": 0, "height": 1.0, "gap": 1e-3, "stiffness": 1e5},
                     {"left": 0, "right": 1, "height": 0.6, "gap": 5e-4, "stiffness": 1e5},
                     {"left": 1, "right": "wall", "height": 1.0, "gap": 1e-3, "stiffness": 1e5}],
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 30.0, "duration": 0.01}},
        "output": {"heights": heights, "interval": 2e-4},
        "solver": {"duration": 0.05, "check": "none"}}));
    let moments = output
        .histories
        .iter()
        .find(|h| h.name == "bending_moments")
        .unwrap();
    let largest = (moments.series.iter().flat_map(|(_, values)| values)).fold(0.0f64, |m, v| m.max(v.abs()));
    let envelope = output.document["max_bending"]["moment"].as_f64().unwrap();
    assert!(largest > 0.0);
    assert!(
        (envelope - largest).abs() <= 1e-12 * largest,
        "envelope {envelope:e}, histories {largest:e}"
    );
}

/// `pin.timoshenko`: a thick pinned–pinned tube's first frequency is the exact
/// Timoshenko one (the lower root of (ρ²I/κG) ω⁴ − (ρA + ρI k² + ρEI k²/κG) ω² + EI k⁴,
/// k = π/L, κ Cowper's for the tube), below Euler–Bernoulli's; bad values are refused at
/// their members.
#[test]
fn a_timoshenko_pin_has_the_exact_thick_beam_frequency() {
    let (length, outer, inner, nu) = (0.3, 0.05f64, 0.04f64, 0.3);
    let (e, rho) = (2.1e11, 7800.0);
    let pin = |timoshenko: Value| {
        json!({"length": length, "young_modulus": e, "density": rho,
               "section": {"type": "tube", "outer_diameter": outer, "inner_diameter": inner},
               "supports": {"foot": "pinned", "top": "pinned"},
               "elements": 40, "modes": 2, "timoshenko": timoshenko})
    };
    let row = |pin: Value| {
        json!({"pin": pin, "pins": 1, "contacts": [],
               "initial": {"tip_displacements": [0.0]},
               "solver": {"duration": 1e-4, "check": "none"}})
    };
    let frequency = |pin: Value| run(&row(pin)).document["frequencies_hz"][0].as_f64().unwrap();
    let thick = frequency(pin(json!({"poisson_ratio": nu})));
    let slender = frequency(pin(Value::Null));
    let area = std::f64::consts::PI / 4.0 * (outer.powi(2) - inner.powi(2));
    let inertia = std::f64::consts::PI / 64.0 * (outer.powi(4) - inner.powi(4));
    let m2 = (inner / outer).powi(2);
    let kappa = 6.0 * (1.0 + nu) * (1.0 + m2).powi(2)
        / ((7.0 + 6.0 * nu) * (1.0 + m2).powi(2) + (20.0 + 12.0 * nu) * m2);
    let kg = kappa * e / (2.0 * (1.0 + nu));
    let k = std::f64::consts::PI / length;
    let (a, b, c) = (
        rho * rho * inertia / kg,
        rho * area + rho * inertia * k * k + rho * e * inertia * k * k / kg,
        e * inertia * k.powi(4),
    );
    let exact = ((b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)).sqrt() / (2.0 * std::f64::consts::PI);
    assert!((thick / exact - 1.0).abs() < 1e-4, "{thick} Hz vs {exact} Hz");
    assert!(
        thick < 0.97 * slender,
        "{thick} Hz vs Euler–Bernoulli {slender} Hz"
    );

    let mut bad = row(pin(json!({"poisson_ratio": 0.6, "shear_coefficient": 0.0})));
    assert_eq!(
        pointers(&bad),
        [
            "/inputs/pin/timoshenko/shear_coefficient",
            "/inputs/pin/timoshenko/poisson_ratio"
        ]
    );
    bad["pin"]["section"] = json!({"type": "explicit", "area": area, "inertia": inertia});
    bad["pin"]["timoshenko"] = json!({});
    assert_eq!(pointers(&bad), ["/inputs/pin/timoshenko/shear_coefficient"]);
}

/// A pin thrown from straight with tip velocity V moves in its tip-load shape: its tip
/// starts at w(t) = c V t (1 + O(ω²t²)), where c = Σ φᵢ(L) uᵢ is the tip deflection the
/// basis gives the unit tip-load shape, read from a pin released from it with tip D
/// (w(0) = c D); thrown toward the right wall it meets it first, thrown away the left one.
/// A wrong count, or a throw with a top that is not free, is refused at its pointer.
#[test]
fn a_pin_thrown_moves_in_its_tip_load_shape_at_its_tip_velocity() {
    let contacts = |gap: f64| {
        json!([{"left": "wall", "right": 0, "height": 1.0, "gap": gap, "stiffness": 1e4},
               {"left": 0, "right": "wall", "height": 1.0, "gap": gap, "stiffness": 1e4}])
    };
    let (speed, tip) = (0.02, 1e-3);
    let body = |initial: Value| {
        json!({"pin": pin(), "pins": 1, "contacts": contacts(1e-4), "initial": initial,
               "solver": {"duration": 0.01, "time_step": 1e-6, "check": "none"},
               "output": {"interval": 1e-5}})
    };
    let released = run(&body(json!({"tip_displacements": [tip]})));
    let c = series(&released.histories[1], "p0")[0] / tip;
    assert!(
        (0.95..1.05).contains(&c),
        "the basis gives the tip-load shape a tip of {c}"
    );
    let thrown = run(&body(json!({"tip_velocities": [speed]})));
    let tips = series(&thrown.histories[1], "p0");
    assert_eq!(tips[0], 0.0, "thrown from straight");
    let t = 1e-5;
    let measured = tips[1] / (c * speed * t);
    assert!((measured - 1.0).abs() < 2e-3, "w(t)/(c V t) = {measured}");
    // Toward the right wall (contact 1) first: the left one has not closed then.
    let first = |document: &Value, k: usize| document["contacts"][k]["first_impact_time"].as_f64();
    let right = first(&thrown.document, 1).expect("reaches the right wall");
    assert!(first(&thrown.document, 0).is_none_or(|left| left > right));
    let away = run(&body(json!({"tip_velocities": [-speed]})));
    assert_eq!(first(&away.document, 0), Some(right), "the mirror image");

    let two = json!({"pin": pin(), "pins": 1, "contacts": contacts(1e-3),
                     "initial": {"tip_velocities": [speed, 0.0]}});
    assert_eq!(pointers(&two), ["/inputs/initial/tip_velocities"]);
    let mut clamped_top = pin();
    clamped_top["supports"] = json!({"foot": "clamped", "top": "clamped"});
    let held = json!({"pin": clamped_top, "pins": 1, "contacts": contacts(1e-3),
                      "initial": {"tip_velocities": [speed]}});
    assert_eq!(pointers(&held), ["/inputs/initial/tip_velocities"]);
}
