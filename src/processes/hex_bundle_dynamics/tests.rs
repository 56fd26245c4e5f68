//! `hex-bundle-dynamics` against physics: the generated geometry has the counts of the
//! lattice, the whole bundle turned by 60° (wires and excitation) gives the turned
//! response, a direction and its two components are the same excitation, the energy
//! balance closes, runs are deterministic, and validation names every bad field with the
//! bound it broke.

use std::ops::ControlFlow;

use serde_json::{Value, json};

use super::*;
use crate::physics::hex::{Lattice, Vec2};
use crate::processes::{Process, RunOutput};

/// A 7-pin bundle of short tubes (24 levels), shaken hard enough to rattle.
fn inputs() -> Value {
    json!({
        "pin": {"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
                "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
                "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "static_correction": "none"},
        "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                   "wrapper_flat_to_flat": 0.0305},
        "contact": {"stiffness": 2e6, "damping": 20.0},
        "gaps": {"type": "uniform", "pin_pin": 5e-5, "pin_wall": 1e-4},
        "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 50.0, "duration": 0.01},
                       "direction": 10.0},
        "solver": {"duration": 0.03, "check": "none"},
        "output": {"interval": 1e-3, "contacts": {"type": "all"}}
    })
}

fn run(inputs: &Value) -> RunOutput {
    HexBundleDynamics.validate(inputs).expect("valid inputs");
    HexBundleDynamics
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .expect("run succeeds")
}

fn errors(inputs: &Value) -> Vec<(String, String)> {
    HexBundleDynamics
        .validate(inputs)
        .expect_err("invalid")
        .0
        .into_iter()
        .map(|e| (e.pointer, e.detail))
        .collect()
}

/// `base` with the member at `pointer` set (created in its object if absent).
fn with(mut base: Value, pointer: &str, value: Value) -> Value {
    let (parent, key) = pointer.rsplit_once('/').expect("a pointer");
    base.pointer_mut(parent)
        .and_then(Value::as_object_mut)
        .unwrap_or_else(|| panic!("no object at {parent}"))
        .insert(key.to_owned(), value);
    base
}

fn contacts(document: &Value) -> &Vec<Value> {
    document["contacts"].as_array().unwrap()
}

#[test]
fn the_generated_bundle_has_the_lattice_counts_and_echoes_every_contact() {
    let output = run(&inputs());
    let doc = &output.document;
    let geometry = &doc["geometry"];
    assert_eq!(geometry["pins"], 7);
    assert_eq!(geometry["neighbour_pairs"], 12, "9n² + 3n for n = 1");
    // L/H = 2 leads, 12 levels each; every pair met twice per lead (24 pin–pin
    // contacts per lead) and each flat faced by 2 pins (12 wall contacts per lead).
    assert_eq!(geometry["levels"].as_array().unwrap().len(), 24);
    let list = contacts(doc);
    assert_eq!(list.len(), 2 * (24 + 12));
    assert_eq!(geometry["contacts"], list.len());
    let walls = list.iter().filter(|c| c["touched_flat"].is_number()).count();
    assert_eq!(walls, 24);
    for c in list {
        let n = c["normal"].as_array().unwrap();
        let (nx, ny) = (n[0].as_f64().unwrap(), n[1].as_f64().unwrap());
        assert!(((nx * nx + ny * ny).sqrt() - 1.0).abs() < 1e-12);
        let expected_gap = if c["touched_flat"].is_number() { 1e-4 } else { 5e-5 };
        assert_eq!(c["gap"], expected_gap);
    }
    // Nominal pin–pin clearance P − D − d_w = 0 here.
    assert!(geometry["pin_clearance"].as_f64().unwrap().abs() < 1e-15);
    // Every contact recorded ("all"): one force column per contact.
    let forces = &output.histories[0];
    assert_eq!(forces.series.len(), list.len());
    assert_eq!(doc["recorded_contacts"].as_array().unwrap().len(), list.len());
    assert!(doc["impacts"].as_u64().unwrap() > 0, "the bundle rattles");
}

/// Turning the wires' start angle and the excitation by 60° turns the whole problem:
/// the lattice, wrapper and gaps are 6-fold symmetric, so contact (level, i, j) of the
/// first run behaves as contact (level, R i, R j) of the second, and pin p's deflection
/// turned by 60° is pin R p's.
#[test]
fn the_bundle_turned_by_sixty_degrees_gives_the_turned_response() {
    let first = run(&inputs());
    let turned = with(inputs(), "/bundle/wire_start_angle", json!(60.0));
    let turned = run(&with(turned, "/excitation/direction", json!(70.0)));
    let lattice = Lattice::new(1);
    let key = |c: &Value, sixths: i64| {
        let pin = |v: &Value| v.as_u64().map(|p| lattice.rotated(p as usize, sixths));
        (
            c["level"].as_u64().unwrap(),
            pin(&c["wire_pin"]),
            pin(&c["touched_pin"]),
            c["touched_flat"].as_u64().map(|f| (f + sixths as u64) % 6),
        )
    };
    let (a, b) = (contacts(&first.document), contacts(&turned.document));
    let peak = first.document["max_contact_force"]["force"].as_f64().unwrap();
    assert!(
        peak > 1.0,
        "contacts must carry force for the check to mean anything"
    );
    let mut matched = 0;
    for ca in a {
        let target = key(ca, 1);
        let cb = b
            .iter()
            .find(|cb| key(cb, 0) == target)
            .expect("the turned contact exists");
        for field in ["max_force", "impulse", "contact_time"] {
            let (x, y) = (ca[field].as_f64().unwrap(), cb[field].as_f64().unwrap());
            let scale = if field == "max_force" {
                peak
            } else {
                x.abs().max(1e-12)
            };
            assert!((x - y).abs() <= 1e-6 * scale, "{field}: {x} vs {y} at {ca}");
        }
        matched += 1;
    }
    assert_eq!(matched, a.len());
    let rotation = std::f64::consts::FRAC_PI_3;
    for (p, pin) in first.document["pins"].as_array().unwrap().iter().enumerate() {
        // Peaks along x and y are not the components of one vector; the tips' final
        // deflections are: compare the last samples.
        assert_eq!(pin["pin"], p);
        let q = lattice.rotated(p, 1);
        let history = &first.histories[1];
        let last = |h: &History, name: &str| *series(h, name).last().unwrap();
        let u =
            Vec2::new(last(history, &format!("p{p}x")), last(history, &format!("p{p}y"))).rotated(rotation);
        let turned_history = &turned.histories[1];
        let v = Vec2::new(
            last(turned_history, &format!("p{q}x")),
            last(turned_history, &format!("p{q}y")),
        );
        assert!(
            (u - v).norm() <= 1e-6 * u.norm().max(1e-9),
            "pin {p}: {u:?} vs {v:?}"
        );
    }
}

fn series<'a>(history: &'a History, name: &str) -> &'a [f64] {
    &history
        .series
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .1
}

/// A signal along θ and its two components (a cos θ, a sin θ) are the same load.
#[test]
fn a_direction_and_its_components_are_the_same_excitation() {
    let along = run(&inputs());
    let angle = 10f64.to_radians();
    let components = with(
        inputs(),
        "/excitation",
        json!({
            "base_acceleration_x": {"type": "half_sine", "amplitude": 50.0 * angle.cos(), "duration": 0.01},
            "base_acceleration_y": {"type": "half_sine", "amplitude": 50.0 * angle.sin(), "duration": 0.01}
        }),
    );
    let split = run(&components);
    assert_eq!(along.document["contacts"], split.document["contacts"]);
    let responses = crate::processes::excitation_record::responses;
    assert_eq!(responses(&along.histories), responses(&split.histories));
}

#[test]
fn energy_balance_closes_and_runs_are_deterministic() {
    let first = run(&inputs());
    let energy = &first.document["energy"];
    let relative = energy["relative_residual"].as_f64().unwrap();
    assert!(relative < 1e-2, "energy residual {relative}: {energy}");
    assert!(energy["external_work"].as_f64().unwrap() > 0.0);
    let second = run(&inputs());
    assert_eq!(first, second);
}

#[test]
fn output_selection_records_only_the_selected_contacts() {
    let walls = run(&with(inputs(), "/output/contacts", json!({"type": "walls"})));
    let doc = &walls.document;
    let recorded: Vec<u64> = doc["recorded_contacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_u64().unwrap())
        .collect();
    assert_eq!(recorded.len(), 24);
    for k in &recorded {
        assert!(doc["contacts"][*k as usize]["touched_flat"].is_number());
    }
    let names: Vec<&str> = walls.histories[0]
        .series
        .iter()
        .map(|(n, _)| n.as_str())
        .collect();
    assert_eq!(names[0], format!("c{}", recorded[0]));
    // The force history of a recorded contact peaks at its max_force (the peaks history
    // keeps every step's maximum).
    let k = recorded[0] as usize;
    let peaks = series(&walls.histories[2], &format!("c{k}"));
    let max = peaks.iter().copied().fold(0.0, f64::max);
    assert_eq!(max, doc["contacts"][k]["max_force"].as_f64().unwrap());

    let list = run(&with(
        inputs(),
        "/output/contacts",
        json!({"type": "list", "contacts": [5, 2]}),
    ));
    let names: Vec<&str> = list.histories[0].series.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["c5", "c2"]);
    let ring = run(&with(
        inputs(),
        "/output/contacts",
        json!({"type": "rings", "first": 0, "last": 0}),
    ));
    // The centre pin: its wire on a neighbour at each pin–pin level, and touched once
    // per pin–pin level by the neighbour whose wire points at it (12 levels each way).
    assert_eq!(ring.document["recorded_contacts"].as_array().unwrap().len(), 24);
}

#[test]
fn bad_geometry_is_refused_at_its_pointers_with_the_bound() {
    let check = |pointer: &str, value: Value, expected: &str, bound: &str| {
        let errors = errors(&with(inputs(), pointer, value));
        let full = format!("/inputs{expected}");
        let (_, message) = errors
            .iter()
            .find(|(p, _)| *p == full)
            .unwrap_or_else(|| panic!("no error at {full}: {errors:?}"));
        assert!(message.contains(bound), "{full}: {message} (expected {bound})");
    };
    check("/bundle/rings", json!(0), "/bundle/rings", "at least 1");
    check("/bundle/rings", json!(10), "/bundle/rings", "at most 9");
    // D + d_w = 10.7 mm.
    check("/bundle/pitch", json!(0.0105), "/bundle/pitch", "0.0107");
    // √3·P + D + 2 d_w = 0.030233 m for one ring.
    check(
        "/bundle/wrapper_flat_to_flat",
        json!(0.03),
        "/bundle/wrapper_flat_to_flat",
        "0.0302",
    );
    // 6 elements of 0.05 m.
    check("/bundle/wire_lead", json!(0.2), "/bundle/wire_lead", "0.3");
    check("/contact/stiffness", json!(-1.0), "/contact/stiffness", "");
}

#[test]
fn zones_and_selections_outside_the_bundle_are_refused_together() {
    let bad = with(
        inputs(),
        "/output/contacts",
        json!({"type": "levels", "first": 3, "last": 24}),
    );
    let mut bad = bad;
    bad["closures"] = json!([
        {"first_ring": 0, "last_ring": 2, "first_level": 0, "last_level": 3, "factor": 0.0},
        {"first_sector": 1, "last_sector": 2, "first_level": 0, "last_level": 30, "factor": 0.5},
        {"first_level": 0, "last_level": 1, "factor": 0.5}
    ]);
    bad["offset"] = json!({"flat": 6, "distance": 1e-5});
    let pointers: Vec<String> = errors(&bad).into_iter().map(|(p, _)| p).collect();
    for expected in [
        "/inputs/closures/0/last_ring",
        "/inputs/closures/1/last_level",
        "/inputs/closures/2",
        "/inputs/offset/flat",
        "/inputs/output/contacts/last",
    ] {
        assert!(
            pointers.iter().any(|p| p == expected),
            "{expected} missing from {pointers:?}"
        );
    }
}

#[test]
fn excitation_forms_are_exclusive() {
    let both = with(
        inputs(),
        "/excitation/base_acceleration_y",
        json!({"type": "half_sine", "amplitude": 1.0, "duration": 0.01}),
    );
    let pointers: Vec<String> = errors(&both).into_iter().map(|(p, _)| p).collect();
    assert_eq!(pointers, ["/inputs/excitation/base_acceleration_y"]);
    let orphan = with(
        inputs(),
        "/excitation",
        json!({"direction": 30.0, "base_acceleration_x": {"type": "half_sine", "amplitude": 1.0, "duration": 0.01}}),
    );
    let pointers: Vec<String> = errors(&orphan).into_iter().map(|(p, _)| p).collect();
    assert_eq!(pointers, ["/inputs/excitation/direction"]);
}

/// Impacts in the plane: every contact's impacts in the table add up to its impulse
/// along the normal, and the summary counts them all.
#[test]
fn the_impact_table_adds_up_to_every_contacts_impulse() {
    let output = run(&inputs());
    let doc = &output.document;
    let table = (output.histories.iter())
        .find(|h| h.name == "impacts")
        .expect("the impacts table");
    let rows = crate::processes::impact_report::read_table(table)
        .expect("a table")
        .rows;
    let contacts = contacts(doc);
    let mut total = 0;
    for (k, contact) in contacts.iter().enumerate() {
        let mine: Vec<_> = rows.iter().filter(|r| r.contact == k).collect();
        assert_eq!(
            mine.len() as u64,
            contact["impacts"].as_u64().unwrap(),
            "contact {k}"
        );
        let impulse: f64 = mine.iter().map(|r| r.impulse).sum();
        let expected = contact["impulse"].as_f64().unwrap();
        assert!(
            (impulse - expected).abs() <= 1e-12 * expected.max(1e-300),
            "contact {k}"
        );
        total += mine.len() as u64;
    }
    assert!(total > 0, "the case must exercise contacts");
    assert_eq!(doc["impact_summary"]["impacts"].as_u64(), Some(total));
    assert_eq!(doc["impacts"].as_u64(), Some(total));
}

#[test]
fn bad_counting_settings_are_refused_at_their_pointers() {
    let bad = with(
        inputs(),
        "/output/impacts",
        json!({"force_threshold": -1.0, "rest_time": -1.0, "classes": 0}),
    );
    let errors = errors(&with(bad, "/output/blocks", json!(101)));
    let pointers: Vec<&str> = errors.iter().map(|(p, _)| p.as_str()).collect();
    for pointer in [
        "/inputs/output/impacts/force_threshold",
        "/inputs/output/impacts/rest_time",
        "/inputs/output/impacts/classes",
        "/inputs/output/blocks",
    ] {
        assert!(pointers.contains(&pointer), "{pointer} in {errors:?}");
    }
}

/// A wrapper given the feet's acceleration (one signal along the same direction, or its
/// two components) moves with the feet: the same results, contact by contact.
#[test]
fn a_wrapper_given_the_feet_motion_moves_with_them() {
    let still = run(&inputs());
    let excitation = &inputs()["excitation"];
    let along = with(
        inputs(),
        "/excitation/wrapper_acceleration",
        excitation["base_acceleration"].clone(),
    );
    let moving = run(&along);
    assert_eq!(still.document["contacts"], moving.document["contacts"]);
    let responses = crate::processes::excitation_record::responses;
    assert_eq!(responses(&still.histories), responses(&moving.histories));
}

/// A wrapper on its own motion changes the contacts (here the wrapper shaken across
/// while the feet stay still), the energy balance still closing with its work.
#[test]
fn a_wrapper_on_its_own_motion_drives_the_bundle_through_the_walls() {
    let mut shaken = with(
        inputs(),
        "/excitation",
        json!({"wrapper_acceleration": {"type": "half_sine", "amplitude": 50.0, "duration": 0.01},
               "wrapper_direction": 10.0}),
    );
    shaken["solver"]["duration"] = json!(0.03);
    let result = run(&shaken);
    let walls: f64 = contacts(&result.document)
        .iter()
        .filter(|c| c["touched_flat"].is_number())
        .map(|c| c["impulse"].as_f64().unwrap())
        .sum();
    assert!(walls > 0.0, "the wrapper must hit the pins");
    let energy = &result.document["energy"];
    let relative = energy["relative_residual"].as_f64().unwrap();
    assert!(relative < 1e-2, "energy residual {relative}: {energy}");
}

#[test]
fn wrapper_motion_forms_are_exclusive_and_checked() {
    let both = with(
        with(
            inputs(),
            "/excitation/wrapper_acceleration",
            json!({"type": "half_sine", "amplitude": 1.0, "duration": 0.01}),
        ),
        "/excitation/wrapper_acceleration_x",
        json!({"type": "half_sine", "amplitude": 1.0, "duration": 0.01}),
    );
    let pointers: Vec<String> = errors(&both).into_iter().map(|(p, _)| p).collect();
    assert_eq!(pointers, ["/inputs/excitation/wrapper_acceleration_x"]);
    let orphan = with(inputs(), "/excitation/wrapper_direction", json!(30.0));
    let pointers: Vec<String> = errors(&orphan).into_iter().map(|(p, _)| p).collect();
    assert_eq!(pointers, ["/inputs/excitation/wrapper_direction"]);
    let bad = with(
        inputs(),
        "/excitation/wrapper_acceleration",
        json!({"type": "half_sine", "amplitude": 1.0, "duration": -0.01}),
    );
    let pointers: Vec<String> = errors(&bad).into_iter().map(|(p, _)| p).collect();
    assert_eq!(pointers, ["/inputs/excitation/wrapper_acceleration/duration"]);
}

#[test]
fn its_columns_name_their_bodies_heights_and_units() {
    let hex_document = serde_json::json!({"contacts": [
        {"wire_pin": 3, "touched_pin": 10, "touched_flat": null, "height": 0.45},
        {"wire_pin": 8, "touched_pin": null, "touched_flat": 2, "height": 0.6}]});
    assert_eq!(
        column_of("contact_forces", "c0", &hex_document)
            .unwrap()
            .description
            .unwrap(),
        "contact of p3's wire on the clad of p10 at 0.45 m"
    );
    assert_eq!(
        column_of("contact_forces", "c1", &hex_document)
            .unwrap()
            .description
            .unwrap(),
        "contact of p8's wire on wrapper flat 2 at 0.6 m"
    );
    assert!(
        column_of("displacements", "p12y@0.3", &hex_document)
            .unwrap()
            .description
            .unwrap()
            .starts_with("deflection of p12 along y at 0.3 m")
    );
}

/// A slow force along 30° on one pin at its top, no contact closing (gaps of 5 mm): the
/// pin bends in x and y, and its bending is the resultant, F (L − z) at every node; the
/// histories are its cos and sin parts.
#[test]
fn a_pin_bent_in_x_and_y_reports_the_resultant() {
    let (force, length, angle) = (0.05, 0.6, 30f64);
    let mut inputs = inputs();
    inputs["pin"]["damping_ratio"] = json!(0.9);
    inputs["pin"]["static_correction"] = json!("contacts");
    inputs["gaps"] = json!({"type": "uniform", "pin_pin": 5e-3, "pin_wall": 5e-3});
    inputs["bundle"]["pitch"] = json!(0.0157);
    inputs["bundle"]["wrapper_flat_to_flat"] = json!(0.06);
    inputs["excitation"] = json!({"point_forces": [{"pin": 3, "height": length, "direction": angle,
        "time": [0.0, 1.0, 10.0], "force": [0.0, force, force]}]});
    inputs["solver"] = json!({"duration": 1.6, "check": "none"});
    inputs["output"] = json!({"interval": 1e-3, "heights": [0.0]});
    let output = run(&inputs);
    let document = &output.document;
    assert!(
        contacts(document).iter().all(|c| c["impacts"] == 0),
        "no contact closes"
    );
    let worst = &document["max_bending"];
    assert_eq!(worst["pin"], 3);
    let moment = worst["moment"].as_f64().unwrap();
    assert!(
        (moment - force * length).abs() <= 1e-4 * force * length,
        "{moment:e}"
    );
    assert_eq!(document["pins"][3]["bending"], *worst);
    // The resultant deflection: the static F L³/3EI at the tip, along 30° (its x and y
    // extremes are its cos and sin parts).
    let pin = &document["pins"][3];
    let resultant = pin["deflection"]["max_deflection"].as_f64().unwrap();
    let x = pin["x"]["max_abs_deflection"].as_f64().unwrap();
    let y = pin["y"]["max_abs_deflection"].as_f64().unwrap();
    assert_eq!(pin["deflection"]["height"], length);
    assert!(
        (resultant - x.hypot(y)).abs() <= 1e-4 * resultant,
        "{resultant:e} vs ({x:e}, {y:e})"
    );
    assert!((x - resultant * angle.to_radians().cos()).abs() <= 1e-4 * resultant);
    let moments = output
        .histories
        .iter()
        .find(|h| h.name == "bending_moments")
        .unwrap();
    let last = |name: &str| {
        *moments
            .series
            .iter()
            .find(|(n, _)| n == name)
            .unwrap()
            .1
            .last()
            .unwrap()
    };
    let (x, y) = (last("p3x@0"), last("p3y@0"));
    let expected = force * length;
    assert!(
        (x - expected * angle.to_radians().cos()).abs() <= 1e-5 * expected,
        "{x:e}"
    );
    assert!(
        (y - expected * angle.to_radians().sin()).abs() <= 1e-5 * expected,
        "{y:e}"
    );
}

/// With an output height at every node, the largest resultant moment of the histories
/// (√(Mx² + My²) of a pin at a height and sample) is the envelope's largest.
#[test]
fn the_envelope_holds_the_largest_resultant_moment_of_the_histories() {
    let mut inputs = inputs();
    let heights: Vec<f64> = (0..=12).map(|n| n as f64 * 0.6 / 12.0).collect();
    inputs["output"]["heights"] = json!(heights);
    let output = run(&inputs);
    let moments = output
        .histories
        .iter()
        .find(|h| h.name == "bending_moments")
        .unwrap();
    let column = |name: String| &moments.series.iter().find(|(n, _)| *n == name).unwrap().1;
    let mut largest = 0.0f64;
    for height in &heights {
        for pin in 0..7 {
            let (x, y) = (
                column(format!("p{pin}x@{height}")),
                column(format!("p{pin}y@{height}")),
            );
            largest = x.iter().zip(y).fold(largest, |m, (x, y)| m.max(x.hypot(*y)));
        }
    }
    let envelope = output.document["max_bending"]["moment"].as_f64().unwrap();
    assert!(largest > 0.0);
    assert!(
        (envelope - largest).abs() <= 1e-12 * largest,
        "envelope {envelope:e}, histories {largest:e}"
    );
}

/// 19 pins at their nominal clearances (the wires touch their neighbours with no gap)
/// with dashpots, shaken: the pins move together at first, so the wires' penetrations
/// are rounding (±1e-20 m) on more wire contacts per pin than the basis has modes.
/// `exact_modal` must not let rounding decide which contacts push (its first solver
/// did not settle at the first step); it rattles to central difference's peak within
/// the verdict's bound for peaks (10 × the tolerance) and closes its energy balance.
#[test]
fn exact_modal_rattles_nineteen_pins_touching_at_rest_to_central_differences_peak() {
    let mut base = inputs();
    base["bundle"]["rings"] = json!(2);
    base["bundle"]["wrapper_flat_to_flat"] = json!(3f64.sqrt() * 2.0 * 0.0107 + 0.0117 + 0.001);
    base.as_object_mut().unwrap().remove("gaps");
    base["solver"]["duration"] = json!(0.01);
    base["solver"]["time_step"] = json!("auto");
    let peak = |scheme: &str| {
        let output = run(&with(base.clone(), "/solver/scheme", json!(scheme)));
        let document = &output.document;
        let residual = document["energy"]["relative_residual"].as_f64().unwrap();
        assert!(residual < 1e-3, "{scheme}: energy residual {residual}");
        contacts(document)
            .iter()
            .map(|c| c["max_force"].as_f64().unwrap())
            .fold(0.0, f64::max)
    };
    let (explicit, exact) = (peak("central_difference"), peak("exact_modal"));
    assert!(explicit > 1.0, "the case must rattle: peak {explicit} N");
    assert!(
        (exact - explicit).abs() <= 10.0 * 1e-3 * explicit,
        "peak {exact} N (exact_modal) vs {explicit} N (central difference)"
    );
}
