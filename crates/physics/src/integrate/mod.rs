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
//! A step above the critical one ([`super::stability`]) is refused before running;
//! `auto` picks one for accuracy ([`step_size`]), and [`run`] checks the result by
//! repeating it at half the step ([`quality`]). A run
//! whose mechanical energy exceeds what the initial energy and the external work can
//! supply (or stops being finite) is stopped at once with [`SimulationError::Diverged`]:
//! no NaN ever leaves this module.
//!
//! A run is three things with clear owners (see `stepper`): the layout (what does not
//! change during the run: modal coefficients, shapes, contact indexing), the state (what
//! the step advances) and the recorder (histories, statistics, energy).

use std::ops::ControlFlow;

use super::contact::Contact;
use super::loads::{BaseAcceleration, PointForce};
use super::modal::ModalBasis;
use super::stability::Scheme;
pub use super::statistics::{ContactStatistics, EnergyBalance, PeakDeflection, PinExtreme};
pub use quality::{Check, Quality, StepHalving, Verdict};
pub use step_size::{DEFAULT_TOLERANCE, StepLimit, StepSize, critical_time_step};

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
    /// Chosen for accuracy within stability ([`step_size`]).
    Auto,
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub scheme: Scheme,
    pub time_step: TimeStep,
    /// Relative accuracy target of `auto` and of the quality verdict, in (0, 1)
    /// ([`DEFAULT_TOLERANCE`]).
    pub tolerance: f64,
    /// The accuracy check run with [`run`] ([`simulate`] runs none).
    pub check: Check,
    /// Simulated duration (s).
    pub duration: f64,
    /// Time between two history samples (s), rounded to a whole number of steps (which
    /// `auto` makes exact); `None` samples every step. Samples are at t = k·interval ≤
    /// duration.
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
    #[error(
        "the integration diverged at t = {time:e} s ({detail}) with a time step of {time_step:e} s \
         (critical time step {critical_time_step:e} s); use time_step \"auto\", which picks the step for accuracy"
    )]
    Diverged {
        time: f64,
        detail: String,
        time_step: f64,
        critical_time_step: f64,
    },
    #[error("cancelled")]
    Cancelled,
}

/// Everything a run produces.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// The step used and its stability limit.
    pub step: StepSize,
    /// Number of steps taken.
    pub steps: u64,
    /// Time between two samples actually used (s); sample k is at exactly k × this.
    pub output_interval: f64,
    /// Sample times (s).
    pub time: Vec<f64>,
    /// `deflections[h][p]`: deflection (m) of pin p at output height h, per sample.
    pub deflections: Vec<Vec<Vec<f64>>>,
    /// `deflection_peaks[h][p]`: per sample, the deflection of largest magnitude (signed)
    /// reached at any step since the previous sample (the sample itself included).
    pub deflection_peaks: Vec<Vec<Vec<f64>>>,
    /// `peak_deflections[h][p]`: the deflection of largest magnitude of pin p at output
    /// height h over every step, and when: the extreme of `deflection_peaks[h][p]`.
    pub peak_deflections: Vec<Vec<PeakDeflection>>,
    /// Contact force (N) of each contact, per sample.
    pub contact_forces: Vec<Vec<f64>>,
    /// Per contact and sample, the largest force reached at any step since the previous
    /// sample: its maximum over the run is the contact's `max_force` exactly.
    pub contact_force_peaks: Vec<Vec<f64>>,
    /// Per contact, accumulated at every step.
    pub contact_statistics: Vec<ContactStatistics>,
    /// Per pin.
    pub pin_extremes: Vec<PinExtreme>,
    /// Energy balance at the end of the run.
    pub energy: EnergyBalance,
    /// Mechanical energy (kinetic + strain + contact) per sample (J).
    pub mechanical_energy: Vec<f64>,
}

/// A run with its accuracy assessment.
#[derive(Debug, Clone, PartialEq)]
pub struct Assessed {
    pub simulation: Simulation,
    pub quality: Quality,
}

/// The step a run will use, or why it cannot run.
pub fn resolve_time_step(model: &Model<'_>, settings: &Settings) -> Result<StepSize, SimulationError> {
    step_size::resolve(model, settings)
}

/// Integrates the model once, with no accuracy check. `progress` is called every few
/// thousand steps with the fraction done; `ControlFlow::Break` stops the run with
/// [`SimulationError::Cancelled`].
pub fn simulate(
    model: &Model<'_>,
    settings: &Settings,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let step = resolve_time_step(model, settings)?;
    stepper::integrate(pulp::Arch::new(), model, settings, &step, progress)
}

/// Integrates the model and assesses the result: the check of `settings.check` (the whole
/// run again at Δt/2 for step halving), then the verdict ([`quality`]).
pub fn run(
    model: &Model<'_>,
    settings: &Settings,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Assessed, SimulationError> {
    let step = resolve_time_step(model, settings)?;
    run_resolved(model, settings, &step, progress)
}

/// [`run`] with a step already resolved by [`resolve_time_step`] (callers that validated
/// the step first need not solve the stability eigenproblem twice).
pub fn run_resolved(
    model: &Model<'_>,
    settings: &Settings,
    step: &StepSize,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Assessed, SimulationError> {
    if step.time_step > step.critical_time_step * (1.0 + 1e-12) {
        return Err(SimulationError::TimeStepAboveCritical {
            time_step: step.time_step,
            critical_time_step: step.critical_time_step,
        });
    }
    let arch = pulp::Arch::new();
    // The check takes twice the steps of the run: a third of the progress for the run.
    let share = match settings.check {
        Check::StepHalving => 1.0 / 3.0,
        Check::None => 1.0,
    };
    let simulation = stepper::integrate(arch, model, settings, step, &mut |f| progress(share * f))?;
    let step_halving = match settings.check {
        Check::None => None,
        Check::StepHalving => {
            let started = std::time::Instant::now();
            let halved = step.halved();
            // The same samples, so that the repeated run costs no more memory per step.
            let settings = Settings {
                output_interval: Some(simulation.output_interval),
                ..settings.clone()
            };
            let check = stepper::integrate(arch, model, &settings, &halved, &mut |f| {
                progress(share + (1.0 - share) * f)
            })?;
            Some(quality::step_halving(
                settings.scheme,
                step,
                quality::KeyFigures::of(&simulation),
                quality::KeyFigures::of(&check),
                (check.steps, simulation.steps, started.elapsed().as_secs_f64()),
            ))
        }
    };
    let quality = quality::assess(&simulation, step, settings.tolerance, step_halving);
    Ok(Assessed { simulation, quality })
}

/// Runs with step `dt` whatever the critical step (tests probe instability with it).
#[cfg(test)]
fn simulate_unchecked(
    model: &Model<'_>,
    settings: &Settings,
    dt: f64,
) -> Result<Simulation, SimulationError> {
    let step = StepSize {
        time_step: dt,
        ..resolve_time_step(
            model,
            &Settings {
                time_step: TimeStep::Auto,
                ..settings.clone()
            },
        )?
    };
    stepper::integrate(pulp::Arch::new(), model, settings, &step, &mut |_| {
        ControlFlow::Continue(())
    })
}

/// [`simulate`] at the SIMD level `arch` (tests compare the vector and scalar layouts).
#[cfg(test)]
fn simulate_on(
    arch: pulp::Arch,
    model: &Model<'_>,
    settings: &Settings,
) -> Result<Simulation, SimulationError> {
    let step = resolve_time_step(model, settings)?;
    stepper::integrate(arch, model, settings, &step, &mut |_| ControlFlow::Continue(()))
}

/// Steps of a run and the number of steps between two history samples (cost
/// estimates): (⌊duration/Δt⌋ (never past the duration), round(interval/Δt) or 1 without
/// an interval). A run records `steps / every + 1` samples.
pub fn step_counts(duration: f64, step: &StepSize, interval: Option<f64>) -> (u64, u64) {
    (step.steps(duration), step.output_every(interval))
}

mod kernels;
mod layout;
pub mod quality;
mod recorder;
mod state;
pub mod step_size;
mod stepper;

#[cfg(test)]
mod tests;

#[cfg(test)]
mod accuracy_tests;
