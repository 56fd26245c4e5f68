//! Pins of several kinds in one row over HTTP (docs/kinds.md): a kind that is the pin
//! changes nothing, a guide tube bends with its own section, and kinds the row cannot
//! take are refused at their members.

use serde_json::{Value, json};

use chocmodal::processes::Registry;

use crate::helpers::{TestApp, spawn_app_with_processes};

async fn spawn() -> TestApp {
    spawn_app_with_processes(Registry::builtin().all().to_vec(), |_| {}).await
}

const ROD: (f64, f64) = (0.0097, 0.0085);
const TUBE: (f64, f64) = (0.0124, 0.0114);

fn pin() -> Value {
    json!({"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": ROD.0, "inner_diameter": ROD.1},
           "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "damping_ratio": 0.01})
}

/// Three pins between two walls touching at their tips, released and shaken, with
/// `kinds`.
fn row(kinds: Value) -> Value {
    let contact = |left: Value, right: Value| json!({"left": left, "right": right, "height": 0.6, "gap": 1e-4, "stiffness": 2e5});
    json!({"pin": pin(), "pins": 3, "kinds": kinds,
           "contacts": [contact(json!("wall"), json!(0)), contact(json!(0), json!(1)),
                        contact(json!(1), json!(2)), contact(json!(2), json!("wall"))],
           "initial": {"tip_displacements": [1e-3, 0.0, -1e-3]},
           "excitation": {"base_acceleration": {"type": "half_sine", "amplitude": 40.0, "duration": 0.01}},
           "solver": {"duration": 0.05, "check": "none"}})
}

fn guide_tube(pins: Value) -> Value {
    json!({"name": "guide_tube", "pins": pins, "young_modulus": 0.99e11, "density": 6550.0,
           "section": {"type": "tube", "outer_diameter": TUBE.0, "inner_diameter": TUBE.1}})
}

fn inertia((outer, inner): (f64, f64)) -> f64 {
    std::f64::consts::PI / 64.0 * (outer.powi(4) - inner.powi(4))
}

async fn refused(app: &TestApp, inputs: Value) -> Vec<String> {
    app.refused_pointers("bundle-dynamics", &inputs).await
}

/// Each pin's bending stress over its moment is c/I of its section (`sections`: the
/// pin's number and its tube's diameters).
fn assert_bends_with_own_section(pins: &[Value], sections: &[(usize, (f64, f64))]) {
    for (p, section) in sections {
        let bending = &pins[*p]["bending"];
        let ratio = number(&bending["stress"]) / number(&bending["moment"]);
        let expected = section.0 / 2.0 / inertia(*section);
        assert!(
            (ratio - expected).abs() < 1e-9 * expected,
            "pin {p}: σ/M {ratio} vs c/I {expected}"
        );
    }
}

fn number(value: &Value) -> f64 {
    value.as_f64().unwrap_or_else(|| panic!("a number: {value}"))
}

#[tokio::test]
async fn a_kind_that_is_the_pin_changes_no_result_and_names_its_pins() {
    let app = spawn().await;
    let same = json!([{"name": "same", "pins": [1], "young_modulus": 2.1e11, "density": 7800.0,
                       "section": {"type": "tube", "outer_diameter": ROD.0, "inner_diameter": ROD.1},
                       "added_mass_per_length": 0.6}]);
    let plain = app
        .results_of("bundle-dynamics", &json!({"inputs": row(json!([]))}))
        .await;
    let kinds = app
        .results_of("bundle-dynamics", &json!({"inputs": row(same)}))
        .await;
    for (a, b) in plain["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .zip(kinds["contacts"].as_array().unwrap())
    {
        let (fa, fb) = (number(&a["max_force"]), number(&b["max_force"]));
        assert!(fa > 0.0 && (fa - fb).abs() <= 1e-9 * fa, "{fa} vs {fb}");
    }
    assert_eq!(kinds["pins"][1]["kind"], "same");
    assert!(kinds["pins"][0].get("kind").is_none() && plain["pins"][1].get("kind").is_none());
}

/// The tube's moment and stress come from its own section: σ/M = c/I for each pin, with
/// the tube's c and I on the tube; the run's largest bending is the most stressed pin.
#[tokio::test]
async fn a_guide_tube_in_a_row_bends_with_its_own_section() {
    let app = spawn().await;
    let results = app
        .results_of(
            "bundle-dynamics",
            &json!({"inputs": row(json!([guide_tube(json!([1]))]))}),
        )
        .await;
    let pins = results["pins"].as_array().unwrap();
    assert_bends_with_own_section(pins, &[(0, ROD), (1, TUBE), (2, ROD)]);
    for p in 0..3 {
        assert_eq!(
            pins[p].get("kind").and_then(Value::as_str),
            (p == 1).then_some("guide_tube")
        );
    }
    let most = pins
        .iter()
        .map(|p| number(&p["bending"]["stress"]))
        .fold(0.0, f64::max);
    let run = number(&results["max_bending"]["stress"]);
    assert!((run - most).abs() <= 1e-9 * most, "run {run} vs pins {most}");
    assert!(results["energy"]["relative_residual"].as_f64().unwrap().abs() < 1e-3);
}

#[tokio::test]
async fn kinds_the_row_cannot_take_are_refused_at_their_members() {
    let app = spawn().await;
    let mut bad = guide_tube(json!([1, 7]));
    bad["density"] = json!(-1.0);
    let twice = guide_tube(json!([2]));
    assert_eq!(
        refused(&app, row(json!([bad, twice]))).await,
        [
            "/inputs/kinds/0/density",
            "/inputs/kinds/0/pins/1",
            "/inputs/kinds/1/name"
        ]
    );
    // A Timoshenko pin whose tube has another shear proportion: other mode shapes.
    let mut sheared = row(json!([guide_tube(json!([1]))]));
    sheared["pin"]["timoshenko"] = json!({"poisson_ratio": 0.3});
    assert_eq!(refused(&app, sheared).await, ["/inputs/kinds/0"]);
}

/// The exact modal scheme takes kinds: its peaks agree with central difference's.
#[tokio::test]
async fn a_guide_tube_row_under_exact_modal_agrees_with_central_difference() {
    let app = spawn().await;
    let inputs = row(json!([guide_tube(json!([1]))]));
    let mut exact = inputs.clone();
    exact["solver"]["scheme"] = json!("exact_modal");
    let explicit = app
        .results_of("bundle-dynamics", &json!({"inputs": inputs}))
        .await;
    let exact = app.results_of("bundle-dynamics", &json!({"inputs": exact})).await;
    let peak = |r: &Value| number(&r["max_contact_force"]["force"]);
    let (a, b) = (peak(&explicit), peak(&exact));
    assert!(
        a > 0.0 && (a - b).abs() < 0.02 * a,
        "central difference {a} N, exact {b} N"
    );
    assert!(number(&exact["steps"]) < number(&explicit["steps"]));
}

/// Seven wire-wrapped pins with `kinds`, pressed together and shaken.
fn hex(kinds: Value) -> Value {
    json!({"pin": pin(), "kinds": kinds,
           "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                      "wrapper_flat_to_flat": 0.0305},
           "contact": {"stiffness": 2e5},
           "gaps": {"type": "uniform", "pin_pin": 0.0, "pin_wall": 0.0},
           "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 30.0, "cycles": 2},
                          "direction": 30.0},
           "solver": {"duration": 0.03, "check": "none"}})
}

/// The centre pin of a hexagonal bundle of another kind (a thicker clad of the same
/// diameter, heavier): its stress over moment is c/I of its own section, and a kind of
/// another clad diameter, or of a pin the bundle does not have, is refused.
#[tokio::test]
async fn a_hexagonal_bundle_takes_kinds_of_its_clad_diameter() {
    let app = spawn().await;
    let thick = (ROD.0, 0.0075);
    let kind = json!({"name": "absorber", "pins": [0], "young_modulus": 2.0e11, "density": 8000.0,
                      "section": {"type": "tube", "outer_diameter": thick.0, "inner_diameter": thick.1},
                      "added_mass_per_length": 1.2});
    let results = app
        .results_of(
            "hex-bundle-dynamics",
            &json!({"inputs": hex(json!([kind.clone()]))}),
        )
        .await;
    let pins = results["pins"].as_array().unwrap();
    assert_bends_with_own_section(pins, &[(0, thick), (1, ROD)]);
    assert_eq!(pins[0]["kind"], "absorber");
    let mut wider = kind.clone();
    wider["section"]["outer_diameter"] = json!(0.0105);
    wider["pins"] = json!([0, 9]);
    let pointers = app
        .refused_pointers("hex-bundle-dynamics", &hex(json!([wider])))
        .await;
    assert_eq!(pointers, ["/inputs/kinds/0/section"]);
    let mut missing = kind;
    missing["pins"] = json!([0, 9]);
    let pointers = app
        .refused_pointers("hex-bundle-dynamics", &hex(json!([missing])))
        .await;
    assert_eq!(pointers, ["/inputs/kinds/0/pins/1"]);
}
