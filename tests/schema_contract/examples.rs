//! Small valid inputs that, together, hold every object of each process's inputs and
//! every alternative of its choices (sections, damping forms, gap states, excitations,
//! contact selections): short runs on coarse meshes, so that each default can be
//! checked by running the process twice.

use std::sync::Arc;

use chocmodal::physics::hex::{Handedness, HexBundle, HexLayout};
use chocmodal::physics::loads::Table;
use chocmodal::processes::signal_input::{SignalLibrary, SignalSource};
use serde_json::{Value, json};

/// Id of the stored accelerogram the `signal` examples refer to.
const SIGNAL: &str = "recorded";

/// The stored signals of the examples: one short accelerogram.
pub fn signals() -> SignalLibrary {
    let mut library = SignalLibrary::new(SignalSource::Stored);
    let time: Vec<f64> = (0..=50).map(|k| k as f64 * 1e-4).collect();
    let values = time.iter().map(|t| 30.0 * (600.0 * t).sin()).collect();
    library.insert(SIGNAL, Arc::new(Table { time, values }));
    library
}

fn tube_beam(length: f64) -> Value {
    json!({"length": length, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
           "added_mass_per_length": 0.1, "elements": 6, "modes": 3, "damping_ratio": 0.01,
           "supports": {"foot": "clamped", "top": "free"}, "static_correction": "contacts"})
}

/// The same pin as [`tube_beam`] by its area and inertia, with a damping ratio per mode,
/// as a Timoshenko beam (a thin tube's κ, ν given).
fn explicit_beam(length: f64) -> Value {
    json!({"length": length, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "explicit", "area": 1.7153e-5, "inertia": 1.8338e-10},
           "elements": 6, "modes": 3, "damping_ratio": [0.01, 0.02],
           "timoshenko": {"poisson_ratio": 0.3, "shear_coefficient": 0.53}})
}

/// A fixed step with the Tchamwa scheme, and every other member of `solver`.
fn tchamwa(duration: f64) -> Value {
    json!({"scheme": "tchamwa", "phi": 1.1, "time_step": 1e-6, "duration": duration,
           "tolerance": 1e-3, "check": "step_halving", "threads": 2})
}

/// One base acceleration of each type.
fn base_accelerations() -> Vec<Value> {
    vec![
        json!({"type": "half_sine", "amplitude": 50.0, "duration": 0.003}),
        json!({"type": "sine", "amplitude": 20.0, "frequency": 200.0, "cycles": 1.5}),
        json!({"type": "table", "time": [0.0, 0.002, 0.004], "acceleration": [0.0, 40.0, 0.0]}),
        json!({"type": "haversine", "amplitude": 50.0, "duration": 0.003}),
        json!({"type": "terminal_peak_sawtooth", "amplitude": 50.0, "duration": 0.003}),
        json!({"type": "trapezoid", "amplitude": 50.0, "rise": 0.001, "plateau": 0.001, "fall": 0.001}),
        json!({"type": "signal", "id": SIGNAL, "scale": 1.0}),
        json!({"type": "spectrum_compatible",
               "target": {"frequencies": [5.0, 20.0], "accelerations": [3.0, 3.0], "damping": 0.05},
               "duration": 1.0, "strong_motion": 0.5, "seed": 1, "rise": 0.1, "time_step": 0.005,
               "tolerance": 0.2, "max_iterations": 40}),
    ]
}

/// The three kinds of contact law, between them every member of `law`: a power law
/// with a restitution at a speed, Hunt–Crossley damping, and a linear law's restitution
/// with its mass (docs/contact-laws.md).
fn laws() -> [Value; 3] {
    [
        json!({"exponent": 1.5, "force_scale": 50.0, "restitution": 0.8, "restitution_speed": 0.5,
               "allowable_force": 100.0}),
        json!({"hunt_crossley": 0.1, "allowable_force": 100.0}),
        json!({"restitution": 0.7, "restitution_mass": 0.05}),
    ]
}

/// [`laws`] with friction and a wear law of each geometry, for pins in the plane.
fn plane_laws() -> [Value; 3] {
    let geometries = [
        json!({"type": "flat", "radius": 0.00485, "width": 0.002}),
        json!({"type": "crossed_tubes", "radius": 0.00485, "angle": 10.0}),
        json!({"type": "bore", "radius": 0.00485, "length": 0.01}),
    ];
    let mut laws = laws();
    for (law, geometry) in laws.iter_mut().zip(geometries) {
        law["friction"] = json!({"coefficient": 0.3, "tangential_stiffness": 1e5});
        law["wear"] = json!({"coefficient": 1e-13, "geometry": geometry});
    }
    laws
}

/// `cantilever-impact`: a tube with `rk`, and an explicit section with a stiffness, a
/// per-mode damping list and the Tchamwa scheme; each kind of contact law.
pub fn cantilever() -> Vec<Value> {
    let mut examples = vec![
        json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                        "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                        "added_mass_per_length": 0.1, "elements": 8, "modes": 4, "damping_ratio": 0.01,
                        "supports": {"foot": "clamped", "top": "free"}, "static_correction": "contacts",
                        "timoshenko": {"poisson_ratio": 0.3, "shear_coefficient": 0.53}},
               "contact": {"rk": 1.0, "gap": 0.0, "damping": 0.0},
               "release": {"tip_displacement": 0.001},
               "solver": {"scheme": "central_difference", "time_step": 1e-5, "duration": 0.04,
                          "tolerance": 1e-3, "check": "step_halving", "threads": 2},
               "reference": {"modes": 6},
               "output": {"interval": 1e-4, "blocks": 2,
                          "impacts": {"force_threshold": 0.0, "rest_time": 0.0, "classes": 10,
                                      "max_rows": 1000},
                          "allowables": {"contact_force": 0.5, "stress": 1e8}},
               "warnings": "on"}),
        json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                        "section": {"type": "explicit", "area": 1.49e-5, "inertia": 1.68e-10},
                        "elements": 8, "modes": 4, "damping_ratio": [0.01, 0.02]},
               "contact": {"stiffness": 50.0, "gap": 1e-4, "damping": 0.1},
               "solver": {"scheme": "tchamwa", "phi": 1.1, "time_step": "auto", "duration": 0.04},
               "reference": {"modes": 6}}),
    ];
    for law in laws() {
        let stiffness = if law.get("exponent").is_some() { 1e8 } else { 50.0 };
        examples.push(json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                                      "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                                      "elements": 8, "modes": 4},
                             "contact": {"stiffness": stiffness, "law": law},
                             "solver": {"duration": 0.02, "check": "none"},
                             "reference": {"modes": 6}}));
    }
    examples
}

/// A row of two pins between the walls, explicit form.
fn explicit_row() -> Value {
    json!({"pin": tube_beam(1.0),
           "pins": 2,
           "contacts": [
               {"left": "wall", "right": 0, "height": 1.0, "gap": 1e-4, "stiffness": 2e5, "damping": 1.0},
               {"left": 0, "right": 1, "height": 1.0, "gap": 1e-4, "stiffness": 2e5, "damping": 1.0},
               {"left": 1, "right": "wall", "height": 1.0, "gap": 1e-4, "stiffness": 2e5, "damping": 1.0}],
           "solver": {"duration": 0.01}})
}

/// `bundle-dynamics`: the explicit form with a release, a pulse and a point force, on
/// each section and scheme; the generator form with each gap state and closures; every
/// base acceleration.
pub fn bundle() -> Vec<Value> {
    let mut explicit = explicit_row();
    explicit["initial"] = json!({"tip_displacements": [0.001, 0.0], "tip_velocities": [0.0, -0.05]});
    explicit["excitation"] = json!({
        "base_acceleration": {"type": "half_sine", "amplitude": 50.0, "duration": 0.005},
        "point_forces": [{"pin": 1, "height": 0.5, "time": [0.0, 0.002, 0.004], "force": [0.0, 5.0, 0.0]}]});
    explicit["output"] = json!({"interval": 1e-4, "heights": [0.5, 1.0], "blocks": 2,
                                "impacts": {"force_threshold": 0.0, "rest_time": 0.0, "classes": 10,
                                            "max_rows": 1000},
                                "allowables": {"contact_force": {"pin_pin": 5.0, "pin_wall": 6.0},
                                               "stress": 1e8}});
    explicit["warnings"] = json!("on");
    // A guide tube among the pins (docs/kinds.md).
    explicit["kinds"] = json!([{"name": "guide_tube", "pins": [1], "young_modulus": 1.9e11, "density": 6500.0,
                                "section": {"type": "tube", "outer_diameter": 0.0124, "inner_diameter": 0.0114},
                                "added_mass_per_length": 0.2, "damping_ratio": 0.02}]);
    let mut explicit_section = explicit_row();
    explicit_section["pin"] = explicit_beam(1.0);
    explicit_section["solver"] = tchamwa(0.01);
    explicit_section["initial"] = json!({"tip_displacements": [0.0, 0.001]});
    explicit_section["output"] = json!({"allowables": {"contact_force": 5.0}});
    // A kind of the Timoshenko pin scaled: twice its area and inertia (the same shear
    // and rotary proportions, so the same shapes), another material.
    explicit_section["kinds"] = json!([{"name": "thick", "pins": [0], "young_modulus": 1.5e11, "density": 6000.0,
                                        "section": {"type": "explicit", "area": 3.4306e-5, "inertia": 3.6676e-10},
                                        "damping_ratio": [0.02, 0.03]}]);
    let generator = |gaps: Value, base: Value| {
        json!({"pin": tube_beam(1.0),
               "bundle": {"pins": 3, "levels": {"first": 0.5, "spacing": 0.5, "count": 2},
                          "stiffness": 2e5, "damping": 1.0, "wall_gap": 1e-4, "pin_gap": 1e-4,
                          "gaps": gaps,
                          "closures": [{"first_level": 0, "last_level": 1, "first_pin": 0, "last_pin": 1,
                                        "factor": 0.5}]},
               "excitation": {"base_acceleration": base},
               "solver": {"duration": 0.01}})
    };
    let gap_states = [
        json!({"type": "uniform"}),
        json!({"type": "random", "distribution": {"type": "uniform", "low": 0.0, "high": 2e-4},
               "seed": 7, "relative": false}),
        json!({"type": "random", "distribution": {"type": "normal", "mean": 1e-4, "std": 2e-5},
               "seed": 3, "relative": false}),
        json!({"type": "per_contact", "values": [1e-4, 1e-4, 1e-4, 1e-4, 0.0, 1e-4, 1e-4, 1e-4]}),
    ];
    let mut examples = vec![explicit, explicit_section];
    // Each kind of law on an explicit contact, and on each family of the generator.
    let mut with_laws = explicit_row();
    for (contact, law) in laws().into_iter().enumerate() {
        // A restitution sets the damping: none is given beside it.
        with_laws["contacts"][contact]["damping"] = json!(0.0);
        with_laws["contacts"][contact]["law"] = law;
    }
    examples.push(with_laws);
    for k in 0..3 {
        let mut families = generator(json!({"type": "uniform"}), base_accelerations()[0].clone());
        families["bundle"]["damping"] = json!(0.0);
        families["bundle"]["law"] = laws()[k].clone();
        families["bundle"]["wall_law"] = laws()[(k + 1) % 3].clone();
        examples.push(families);
    }
    let bases = base_accelerations();
    for (k, base) in bases.iter().enumerate() {
        examples.push(generator(gap_states[k % gap_states.len()].clone(), base.clone()));
    }
    examples[3]["bundle"]["levels"] = json!([0.6, 1.0]);
    // The walls' own motions, every signal form on each member.
    for (k, base) in bases.iter().enumerate() {
        let mut both = generator(gap_states[k % gap_states.len()].clone(), bases[0].clone());
        both["excitation"]["wall_acceleration"] = base.clone();
        let mut each = generator(gap_states[(k + 1) % gap_states.len()].clone(), bases[0].clone());
        each["excitation"]["left_wall_acceleration"] = base.clone();
        each["excitation"]["right_wall_acceleration"] = bases[(k + 1) % bases.len()].clone();
        examples.extend([both, each]);
    }
    examples
}

/// The hexagonal bundle of the examples: one ring around the centre pin, on 0.4 m pins.
const PIN_LENGTH: f64 = 0.4;
const PITCH: f64 = 0.0107;
const WIRE: f64 = 0.001;
const LEAD: f64 = 0.4;
const FLAT_TO_FLAT: f64 = 0.0312;
const ELEMENTS: usize = 6;

fn hex_example(gaps: Value, excitation: Value, selection: Value) -> Value {
    json!({"pin": tube_beam(PIN_LENGTH),
           "bundle": {"rings": 1, "pitch": PITCH, "wire_diameter": WIRE, "wire_lead": LEAD,
                      "wrapper_flat_to_flat": FLAT_TO_FLAT, "pin_diameter": 0.0097,
                      "wire_start_angle": 0.0, "handedness": "right"},
           "contact": {"stiffness": 2e5, "damping": 1.0, "wall_stiffness": 2e5, "wall_damping": 1.0},
           "gaps": gaps,
           "excitation": excitation,
           "solver": {"duration": 0.005},
           "output": {"interval": 1e-4, "heights": [PIN_LENGTH], "contacts": selection}})
}

/// `hex-bundle-dynamics`: each gap state, closures by rings and by sectors, an offset,
/// every base acceleration along a direction and as each component, each contact
/// selection, each section and scheme; a release and point forces alone.
pub fn hex() -> Vec<Value> {
    let layout = HexLayout {
        rings: 1,
        pitch: PITCH,
        pin_diameter: 0.0097,
        wire_diameter: WIRE,
        wire_lead: LEAD,
        wrapper_flat_to_flat: FLAT_TO_FLAT,
        wire_start_angle: 0.0,
        handedness: Handedness::Right,
    };
    let contacts = HexBundle::new(layout, PIN_LENGTH, ELEMENTS)
        .expect("the examples' bundle")
        .contact_count();
    let gap_states = [
        json!({"type": "uniform", "pin_pin": 3e-4, "pin_wall": 3e-4}),
        json!({"type": "per_contact", "values": vec![3e-4; contacts]}),
        json!({"type": "random", "distribution": {"type": "normal", "mean": 1.0, "std": 0.1},
               "seed": 5, "relative": true}),
        json!({"type": "random", "distribution": {"type": "uniform", "low": 0.0, "high": 3e-4},
               "seed": 5, "relative": false}),
        json!({"type": "uniform"}),
    ];
    let selections = [
        json!({"type": "walls"}),
        json!({"type": "list", "contacts": [0, 1]}),
        json!({"type": "levels", "first": 0, "last": 1}),
        json!({"type": "rings", "first": 0, "last": 1}),
        json!({"type": "all"}),
        json!({"type": "none"}),
    ];
    let bases = base_accelerations();
    let mut first = hex_example(
        gap_states[0].clone(),
        json!({"base_acceleration": bases[0], "direction": 30.0}),
        selections[0].clone(),
    );
    first["closures"] = json!([
        {"first_ring": 0, "last_ring": 1, "first_level": 0, "last_level": 2, "factor": 0.5},
        {"first_sector": 0, "last_sector": 2, "first_level": 0, "last_level": 1, "factor": 0.0}]);
    first["offset"] = json!({"flat": 2, "distance": 1e-4});
    first["output"]["impacts"] = json!({"force_threshold": 0.0, "rest_time": 0.0, "classes": 10,
                                        "max_rows": 1000});
    first["output"]["blocks"] = json!(2);
    first["output"]["allowables"] =
        json!({"contact_force": {"pin_pin": 5.0, "pin_wall": 6.0}, "stress": 1e8});
    first["warnings"] = json!("on");
    // An absorber pin at the centre: the clad diameter D, a thicker wall, heavier.
    first["kinds"] = json!([{"name": "absorber", "pins": [0], "young_modulus": 2.0e11, "density": 8000.0,
                             "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0075},
                             "added_mass_per_length": 1.2, "damping_ratio": 0.02}]);
    let mut explicit_section = hex_example(
        gap_states[4].clone(),
        json!({"base_acceleration": bases[0]}),
        selections[0].clone(),
    );
    explicit_section["pin"] = explicit_beam(PIN_LENGTH);
    explicit_section["solver"] = tchamwa(0.005);
    explicit_section["output"]["allowables"] = json!({"contact_force": 5.0, "stress": 1e8});
    explicit_section["kinds"] = json!([{"name": "thick", "pins": [1], "young_modulus": 1.5e11, "density": 6000.0,
                                        "section": {"type": "explicit", "area": 3.4306e-5, "inertia": 3.6676e-10},
                                        "damping_ratio": [0.02, 0.03]}]);
    // Moved by loads alone: the centre pin released along 45°, point forces along a
    // direction and along x (the default).
    let mut loaded = hex_example(gap_states[0].clone(), json!({}), selections[4].clone());
    loaded["initial"] = json!({"tip_displacements": [{"pin": 0, "x": 2e-4, "y": 2e-4}],
                               "tip_velocities": [{"pin": 2, "x": 0.01, "y": -0.02}]});
    loaded["excitation"] = json!({"point_forces": [
        {"pin": 1, "height": PIN_LENGTH, "direction": 120.0, "time": [0.0, 0.002, 0.004],
         "force": [0.0, 2.0, 0.0]},
        {"pin": 4, "height": 0.5 * PIN_LENGTH, "time": [0.0, 0.003], "force": [1.0, 0.0]}]});
    let mut examples = vec![first, explicit_section, loaded];
    // Each kind of law, with friction and each wear geometry, on each family.
    for k in 0..3 {
        let mut rubbing = hex_example(
            gap_states[0].clone(),
            json!({"base_acceleration": bases[0], "direction": 30.0}),
            selections[0].clone(),
        );
        rubbing["contact"]["damping"] = json!(0.0);
        rubbing["contact"]["wall_damping"] = json!(0.0);
        rubbing["contact"]["law"] = plane_laws()[k].clone();
        rubbing["contact"]["wall_law"] = plane_laws()[(k + 1) % 3].clone();
        rubbing["output"]["service_time"] = json!(3.15e7);
        examples.push(rubbing);
    }
    for (k, base) in bases.iter().enumerate() {
        examples.push(hex_example(
            gap_states[k % gap_states.len()].clone(),
            json!({"base_acceleration": base, "direction": 30.0}),
            selections[k % selections.len()].clone(),
        ));
        examples.push(hex_example(
            gap_states[(k + 1) % gap_states.len()].clone(),
            json!({"base_acceleration_x": base, "base_acceleration_y": bases[(k + 1) % bases.len()]}),
            selections[(k + 1) % selections.len()].clone(),
        ));
        // The wrapper's own motion, along a direction and as components.
        examples.push(hex_example(
            gap_states[k % gap_states.len()].clone(),
            json!({"base_acceleration": bases[0], "wrapper_acceleration": base, "wrapper_direction": 10.0}),
            selections[k % selections.len()].clone(),
        ));
        examples.push(hex_example(
            gap_states[(k + 1) % gap_states.len()].clone(),
            json!({"wrapper_acceleration_x": base, "wrapper_acceleration_y": bases[(k + 1) % bases.len()]}),
            selections[(k + 1) % selections.len()].clone(),
        ));
    }
    examples
}

/// Sweep requests over short cantilever runs: a grid and a random design, with every
/// member of a request.
pub fn sweeps() -> Vec<Value> {
    let inputs = json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                                 "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009},
                                 "elements": 8, "modes": 4},
                        "solver": {"duration": 0.02, "check": "none"}, "reference": {"modes": 6}});
    vec![
        json!({"process": "cantilever-impact", "inputs": inputs,
               "axes": [{"pointer": "/contact/rk", "values": [0.5, 1.0]},
                        {"pointer": "/contact/gap", "linspace": [0.0, 1e-4, 2]}],
               "design": "grid", "seed": 0, "policy": "continue", "invalid_runs": "refuse"}),
        json!({"process": "cantilever-impact", "inputs": inputs,
               "axes": [{"pointer": "/contact/rk", "uniform": [0.5, 2.0]},
                        {"pointer": "/release/tip_displacement", "normal": {"mean": 1e-3, "std": 1e-4}}],
               "design": "monte_carlo", "samples": 2, "seed": 7, "policy": "fail_fast",
               "invalid_runs": "record"}),
    ]
}
