//! code_aster test case `sdnl301a` (astest/sdnl301a.comm; its mesh, astest/sdnl301a.mmed,
//! is stored out of the repository and was not read: the node positions below are the
//! command file's), a solver no one here wrote, through the `bundle-dynamics` process
//! (`examples/sdnl301a.json`, docs/beams.md "code_aster sdnl301a").
//!
//! A steel tube (outer radius 7.95 mm, wall 1.15 mm; E = 2.07e11 Pa, ν = 0.3,
//! ρ = 7870 kg/m³), clamped at node N1 (x = 0), 2.436 m long, on four loose supports
//! (`DIS_CHOC`, `PLAN_Y` obstacle: a wall on both sides, gap 0.406 mm, Kn = 1e5 N/m,
//! Cn = 0.28 N·s/m) at N14, N26, N38 and N2, x = 0.609, 1.218, 1.827, 2.436 m: three
//! inner supports and one at the free end. 48 Timoshenko elements (`POU_D_T`, 12 per
//! span), Rayleigh damping C = 1.79e-5 K + 0.1526 M, 30 modes. Nodal forces FY = ±4.138 N
//! at the 11 inner nodes of every span (+ on spans 1 and 3, − on 2 and 4) times
//! sin(251.2 t), tabulated every 1e-4 s. Central difference (`DIFF_CENTRE`), Δt = 5e-6 s,
//! 0.25 s, archived every 10 steps. Tested: `RMS_T_TOTAL` of the normal force at N2 over
//! [0.17, 0.25] s (`POST_DYNA_MODA_T`: √(mean of F² over the archived samples)).
//!
//! Differences, all of them in the example: the load table is sampled every 5e-4 s
//! instead of 1e-4 s (the example would pass the 1 MiB request limit; linear
//! interpolation of the sine then lowers its amplitude by (ωh)²/12 = 1.3e-3); the modal
//! damping is code_aster's Rayleigh damping, ξᵢ = (α ωᵢ + β / ωᵢ) / 2, at our own
//! frequencies; the shear coefficient is code_aster's for this section (its `CERCLE`
//! table at r_i/r_e = 0.855: A_y = 1.977, κ = 1 / A_y = 0.5058, not Cowper's 0.536).

use std::ops::ControlFlow;
use std::sync::OnceLock;

use chocmodal::processes::bundle_dynamics::BundleDynamics;
use chocmodal::processes::{Process, RunOutput};
use serde_json::{Value, json};

/// Published by code_aster (`TEST_TABLE`, `VALE_CALC` of sdnl301a): `RMS_T_TOTAL` of
/// `FORCE_NORMALE` at N2 over [0.17, 0.25] s (N), with the 30 modes (`DYNA_VIBRA` on
/// `MODE`), and with the 30 modes and the static modes of the four supports
/// (`MODE_STATIQUE`, `DEFI_BASE_MODALE` Ritz basis).
const THIRTY_MODES: f64 = 23.9833137772;
const THIRTY_MODES_AND_STATIC_MODES: f64 = 24.5382986473;
/// The window of `POST_DYNA_MODA_T` (TDEB, TFIN), s.
const WINDOW: (f64, f64) = (0.17, 0.25);
/// The material's Rayleigh damping (`AMOR_ALPHA`, s; `AMOR_BETA`, 1/s).
const AMOR_ALPHA: f64 = 1.79e-5;
const AMOR_BETA: f64 = 0.1526;

/// The comparison's tolerance on the RMS force at N2. A reference computed by another
/// solver on another discretisation is not exact, and the quantity is sensitive: the
/// support impacts make the tube's response depend strongly on small changes of the
/// model. Changes that are no difference of physics (the load table sampled every 1e-4,
/// 2e-4, 2.5e-4, 4e-4 or 5e-4 s; 48, 60, 72 or 96 elements; 30 to 35 modes) move our own
/// RMS force at N2 between 23.68 and 24.43 N, −2.4 % … +0.7 % of the example's run
/// (its inner supports by up to 28 %), while the time step is converged (checked below).
/// code_aster's discretisation differs from ours by changes of that kind (its element
/// and shear coefficient table, its load sampled every 1e-4 s, its own modes): the two
/// can be expected to agree within that band, ±3 %, not better.
const TOLERANCE: f64 = 3e-2;

fn example() -> Value {
    let path = format!("{}/examples/sdnl301a.json", env!("CARGO_MANIFEST_DIR"));
    let body: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    body["inputs"].clone()
}

fn run(inputs: &Value) -> RunOutput {
    BundleDynamics
        .run(inputs, &mut |_| ControlFlow::Continue(()))
        .expect("sdnl301a runs")
}

/// The frequencies (Hz) of the modes, then of the pseudo-modes, of `inputs`' basis.
fn frequencies(inputs: &Value) -> Vec<f64> {
    let mut short = inputs.clone();
    short["solver"]["duration"] = json!(1e-4);
    short["solver"]["check"] = json!("none");
    let output = run(&short);
    let basis = &output.document["basis"];
    let list = |name: &str| -> Vec<f64> {
        basis[name]
            .as_array()
            .unwrap_or_else(|| panic!("basis.{name}"))
            .iter()
            .map(|f| f.as_f64().unwrap())
            .collect()
    };
    [list("mode_frequencies_hz"), list("pseudo_mode_frequencies_hz")].concat()
}

/// code_aster's damping projected on a basis: C = α K + β M on M-orthonormal modes of
/// circular frequency ω is the ratio ξ = (α ω + β / ω) / 2.
fn rayleigh(frequencies_hz: &[f64]) -> Vec<f64> {
    frequencies_hz
        .iter()
        .map(|f| {
            let omega = 2.0 * std::f64::consts::PI * f;
            (AMOR_ALPHA * omega + AMOR_BETA / omega) / 2.0
        })
        .collect()
}

/// `inputs` with code_aster's Rayleigh damping on its own basis (modes and pseudo-modes),
/// and without the repeated run of the accuracy check (the time step's convergence is
/// tested on its own).
fn with_rayleigh_damping(inputs: &Value) -> Value {
    let mut inputs = inputs.clone();
    inputs["pin"]["damping_ratio"] = json!(rayleigh(&frequencies(&inputs)));
    inputs["solver"]["check"] = json!("none");
    inputs
}

/// What a run gives at the four supports (N14, N26, N38, N2), each the sum of its two
/// walls' contacts (one at most is closed at a time).
#[derive(Debug)]
struct Supports {
    /// `RMS_T_TOTAL`: √(mean of F²) over the history samples in the window (N).
    window_rms: [f64; 4],
    /// The largest force of the run (N).
    peak: [f64; 4],
    /// Mode frequencies (Hz).
    frequencies: Vec<f64>,
}

fn supports(inputs: &Value) -> Supports {
    let output = run(inputs);
    let history = output
        .histories
        .iter()
        .find(|h| h.name == "contact_forces")
        .expect("contact_forces history");
    let column = |k: usize| -> &Vec<f64> {
        let name = format!("c{k}");
        &history.series.iter().find(|(n, _)| *n == name).expect("column").1
    };
    let in_window: Vec<usize> = (history.time.iter().enumerate())
        .filter(|(_, t)| **t >= WINDOW.0 - 1e-9 && **t <= WINDOW.1 + 1e-9)
        .map(|(i, _)| i)
        .collect();
    // Archived every 10 steps of 5e-6 s, as code_aster's PAS_ARCH = 10: 1601 samples.
    assert_eq!(in_window.len(), 1601, "samples in the window");
    let contacts = output.document["contacts"].as_array().expect("contacts");
    let mut window_rms = [0.0; 4];
    let mut peak = [0.0; 4];
    for support in 0..4 {
        let (left, right) = (column(2 * support), column(2 * support + 1));
        let squares: f64 = in_window.iter().map(|&i| (left[i] + right[i]).powi(2)).sum();
        window_rms[support] = (squares / in_window.len() as f64).sqrt();
        peak[support] = (2 * support..2 * support + 2)
            .map(|k| contacts[k]["impact_statistics"]["max_force"].as_f64().unwrap())
            .fold(0.0, f64::max);
    }
    let frequencies = (output.document["basis"]["mode_frequencies_hz"].as_array())
        .expect("mode frequencies")
        .iter()
        .map(|f| f.as_f64().unwrap())
        .collect();
    Supports {
        window_rms,
        peak,
        frequencies,
    }
}

/// The example as it is (Timoshenko, 30 modes), without the repeated run of the
/// accuracy check (the time step's convergence is tested on its own).
fn example_run_inputs() -> Value {
    let mut inputs = example();
    inputs["solver"]["check"] = json!("none");
    inputs
}

/// The example's run, shared by the tests that need it.
fn timoshenko() -> &'static Supports {
    static RUN: OnceLock<Supports> = OnceLock::new();
    RUN.get_or_init(|| supports(&example_run_inputs()))
}

fn relative(measured: f64, reference: f64) -> f64 {
    (measured - reference) / reference
}

/// The example's `damping_ratio` is code_aster's Rayleigh damping at its modes'
/// frequencies (to its 6 decimals): the example is the run the comparisons test.
#[test]
fn the_example_carries_code_aster_rayleigh_damping() {
    let inputs = example();
    let expected = rayleigh(&frequencies(&inputs));
    let given: Vec<f64> = (inputs["pin"]["damping_ratio"].as_array())
        .expect("a list")
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(given.len(), 30);
    for (mode, (g, e)) in given.iter().zip(&expected).enumerate() {
        assert!((g - e).abs() <= 5e-7, "mode {mode}: ξ {g} vs α ω/2 + β/2ω = {e}");
    }
}

/// 30 Timoshenko modes, central difference at 5e-6 s: code_aster's `DYNA_VIBRA` run
/// (23.98 N; ours 24.25 N, +1.1 %).
#[test]
fn thirty_timoshenko_modes_reproduce_code_aster() {
    let measured = timoshenko().window_rms[3];
    let difference = relative(measured, THIRTY_MODES);
    eprintln!("30 modes: RMS force at N2 {measured:.3} N, code_aster {THIRTY_MODES:.3} N");
    assert!(
        difference.abs() < TOLERANCE,
        "RMS force at N2 over {WINDOW:?} s: {measured} N vs code_aster {THIRTY_MODES} N \
         (rel. {difference:e}, tolerance {TOLERANCE:e})"
    );
}

/// The 30 modes and one pseudo-mode per support (our `contacts` correction, the static
/// responses to unit forces at the supports: code_aster's `MODE_STATIQUE` /
/// `FORCE_NODALE` in its Ritz basis), damped by the same Rayleigh rule at their own
/// frequencies (24.54 N; ours 24.54 N).
#[test]
fn thirty_modes_and_the_static_modes_reproduce_code_aster() {
    let mut inputs = example();
    inputs["pin"]["static_correction"] = json!("contacts");
    let measured = supports(&with_rayleigh_damping(&inputs)).window_rms[3];
    let difference = relative(measured, THIRTY_MODES_AND_STATIC_MODES);
    eprintln!(
        "30 modes + static modes: RMS force at N2 {measured:.3} N, code_aster \
         {THIRTY_MODES_AND_STATIC_MODES:.3} N"
    );
    assert!(
        difference.abs() < TOLERANCE,
        "RMS force at N2 over {WINDOW:?} s: {measured} N vs code_aster \
         {THIRTY_MODES_AND_STATIC_MODES} N (rel. {difference:e}, tolerance {TOLERANCE:e})"
    );
}

/// The time step is converged: at Δt / 2 every support's RMS force over the window moves
/// by less than 1 % (central difference, second order, at 1/11 of its critical step and
/// 35 steps per contact period). What is left of the difference to code_aster is the
/// difference of the two discretisations.
#[test]
fn the_window_statistics_are_converged_in_the_time_step() {
    let base = timoshenko();
    let mut inputs = example_run_inputs();
    inputs["solver"]["time_step"] = json!(2.5e-6);
    let halved = supports(&inputs);
    for support in 0..4 {
        let change = relative(halved.window_rms[support], base.window_rms[support]);
        assert!(
            change.abs() < 1e-2,
            "support {support}: RMS {} N at Δt = 5e-6 s, {} N at 2.5e-6 s (rel. {change:e})",
            base.window_rms[support],
            halved.window_rms[support]
        );
    }
}

/// The same case on Euler–Bernoulli beams (code_aster's `POU_D_E`), against the
/// Timoshenko run.
///
/// What physics says, and is asserted:
/// - shear and rotary inertia lower a frequency as the exact Timoshenko dispersion at
///   the mode's wavenumber k says: by 5e-5 for the first mode (k r_g ≈ 4e-3, this is a
///   slender tube: spans 38 diameters long), by about 10 % at the 30th (k r_g ≈ 0.2;
///   8 % on this mesh, 1.6 elements per half wave): asserted to 1e-4 and > 5 %;
/// - the impacts are made by the low modes, which the theories share: the largest force
///   at every support, inner ones included, agrees within 3 % (the first impacts come at
///   the same instants);
/// - the RMS force at the end support N2 over code_aster's window is code_aster's
///   within the comparison's tolerance in both theories: the end support does not tell
///   them apart.
///
/// What is measured and not asserted: over the window, the inner supports' RMS forces
/// of the two theories differ by 2 to 18 % (printed). That is the 10–30 % at
/// one support of three, yet not a property of the theories: the same Timoshenko model
/// moves by up to 28 % at an inner support under changes of no physical weight (see
/// [`TOLERANCE`]), and over a longer window (0.17 to 1 s, measured by hand) the
/// theories' inner-support RMS forces overlap within that scatter.
#[test]
fn euler_bernoulli_and_timoshenko_make_the_same_impacts() {
    let timoshenko = timoshenko();
    let mut inputs = example();
    inputs["pin"]
        .as_object_mut()
        .unwrap()
        .remove("timoshenko")
        .expect("the example is Timoshenko");
    let euler = supports(&with_rayleigh_damping(&inputs));

    // The exact Timoshenko dispersion at the Euler–Bernoulli wavenumber of the first
    // mode: (ρ²I/κG) ω⁴ − (ρA + ρI k² + ρEI k²/κG) ω² + EI k⁴ = 0, lower root.
    let pin = &inputs["pin"];
    let (young, density) = (
        pin["young_modulus"].as_f64().unwrap(),
        pin["density"].as_f64().unwrap(),
    );
    let (outer, inner) = (
        pin["section"]["outer_diameter"].as_f64().unwrap(),
        pin["section"]["inner_diameter"].as_f64().unwrap(),
    );
    let timoshenko_inputs = &example()["pin"]["timoshenko"];
    let nu = timoshenko_inputs["poisson_ratio"].as_f64().unwrap();
    let kappa = timoshenko_inputs["shear_coefficient"].as_f64().unwrap();
    let pi = std::f64::consts::PI;
    let area = pi / 4.0 * (outer.powi(2) - inner.powi(2));
    let inertia = pi / 64.0 * (outer.powi(4) - inner.powi(4));
    let shear = kappa * young / (2.0 * (1.0 + nu));
    let omega_euler = 2.0 * pi * euler.frequencies[0];
    let k2 = omega_euler / (young * inertia / (density * area)).sqrt();
    let a = density * density * inertia / shear;
    let b = density * area + density * inertia * k2 + density * young * inertia * k2 / shear;
    let c = young * inertia * k2 * k2;
    let omega_timoshenko = ((b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)).sqrt();
    let predicted = omega_timoshenko / omega_euler;
    let measured = timoshenko.frequencies[0] / euler.frequencies[0];
    assert!(
        (measured - predicted).abs() < 1e-4,
        "first mode: Timoshenko / Euler–Bernoulli {measured} vs dispersion {predicted}"
    );
    let last = timoshenko.frequencies[29] / euler.frequencies[29];
    assert!(last < 0.95, "30th mode: Timoshenko / Euler–Bernoulli {last}");

    for support in 0..4 {
        let (t, e) = (timoshenko.peak[support], euler.peak[support]);
        assert!(
            relative(t, e).abs() < 3e-2,
            "support {support}: largest force {t} N (Timoshenko) vs {e} N (Euler–Bernoulli)"
        );
    }
    let euler_n2 = relative(euler.window_rms[3], THIRTY_MODES);
    assert!(
        euler_n2.abs() < TOLERANCE,
        "Euler–Bernoulli RMS force at N2: {} N vs code_aster {THIRTY_MODES} N (rel. {euler_n2:e})",
        euler.window_rms[3]
    );
    eprintln!(
        "largest forces {:?} N (Timoshenko), {:?} N (Euler–Bernoulli); RMS at N2 {:.3} / {:.3} N",
        timoshenko.peak, euler.peak, timoshenko.window_rms[3], euler.window_rms[3]
    );
    for support in 0..3 {
        eprintln!(
            "inner support {support}: RMS over {WINDOW:?} s {:.3} N (Timoshenko), {:.3} N \
             (Euler–Bernoulli), {:+.1} %",
            timoshenko.window_rms[support],
            euler.window_rms[support],
            100.0 * relative(timoshenko.window_rms[support], euler.window_rms[support])
        );
    }
}
