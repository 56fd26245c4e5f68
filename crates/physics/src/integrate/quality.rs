//! How right a run is: the energy balance, the step against the stability limit and the
//! fastest motion, and the step-halving check, summed up in a verdict.
//!
//! **The step check.** The run is repeated over its whole duration at another step and
//! three results are compared: the peak contact force (largest over all contacts, every
//! step), the peak deflection (largest |w| at the output heights, every step; in the
//! plane over the x and the y lines alike) and the total impact count, all three over
//! every contact and line whatever `recorded_contacts` (both runs record the same). For a
//! scheme of order p (Richardson):
//! - **at Δt/2** (step halving): X(Δt) − X* ≈ (X(Δt) − X(Δt/2)) · 2ᵖ/(2ᵖ − 1), so the
//!   estimated error of the reported peak is 4/3 of its relative change for central
//!   difference (2 for first-order Tchamwa–Wielgosz). It costs twice the run.
//! - **at 2Δt** (step doubling): X(Δt) − X* ≈ (X(2Δt) − X(Δt)) / (2ᵖ − 1), a third of the
//!   change for central difference: the same estimate of the same run for a quarter of
//!   the cost (half the run), valid while 2Δt is in the asymptotic range
//!   ([`StepSize::doubled`]: 20 steps per period of the fastest motion and of the
//!   excitation, no table sample stepped over).
//!
//! `solver.check: "auto"` (the default) compares with 2Δt where it is valid, and accepts
//! that comparison only when it is as strict as halving would be: every change within
//! what the halving check accepts for its own change (7.5 τ for the peaks with central
//! difference, so that a change that does not shrink with the step, as in chaotic
//! rattling, is judged as strictly), the impact count within its bound. Otherwise (2Δt
//! out of range, or the comparison not that close) the run is repeated at Δt/2 and that
//! decides, as with `"step_halving"`. In long chaotic rattling the two runs drift apart
//! whatever the step, so the change then also measures how sensitive the reported
//! statistics are: a reason for doubt either way.
//!
//! **Verdict** at tolerance τ (`solver.tolerance`, 10⁻³ by default):
//! - `good`: energy residual ≤ τ, estimated peak errors ≤ 10 τ, impact count change
//!   ≤ [`IMPACT_COUNT_DOUBT`];
//! - `poor`: energy residual > 10 τ, or an estimated peak error > [`POOR_FACTOR`] × 10 τ,
//!   or fewer than [`POOR_STEPS_PER_PERIOD`] steps per period of the fastest motion
//!   (there the error is no longer O(Δt²) and halving the step says nothing: at 5 steps
//!   per period a peak 8 % off changed by 0.1 % when halved);
//! - `doubtful`: anything between, and without the check fewer than
//!   [`DOUBTFUL_STEPS_PER_PERIOD`] steps per period.
//!
//! The impact count is only a reason for doubt: contacts that graze (gap 0) open and
//! close on rounding, so their count has no Δt → 0 limit.

use super::Simulation;
use super::step_size::{StepSize, scheme_order};
use crate::discretisation::{BasisErrors, ProbeError};
use crate::stability::Scheme;

/// Peaks are held to this multiple of the tolerance (1 % at the default 10⁻³).
pub const PEAK_TOLERANCE_FACTOR: f64 = 10.0;
/// An estimated peak error beyond this multiple of the peak tolerance is `poor`.
pub const POOR_FACTOR: f64 = 2.0;
/// A relative change of the impact count beyond this is a reason for doubt.
pub const IMPACT_COUNT_DOUBT: f64 = 0.25;
/// Fewer steps per period of the fastest motion than this is `poor`.
pub const POOR_STEPS_PER_PERIOD: f64 = 8.0;
/// Fewer steps per period than this is a reason for doubt when no check runs.
pub const DOUBTFUL_STEPS_PER_PERIOD: f64 = 15.0;

/// Which accuracy check a run performs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Check {
    /// Repeat the run at 2Δt where that proves as much (half the run's cost), else at
    /// Δt/2 (the default for jobs; see the module doc).
    #[default]
    Auto,
    /// Repeat the run at Δt/2 and compare.
    StepHalving,
    /// No repeated run (cheap sweeps): the verdict rests on the energy balance and the
    /// steps per period.
    None,
}

/// Overall judgement of a run's accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Within the tolerance by every measure.
    Good,
    /// Outside the tolerance by some measure, not far enough to call it wrong.
    Doubtful,
    /// Do not use the numbers: some measure is far outside the tolerance.
    Poor,
    /// Within the tolerance by every measure taken, but some discretisation error was
    /// not measured (no step check): not proven good.
    Unchecked,
}

impl Verdict {
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Good => "good",
            Verdict::Doubtful => "doubtful",
            Verdict::Poor => "poor",
            Verdict::Unchecked => "unchecked",
        }
    }

    /// Every verdict, from the best to the worst.
    pub const ALL: [Verdict; 4] = [
        Verdict::Good,
        Verdict::Unchecked,
        Verdict::Doubtful,
        Verdict::Poor,
    ];
}

/// The step check: the whole run repeated at twice or at half the step (the results'
/// `quality.step_halving`, named after the check's first form, whichever step it used).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema), schema(as = StepHalvingReport))]
pub struct StepHalving {
    /// The step the run was compared with: `double_step` (2Δt) or `half_step` (Δt/2).
    pub compared_with: StepComparison,
    /// Why the run was repeated at Δt/2 rather than at 2Δt (half the cost); null when
    /// it was compared with 2Δt.
    pub why_half_step: Option<String>,
    /// Step of the repeated run (s).
    pub time_step: f64,
    /// |F_coarse − F_fine| / F_fine of the peak contact force over all contacts and steps,
    /// between the run and its repetition (fine: Δt/2, or the run itself against 2Δt).
    pub peak_force_change: f64,
    /// The same for the peak |deflection| at the output heights.
    pub peak_displacement_change: f64,
    /// |n_coarse − n_fine| / max(n_fine, 1) of the total impact count.
    pub impact_count_change: f64,
    /// Estimated relative error of the reported peak force (Richardson): 2ᵖ/(2ᵖ − 1) × its
    /// change against Δt/2 (4/3 for central difference), 1/(2ᵖ − 1) × its change against
    /// 2Δt (1/3).
    pub estimated_peak_force_error: f64,
    /// Estimated relative error of the reported peak deflection.
    pub estimated_peak_displacement_error: f64,
    /// The relative change of the largest wear work rate of a contact (pins in the
    /// plane; null for the row): far more sensitive than the peaks, it is judged with
    /// them, by its estimated error (the same factor times its change).
    pub wear_work_rate_change: Option<f64>,
    pub estimated_wear_work_rate_error: Option<f64>,
    /// Steps taken by the check (every repeated run).
    pub steps: u64,
    /// Wall time of the check (s).
    pub seconds: f64,
    /// Steps of the check over steps of the run: 0.5 against 2Δt, 2 against Δt/2, 2.5
    /// when a comparison with 2Δt did not suffice and Δt/2 decided.
    pub relative_cost: f64,
}

/// The step a run is compared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub enum StepComparison {
    /// 2Δt: a run at twice the step.
    DoubleStep,
    /// Δt/2: a run at half the step.
    HalfStep,
}

impl StepComparison {
    /// What the step did, for sentences ("when the step is halved").
    fn verb(&self) -> &'static str {
        match self {
            StepComparison::DoubleStep => "doubled",
            StepComparison::HalfStep => "halved",
        }
    }
}

impl StepHalving {
    /// Whether a comparison with 2Δt proves as much as halving would: every change
    /// within what the halving check accepts for its own change (see the module doc).
    pub(super) fn proves(&self, scheme: Scheme, tolerance: f64) -> bool {
        let order = scheme_order(scheme);
        let accepted_change = PEAK_TOLERANCE_FACTOR * tolerance * (2f64.powf(order) - 1.0) / 2f64.powf(order);
        [
            Some(self.peak_force_change),
            Some(self.peak_displacement_change),
            self.wear_work_rate_change,
        ]
        .into_iter()
        .flatten()
        .all(|change| change <= accepted_change)
            && self.impact_count_change <= IMPACT_COUNT_DOUBT
    }
}

/// The `quality` section of every results document: how right the result is.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema), schema(as = QualityReport))]
pub struct Quality {
    /// |kinetic + strain + contact + dissipated − external work − initial| over the largest
    /// energy involved, at the end of the run (dimensionless).
    pub energy_residual: f64,
    /// Time step over the critical step with every contact closed (dimensionless).
    pub time_step_over_critical: f64,
    /// 2π / (ω_max Δt): steps per period of the fastest motion with the contacts closed,
    /// the shortest contact period resolved. `auto` uses 50 at the default tolerance.
    pub steps_per_contact_period: f64,
    /// The relative tolerance the verdict was judged against (`solver.tolerance`).
    pub tolerance: f64,
    /// What set the step: `given` (a fixed step), or for `auto` `fastest_motion`,
    /// `excitation` or `stability`.
    #[cfg_attr(
        feature = "schema",
        schema(value_type = String, pattern = "^(given|fastest_motion|excitation|stability)$")
    )]
    pub time_step_limited_by: super::step_size::StepLimit,
    /// The step check: the run repeated at 2Δt or Δt/2 (`solver.check` `"auto"` or
    /// `"step_halving"`); null with `"none"`.
    pub step_halving: Option<StepHalving>,
    /// The error of the peak contact force due to the modal basis (truncation, and the
    /// static correction when there is one): the impact probe on the basis against the
    /// complete basis of the same mesh, at the contact where it differs most.
    pub modal_truncation: ProbeError,
    /// The error of the peak contact force due to the element mesh: the impact probe on
    /// the complete basis of the mesh against a mesh twice as fine.
    pub mesh: ProbeError,
    /// `good`: every discretisation error (step, modes, mesh) measured and within the
    /// tolerance; `unchecked`: within it by every measure taken, but the step's error was
    /// not measured (`solver.check: "none"`); `doubtful`: some measure outside it, none
    /// by far; `poor`: do not use the numbers (energy residual > 10 × tolerance, an
    /// estimated peak error > 20 × tolerance, or fewer than 8 steps per contact period).
    #[cfg_attr(
        feature = "schema",
        schema(value_type = String, pattern = "^(good|unchecked|doubtful|poor)$")
    )]
    pub verdict: Verdict,
    /// One sentence per measure outside the tolerance (empty when `good`).
    pub reasons: Vec<String>,
}

/// The figures of a run that the check compares.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct KeyFigures {
    pub peak_force: f64,
    pub peak_displacement: f64,
    pub impacts: u64,
    /// The largest wear work ∫ F |v_t| dt of a contact (J); `None` for the row.
    pub peak_wear_work: Option<f64>,
}

impl KeyFigures {
    pub fn of(simulation: &Simulation) -> Self {
        let peak_force = simulation
            .contact_statistics
            .iter()
            .map(|s| s.max_force)
            .fold(0.0, f64::max);
        let peak_displacement = simulation
            .deflection_peaks
            .iter()
            .flatten()
            .flatten()
            .fold(0.0f64, |m, w| m.max(w.abs()));
        let impacts = simulation.contact_statistics.iter().map(|s| s.impacts).sum();
        let peak_wear_work = (!simulation.wear_work.is_empty())
            .then(|| simulation.wear_work.iter().copied().fold(0.0, f64::max));
        Self {
            peak_force,
            peak_displacement,
            impacts,
            peak_wear_work,
        }
    }
}

/// |coarse − fine| / |fine|; 0 when both are 0, 1 when only the fine one is.
pub(super) fn relative_change(coarse: f64, fine: f64) -> f64 {
    if coarse == fine {
        0.0
    } else if fine == 0.0 {
        1.0
    } else {
        (coarse - fine).abs() / fine.abs()
    }
}

/// Compares a run with its repetition at the step `repeated` (2Δt or Δt/2, as
/// `compared_with` says).
pub(super) fn compare(
    scheme: Scheme,
    (compared_with, repeated): (StepComparison, &StepSize),
    run: KeyFigures,
    repetition: KeyFigures,
    (steps, run_steps, seconds): (u64, u64, f64),
) -> StepHalving {
    let order = scheme_order(scheme);
    let (coarse, fine, richardson) = match compared_with {
        StepComparison::HalfStep => (run, repetition, 2f64.powf(order) / (2f64.powf(order) - 1.0)),
        StepComparison::DoubleStep => (repetition, run, 1.0 / (2f64.powf(order) - 1.0)),
    };
    let peak_force_change = relative_change(coarse.peak_force, fine.peak_force);
    let peak_displacement_change = relative_change(coarse.peak_displacement, fine.peak_displacement);
    let impact_count_change =
        (coarse.impacts as f64 - fine.impacts as f64).abs() / (fine.impacts.max(1) as f64);
    let wear_work_rate_change = coarse
        .peak_wear_work
        .zip(fine.peak_wear_work)
        .map(|(coarse, fine)| relative_change(coarse, fine));
    StepHalving {
        compared_with,
        why_half_step: None,
        wear_work_rate_change,
        estimated_wear_work_rate_error: wear_work_rate_change.map(|change| richardson * change),
        time_step: repeated.time_step,
        peak_force_change,
        peak_displacement_change,
        impact_count_change,
        estimated_peak_force_error: richardson * peak_force_change,
        estimated_peak_displacement_error: richardson * peak_displacement_change,
        steps,
        seconds,
        relative_cost: steps as f64 / run_steps.max(1) as f64,
    }
}

/// A finding of the run's other checks (a power law's peak above the force its step
/// was sized for): a reason, and whether it makes the result `poor`.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    pub poor: bool,
    pub reason: String,
}

/// The verdict on a run (see the module doc).
pub(super) fn assess(
    simulation: &Simulation,
    step: &StepSize,
    tolerance: f64,
    (step_halving, basis): (Option<StepHalving>, &BasisErrors),
    findings: Vec<Finding>,
) -> Quality {
    let energy_residual = simulation.energy.relative_residual();
    let steps_per_period = step.steps_per_fastest_period();
    let peak_tolerance = PEAK_TOLERANCE_FACTOR * tolerance;
    let mut poor = false;
    let mut reasons = Vec::new();
    let percent = |x: f64| format!("{:.2} %", 100.0 * x);
    if energy_residual > tolerance {
        poor |= energy_residual > PEAK_TOLERANCE_FACTOR * tolerance;
        reasons.push(format!(
            "the energy balance is off by {} of the energy involved (tolerance {})",
            percent(energy_residual),
            percent(tolerance)
        ));
    }
    if steps_per_period < POOR_STEPS_PER_PERIOD {
        poor = true;
        reasons.push(format!(
            "only {steps_per_period:.1} steps per period of the fastest contact motion: \
             below {POOR_STEPS_PER_PERIOD}, peaks and impacts are not resolved"
        ));
    }
    match &step_halving {
        Some(check) => {
            for (what, change, error) in [
                (
                    "peak contact force",
                    check.peak_force_change,
                    check.estimated_peak_force_error,
                ),
                (
                    "peak deflection",
                    check.peak_displacement_change,
                    check.estimated_peak_displacement_error,
                ),
            ] {
                if error > peak_tolerance {
                    poor |= error > POOR_FACTOR * peak_tolerance;
                    reasons.push(format!(
                        "the {what} changes by {} when the step is {}: estimated error {} (tolerance {})",
                        percent(change),
                        check.compared_with.verb(),
                        percent(error),
                        percent(peak_tolerance)
                    ));
                }
            }
            if let Some(error) = check.estimated_wear_work_rate_error
                && error > peak_tolerance
            {
                poor |= error > POOR_FACTOR * peak_tolerance;
                reasons.push(format!(
                    "the largest wear work rate of a contact changes by {} when the step is {}: \
                     estimated error {} (tolerance {})",
                    percent(check.wear_work_rate_change.unwrap_or(0.0)),
                    check.compared_with.verb(),
                    percent(error),
                    percent(peak_tolerance)
                ));
            }
            if check.impact_count_change > IMPACT_COUNT_DOUBT {
                reasons.push(format!(
                    "the impact count changes by {} when the step is {}",
                    percent(check.impact_count_change),
                    check.compared_with.verb()
                ));
            }
        }
        None => {
            if (POOR_STEPS_PER_PERIOD..DOUBTFUL_STEPS_PER_PERIOD).contains(&steps_per_period) {
                reasons.push(format!(
                    "only {steps_per_period:.1} steps per period of the fastest contact motion \
                     (at least {DOUBTFUL_STEPS_PER_PERIOD} wanted), and no step check was run"
                ));
            }
        }
    }
    if !reasons.is_empty() && step.limited_by == super::step_size::StepLimit::Given {
        reasons.push("use time_step \"auto\" (it picks the step for the tolerance)".to_owned());
    }
    for (what, advice, probe) in [
        (
            "modal basis",
            "add modes (or keep the static correction)",
            &basis.modal_truncation,
        ),
        ("element mesh", "add elements", &basis.mesh),
    ] {
        let error = probe.estimated_peak_force_error;
        if error > peak_tolerance {
            poor |= error > POOR_FACTOR * peak_tolerance;
            let at = probe
                .height
                .map(|z| format!(" at the contact at {} m", crate::number(z)))
                .unwrap_or_default();
            reasons.push(format!(
                "the {what} puts the peak contact force off by an estimated {}{at} (tolerance {}): {advice}",
                percent(error),
                percent(peak_tolerance)
            ));
        }
    }
    for finding in findings {
        poor |= finding.poor;
        reasons.push(finding.reason);
    }
    let verdict = if poor {
        Verdict::Poor
    } else if !reasons.is_empty() {
        Verdict::Doubtful
    } else if step_halving.is_none() {
        reasons.push(
            "the time step's error of the peaks was not measured (solver.check \"none\"): \
             run with \"auto\" to prove the result"
                .to_owned(),
        );
        Verdict::Unchecked
    } else {
        Verdict::Good
    };
    Quality {
        energy_residual,
        time_step_over_critical: step.over_critical(),
        steps_per_contact_period: steps_per_period,
        tolerance,
        time_step_limited_by: step.limited_by,
        step_halving,
        modal_truncation: basis.modal_truncation,
        mesh: basis.mesh,
        verdict,
        reasons,
    }
}
