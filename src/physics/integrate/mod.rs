//! Explicit time integration of a row of identical pins on their shared modal basis,
//! with penalty point contacts, base excitation and point forces.
//!
//! Modal equations per pin p: q̈ᵢ + 2ξᵢωᵢ q̇ᵢ + ωᵢ² qᵢ = ψᵢ(z)·(contact and point forces)
//! − Γᵢ a(t). Coordinates are stored pin-major (`q[p * row + i]`, see `stepper`) so that
//! a closed contact reads and writes whole contiguous rows.
//!
//! **Velocity-dependent forces.** Central difference (velocity form):
//! v½ = vₙ + ½Δt aₙ, qₙ₊₁ = qₙ + Δt v½, vₙ₊₁ = v½ + ½Δt aₙ₊₁. Modal damping is diagonal,
//! so it is taken at vₙ₊₁ exactly: aₙ₊₁ = (f − ω²qₙ₊₁ − 2ξω v½)/(1 + ξωΔt), still explicit
//! and second order. Contact dashpots couple modes; they use the predicted velocity
//! ṽₙ₊₁ = vₙ + Δt aₙ (error O(Δt²), which keeps the scheme second order).
//! Tchamwa–Wielgosz: qₙ₊₁ = qₙ + Δt vₙ + φΔt² aₙ, vₙ₊₁ = vₙ + Δt aₙ, and all
//! velocity-dependent forces use that vₙ₊₁, which is exact for the scheme.
//!
//! A step above the critical one ([`super::stability`]) is refused before running. A run
//! whose mechanical energy exceeds what the initial energy and the external work can
//! supply (or stops being finite) is stopped at once with [`SimulationError::Diverged`]:
//! no NaN ever leaves this module.

use std::ops::ControlFlow;

use super::contact::Contact;
use super::loads::{BaseAcceleration, PointForce};
use super::modal::ModalBasis;
use super::stability::{Scheme, max_angular_frequency};
pub use super::statistics::{ContactStatistics, EnergyBalance, PinExtreme};

/// Fraction of the critical step used by `time_step: auto`.
pub const AUTO_SAFETY_FACTOR: f64 = 0.8;
/// Steps between two calls of the progress callback.
const PROGRESS_EVERY: u64 = 4096;
/// Steps between two divergence checks.
const DIVERGENCE_CHECK_EVERY: u64 = 32;

/// The row being integrated.
#[derive(Debug, Clone)]
pub struct Model<'a> {
    /// Modal basis shared by every pin.
    pub basis: &'a ModalBasis,
    /// Number of pins (≥ 1).
    pub pins: usize,
    /// Modal damping ratio ξᵢ of each mode (length = modes).
    pub damping_ratios: Vec<f64>,
    pub contacts: Vec<Contact>,
    /// Release of each pin from its static tip-load shape with this tip deflection (m);
    /// empty means all at rest.
    pub initial_tip_displacements: Vec<f64>,
    pub base_acceleration: Option<BaseAcceleration>,
    pub point_forces: Vec<PointForce>,
}

/// Time step choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// This step (s); refused when above the critical step.
    Fixed(f64),
    /// [`AUTO_SAFETY_FACTOR`] × the critical step.
    Auto,
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub scheme: Scheme,
    pub time_step: TimeStep,
    /// Simulated duration (s).
    pub duration: f64,
    /// Time between two history samples (s), rounded to a whole number of steps;
    /// `None` samples every step. Samples are uniform: t = 0, k·interval, ... ≤ duration.
    pub output_interval: Option<f64>,
    /// Heights (m) where every pin's deflection is recorded.
    pub output_heights: Vec<f64>,
}

/// Why a run produced no result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimulationError {
    #[error(
        "time step {time_step:e} s exceeds the critical time step {critical_time_step:e} s of this model \
         (contact stiffness included); use at most the critical step or \"auto\""
    )]
    TimeStepAboveCritical { time_step: f64, critical_time_step: f64 },
    #[error("the integration diverged at t = {time:e} s ({detail}); reduce the time step")]
    Diverged { time: f64, detail: String },
    #[error("cancelled")]
    Cancelled,
}

/// Everything a run produces.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// Step used (s).
    pub time_step: f64,
    /// Critical step of the scheme with every contact closed (s).
    pub critical_time_step: f64,
    /// Number of steps taken.
    pub steps: u64,
    /// Sample times (s).
    pub time: Vec<f64>,
    /// `deflections[h][p]`: deflection (m) of pin p at output height h, per sample.
    pub deflections: Vec<Vec<Vec<f64>>>,
    /// Contact force (N) of each contact, per sample.
    pub contact_forces: Vec<Vec<f64>>,
    /// Per contact, accumulated at every step.
    pub contact_statistics: Vec<ContactStatistics>,
    /// Per pin.
    pub pin_extremes: Vec<PinExtreme>,
    /// Energy balance at the end of the run.
    pub energy: EnergyBalance,
    /// Mechanical energy (kinetic + strain + contact) per sample (J).
    pub mechanical_energy: Vec<f64>,
}

/// Critical time step (s) of `scheme` for this model, all contacts closed.
pub fn critical_time_step(model: &Model<'_>, scheme: Scheme) -> f64 {
    let shapes: Vec<Vec<f64>> = model
        .contacts
        .iter()
        .map(|c| model.basis.deflection_at(c.height))
        .collect();
    let omega_max = max_angular_frequency(
        model.basis.angular_frequencies(),
        model.pins,
        &model.contacts,
        &shapes,
    );
    scheme.stability_limit() / omega_max
}

/// The step a run will use, or why it cannot run.
pub fn resolve_time_step(model: &Model<'_>, settings: &Settings) -> Result<(f64, f64), SimulationError> {
    let critical = critical_time_step(model, settings.scheme);
    match settings.time_step {
        TimeStep::Auto => Ok((AUTO_SAFETY_FACTOR * critical, critical)),
        TimeStep::Fixed(dt) if dt > critical * (1.0 + 1e-12) => Err(SimulationError::TimeStepAboveCritical {
            time_step: dt,
            critical_time_step: critical,
        }),
        TimeStep::Fixed(dt) => Ok((dt, critical)),
    }
}

/// Integrates the model. `progress` is called every few thousand steps with the
/// fraction done; `ControlFlow::Break` stops the run with [`SimulationError::Cancelled`].
pub fn simulate(
    model: &Model<'_>,
    settings: &Settings,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let (dt, critical) = resolve_time_step(model, settings)?;
    integrate_with_step(model, settings, dt, critical, progress)
}

/// Runs with step `dt` whatever the critical step (tests probe instability with it).
#[cfg(test)]
fn simulate_unchecked(
    model: &Model<'_>,
    settings: &Settings,
    dt: f64,
) -> Result<Simulation, SimulationError> {
    integrate_with_step(model, settings, dt, f64::NAN, &mut |_| ControlFlow::Continue(()))
}

/// [`simulate`] at the SIMD level `arch` (tests compare the vector and scalar layouts).
#[cfg(test)]
fn simulate_on(
    arch: pulp::Arch,
    model: &Model<'_>,
    settings: &Settings,
) -> Result<Simulation, SimulationError> {
    let (dt, critical) = resolve_time_step(model, settings)?;
    integrate_on(arch, model, settings, (dt, critical), &mut |_| {
        ControlFlow::Continue(())
    })
}

/// Integrates with a step already resolved by [`resolve_time_step`] (`dt`, `critical`):
/// callers that validated the step first need not solve the stability eigenproblem twice.
pub fn simulate_resolved(
    model: &Model<'_>,
    settings: &Settings,
    (dt, critical): (f64, f64),
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    if dt > critical * (1.0 + 1e-12) {
        return Err(SimulationError::TimeStepAboveCritical {
            time_step: dt,
            critical_time_step: critical,
        });
    }
    integrate_with_step(model, settings, dt, critical, progress)
}

/// Steps of a run and the number of steps between two history samples:
/// (⌊duration/Δt⌋ (never past the duration), round(interval/Δt) or 1 without an interval).
/// A run records `steps / every + 1` samples.
pub fn step_counts(duration: f64, dt: f64, interval: Option<f64>) -> (u64, u64) {
    // Never past the duration: the last step ends at or (by rounding) just before it.
    let total_steps = ((duration / dt) * (1.0 + 1e-12)).floor().max(1.0) as u64;
    let output_every = interval.map_or(1, |interval| ((interval / dt).round() as u64).max(1));
    (total_steps, output_every)
}

fn integrate_with_step(
    model: &Model<'_>,
    settings: &Settings,
    dt: f64,
    critical: f64,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    integrate_on(pulp::Arch::new(), model, settings, (dt, critical), progress)
}

/// The time loop, with the step compiled for the SIMD level `arch`.
fn integrate_on(
    arch: pulp::Arch,
    model: &Model<'_>,
    settings: &Settings,
    (dt, critical): (f64, f64),
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let mut run = Integrator::new(arch, model, settings, (dt, critical));
    let (total_steps, output_every) = step_counts(settings.duration, dt, settings.output_interval);
    run.record_sample(0.0);
    let mut n = 0;
    while n < total_steps {
        // Steps run in batches up to the next check, sample or progress call, all in
        // one SIMD context.
        let next = [DIVERGENCE_CHECK_EVERY, output_every, PROGRESS_EVERY]
            .iter()
            .map(|every| (n / every + 1) * every)
            .fold(total_steps, u64::min);
        run.steps(n + 1..=next);
        n = next;
        let t = n as f64 * dt;
        if n % DIVERGENCE_CHECK_EVERY == 0 || n == total_steps {
            run.check_divergence(t)?;
        }
        if n % output_every == 0 {
            run.record_sample(t);
        }
        if n % PROGRESS_EVERY == 0 && progress(n as f64 / total_steps as f64).is_break() {
            return Err(SimulationError::Cancelled);
        }
    }
    Ok(run.finish(dt, critical, total_steps))
}

mod kernels;
mod stepper;

use stepper::Integrator;

#[cfg(test)]
mod tests;
