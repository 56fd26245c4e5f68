//! Accuracy of `time_step: auto` and of the step-halving check on the class of jobs
//! engineers submit: rows of 5 to 20 pins (E from 2e9 to 2.1e11 Pa, Kc from 1e5 to
//! 1e7 N/m, gaps 0 to 1 mm) under sine, half-sine and table base excitation.
//!
//! The Δt → 0 limit of a result X is estimated from runs at Δt/10 and Δt/20 of the
//! `auto` step by Richardson extrapolation for a second-order scheme:
//! X* = X(h/20) + (X(h/20) − X(h/10)) / 3. Nothing here is compared with a number
//! copied from our own output.

use std::ops::ControlFlow;

use super::*;
use crate::beam::{BeamSpec, Section, Support};
use crate::contact::{Body, Contact, Law};
use crate::loads::{BaseAcceleration, Table};
use crate::modal::ModalBasis;
use crate::stability::Scheme;

/// A row of identical pins between two walls.
#[derive(Debug, Clone)]
struct Row {
    pins: usize,
    length: f64,
    young_modulus: f64,
    levels: usize,
    stiffness: f64,
    gap: f64,
    modes: usize,
    excitation: BaseAcceleration,
    duration: f64,
    scheme: Scheme,
}

impl Row {
    /// The plausible job: 7 pins of 1.2 m, tube 9.7/8.5 mm, 6 levels,
    /// Kc = 1e6 N/m, gaps 0.1 mm, a 10 Hz sine base shake.
    fn plausible() -> Self {
        Self {
            pins: 7,
            length: 1.2,
            young_modulus: 2.1e11,
            levels: 6,
            stiffness: 1e6,
            gap: 1e-4,
            modes: 10,
            excitation: BaseAcceleration::Sine {
                amplitude: 20.0,
                frequency: 10.0,
                cycles: 100.0,
            },
            duration: 0.3,
            scheme: Scheme::CentralDifference,
        }
    }

    fn basis(&self) -> ModalBasis {
        let spec = BeamSpec {
            length: self.length,
            young_modulus: self.young_modulus,
            density: 7800.0,
            section: Section::Tube {
                outer_diameter: 0.0097,
                inner_diameter: 0.0085,
            },
            added_mass_per_length: 0.3,
            elements: 30,
            foot: Support::Clamped,
            top: Support::Free,
            shear: None,
        };
        ModalBasis::compute(&spec, self.modes).expect("valid pin")
    }

    fn model<'a>(&self, basis: &'a ModalBasis) -> Model<'a> {
        let mut contacts = Vec::new();
        for level in 1..=self.levels {
            let height = self.length * level as f64 / self.levels as f64;
            let bodies: Vec<Body> = std::iter::once(Body::Wall)
                .chain((0..self.pins).map(Body::Pin))
                .chain(std::iter::once(Body::Wall))
                .collect();
            for pair in bodies.windows(2) {
                contacts.push(Contact {
                    left: pair[0],
                    right: pair[1],
                    height,
                    gap: self.gap,
                    stiffness: self.stiffness,
                    damping: 0.0,
                    law: Law::LINEAR,
                });
            }
        }
        Model {
            basis,
            pins: self.pins,
            damping_ratios: vec![0.01; basis.modes()],
            contacts,
            initial_tip_displacements: vec![],
            initial_tip_velocities: vec![],
            base_acceleration: Some(self.excitation.clone()),
            walls: None,
            plane: None,
            point_forces: vec![],
            kinds: Vec::new(),
        }
    }

    fn settings(&self, time_step: TimeStep) -> Settings {
        Settings {
            scheme: self.scheme,
            time_step,
            tolerance: DEFAULT_TOLERANCE,
            check: Check::None,
            duration: self.duration,
            output_interval: Some(1e-3),
            recorded_contacts: None,
            impacts: Default::default(),
            threads: 1,
            output_heights: vec![self.length],
        }
    }
}

fn figures(simulation: &Simulation) -> (f64, f64, f64) {
    let figures = quality::KeyFigures::of(simulation);
    (
        figures.peak_force,
        figures.peak_displacement,
        simulation.energy.relative_residual(),
    )
}

/// The class of jobs of the issue: sine, half-sine and table excitation of rows of 5 to
/// 20 pins, E from 2e9 to 2.1e11 Pa, Kc from 1e5 to 1e7 N/m, gaps 0 to 1 mm.
fn realistic_rows() -> Vec<(&'static str, Row)> {
    let base = Row::plausible();
    vec![
        ("7 pins, 10 Hz sine", base.clone()),
        (
            "7 soft pins (E 2e9 Pa)",
            Row {
                young_modulus: 2e9,
                ..base.clone()
            },
        ),
        (
            "Kc 1e7 N/m, no gap",
            Row {
                stiffness: 1e7,
                gap: 0.0,
                ..base.clone()
            },
        ),
        (
            "Kc 1e5 N/m, 1 mm gaps",
            Row {
                stiffness: 1e5,
                gap: 1e-3,
                ..base.clone()
            },
        ),
        (
            "20 pins, half-sine shock",
            Row {
                pins: 20,
                excitation: BaseAcceleration::HalfSine {
                    amplitude: 100.0,
                    duration: 0.01,
                },
                duration: 0.1,
                ..base.clone()
            },
        ),
        (
            "5 pins, table excitation",
            Row {
                pins: 5,
                excitation: BaseAcceleration::Table(Table {
                    time: (0..=200).map(|k| k as f64 * 5e-4).collect(),
                    values: (0..=200)
                        .map(|k| 30.0 * ((k as f64 * 0.37).sin() + (k as f64 * 0.11).cos()))
                        .collect(),
                }),
                duration: 0.15,
                ..base.clone()
            },
        ),
    ]
}

fn run_at(model: &Model<'_>, row: &Row, time_step: TimeStep, check: Check) -> Assessed {
    let settings = Settings {
        check,
        ..row.settings(time_step)
    };
    Plan::new(model, &settings)
        .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
        .expect("the run succeeds")
}

/// The Δt → 0 limit of (peak force, peak deflection) from runs at h/10 and h/20
/// (Richardson, second order).
fn limit(model: &Model<'_>, row: &Row, h: f64) -> (f64, f64) {
    let at = |dt: f64| figures(&run_at(model, row, TimeStep::Fixed(dt), Check::None).simulation);
    let (fine, finer) = (at(h / 10.0), at(h / 20.0));
    (
        finer.0 + (finer.0 - fine.0) / 3.0,
        finer.1 + (finer.1 - fine.1) / 3.0,
    )
}

/// Each case with central difference, then with the exact modal scheme (named so).
fn both_schemes(rows: Vec<(&'static str, Row)>) -> Vec<(String, Row)> {
    let exact = rows.iter().map(|(name, row)| {
        (
            format!("{name} (exact_modal)"),
            Row {
                scheme: Scheme::ExactModal,
                ..row.clone()
            },
        )
    });
    let explicit = rows.iter().map(|(name, row)| (name.to_string(), row.clone()));
    explicit.chain(exact).collect()
}

/// Over the whole run, chaotic rattling included, the energy balance of an `auto` run
/// closes within the default tolerance: energy is neither created nor lost by the
/// scheme beyond 1e-3 of the energy involved.
#[test]
fn auto_closes_the_energy_balance_within_the_tolerance() {
    for (name, row) in both_schemes(realistic_rows()) {
        let basis = row.basis();
        let model = row.model(&basis);
        let assessed = run_at(&model, &row, TimeStep::Auto, Check::None);
        let impacts: u64 = assessed
            .simulation
            .contact_statistics
            .iter()
            .map(|s| s.impacts)
            .sum();
        assert!(impacts >= 10, "{name}: the case must rattle, {impacts} impacts");
        let residual = assessed.quality.energy_residual;
        assert!(
            residual <= DEFAULT_TOLERANCE,
            "{name}: energy residual {residual:.3e}, tolerance {DEFAULT_TOLERANCE:e}"
        );
    }
}

/// The first impacts of a case: 30 ms, and 15 ms for 20 pins (where impacts cascade
/// across the row and the peak becomes sensitive to any perturbation sooner).
fn shock_window(row: Row) -> Row {
    let duration = if row.pins > 10 { 0.015 } else { 0.03 };
    Row { duration, ..row }
}

/// The check's estimate of the peak force error is within a factor 3 of the true
/// `error`; below 1e-4 both are at the level of the extrapolation's own error.
fn assert_estimates(name: &str, estimate: f64, error: f64) {
    if error > 1e-4 {
        assert!(
            estimate <= 3.0 * error && estimate >= error / 3.0,
            "{name}: estimated peak force error {estimate:.2e}, true {error:.2e}"
        );
    } else {
        assert!(
            estimate < 3e-4,
            "{name}: estimate {estimate:.2e}, true {error:.2e}"
        );
    }
}

/// The step is judged good: no reason but the basis's and the mesh's (these rows' 10
/// modes, no correction, 30 elements, which the impact probes judge, not the step).
fn assert_no_step_reason(name: &str, quality: &Quality) {
    let step_reasons: Vec<&String> = quality
        .reasons
        .iter()
        .filter(|r| !r.contains("modal basis") && !r.contains("element mesh"))
        .collect();
    assert!(step_reasons.is_empty(), "{name}: {step_reasons:?}");
}

/// Shocks (the first impacts, where the row has not yet turned chaotic and a Δt → 0
/// limit exists): the peak contact force of an `auto` run is within 1 % (10 × the
/// tolerance) of the limit, and the step-halving estimate of its error is within a
/// factor 3 of the true error.
#[test]
fn auto_peaks_are_within_one_percent_of_the_limit_and_the_check_estimates_the_error() {
    for (name, row) in both_schemes(realistic_rows()) {
        let row = shock_window(row);
        let basis = row.basis();
        let model = row.model(&basis);
        let assessed = run_at(&model, &row, TimeStep::Auto, Check::StepHalving);
        let (force, displacement, _) = figures(&assessed.simulation);
        assert!(force > 0.0, "{name}: some contact must close");
        let (limit_force, limit_displacement) = limit(&model, &row, assessed.simulation.step.time_step);
        let error = (force / limit_force - 1.0).abs();
        assert!(
            error <= 10.0 * DEFAULT_TOLERANCE,
            "{name}: peak force {force:.6e} N vs limit {limit_force:.6e} N, error {error:.2e}"
        );
        let displacement_error = (displacement / limit_displacement - 1.0).abs();
        assert!(
            displacement_error <= 10.0 * DEFAULT_TOLERANCE,
            "{name}: peak deflection {displacement:.6e} m vs limit {limit_displacement:.6e} m"
        );
        let check = assessed.quality.step_halving.as_ref().expect("the check ran");
        assert_estimates(&name, check.estimated_peak_force_error, error);
        assert_no_step_reason(&name, &assessed.quality);
        if assessed.quality.reasons.is_empty() {
            assert_eq!(assessed.quality.verdict, Verdict::Good, "{name}");
        }
    }
}

/// The check at 2Δt (`auto`, the default) estimates the error of the same run as the
/// check at Δt/2, for a quarter of its cost: on every shock of the class where 2Δt is in
/// range, its estimate (a third of the change, Richardson) is within a factor 3 of the
/// true error against the Δt → 0 limit, its repeated run takes half the run's steps, and
/// the step raises no reason. Where it is not in range the run is repeated at Δt/2 and
/// says why.
#[test]
fn the_check_at_twice_the_step_estimates_the_error_for_a_quarter_of_the_cost() {
    let mut doubled = 0;
    for (name, row) in realistic_rows() {
        let row = shock_window(row);
        let basis = row.basis();
        let model = row.model(&basis);
        let assessed = run_at(&model, &row, TimeStep::Auto, Check::Auto);
        let (force, _, _) = figures(&assessed.simulation);
        let step = assessed.simulation.step;
        let check = assessed.quality.step_halving.clone().expect("the check ran");
        match check.compared_with {
            StepComparison::DoubleStep => {
                doubled += 1;
                assert!(check.why_half_step.is_none(), "{name}: {check:?}");
                assert_eq!(check.time_step, 2.0 * step.time_step, "{name}");
                assert!(
                    (check.relative_cost - 0.5).abs() <= 0.01,
                    "{name}: relative cost {}",
                    check.relative_cost
                );
                let (limit_force, _) = limit(&model, &row, step.time_step);
                let error = (force / limit_force - 1.0).abs();
                assert_estimates(name, check.estimated_peak_force_error, error);
            }
            StepComparison::HalfStep => {
                let why = check.why_half_step.as_deref().unwrap_or_default();
                assert!(!why.is_empty(), "{name}: a half-step check says why");
                assert!((check.relative_cost - 2.0).abs() <= 0.51, "{name}: {check:?}");
            }
        }
        assert_no_step_reason(name, &assessed.quality);
    }
    assert!(doubled >= 4, "only {doubled} of the shocks were checked at 2Δt");
}

/// A repeated run records one sample (its key figures are tracked at every step): the
/// check's changes are those of the same run at Δt/2 sampled like the run itself.
#[test]
fn the_check_compares_the_figures_of_a_fully_sampled_repeat() {
    let (_, row) = realistic_rows().remove(0);
    let row = shock_window(row);
    let basis = row.basis();
    let model = row.model(&basis);
    let assessed = run_at(&model, &row, TimeStep::Auto, Check::StepHalving);
    let half = assessed.simulation.step.time_step / 2.0;
    let sampled = run_at(&model, &row, TimeStep::Fixed(half), Check::None).simulation;
    assert!(
        sampled.time.len() > 10,
        "the repeat sampled at the run's interval"
    );
    let (run, fine) = (
        quality::KeyFigures::of(&assessed.simulation),
        quality::KeyFigures::of(&sampled),
    );
    let check = assessed.quality.step_halving.expect("the check ran");
    assert_eq!(
        check.peak_force_change,
        quality::relative_change(run.peak_force, fine.peak_force)
    );
    assert_eq!(
        check.peak_displacement_change,
        quality::relative_change(run.peak_displacement, fine.peak_displacement)
    );
    assert!(fine.impacts > 0);
    assert_eq!(
        check.impact_count_change,
        (run.impacts as f64 - fine.impacts as f64).abs() / fine.impacts as f64
    );
}

/// Where 2Δt would be out of range, or the comparison with it is not as strict as
/// halving, the run is repeated at Δt/2, which decides, and the check says why: a given
/// step with 30 steps per period of the fastest motion (15 at 2Δt); a table sampled
/// more finely than 2Δt; a tolerance so tight that no change passes.
#[test]
fn the_check_falls_back_to_half_the_step_and_says_why() {
    let (_, row) = realistic_rows().remove(0);
    let row = shock_window(row);
    let basis = row.basis();
    let model = row.model(&basis);
    let auto = *Plan::new(&model, &row.settings(TimeStep::Auto)).unwrap().step();
    let coarse = std::f64::consts::TAU / (auto.max_angular_frequency * 30.0);
    let check = |model: &Model<'_>, settings: Settings| {
        Plan::new(model, &settings)
            .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
            .expect("runs")
            .quality
            .step_halving
            .expect("the check ran")
    };
    let given = check(
        &model,
        Settings {
            check: Check::Auto,
            ..row.settings(TimeStep::Fixed(coarse))
        },
    );
    assert_eq!(given.compared_with, StepComparison::HalfStep);
    let why = given.why_half_step.unwrap();
    assert!(why.contains("steps per period") && why.contains("15.0"), "{why}");
    assert!(
        (given.relative_cost - 2.0).abs() <= 0.01,
        "{}",
        given.relative_cost
    );

    let mut sampled = model.clone();
    let interval = 1.5 * auto.time_step;
    sampled.base_acceleration = Some(BaseAcceleration::Table(Table {
        time: (0..=2000).map(|k| k as f64 * interval).collect(),
        values: (0..=2000).map(|k| 50.0 * (k as f64 * 0.01).sin()).collect(),
    }));
    let table = check(
        &sampled,
        Settings {
            check: Check::Auto,
            ..row.settings(TimeStep::Auto)
        },
    );
    assert_eq!(table.compared_with, StepComparison::HalfStep);
    assert!(table.why_half_step.unwrap().contains("samples of a table"));

    let tight = check(
        &model,
        Settings {
            check: Check::Auto,
            tolerance: 1e-9,
            ..row.settings(TimeStep::Fixed(auto.time_step))
        },
    );
    assert_eq!(tight.compared_with, StepComparison::HalfStep);
    assert!(tight.why_half_step.unwrap().contains("did not prove"));
    // Both repetitions counted: half the run's steps, then twice.
    assert!(
        (tight.relative_cost - 2.5).abs() <= 0.01,
        "{}",
        tight.relative_cost
    );

    let asked = check(
        &model,
        Settings {
            check: Check::StepHalving,
            ..row.settings(TimeStep::Auto)
        },
    );
    assert_eq!(asked.compared_with, StepComparison::HalfStep);
    assert!(asked.why_half_step.unwrap().contains("asked for"));
}

/// The progress is the share of the steps done: a run checked at 2Δt fills the bar
/// with its 1.5 runs of steps; when the comparison does not prove the result, the
/// repetition at Δt/2 adds two runs, and the bar steps back once, to the 1.5 of 3.5
/// done, then fills again (so that a time left extrapolated from it holds).
#[test]
fn the_progress_follows_the_steps_and_steps_back_once_when_the_check_falls_back() {
    let (_, row) = realistic_rows().remove(0);
    let basis = row.basis();
    let model = row.model(&basis);
    let auto = *Plan::new(&model, &row.settings(TimeStep::Auto)).unwrap().step();
    let progress_of = |tolerance: f64| {
        let mut seen = Vec::new();
        let settings = Settings {
            check: Check::Auto,
            tolerance,
            ..row.settings(TimeStep::Fixed(auto.time_step))
        };
        Plan::new(&model, &settings)
            .and_then(|plan| {
                plan.run(&mut |f| {
                    seen.push(f);
                    ControlFlow::Continue(())
                })
            })
            .expect("runs");
        seen
    };
    let drops = |seen: &[f64]| seen.windows(2).filter(|w| w[1] < w[0]).count();
    let proven = progress_of(0.05);
    assert!(proven.len() >= 4, "{proven:?}");
    assert_eq!(drops(&proven), 0, "{proven:?}");
    assert!(proven.iter().all(|f| (0.0..=1.0).contains(f)), "{proven:?}");
    // The last report comes within a batch of reports (4 096 steps) of the end.
    let batch = 4096.0 / (1.5 * (row.duration / auto.time_step).round());
    assert!(proven.last().unwrap() >= &(1.0 - batch), "{proven:?}");

    let fallback = progress_of(1e-9);
    assert_eq!(drops(&fallback), 1, "{fallback:?}");
    let at = fallback.windows(2).position(|w| w[1] < w[0]).unwrap() + 1;
    let (before, after) = (fallback[at - 1], fallback[at]);
    assert!(
        before >= 1.0 - batch,
        "the bar was full before the fallback: {before}"
    );
    let restart = 1.5 / 3.5;
    assert!(
        after >= restart && after <= restart + batch * 1.5 / 3.5 * 2.0,
        "after the step back: {after}, 1.5/3.5 = {restart}"
    );
    assert!(fallback.last().unwrap() >= &(1.0 - batch), "{fallback:?}");
}

/// Without the step-halving check the step's error is not measured: the same run is
/// `unchecked` where the checked one is `good`, and never `good`.
#[test]
fn a_run_without_the_check_is_never_good() {
    let (name, row) = realistic_rows().remove(0);
    let row = shock_window(row);
    let basis = row.basis();
    let model = row.model(&basis);
    let checked = run_at(&model, &row, TimeStep::Auto, Check::StepHalving);
    let unchecked = run_at(&model, &row, TimeStep::Auto, Check::None);
    assert_ne!(
        unchecked.quality.verdict,
        Verdict::Good,
        "{name}: {:?}",
        unchecked.quality
    );
    if checked.quality.verdict == Verdict::Good {
        assert_eq!(
            unchecked.quality.verdict,
            Verdict::Unchecked,
            "{name}: {:?}",
            unchecked.quality
        );
        assert!(
            unchecked
                .quality
                .reasons
                .iter()
                .any(|r| r.contains("solver.check")),
            "{name}: {:?}",
            unchecked.quality.reasons
        );
    }
}

/// Stable but coarse explicit steps (6 steps per period of the fastest motion): the
/// check flags `poor` every run whose true peak force error exceeds 5 %, and such runs
/// exist among the cases.
#[test]
fn coarse_steps_with_a_peak_error_above_five_percent_are_flagged_poor() {
    let mut flagged = 0;
    for (name, row) in realistic_rows() {
        let row = shock_window(row);
        let basis = row.basis();
        let model = row.model(&basis);
        let period = std::f64::consts::TAU / step_size::max_frequency(&model);
        for per_period in [4.0, 6.0, 8.0, 10.0] {
            let dt = period / per_period;
            let assessed = run_at(&model, &row, TimeStep::Fixed(dt), Check::StepHalving);
            let (force, ..) = figures(&assessed.simulation);
            let (limit_force, _) = limit(&model, &row, dt / 4.0);
            let error = (force / limit_force - 1.0).abs();
            if error > 0.05 {
                flagged += 1;
                assert_eq!(
                    assessed.quality.verdict,
                    Verdict::Poor,
                    "{name}, {per_period} steps per period: true peak error {error:.2e}, quality {:?}",
                    assessed.quality
                );
            }
        }
    }
    assert!(flagged >= 2, "only {flagged} runs had a peak error above 5 %");
}

/// Unit slips (Young's modulus in MPa, lengths in mm, diameters in mm) are valid
/// inputs: `auto` runs them to the end, with finite results, however odd the physics.
#[test]
fn unit_slips_never_diverge_under_auto() {
    let base = Row {
        duration: 1.0,
        ..Row::plausible()
    };
    let slips = [
        (
            "E in MPa",
            Row {
                young_modulus: 2.1e5,
                ..base.clone()
            },
        ),
        (
            "length in mm",
            Row {
                length: 1200.0,
                ..base.clone()
            },
        ),
        (
            "gaps in mm",
            Row {
                gap: 0.1,
                ..base.clone()
            },
        ),
    ];
    for (name, row) in slips {
        let basis = row.basis();
        let model = row.model(&basis);
        let settings = Settings {
            check: Check::None,
            output_interval: None,
            ..row.settings(TimeStep::Auto)
        };
        let settings = Settings {
            output_interval: Some(settings.duration / 1000.0),
            ..settings
        };
        let result =
            Plan::new(&model, &settings).and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())));
        let assessed = result.unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            assessed.quality.energy_residual.is_finite()
                && assessed
                    .simulation
                    .contact_statistics
                    .iter()
                    .all(|s| s.max_force.is_finite()),
            "{name}: non-finite results"
        );
    }
}

/// The envelope outputs keep what sampling loses: the largest value of each contact's
/// peak column is its `max_force` exactly, every sample lies within its peak, and the
/// peak deflection is at least the largest sampled one.
#[test]
fn peaks_keep_the_extremes_that_samples_miss() {
    let row = Row::plausible();
    let basis = row.basis();
    let model = row.model(&basis);
    let settings = Settings {
        output_interval: Some(2e-3),
        ..row.settings(TimeStep::Auto)
    };
    let simulation = simulate(&model, &settings, &mut |_| ControlFlow::Continue(())).expect("runs");
    let mut missed = 0;
    for (k, (stats, peaks)) in simulation
        .contact_statistics
        .iter()
        .zip(&simulation.contact_force_peaks)
        .enumerate()
    {
        let peak = peaks.iter().fold(0.0f64, |m, f| m.max(*f));
        assert_eq!(peak, stats.max_force, "contact {k}");
        let sampled = simulation.contact_forces[k].iter().fold(0.0f64, |m, f| m.max(*f));
        missed += usize::from(sampled < stats.max_force);
        for (sample, peak) in simulation.contact_forces[k].iter().zip(peaks) {
            assert!(
                sample <= peak,
                "contact {k}: sample {sample} above its peak {peak}"
            );
        }
    }
    assert!(
        missed > 0,
        "sampling every 2 ms must miss some peaks for the test to mean anything"
    );
    for (samples, peaks) in simulation.deflections[0]
        .iter()
        .zip(&simulation.deflection_peaks[0])
    {
        for (w, peak) in samples.iter().zip(peaks) {
            assert!(w.abs() <= peak.abs(), "sample {w} above its peak {peak}");
        }
    }
}

/// Samples fall on k × interval written as a decimal (the double nearest to k × 10^-4,
/// not the product k × 1e-4), and `auto` divides the interval asked for.
#[test]
fn samples_are_at_exact_multiples_of_the_interval() {
    let row = Row::plausible();
    let basis = row.basis();
    let model = row.model(&basis);
    let settings = Settings {
        output_interval: Some(1e-4),
        ..row.settings(TimeStep::Auto)
    };
    let simulation = simulate(&model, &settings, &mut |_| ControlFlow::Continue(())).expect("runs");
    assert_eq!(simulation.output_interval, 1e-4);
    let every = (1e-4 / simulation.step.time_step).round();
    assert!((every * simulation.step.time_step / 1e-4 - 1.0).abs() < 1e-12);
    for (k, t) in simulation.time.iter().enumerate() {
        assert_eq!(*t, format!("{k}e-4").parse::<f64>().unwrap(), "sample {k}");
    }
}

/// Prints, for several steps per period, the energy residual and the peak errors
/// against the extrapolated limit (calibration of [`step_size::STEPS_PER_PERIOD`]).
#[test]
#[ignore = "calibration table, run by hand with --nocapture"]
fn energy_spread() {
    for (name, row) in realistic_rows() {
        let basis = row.basis();
        let model = row.model(&basis);
        let period = std::f64::consts::TAU / step_size::max_frequency(&model);
        for n in [40.0, 50.0, 60.0, 70.0] {
            let worst = (0..8)
                .map(|k| {
                    let dt = period / (n + 0.37 * k as f64);
                    let r = run_at(&model, &row, TimeStep::Fixed(dt), Check::None);
                    r.quality.energy_residual
                })
                .fold(0.0f64, f64::max);
            println!("{name}: N {n}: worst residual over 8 steps {worst:.2e}");
        }
    }
}

#[test]
#[ignore = "calibration table, run by hand with --nocapture"]
fn calibration_table() {
    let mut cases = realistic_rows();
    cases.push((
        "E in MPa",
        Row {
            young_modulus: 2.1e5,
            ..Row::plausible()
        },
    ));
    let short: Vec<(String, Row)> = cases
        .iter()
        .map(|(name, row)| {
            (
                format!("{name}, first 30 ms"),
                Row {
                    duration: 0.03,
                    ..row.clone()
                },
            )
        })
        .collect();
    let cases: Vec<(String, Row)> = cases
        .into_iter()
        .map(|(n, r)| (n.to_owned(), r))
        .chain(short)
        .collect();
    for (name, row) in cases {
        let basis = row.basis();
        let model = row.model(&basis);
        let omega = step_size::max_frequency(&model);
        let period = std::f64::consts::TAU / omega;
        let at = |dt: f64| {
            simulate(&model, &row.settings(TimeStep::Fixed(dt)), &mut |_| {
                ControlFlow::Continue(())
            })
            .map(|s| figures(&s))
        };
        let reference_dt = period / 30.0;
        let (Ok(fine), Ok(finer)) = (at(reference_dt / 10.0), at(reference_dt / 20.0)) else {
            println!("{name}: reference runs failed");
            continue;
        };
        let limit_force = finer.0 + (finer.0 - fine.0) / 3.0;
        let limit_disp = finer.1 + (finer.1 - fine.1) / 3.0;
        println!(
            "{name}: ω_max {omega:.3e} rad/s, critical {:.3e} s, limit force {limit_force:.5e} N, disp {limit_disp:.5e} m",
            2.0 / omega
        );
        for per_period in [20.0, 30.0, 40.0, 50.0, 60.0] {
            let dt = period / per_period;
            match at(dt) {
                Ok((force, disp, residual)) => {
                    let half = at(dt / 2.0).expect("half step runs");
                    let estimate = 4.0 / 3.0 * (force - half.0).abs() / half.0.max(1e-300);
                    println!(
                        "  N {per_period:>4}: residual {residual:.2e}, force err {:+.2e} (est {estimate:.2e}), disp err {:+.2e}",
                        force / limit_force - 1.0,
                        disp / limit_disp - 1.0
                    );
                }
                Err(e) => println!("  N {per_period:>4}: {e}"),
            }
        }
    }
}
