//! Process `cantilever-impact`: the paper's validation case. A cantilever released from
//! its static tip-load shape hits a spring (wall contact) at its tip; the numerical
//! modal scheme and the semi-analytic reference are run on the same beam and compared
//! through f_err (paper eq. 11).

use serde::Deserialize;
use serde_json::json;
use utoipa::ToSchema;

use super::basis_report::BasisReport;
use super::inputs::{self, BeamInput, SchemeInput, SupportInput, TimeStepInput, at};
use super::{FieldError, History, InvalidInputs, Process, ProgressFn, RunError, RunOutput, WorkEstimate};
use crate::physics::InputIssue;
use crate::physics::contact::{Body, Contact};
use crate::physics::integrate::{Model, Settings, StepSize, step_counts};
use crate::physics::modal::ModalBasis;
use crate::physics::reference::{CantileverReference, ContactEventKind, MAX_MODES, ReferenceError};
use crate::physics::spectrum::spectral_error;

/// Threshold of f_err below which the paper calls two signals identical.
pub const AGREEMENT_THRESHOLD: f64 = 0.2;
/// Largest number of history samples (per column).
pub const MAX_HISTORY_SAMPLES: f64 = 2e6;

/// Inputs of `cantilever-impact`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CantileverInputs {
    /// The cantilever (clamped at its foot, free at its top).
    pub beam: BeamInput,
    #[serde(default)]
    pub contact: ContactInput,
    #[serde(default)]
    pub release: ReleaseInput,
    #[serde(default)]
    pub solver: SolverInput,
    #[serde(default)]
    pub reference: ReferenceInput,
    #[serde(default)]
    pub output: OutputInput,
}

/// The tip contact: a spring below the tip, acting while w(L) < −gap.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactInput {
    /// Rk = Kc L³ / 3EI (dimensionless): contact stiffness over the static tip
    /// stiffness. Exactly one of `rk` and `stiffness`; default `rk` = 1.
    pub rk: Option<f64>,
    /// Contact stiffness Kc (N/m).
    pub stiffness: Option<f64>,
    /// Gap between the tip at rest and the spring (m).
    #[serde(default)]
    pub gap: f64,
    /// Contact dashpot cc (N·s/m); the reference has none.
    #[serde(default)]
    pub damping: f64,
}

/// Initial state: released at rest from the static shape of a tip load.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ReleaseInput {
    /// Tip deflection of the release shape (m), positive away from the spring.
    #[serde(default = "default_release")]
    pub tip_displacement: f64,
}
impl Default for ReleaseInput {
    fn default() -> Self {
        Self {
            tip_displacement: default_release(),
        }
    }
}
fn default_release() -> f64 {
    1e-3
}

/// Explicit integration settings.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SolverInput {
    #[serde(default)]
    pub scheme: SchemeInput,
    /// Tchamwa–Wielgosz parameter φ in [1, 2] (default 1.1).
    pub phi: Option<f64>,
    /// Time step (s) or "auto" (chosen for accuracy at `tolerance` within stability);
    /// default 1e-5 s.
    #[serde(default = "default_time_step")]
    pub time_step: TimeStepInput,
    /// Simulated duration (s) (default 0.5 s).
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Relative accuracy target in (0, 1), default 1e-3: `auto` picks its step so that
    /// the energy balance closes within it and peaks are within 10 × it, and
    /// `quality.verdict` judges against it. Larger values trade accuracy for speed (sweeps).
    #[serde(default = "super::inputs::default_tolerance")]
    #[schema(default = 1e-3, exclusive_minimum = 0.0, exclusive_maximum = 1.0)]
    pub tolerance: f64,
    /// Accuracy check: `step_halving` (default; the run repeated at Δt/2, three times the
    /// cost) or `none` (cheap sweeps).
    #[serde(default)]
    pub check: super::inputs::CheckInput,
}
impl SolverInput {
    /// The fields the shared solver checks read.
    pub fn fields(&self) -> super::inputs::SolverFields {
        super::inputs::SolverFields {
            scheme: self.scheme,
            phi: self.phi,
            time_step: self.time_step,
            duration: self.duration,
            tolerance: self.tolerance,
            check: self.check,
        }
    }
}

impl Default for SolverInput {
    fn default() -> Self {
        Self {
            scheme: SchemeInput::default(),
            phi: None,
            time_step: default_time_step(),
            duration: default_duration(),
            tolerance: super::inputs::default_tolerance(),
            check: super::inputs::CheckInput::default(),
        }
    }
}
fn default_time_step() -> TimeStepInput {
    TimeStepInput::Seconds(1e-5)
}
fn default_duration() -> f64 {
    0.5
}

/// Semi-analytic reference settings.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ReferenceInput {
    /// Modes per analytic basis (clamped-free and clamped-spring), 1..60 (default 30).
    #[serde(default = "default_reference_modes")]
    pub modes: usize,
}
impl Default for ReferenceInput {
    fn default() -> Self {
        Self {
            modes: default_reference_modes(),
        }
    }
}
fn default_reference_modes() -> usize {
    30
}

/// History sampling.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputInput {
    /// Time between two history samples (s), a whole number of steps; default: every step.
    pub interval: Option<f64>,
}

/// Validated inputs, ready to run.
#[derive(Debug)]
struct Prepared {
    inputs: CantileverInputs,
    basis: ModalBasis,
    contact_stiffness: f64,
    settings: Settings,
    reference: CantileverReference,
}

impl Prepared {
    fn model(&self) -> Model<'_> {
        let contact = &self.inputs.contact;
        Model {
            basis: &self.basis,
            pins: 1,
            damping_ratios: self.inputs.beam.damping_ratios_for(self.basis.modes()),
            contacts: vec![Contact {
                left: Body::Wall,
                right: Body::Pin(0),
                height: self.inputs.beam.length,
                gap: contact.gap,
                stiffness: self.contact_stiffness,
                damping: contact.damping,
            }],
            initial_tip_displacements: vec![self.inputs.release.tip_displacement],
            base_acceleration: None,
            point_forces: vec![],
        }
    }

    /// What the run costs: one pin of `modes` modes and one contact per step; two
    /// histories of three columns (time, numerical, reference).
    fn estimate(&self, step: &StepSize) -> WorkEstimate {
        let (steps, every) = step_counts(self.settings.duration, step, self.settings.output_interval);
        // The step-halving check takes twice the steps of the run.
        let check = match self.settings.check {
            crate::physics::integrate::Check::StepHalving => 3.0,
            crate::physics::integrate::Check::None => 1.0,
        };
        let mut history_drivers = vec![
            "/inputs/solver/duration".to_owned(),
            "/inputs/output/interval".to_owned(),
        ];
        if self.settings.output_interval.is_none() {
            history_drivers.push("/inputs/solver/time_step".to_owned());
        }
        WorkEstimate {
            steps: check * steps as f64,
            modal_dofs: self.basis.modes() as f64,
            contacts: 1.0,
            // tip_displacement and contact_force, and their peaks.
            history_values: (steps / every + 1) as f64 * 12.0,
            work_drivers: [
                "/inputs/solver/duration",
                "/inputs/solver/time_step",
                "/inputs/beam/modes",
            ]
            .map(str::to_owned)
            .to_vec(),
            history_drivers,
        }
    }
}

/// Validated inputs and the step they run with.
#[derive(Debug)]
struct Plan {
    prepared: Prepared,
    step: StepSize,
}

fn prepare(json: &serde_json::Value) -> Result<Plan, InvalidInputs> {
    let inputs: CantileverInputs = inputs::parse(json)?;
    let mut errors: Vec<FieldError> = at("/inputs/beam", inputs.beam.validate());
    let supports = inputs.beam.supports;
    if supports.foot != SupportInput::Clamped || supports.top != SupportInput::Free {
        errors.push(FieldError::new(
            "/inputs/beam/supports",
            "cantilever-impact models a clamped-free beam",
        ));
    }
    let spec = inputs.beam.spec();
    let tip_stiffness = 3.0 * spec.bending_stiffness() / spec.length.powi(3);

    let contact = inputs.contact;
    let mut contact_issues = Vec::new();
    let contact_stiffness = match (contact.rk, contact.stiffness) {
        (Some(_), Some(_)) => {
            contact_issues.push(InputIssue::new(
                "stiffness",
                "give exactly one of `rk` and `stiffness`",
            ));
            0.0
        }
        (rk, None) => {
            let rk = rk.unwrap_or(1.0);
            crate::physics::require_non_negative(&mut contact_issues, "rk", rk);
            rk * tip_stiffness
        }
        (None, Some(stiffness)) => {
            crate::physics::require_non_negative(&mut contact_issues, "stiffness", stiffness);
            stiffness
        }
    };
    crate::physics::require_non_negative(&mut contact_issues, "gap", contact.gap);
    crate::physics::require_non_negative(&mut contact_issues, "damping", contact.damping);
    errors.extend(at("/inputs/contact", contact_issues));
    if !inputs.release.tip_displacement.is_finite() {
        errors.push(FieldError::new(
            "/inputs/release/tip_displacement",
            "must be a finite number",
        ));
    }

    let solver = inputs::solver(inputs.solver.fields(), &mut errors);
    if !(1..=MAX_MODES).contains(&inputs.reference.modes) {
        errors.push(FieldError::new(
            "/inputs/reference/modes",
            format!("must be between 1 and {MAX_MODES}"),
        ));
    }
    inputs::check_output_interval(inputs.output.interval, &mut errors);
    if !errors.is_empty() {
        return Err(InvalidInputs(errors));
    }

    // The contact is at the tip: the static correction, if any, is the tip-load shape.
    let basis = inputs.beam.basis(&[spec.length], "/inputs/beam")?;
    let settings = Settings {
        scheme: solver.scheme,
        time_step: solver.time_step,
        tolerance: solver.tolerance,
        check: solver.check,
        duration: inputs.solver.duration,
        output_interval: inputs.output.interval,
        output_heights: vec![spec.length],
    };
    let reference = CantileverReference {
        length: spec.length,
        young_modulus: spec.young_modulus,
        density: spec.density,
        area: spec.section.area(),
        inertia: spec.section.inertia(),
        added_mass_per_length: spec.added_mass_per_length,
        contact_stiffness,
        gap: contact.gap,
        damping_ratios: inputs.beam.damping_ratios(),
        tip_displacement: inputs.release.tip_displacement,
        duration: inputs.solver.duration,
        modes: inputs.reference.modes,
        max_events: 100_000,
    };
    let prepared = Prepared {
        inputs,
        basis,
        contact_stiffness,
        settings,
        reference,
    };
    let step = check_costs(&prepared)?;
    Ok(Plan { prepared, step })
}

/// Refuses steps above the critical one, histories too long, references too costly.
fn check_costs(prepared: &Prepared) -> Result<StepSize, InvalidInputs> {
    let model = prepared.model();
    let step = inputs::resolve_step(&model, &prepared.settings)?;
    let dt = step.time_step;
    let duration = prepared.settings.duration;
    let mut errors = Vec::new();
    if duration / dt > inputs::MAX_STEPS {
        errors.push(FieldError::new(
            "/inputs/solver/duration",
            format!(
                "needs {:.3e} steps of {dt:e} s, above the limit of {:e}{}",
                duration / dt,
                inputs::MAX_STEPS,
                inputs::step_hint(&step, prepared.settings.tolerance)
            ),
        ));
    }
    let interval = prepared.settings.output_interval.unwrap_or(dt).max(dt);
    if duration / interval > MAX_HISTORY_SAMPLES {
        errors.push(FieldError::new(
            "/inputs/output/interval",
            format!(
                "gives {:.3e} samples, above the limit of {MAX_HISTORY_SAMPLES:e}: sample less often",
                duration / interval
            ),
        ));
    }
    // The reference scans at 1/16 of its shortest period; its highest root is below (n + ½)π.
    let reference = &prepared.reference;
    let lambda = (reference.modes as f64 + 0.5) * std::f64::consts::PI;
    let omega = lambda * lambda * (reference.bending_stiffness() / reference.mass_per_length()).sqrt()
        / reference.length.powi(2);
    let scan_samples = duration * 16.0 * omega / std::f64::consts::TAU;
    if scan_samples > crate::physics::reference::MAX_SCAN_SAMPLES {
        errors.push(FieldError::new(
            "/inputs/reference/modes",
            format!("the reference would scan {scan_samples:.3e} samples over the duration: use fewer modes or a shorter duration"),
        ));
    }
    if errors.is_empty() {
        Ok(step)
    } else {
        Err(InvalidInputs(errors))
    }
}

/// The `cantilever-impact` process.
#[derive(Debug, Default)]
pub struct CantileverImpact;

impl Process for CantileverImpact {
    fn id(&self) -> &'static str {
        "cantilever-impact"
    }

    fn title(&self) -> &'static str {
        "Cantilever impacting a spring: numerical scheme vs semi-analytic reference"
    }

    fn description(&self) -> &'static str {
        "Releases a cantilever from its static tip-load shape against a tip spring, integrates it on a \
         truncated modal basis with a penalty contact (central difference or Tchamwa-Wielgosz), solves the \
         same problem semi-analytically (exact up to modal truncation), and compares the tip-deflection \
         spectra with f_err (validity threshold 0.2)."
    }

    fn inputs_description(&self) -> serde_json::Value {
        inputs::ogc_inputs(&inputs::schema_of::<CantileverInputs>())
    }

    fn outputs_description(&self) -> serde_json::Value {
        let history = |what: &str| {
            json!({"title": what, "description": format!("{what}: CSV columns time (s), numerical, reference"),
                   "schema": {"type": "string", "contentMediaType": "text/csv"}})
        };
        let peaks = |what: &str| {
            json!({"title": format!("{what}, peaks"),
                   "description": format!("{what}: per output interval, the extreme over every step of the interval (largest magnitude, signed); CSV columns time (s), numerical, reference (the reference sampled at the integrator's step)"),
                   "schema": {"type": "string", "contentMediaType": "text/csv"}})
        };
        json!({
            "tip_displacement": history("Tip deflection (m)"),
            "contact_force": history("Contact force (N)"),
            "tip_displacement_peaks": peaks("Tip deflection (m)"),
            "contact_force_peaks": peaks("Contact force (N)"),
        })
    }

    fn validate(&self, inputs: &serde_json::Value) -> Result<WorkEstimate, InvalidInputs> {
        prepare(inputs).map(|plan| plan.prepared.estimate(&plan.step))
    }

    fn run(&self, inputs: &serde_json::Value, progress: &mut ProgressFn<'_>) -> Result<RunOutput, RunError> {
        let Plan { prepared, step } = prepare(inputs)?;
        let model = prepared.model();
        let mut numerical_progress = |fraction: f64| progress(0.9 * fraction);
        let assessed = crate::physics::integrate::Plan::with_step(&model, &prepared.settings, step)?
            .run(&mut numerical_progress)?;
        let (simulation, quality) = (assessed.simulation, assessed.quality);
        let solution = prepared
            .reference
            .solve(&mut |fraction| progress(0.9 + 0.1 * fraction))
            .map_err(|e| match e {
                ReferenceError::Cancelled { .. } => RunError::Cancelled,
                other => RunError::Failed(format!("reference: {other}")),
            })?;

        let time = simulation.time.clone();
        let interval = simulation.output_interval;
        let sampled = solution
            .sample_uniform(0.0, interval, time.len())
            .map_err(|e| RunError::Failed(format!("reference sampling: {e}")))?;
        let every = step.output_every(prepared.settings.output_interval);
        let reference_peaks = reference_peaks(&solution, time.len(), interval, every)
            .map_err(|e| RunError::Failed(format!("reference sampling: {e}")))?;
        let numerical_tip = simulation.deflections[0][0].clone();
        let f_err = spectral_error(&numerical_tip, &sampled.tip_deflection)
            .map_err(|e| RunError::Failed(format!("f_err: {e}")))?;

        let stats = &simulation.contact_statistics[0];
        let gap = prepared.inputs.contact.gap;
        let max_force = solution.max_contact_force();
        let min_tip = solution.min_tip_deflection();
        let events: Vec<serde_json::Value> = solution
            .events()
            .iter()
            .map(|e| {
                let kind = match e.kind {
                    ContactEventKind::Impact => "impact",
                    ContactEventKind::Release => "release",
                };
                json!({"time": e.time, "kind": kind})
            })
            .collect();
        let mut notes = Vec::new();
        if prepared.inputs.contact.damping > 0.0 {
            notes.push(format!(
                "the reference has no contact dashpot: contact.damping = {} N·s/m acts on the numerical model only",
                prepared.inputs.contact.damping
            ));
        }
        let spec = prepared.inputs.beam.spec();
        let document = json!({
            "model": {
                "contact_stiffness": prepared.contact_stiffness,
                "rk": prepared.contact_stiffness * spec.length.powi(3) / (3.0 * spec.bending_stiffness()),
                "mass_per_length": spec.mass_per_length(),
                "bending_stiffness": spec.bending_stiffness(),
            },
            "numerical": {
                "first_impact_time": stats.first_impact_time,
                "impacts": stats.impacts,
                "max_contact_force": stats.max_force,
                "max_contact_force_time": stats.max_force_time,
                "contact_time": stats.contact_time,
                "impulse": stats.impulse,
                "min_tip_displacement": -gap - stats.max_penetration,
                "time_step": simulation.step.time_step,
                "critical_time_step": simulation.step.critical_time_step,
                "steps": simulation.steps,
                "output_interval": simulation.output_interval,
                "frequencies_hz": prepared.basis.frequencies_hz(),
                "energy": simulation.energy,
            },
            "basis": BasisReport::of(&model, prepared.settings.scheme, simulation.step.critical_time_step),
            "reference": {
                "first_impact_time": solution.first_impact_time(),
                "impacts": solution.impact_count(),
                "max_contact_force": max_force.value,
                "max_contact_force_time": max_force.time,
                "min_tip_displacement": min_tip.value,
                "events": events,
                "free_frequencies_hz": solution.free_frequencies_hz(),
                "contact_frequencies_hz": solution.contact_frequencies_hz(),
                "contact_damping_ratios": solution.contact_damping_ratios(),
                "modes": prepared.reference.modes,
                "notes": notes,
            },
            "comparison": {
                "f_err": f_err,
                "threshold": AGREEMENT_THRESHOLD,
                "agrees": f_err < AGREEMENT_THRESHOLD,
            },
            "quality": quality,
        });
        let contact_force = simulation.contact_forces[0].clone();
        let pair = |name: &str, numerical: Vec<f64>, reference: Vec<f64>| History {
            name: name.into(),
            time: time.clone(),
            series: vec![("numerical".into(), numerical), ("reference".into(), reference)],
        };
        let mut deflection_peaks = simulation.deflection_peaks;
        let histories = vec![
            pair("tip_displacement", numerical_tip, sampled.tip_deflection),
            pair("contact_force", contact_force, sampled.contact_force),
            pair(
                "tip_displacement_peaks",
                std::mem::take(&mut deflection_peaks[0][0]),
                reference_peaks.tip_deflection,
            ),
            pair(
                "contact_force_peaks",
                simulation.contact_force_peaks[0].clone(),
                reference_peaks.contact_force,
            ),
        ];
        Ok(RunOutput { document, histories })
    }
}

/// Per output interval, the extremes of the reference sampled at the integrator's step
/// (`every` steps per interval; sample 0 is the value at t = 0): the largest |tip
/// deflection| (signed) and the largest contact force, as the numerical peaks are.
fn reference_peaks(
    solution: &crate::physics::reference::ReferenceSolution,
    samples: usize,
    interval: f64,
    every: u64,
) -> Result<crate::physics::reference::TipHistory, crate::physics::reference::ReferenceError> {
    let mut peaks = solution.sample_uniform(0.0, interval, samples.min(1))?;
    let every = every as usize;
    let fine = interval / every as f64;
    // A bounded number of fine samples at a time.
    let intervals_per_chunk = (1 << 16) / every + 1;
    let mut k = 1;
    while k < samples {
        let count = intervals_per_chunk.min(samples - k);
        let start = (k - 1) as f64 * interval + fine;
        let chunk = solution.sample_uniform(start, fine, count * every)?;
        for j in 0..count {
            let range = j * every..(j + 1) * every;
            let tip = chunk.tip_deflection[range.clone()]
                .iter()
                .fold(0.0f64, |m, w| if w.abs() > m.abs() { *w } else { m });
            let force = chunk.contact_force[range].iter().fold(0.0f64, |m, f| m.max(*f));
            peaks.tip_deflection.push(tip);
            peaks.contact_force.push(force);
        }
        k += count;
    }
    Ok(peaks)
}

#[cfg(test)]
#[path = "cantilever_impact_tests.rs"]
mod tests;
