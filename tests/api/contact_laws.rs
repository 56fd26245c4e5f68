//! Contact laws over HTTP (docs/contact-laws.md): each process takes a `law` per
//! contact or per family, refuses a law it cannot carry with a 422 at the member, and
//! reports utilisations, friction and Archard wear that follow from its own numbers by
//! their definitions (peak over allowable, K P t and the geometry's depth).

use serde_json::{Value, json};

use chocmodal::processes::Registry;

use crate::helpers::{TestApp, spawn_app_with_processes};

async fn spawn() -> TestApp {
    spawn_app_with_processes(Registry::builtin().all().to_vec(), |_| {}).await
}

fn pin() -> Value {
    json!({"length": 0.6, "young_modulus": 2.1e11, "density": 7800.0,
           "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
           "added_mass_per_length": 0.6, "elements": 12, "modes": 4, "damping_ratio": 0.01,
           "static_correction": "none"})
}

/// Seven wire-wrapped pins pressed together (zero gaps) and shaken, with `law` on every
/// contact.
fn hex(law: Value, output: Value) -> Value {
    json!({"pin": pin(),
           "bundle": {"rings": 1, "pitch": 0.0107, "wire_diameter": 0.001, "wire_lead": 0.3,
                      "wrapper_flat_to_flat": 0.0305},
           "contact": {"stiffness": 2e5, "law": law},
           "gaps": {"type": "uniform", "pin_pin": 0.0, "pin_wall": 0.0},
           "excitation": {"base_acceleration": {"type": "sine", "amplitude": 20.0, "frequency": 30.0, "cycles": 2},
                          "direction": 30.0},
           "solver": {"duration": 0.05, "check": "none"},
           "output": output})
}

/// A row of two pins between two walls, with `law` on every contact.
fn row(law: Value) -> Value {
    json!({"pin": pin(), "pins": 2,
           "contacts": [
               {"left": "wall", "right": 0, "height": 0.6, "gap": 1e-4, "stiffness": 2e5, "law": law},
               {"left": 0, "right": 1, "height": 0.6, "gap": 1e-4, "stiffness": 2e5, "law": law},
               {"left": 1, "right": "wall", "height": 0.6, "gap": 1e-4, "stiffness": 2e5, "law": law}],
           "initial": {"tip_displacements": [1e-3, -1e-3]},
           "solver": {"duration": 0.05, "check": "none"}})
}

async fn refused(app: &TestApp, process: &str, inputs: Value) -> Vec<String> {
    app.refused_pointers(process, &inputs).await
}

async fn results(app: &TestApp, process: &str, inputs: Value) -> Value {
    app.results_of(process, &json!({"inputs": inputs})).await
}

#[tokio::test]
async fn laws_a_model_cannot_carry_are_refused_at_their_members() {
    let app = spawn().await;
    // The list: μ < 0, e outside (0, 1], n < 1, a preload nothing balances, a
    // wear coefficient without a service time; and friction or wear on a row.
    let bad_row = row(json!({"exponent": 0.5, "restitution": 1.5}));
    assert_eq!(
        refused(&app, "bundle-dynamics", bad_row).await,
        [
            "/inputs/contacts/0/law/exponent",
            "/inputs/contacts/0/law/restitution",
            "/inputs/contacts/1/law/exponent",
            "/inputs/contacts/1/law/restitution",
            "/inputs/contacts/2/law/exponent",
            "/inputs/contacts/2/law/restitution",
        ]
    );
    let mut lonely = row(json!({}));
    lonely["contacts"][0]["gap"] = json!(-1e-5);
    assert_eq!(
        refused(&app, "bundle-dynamics", lonely).await,
        ["/inputs/contacts/0/gap"]
    );
    let rubbing = row(
        json!({"friction": {"coefficient": 0.3, "tangential_stiffness": 1e5},
                             "wear": {"coefficient": 1e-13, "geometry": {"type": "bore", "radius": 0.005, "length": 0.01}}}),
    );
    let pointers = refused(&app, "bundle-dynamics", rubbing).await;
    assert!(
        pointers.contains(&"/inputs/contacts/1/law/friction/coefficient".to_owned()),
        "{pointers:?}"
    );
    assert!(
        pointers.contains(&"/inputs/contacts/1/law/wear".to_owned()),
        "{pointers:?}"
    );
    let negative = hex(
        json!({"friction": {"coefficient": -0.1, "tangential_stiffness": 1e5}}),
        json!({"interval": 1e-3}),
    );
    assert_eq!(
        refused(&app, "hex-bundle-dynamics", negative).await,
        ["/inputs/contact/law/friction/coefficient"]
    );
    let unscheduled = hex(
        json!({"wear": {"coefficient": 1e-13, "geometry": {"type": "crossed_tubes", "radius": 0.00485, "angle": 0.0}}}),
        json!({"interval": 1e-3}),
    );
    assert_eq!(
        refused(&app, "hex-bundle-dynamics", unscheduled).await,
        [
            "/inputs/contact/law/wear/geometry/angle",
            "/inputs/output/service_time"
        ]
    );
    let mut hertz_by_rk = json!({"beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
        "section": {"type": "tube", "outer_diameter": 0.01, "inner_diameter": 0.009},
        "elements": 20, "modes": 4}, "contact": {"rk": 1.0, "law": {"exponent": 1.5, "force_scale": 10.0}}});
    assert_eq!(
        refused(&app, "cantilever-impact", hertz_by_rk.clone()).await,
        ["/inputs/contact/stiffness"]
    );
    hertz_by_rk["contact"]["law"] = json!({"exponent": 1.5});
    hertz_by_rk["contact"]["stiffness"] = json!(1e8);
    hertz_by_rk["contact"].as_object_mut().unwrap().remove("rk");
    assert_eq!(
        refused(&app, "cantilever-impact", hertz_by_rk).await,
        ["/inputs/contact/law/force_scale"]
    );
}

#[tokio::test]
async fn friction_and_wear_reports_follow_from_the_runs_own_numbers() {
    let app = spawn().await;
    let (coefficient, radius, angle, service): (f64, f64, f64, f64) = (1.2e-13, 0.00485, 10.0, 3.15e7);
    let law = json!({"restitution": 0.7,
                     "friction": {"coefficient": 0.3, "tangential_stiffness": 2e5},
                     "allowable_force": 5.0,
                     "wear": {"coefficient": coefficient,
                              "geometry": {"type": "crossed_tubes", "radius": radius, "angle": angle}}});
    let results = results(
        &app,
        "hex-bundle-dynamics",
        hex(law, json!({"interval": 1e-3, "service_time": service})),
    )
    .await;
    let contacts = results["contacts"].as_array().unwrap();
    let mut worst: (f64, usize) = (0.0, 0);
    let mut slid = 0.0;
    for (k, contact) in contacts.iter().enumerate() {
        let (peak, utilisation) = (
            contact["max_force"].as_f64().unwrap(),
            contact["utilisation"].as_f64().unwrap(),
        );
        assert!(
            (utilisation - peak / 5.0).abs() <= 1e-12 * utilisation.max(1.0),
            "{contact}"
        );
        if utilisation > worst.0 {
            worst = (utilisation, k);
        }
        let friction = &contact["friction"];
        let (mean, rms, max) = (
            friction["mean_tangential_force"].as_f64().unwrap(),
            friction["rms_tangential_force"].as_f64().unwrap(),
            friction["max_tangential_force"].as_f64().unwrap(),
        );
        // Mean ≤ RMS ≤ max, and Coulomb: |T| ≤ μ F_n ≤ μ × the peak normal force.
        assert!(
            mean <= rms * (1.0 + 1e-12) && rms <= max * (1.0 + 1e-12),
            "{friction}"
        );
        assert!(max <= 0.3 * peak * (1.0 + 1e-12), "{contact}");
        let stick = friction["stick_fraction"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&stick), "{friction}");
        slid += friction["slip_distance"].as_f64().unwrap();
        // Archard: V = K P t, and the crossed tubes' depth of that volume.
        let wear = &contact["wear"];
        let power = wear["power"].as_f64().unwrap();
        assert_eq!(power, contact["wear_work_rate"].as_f64().unwrap());
        let volume = wear["volume"].as_f64().unwrap();
        assert!(
            (volume - coefficient * power * service).abs() <= 1e-12 * volume.max(1e-30),
            "{wear}"
        );
        let depth = (1.0 / (2.0 * radius)).powf(0.2) * (15.0 * angle.to_radians() * volume / 8.0).powf(0.4);
        assert!(
            (wear["depth"].as_f64().unwrap() - depth).abs() <= 1e-12 * depth.max(1e-30),
            "{wear}"
        );
    }
    assert!(slid > 0.0, "the shaken bundle must rub");
    assert_eq!(results["max_utilisation"]["contact"], worst.1);
    let deepest = contacts
        .iter()
        .map(|c| c["wear"]["depth"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert_eq!(results["max_wear_depth"]["depth"].as_f64().unwrap(), deepest);
    assert!(results["energy"]["dissipated_contact"].as_f64().unwrap() > 0.0);
}

#[tokio::test]
async fn a_generated_row_takes_a_law_per_family_and_echoes_it_in_its_expansion() {
    let app = spawn().await;
    let inputs = json!({"pin": pin(),
        "bundle": {"pins": 2, "levels": [0.6], "stiffness": 2e5, "wall_gap": 1e-4, "pin_gap": 1e-4,
                   "law": {"restitution": 0.5, "allowable_force": 10.0},
                   "wall_law": {"exponent": 1.5, "force_scale": 50.0, "allowable_force": 20.0}},
        "initial": {"tip_displacements": [1e-3, -1e-3]},
        "solver": {"duration": 0.05, "check": "none"}});
    let results = results(&app, "bundle-dynamics", inputs).await;
    let expansion = results["expansion"]["contacts"].as_array().unwrap();
    // Level by level: wall–0, 0–1, 1–wall.
    assert_eq!(expansion[0]["law"]["exponent"], 1.5);
    assert_eq!(expansion[1]["law"]["restitution"], 0.5);
    assert_eq!(expansion[2]["law"]["exponent"], 1.5);
    for (contact, allowable) in results["contacts"]
        .as_array()
        .unwrap()
        .iter()
        .zip([20.0, 10.0, 20.0])
    {
        let peak = contact["max_force"].as_f64().unwrap();
        assert_eq!(
            contact["utilisation"].as_f64().unwrap(),
            peak / allowable,
            "{contact}"
        );
    }
}
