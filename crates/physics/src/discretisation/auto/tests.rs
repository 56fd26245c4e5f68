//! The `auto` mesh and basis against physics: the choice meets its own target and a
//! tighter target never chooses less; a run on the chosen basis gives the peak contact
//! force of a shock-driven impact within 2 % of the value converged in step, modes and
//! elements together (a run on twice the modes and twice the elements at a tenth of the
//! tolerance), where the old default basis is more than 2 % off.

use std::ops::ControlFlow;

use super::*;
use crate::contact::{Body, Contact, Law};
use crate::discretisation::tests::pin;
use crate::integrate::{Check, Model, Settings, TimeStep, simulate};
use crate::loads::BaseAcceleration;
use crate::stability::Scheme;

/// A wall at `height` on the +x side of pin 0, touching it (gap 0), linear `stiffness`.
fn wall(height: f64, stiffness: f64) -> Contact {
    Contact {
        left: Body::Pin(0),
        right: Body::Wall,
        height,
        gap: 0.0,
        stiffness,
        damping: 0.0,
        law: Law::LINEAR,
    }
}

fn auto(target: f64) -> Request {
    Request {
        elements: Count::Auto,
        min_elements: 0,
        modes: Count::Auto,
        static_correction: true,
        target,
    }
}

#[test]
fn the_choice_meets_its_target_and_a_tighter_target_never_chooses_less() {
    let heights = [0.5, 1.0, 1.5];
    let contacts: Vec<Contact> = heights.iter().map(|h| wall(*h, 3e6)).collect();
    let probes = design_contacts(&contacts, 1.5);
    assert_eq!(probes.len(), 3);
    let mut previous: Option<Choice> = None;
    for target in [0.1, 0.03, 0.01] {
        let choice = choose(&pin(40), &auto(target), &probes, &heights).unwrap();
        assert!(
            choice.basis_error <= target && choice.mesh_error <= target,
            "{target}: {choice:?}"
        );
        if let Some(p) = previous {
            assert!(
                choice.modes >= p.modes && choice.elements >= p.elements,
                "{target}: {choice:?} after {p:?}"
            );
        }
        previous = Some(choice);
    }
    // A given count is kept and measured: the default basis is far off on this pin.
    let given = Request {
        elements: Count::Given(40),
        modes: Count::Given(10),
        ..auto(0.01)
    };
    let choice = choose(&pin(40), &given, &probes, &heights).unwrap();
    assert_eq!((choice.elements, choice.modes), (40, 10));
    assert!(choice.basis_error > 0.1, "{choice:?}");
}

#[test]
fn more_probes_than_the_limit_are_spread_over_the_heights() {
    let contacts: Vec<Contact> = (1..=100).map(|k| wall(0.015 * k as f64, 3e6)).collect();
    let probes = design_contacts(&contacts, 1.5);
    assert_eq!(probes.len(), MAX_DESIGN_PROBES);
    assert!((probes.first().unwrap().height - 0.015).abs() < 1e-9);
    assert!((probes.last().unwrap().height - 1.5).abs() < 1e-9);
}

/// The pin's peak contact force against walls at mid-height and at the top, 0.2 mm away,
/// under a 20 g, 5 ms half-sine base shock, on `basis` at `tolerance`.
fn shock_peak(basis: &ModalBasis, tolerance: f64) -> f64 {
    let contacts = vec![
        Contact {
            gap: 2e-4,
            ..wall(0.75, 3e6)
        },
        Contact {
            gap: 2e-4,
            ..wall(1.5, 3e6)
        },
    ];
    let model = Model {
        basis,
        pins: 1,
        damping_ratios: vec![0.01; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: -196.2,
            duration: 0.005,
        }),
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    };
    let settings = Settings {
        scheme: Scheme::CentralDifference,
        time_step: TimeStep::Auto,
        tolerance,
        check: Check::None,
        duration: 0.012,
        output_interval: None,
        recorded_contacts: None,
        impacts: Default::default(),
        threads: 1,
        output_heights: vec![1.5],
    };
    let run = simulate(&model, &settings, &mut |_| ControlFlow::Continue(())).expect("the shock runs");
    run.contact_statistics
        .iter()
        .map(|s| s.max_force)
        .fold(0.0, f64::max)
}

#[test]
fn the_auto_basis_puts_a_shock_peak_within_two_percent_of_the_converged_value() {
    let heights = [0.75, 1.5];
    let contacts: Vec<Contact> = heights.iter().map(|h| wall(*h, 3e6)).collect();
    let probes = design_contacts(&contacts, 1.5);
    let choice = choose(&pin(40), &auto(0.01), &probes, &heights).unwrap();
    let chosen = basis_of(&pin(choice.elements), choice.modes, Some(&heights)).unwrap();
    let peak = shock_peak(&chosen, 1e-3);

    let fine = pin(2 * choice.elements);
    let converged_modes = (2 * choice.modes).min(fine.free_dof_count());
    let converged = shock_peak(&basis_of(&fine, converged_modes, Some(&heights)).unwrap(), 1e-4);
    let error = (peak / converged - 1.0).abs();
    println!("auto {choice:?}: peak {peak} N, converged {converged} N, error {error:e}");
    assert!(
        error < 0.02,
        "auto ({} elements, {} modes): peak {peak} N against {converged} N converged: {error:e}",
        choice.elements,
        choice.modes
    );

    // The old default (10 modes + correction, 40 elements) is far off here: the rule is
    // what brings the peak in.
    let default = shock_peak(&basis_of(&pin(40), 10, Some(&heights)).unwrap(), 1e-3);
    let default_error = (default / converged - 1.0).abs();
    println!("default: peak {default} N, error {default_error:e}");
    assert!(
        default_error > 0.02,
        "default basis: {default} N against {converged} N"
    );
}

/// A row of `pins` pins between two walls, contacts at `levels` heights, gaps around
/// `gap` (± 25 %, a fixed pattern), linear springs `stiffness`.
fn row(pins: usize, levels: &[f64], stiffness: f64, gap: f64) -> Vec<Contact> {
    let mut contacts = Vec::new();
    for (l, height) in levels.iter().enumerate() {
        for slot in 0..=pins {
            let left = if slot == 0 {
                Body::Wall
            } else {
                Body::Pin(slot - 1)
            };
            let right = if slot == pins { Body::Wall } else { Body::Pin(slot) };
            let k = (l * (pins + 1) + slot) as f64;
            contacts.push(Contact {
                left,
                right,
                height: *height,
                gap: gap * (1.0 + 0.25 * (1.7 * k).sin()),
                stiffness,
                damping: 0.0,
                law: Law::LINEAR,
            });
        }
    }
    contacts
}

/// A row under a half-sine base shock, as a convergence study case.
struct Shock {
    pins: usize,
    levels: Vec<f64>,
    stiffness: f64,
    gap: f64,
    /// Peak acceleration (m/s²) and duration (s) of the half-sine.
    amplitude: f64,
    duration: f64,
}

impl Shock {
    /// Peak contact force (N) and verdict of the shock on `basis` at `tolerance`.
    fn run(&self, basis: &ModalBasis, tolerance: f64, check: Check) -> (f64, crate::integrate::Verdict) {
        let model = Model {
            basis,
            pins: self.pins,
            damping_ratios: vec![0.01; basis.modes()],
            contacts: row(self.pins, &self.levels, self.stiffness, self.gap),
            initial_tip_displacements: vec![],
            initial_tip_velocities: vec![],
            base_acceleration: Some(BaseAcceleration::HalfSine {
                amplitude: self.amplitude,
                duration: self.duration,
            }),
            walls: None,
            plane: None,
            point_forces: vec![],
            kinds: Vec::new(),
        };
        let settings = Settings {
            scheme: Scheme::CentralDifference,
            time_step: TimeStep::Auto,
            tolerance,
            check,
            duration: 1.5 * self.duration + 0.004,
            output_interval: None,
            recorded_contacts: None,
            impacts: Default::default(),
            threads: 1,
            output_heights: vec![1.5],
        };
        let assessed = crate::integrate::Plan::new(&model, &settings)
            .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
            .expect("the shock runs");
        let peak = assessed
            .simulation
            .contact_statistics
            .iter()
            .map(|s| s.max_force)
            .fold(0.0, f64::max);
        (peak, assessed.quality.verdict)
    }
}

/// Convergence studies (issue 29's acceptance, on `auto`): rows of 5 to 20 pins, shocks
/// of 2 to 20 g lasting 2 to 20 ms, Kc 1e5 to 1e7 N/m, gaps 0 to 1 mm. The `auto` mesh
/// and basis with the `auto` step and its check give the peak contact force within 2 %
/// of the value converged in step, modes and elements together (twice the elements,
/// twice the modes, a quarter of the tolerance: half the step), with a `good` verdict;
/// the old default basis (10 modes + correction, 40 elements) is never `good` where it
/// is more than 2 % off.
#[test]
fn auto_meets_two_percent_against_runs_converged_in_step_modes_and_elements() {
    let ten_levels: Vec<f64> = (1..=10).map(|k| 0.15 * k as f64).collect();
    convergence_study(&[
        Shock {
            pins: 20,
            levels: vec![0.75, 1.5],
            stiffness: 1e5,
            gap: 1e-3,
            amplitude: 98.1,
            duration: 0.02,
        },
        Shock {
            pins: 8,
            levels: ten_levels,
            stiffness: 1e6,
            gap: 5e-4,
            amplitude: 49.05,
            duration: 0.01,
        },
    ]);
}

/// The row (Kc 3e6 N/m, gaps ~0.2 mm, 20 g, 5 ms) on 5 pins, and the stiffest
/// corner of the ranges (Kc 1e7 N/m, touching, a 2 g, 2 ms shock): `auto` takes 120
/// modes on 80 elements and 240 on 160, and the converged runs twice that, ~80 s:
/// `cargo test --release -p chocmodal-physics --lib auto::tests::stiff -- --ignored --nocapture`.
#[test]
#[ignore]
fn stiff_contacts_meet_two_percent_too() {
    let ten_levels: Vec<f64> = (1..=10).map(|k| 0.15 * k as f64).collect();
    convergence_study(&[
        Shock {
            pins: 5,
            levels: ten_levels,
            stiffness: 3e6,
            gap: 2e-4,
            amplitude: 196.2,
            duration: 0.005,
        },
        Shock {
            pins: 5,
            levels: vec![0.5, 1.0, 1.5],
            stiffness: 1e7,
            gap: 0.0,
            amplitude: 19.62,
            duration: 0.002,
        },
    ]);
}

/// Each case: `auto` (mesh, basis, step, check) against the run converged in step,
/// modes and elements together; the old default judged (see the test above).
fn convergence_study(cases: &[Shock]) {
    let tolerance = 1e-3;
    for (n, case) in cases.iter().enumerate() {
        let contacts = row(case.pins, &case.levels, case.stiffness, case.gap);
        let probes = design_contacts(&contacts, 1.5);
        let choice = choose(&pin(40), &auto(10.0 * tolerance), &probes, &case.levels).unwrap();
        let chosen = basis_of(&pin(choice.elements), choice.modes, Some(&case.levels)).unwrap();
        let (peak, verdict) = case.run(&chosen, tolerance, Check::StepHalving);

        let fine = pin((2 * choice.elements).min(MAX_ELEMENTS));
        let modes = (2 * choice.modes).min(fine.free_dof_count());
        let refined = basis_of(&fine, modes, Some(&case.levels)).unwrap();
        let (converged, _) = case.run(&refined, tolerance / 4.0, Check::None);
        let error = (peak / converged - 1.0).abs();
        println!(
            "case {n}: auto {} modes on {} elements, peak {peak:.4} N, converged {converged:.4} N, \
             error {error:.2e}, {verdict:?}",
            choice.modes, choice.elements
        );
        assert!(converged > 0.0, "case {n}: no contact pushed");
        assert!(error < 0.02, "case {n}: auto is {error:e} off");
        assert_eq!(verdict, crate::integrate::Verdict::Good, "case {n}");

        let old = basis_of(&pin(40), 10, Some(&case.levels)).unwrap();
        let (old_peak, old_verdict) = case.run(&old, tolerance, Check::StepHalving);
        let old_error = (old_peak / converged - 1.0).abs();
        println!("case {n}: default basis peak {old_peak:.4} N, error {old_error:.2e}, {old_verdict:?}");
        if old_error > 0.02 {
            assert_ne!(
                old_verdict,
                crate::integrate::Verdict::Good,
                "case {n}: {old_error:e} off"
            );
        }
    }
}
