//! code_aster test case `sdnl104c` (astest/sdnl104c.comm, mesh astest/sdnl104a.mail), a
//! solver no one here wrote, through the `bundle-dynamics` process
//! (`examples/sdnl104c.json`).
//!
//! A clamped-free beam (L = 1 m, 10 Euler–Bernoulli elements `POU_D_E`, solid circular
//! section R = 0.1 m, E = 1e10 Pa, ρ = 1e6 kg/m³, no damping) carries a step tip force
//! of −1000 N from t = 0. Its tip meets a stop on both sides (`DIS_CHOC`, circular
//! obstacle, gap 1e-4 m, Kc = 1e8 N/m, no contact damping): here one pin with two wall
//! contacts at the tip. Central difference, Δt = 1e-5 s, 0.16 s. Published tip
//! deflection at t = 0.1315 s: full finite elements (`DYNA_NON_LINE`, Newmark
//! Δt = 1e-4 s) −1.85357e-6 m; 5 modes −1.72234e-6 m (`DYNA_VIBRA`, 7 % off); 5 modes +
//! the static mode at the stop (`MODE_STATIQUE`, Ritz basis) −1.88613e-6 m (+1.8 %).

use std::ops::ControlFlow;

use chocmodal::processes::Process;
use chocmodal::processes::bundle_dynamics::BundleDynamics;

/// Published by code_aster (VALE_REFE, VALE_CALC of sdnl104c), m.
const FULL_FE: f64 = -1.85356696663e-6;
const FIVE_MODES: f64 = -1.72233853215e-6;
const FIVE_MODES_AND_STATIC_MODE: f64 = -1.88612773364e-6;
/// Instant of the published values (s).
const T_TEST: f64 = 0.1315;

fn tip_deflection_at_test_time(correction: &str) -> f64 {
    let path = format!("{}/examples/sdnl104c.json", env!("CARGO_MANIFEST_DIR"));
    let body: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut inputs = body["inputs"].clone();
    inputs["pin"]["static_correction"] = serde_json::json!(correction);
    let output = BundleDynamics
        .run(&inputs, &mut |_| ControlFlow::Continue(()))
        .expect("sdnl104c runs");
    let history = output
        .histories
        .iter()
        .find(|h| h.name == "displacements")
        .expect("displacements history");
    let (_, tip) = history
        .series
        .iter()
        .find(|(name, _)| name == "p0")
        .expect("column p0");
    let sample = history
        .time
        .iter()
        .position(|t| (t - T_TEST).abs() < 1e-9)
        .expect("a sample at t = 0.1315 s");
    tip[sample]
}

/// 5 modes alone, central difference at 1e-5 s: the same scheme on the same basis as
/// code_aster's `DYNA_VIBRA`, so the same number to 1e-3.
#[test]
fn five_modes_reproduce_code_aster_five_mode_run() {
    let measured = tip_deflection_at_test_time("none");
    let relative = (measured - FIVE_MODES) / FIVE_MODES;
    assert!(
        relative.abs() < 1e-3,
        "tip deflection at {T_TEST} s: {measured:e} m vs code_aster 5 modes {FIVE_MODES:e} m (rel. {relative:e})"
    );
}

/// 5 modes plus the pseudo-mode at the stop: within 2 % of the full finite-element
/// solution (code_aster's own tolerance for its static-mode runs), where the modes alone
/// are 7 % off; and close to code_aster's static-mode run.
#[test]
fn five_modes_with_the_static_correction_approach_the_full_finite_element_run() {
    let measured = tip_deflection_at_test_time("contacts");
    let relative = (measured - FULL_FE) / FULL_FE;
    assert!(
        relative.abs() < 2e-2,
        "tip deflection at {T_TEST} s: {measured:e} m vs full FE {FULL_FE:e} m (rel. {relative:e}, tolerance 2e-2)"
    );
    let against_aster = (measured - FIVE_MODES_AND_STATIC_MODE) / FIVE_MODES_AND_STATIC_MODE;
    assert!(
        against_aster.abs() < 5e-3,
        "tip deflection at {T_TEST} s: {measured:e} m vs code_aster 5 modes + static mode \
         {FIVE_MODES_AND_STATIC_MODE:e} m (rel. {against_aster:e}, tolerance 5e-3)"
    );
}
