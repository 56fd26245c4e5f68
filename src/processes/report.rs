//! The parts of a results document every process shares, as the types that are
//! serialized (their OpenAPI schemas come from these same types, so they cannot drift):
//! the `quality` section and the energy balance.
//!
//! The physics returns plain data ([`Quality`], [`EnergyBalance`]); these are their wire
//! forms, built by `From`.

use serde::Serialize;
use utoipa::ToSchema;

use crate::physics::integrate::{Quality, StepHalving, StepLimit, Verdict};
use crate::physics::statistics::EnergyBalance;

/// The `quality` section of every results document: how right the result is.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct QualityReport {
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
    #[schema(value_type = String, pattern = "^(given|fastest_motion|excitation|stability)$")]
    pub time_step_limited_by: StepLimitReport,
    /// The run repeated at Δt/2 (`solver.check: "step_halving"`); null with `"none"`.
    pub step_halving: Option<StepHalvingReport>,
    /// `good`: within the tolerance by every measure; `doubtful`: some measure outside it,
    /// none by far; `poor`: do not use the numbers (energy residual > 10 × tolerance, an
    /// estimated peak error > 20 × tolerance, or fewer than 8 steps per contact period).
    #[schema(value_type = String, pattern = "^(good|doubtful|poor)$")]
    pub verdict: VerdictReport,
    /// One sentence per measure outside the tolerance (empty when `good`).
    pub reasons: Vec<String>,
}

/// What set the step: `given` (a fixed step), or for `auto` `fastest_motion` (the
/// period of the fastest motion with the contacts closed), `excitation` (its pulse,
/// period or sampling) or `stability` (the critical step).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepLimitReport {
    Given,
    FastestMotion,
    Excitation,
    Stability,
}

/// `good`: within the tolerance by every measure; `doubtful`: some measure outside it,
/// none by far; `poor`: do not use the numbers (energy residual > 10 × tolerance, an
/// estimated peak error > 20 × tolerance, or fewer than 8 steps per contact period).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VerdictReport {
    Good,
    Doubtful,
    Poor,
}

/// The step-halving check: the whole run repeated at half the step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct StepHalvingReport {
    /// Step of the repeated run (s).
    pub time_step: f64,
    /// |F(Δt) − F(Δt/2)| / F(Δt/2) of the peak contact force over all contacts and steps.
    pub peak_force_change: f64,
    /// The same for the peak |deflection| at the output heights.
    pub peak_displacement_change: f64,
    /// |n(Δt) − n(Δt/2)| / max(n(Δt/2), 1) of the total impact count.
    pub impact_count_change: f64,
    /// Estimated relative error of the reported peak force: 2ᵖ/(2ᵖ − 1) × its change (4/3
    /// for central difference, Richardson).
    pub estimated_peak_force_error: f64,
    /// Estimated relative error of the reported peak deflection.
    pub estimated_peak_displacement_error: f64,
    /// Steps taken by the check.
    pub steps: u64,
    /// Wall time of the check (s).
    pub seconds: f64,
    /// Steps of the check over steps of the run (2).
    pub relative_cost: f64,
}

impl From<StepLimit> for StepLimitReport {
    fn from(value: StepLimit) -> Self {
        match value {
            StepLimit::Given => Self::Given,
            StepLimit::FastestMotion => Self::FastestMotion,
            StepLimit::Excitation => Self::Excitation,
            StepLimit::Stability => Self::Stability,
        }
    }
}

impl From<Verdict> for VerdictReport {
    fn from(value: Verdict) -> Self {
        match value {
            Verdict::Good => Self::Good,
            Verdict::Doubtful => Self::Doubtful,
            Verdict::Poor => Self::Poor,
        }
    }
}

impl From<StepHalving> for StepHalvingReport {
    fn from(c: StepHalving) -> Self {
        Self {
            time_step: c.time_step,
            peak_force_change: c.peak_force_change,
            peak_displacement_change: c.peak_displacement_change,
            impact_count_change: c.impact_count_change,
            estimated_peak_force_error: c.estimated_peak_force_error,
            estimated_peak_displacement_error: c.estimated_peak_displacement_error,
            steps: c.steps,
            seconds: c.seconds,
            relative_cost: c.relative_cost,
        }
    }
}

impl From<Quality> for QualityReport {
    fn from(q: Quality) -> Self {
        Self {
            energy_residual: q.energy_residual,
            time_step_over_critical: q.time_step_over_critical,
            steps_per_contact_period: q.steps_per_contact_period,
            tolerance: q.tolerance,
            time_step_limited_by: q.time_step_limited_by.into(),
            step_halving: q.step_halving.map(Into::into),
            verdict: q.verdict.into(),
            reasons: q.reasons,
        }
    }
}

/// The energy balance at the end of the run (J), in the frame of the moving base: with
/// exact integration kinetic + strain + contact + dissipated − external_work = initial.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct EnergyReport {
    /// Kinetic energy (J).
    pub kinetic: f64,
    /// Strain energy of the beams (J).
    pub strain: f64,
    /// Energy stored in the closed contact springs (J).
    pub contact: f64,
    /// Dissipated by modal (structural) damping since t = 0 (J).
    pub dissipated_modal: f64,
    /// Dissipated by the contact dashpots since t = 0 (J).
    pub dissipated_contact: f64,
    /// Work of the base excitation (inertial load) and point forces since t = 0 (J).
    pub external_work: f64,
    /// kinetic + strain + contact at t = 0 (J).
    pub initial: f64,
    /// kinetic + strain + contact + dissipated − external_work − initial (J): zero for
    /// exact integration.
    pub residual: f64,
    /// |residual| over the largest energy involved (dimensionless).
    pub relative_residual: f64,
}

impl From<EnergyBalance> for EnergyReport {
    fn from(e: EnergyBalance) -> Self {
        Self {
            kinetic: e.kinetic,
            strain: e.strain,
            contact: e.contact,
            dissipated_modal: e.dissipated_modal,
            dissipated_contact: e.dissipated_contact,
            external_work: e.external_work,
            initial: e.initial,
            residual: e.residual(),
            relative_residual: e.relative_residual(),
        }
    }
}
