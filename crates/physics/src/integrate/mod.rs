//! Explicit time integration of identical pins on their shared modal basis, with
//! penalty point contacts, base excitation and point forces.
//!
//! Modal equations per deflection line r: q̈ᵢ + 2ξᵢωᵢ q̇ᵢ + ωᵢ² qᵢ = ψᵢ(z)·(contact and
//! point forces along the line) − Γᵢ a(t). Coordinates are stored line-major
//! (`q[r * row + i]`, see `stepper`) so that a closed contact reads and writes whole
//! contiguous rows.
//!
//! **Row and plane.** In the row ([`Model::plane`] `None`) every pin bends along x only:
//! one line per pin (r = p), every contact normal is +x, δ = w_L − w_R − gap. In the
//! plane every pin bends along x and y on the same basis (the two directions of a
//! straight beam of circular section are uncoupled and identical): 2 × pins lines, r = p
//! along x and r = pins + p along y. A contact with unit normal n (from left to right)
//! has δ = n·(u_L − u_R) − gap, δ̇ = n·(u̇_L − u̇_R), and pushes the left pin by −F n and
//! the right one by +F n on the modes of its x and y lines. The relative sliding
//! velocity is v_t = t·(u̇_L − u̇_R), t = (−n_y, n_x), and the wear work ∫ F |v_t| dt is
//! accumulated per contact at every step ([`Simulation::wear_work`]). The base
//! acceleration has one component per direction (the y one in [`Plane`]); each initial
//! tip displacement and each point force acts on one line (a release or a force along
//! an angle θ is two: cos θ on line p, sin θ on line pins + p). Every per-pin output
//! (deflections, peaks, extremes) is indexed by line. The row runs on its own kernels:
//! the plane costs it nothing.
//!
//! **Velocity-dependent forces.** Central difference (velocity form):
//! v½ = vₙ + ½Δt aₙ, qₙ₊₁ = qₙ + Δt v½, vₙ₊₁ = v½ + ½Δt aₙ₊₁. Modal damping is diagonal,
//! so it is taken at vₙ₊₁ exactly: aₙ₊₁ = (f − ω²qₙ₊₁ − 2ξω v½)/(1 + ξωΔt), still explicit
//! and second order. Contact dashpots couple modes; they use the predicted velocity
//! ṽₙ₊₁ = vₙ + Δt aₙ (error O(Δt²), which keeps the scheme second order).
//! Tchamwa–Wielgosz: qₙ₊₁ = qₙ + Δt vₙ + φΔt² aₙ, vₙ₊₁ = vₙ + Δt aₙ, and all
//! velocity-dependent forces use that vₙ₊₁, which is exact for the scheme.
//!
//! One way in: [`Plan::new`] refuses a model or settings that cannot be integrated
//! ([`Model::validate`], [`Settings::validate`]) and a step above the critical one
//! ([`super::stability`]); `auto` picks one for accuracy ([`step_size`]), and
//! [`Plan::run`] checks the result by repeating it at half the step ([`quality`]). A run
//! whose mechanical energy exceeds what the initial energy and the external work can
//! supply (or stops being finite) is stopped at once with [`SimulationError::Diverged`]:
//! no NaN ever leaves this module.
//!
//! A run is three things with clear owners (see `stepper`): the layout (what does not
//! change during the run: modal coefficients, shapes, contact indexing), the state (what
//! the step advances) and the recorder (histories, statistics, energy).

pub use super::statistics::{
    ContactStatistics, CurvaturePeak, EnergyBalance, FrictionStatistics, PeakDeflection, PinExtreme,
    ResultantPeak,
};
use crate::InputIssue;
pub use crate::impacts::{ImpactCounting, ImpactHistogram, ImpactStatistics, ImpactTable};
pub use kinds::{BodyKind, KindScale, SHAPE_TOLERANCE, pin_kinds_of, relative_mass};
pub use model::{Model, NORMAL_LENGTH_TOLERANCE, Plane, Settings, TimeStep, WallMotion};
pub use plan::Plan;
pub use quality::{Check, Quality, StepComparison, StepHalving, Verdict};
pub use step_size::{
    DEFAULT_TOLERANCE, ExcitationScales, StepLimit, StepSize, critical_time_step, sample_time,
};

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
    #[error(
        "the implicit contact solve of the `exact_modal` scheme did not settle at t = {time:e} s \
         ({sweeps} sweeps over {contacts} contacts); use `central_difference`"
    )]
    ContactSolveFailed {
        time: f64,
        sweeps: usize,
        contacts: usize,
    },
    #[error("the model cannot be integrated: {}", describe(.0))]
    InvalidModel(Vec<InputIssue>),
    #[error("the integration settings are invalid: {}", describe(.0))]
    InvalidSettings(Vec<InputIssue>),
    #[error("cancelled")]
    Cancelled,
}

/// `field: reason; field: reason`.
fn describe(issues: &[InputIssue]) -> String {
    issues
        .iter()
        .map(|i| format!("{}: {}", i.field, i.reason))
        .collect::<Vec<_>>()
        .join("; ")
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
    /// `deflections[h][r]`: deflection (m) of line r at output height h, per sample (the
    /// row: r = pin; the plane: r = p along x, r = pins + p along y).
    pub deflections: Vec<Vec<Vec<f64>>>,
    /// `deflection_peaks[h][r]`: per sample, the deflection of largest magnitude (signed)
    /// reached at any step since the previous sample (the sample itself included).
    pub deflection_peaks: Vec<Vec<Vec<f64>>>,
    /// `peak_deflections[h][r]`: the deflection of largest magnitude of line r at output
    /// height h over every step, and when: the extreme of `deflection_peaks[h][r]`.
    pub peak_deflections: Vec<Vec<PeakDeflection>>,
    /// Contact force (N) of each recorded contact (`Settings::recorded_contacts`, in
    /// that order; every contact by default), per sample.
    pub contact_forces: Vec<Vec<f64>>,
    /// Per recorded contact and sample, the largest force reached at any step since the
    /// previous sample: its maximum over the run is the contact's `max_force` exactly.
    pub contact_force_peaks: Vec<Vec<f64>>,
    /// Per contact (every one, recorded or not), accumulated at every step.
    pub contact_statistics: Vec<ContactStatistics>,
    /// Per contact: wear work ∫ F·|v_t| dt (J), v_t the relative tangential velocity at
    /// the contact (tangent t = (−n_y, n_x)); empty for the row (no tangential motion).
    pub wear_work: Vec<f64>,
    /// Per contact: its friction (empty for the row; zeros for a contact without).
    pub friction_statistics: Vec<FrictionStatistics>,
    /// Per contact: its impacts as `Settings::impacts` counts them, over the run and its
    /// blocks (`contact_statistics[c].impacts` is the same count).
    pub impact_statistics: Vec<ImpactStatistics>,
    /// The per-impact table (every impact, or past `max_rows` the largest with a fair share
    /// per contact: [`crate::impacts::TableKeeper`]) and the peak-force histograms.
    pub impact_table: ImpactTable,
    pub impact_histogram: ImpactHistogram,
    /// Per line (r as in `deflections`).
    pub pin_extremes: Vec<PinExtreme>,
    /// Per pin in the plane (empty for the row): the largest resultant deflection
    /// √(wx² + wy²) over the mesh nodes at every output time, where and when.
    pub resultant_extremes: Vec<PinExtreme>,
    /// `curvatures[h][r]`: bending curvature w'' (1/m) of line r at output height h, per
    /// sample (signed: w'' > 0 bends the line concave toward +x, or +y; the moment is
    /// EI w''), the transport by a moving top support included.
    pub curvatures: Vec<Vec<Vec<f64>>>,
    /// Per mesh node from the foot, the largest curvature there over every pin and
    /// sample (in the plane, the resultant of x and y), which pin and when.
    pub curvature_envelope: Vec<CurvaturePeak>,
    /// Per pin, its largest curvature over its nodes and the samples (in the plane, the
    /// resultant), where and when.
    pub pin_curvatures: Vec<CurvaturePeak>,
    /// Per pin and contact height where a contact acts on it (by pin, then height), the
    /// largest resultant of those contacts' forces on the pin, at every step.
    pub resultant_forces: Vec<ResultantPeak>,
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

/// Steps of a run and the number of steps between two history samples (cost
/// estimates): (⌊duration/Δt⌋ (never past the duration), round(interval/Δt) or 1 without
/// an interval). A run records `steps / every + 1` samples.
pub fn step_counts(duration: f64, step: &StepSize, interval: Option<f64>) -> (u64, u64) {
    (step.steps(duration), step.output_every(interval))
}

/// [`Plan::new`] then [`Plan::run`], the simulation alone (the tests' shorthand).
#[cfg(test)]
pub(crate) fn simulate(
    model: &Model<'_>,
    settings: &Settings,
    progress: &mut dyn FnMut(f64) -> std::ops::ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    Ok(Plan::new(model, settings)?.run(progress)?.simulation)
}

mod exact;
mod kernels;
mod kinds;
mod layout;
mod model;
mod plan;
mod plane_step;
pub mod quality;
mod recorder;
mod resultants;
mod state;
pub mod step_size;
mod stepper;
mod walls;

#[cfg(test)]
mod tests;

#[cfg(test)]
mod accuracy_tests;

#[cfg(test)]
mod plane_tests;

#[cfg(test)]
mod plane_load_tests;

#[cfg(test)]
mod impact_tests;

#[cfg(test)]
mod wall_tests;

#[cfg(test)]
mod thread_tests;

#[cfg(test)]
mod bending_tests;
#[cfg(test)]
mod exact_tests;
#[cfg(test)]
mod kind_tests;
#[cfg(test)]
mod law_tests;
#[cfg(test)]
mod resultant_tests;
