//! Process `cantilever-impact`: the paper's validation case. A cantilever released from
//! its static tip-load shape hits a spring (wall contact) at its tip; the numerical
//! modal scheme and the semi-analytic reference are run on the same beam and compared
//! through f_err (paper eq. 11).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::basis_report::BasisReport;
use super::bending::{BendingReport, Flexure, Flexures};
use super::columns::{self, Column};
use super::common_inputs::{self, BeamInput, SolverDefaults, SolverInput, SupportInput, TimeStepInput, at};
use super::contact_law::LawInput;
use super::impact_report::{self, ContactImpacts, ImpactSummary, ImpactsInput};
use super::margins::{self, StressUtilisation, TipAllowablesInput};
use super::model_check::{self, StandIn};
use super::note_facts::{Fact, NoteFacts, PlotRequest};
use super::report::{EnergyReport, QualityReport};
use super::simulation::{HistoryKind, HistoryOutput, Output, Simulation};
use super::warnings::{Subject, WarningsInput};
use super::{Example, FieldError, History, InvalidInputs, ProgressFn, RunError, WorkEstimate};
use crate::physics::InputIssue;
use crate::physics::contact::{Body, Contact};
use crate::physics::discretisation::auto::Choice as BasisChoice;
use crate::physics::integrate::{self, Model, Settings, StepSize};
use crate::physics::modal::ModalBasis;
use crate::physics::reference::{CantileverReference, ContactEventKind, MAX_MODES, ReferenceError};
use crate::physics::spectrum::spectral_error;

/// The schema of the `solver` block, with this process's defaults.
fn solver_schema() -> utoipa::openapi::RefOr<utoipa::openapi::Schema> {
    super::input_schema::solver_schema(SOLVER_DEFAULTS)
}

/// Threshold of f_err below which the paper calls two signals identical.
pub const AGREEMENT_THRESHOLD: f64 = 0.2;
/// The solver's defaults: the paper's step, 1e-5 s, over 0.5 s.
const SOLVER_DEFAULTS: SolverDefaults = SolverDefaults {
    time_step: TimeStepInput::Seconds(1e-5),
    duration: 0.5,
};

/// Inputs of `cantilever-impact`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CantileverInputs {
    /// The cantilever: clamped at its foot, free at its top (the only supports this
    /// process takes).
    pub beam: BeamInput,
    /// The spring at the tip.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub contact: ContactInput,
    /// The initial state.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub release: ReleaseInput,
    /// Explicit integration of the numerical model.
    #[serde(default)]
    #[schema(schema_with = solver_schema, default = json!({}))]
    pub solver: SolverInput,
    /// The semi-analytic reference.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub reference: ReferenceInput,
    /// History sampling and impact counting.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub output: OutputInput,
    /// Plausibility warnings (a unit slip, nothing exciting the model, ...): `on`
    /// (default) or `off`; never a refusal.
    #[serde(default)]
    #[schema(default = "on")]
    pub warnings: WarningsInput,
}

/// The tip contact: a spring below the tip (on the side of negative deflection),
/// pushing while w(L) < −gap.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(as = TipContactInput)]
pub struct ContactInput {
    /// Rk = Kc L³ / 3EI (dimensionless): contact stiffness over the static tip
    /// stiffness. Give `rk` or `stiffness`, not both; `rk` = 1 when both are left out.
    #[schema(minimum = 0.0)]
    pub rk: Option<f64>,
    /// Contact stiffness Kc (N/m), instead of `rk`.
    #[schema(minimum = 0.0)]
    pub stiffness: Option<f64>,
    /// Gap between the tip at rest and the spring (m).
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0)]
    pub gap: f64,
    /// Contact dashpot cc (N·s/m), acting only while the contact is closed; the
    /// reference has none.
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0)]
    pub damping: f64,
    /// The rest of the contact's law: exponent, restitution, Hunt–Crossley damping,
    /// allowable force (the linear spring when left out). The reference knows the
    /// linear spring without damping only: another law acts on the numerical model.
    #[serde(default)]
    #[schema(schema_with = super::contact_law::row_law_schema, default = json!({}))]
    pub law: LawInput,
}

/// Initial state: released from the static shape of a tip load, at rest or moving in
/// that shape.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ReleaseInput {
    /// Tip deflection of the release shape (m), positive away from the spring.
    #[serde(default = "default_release")]
    #[schema(default = 1e-3)]
    pub tip_displacement: f64,
    /// Tip velocity of the release shape at t = 0 (m/s), positive away from the spring:
    /// the beam thrown (or cut loose from a support moving at this speed), the velocity
    /// field v ψ(x) with ψ the unit tip-load shape; 0 (the default) releases it at rest.
    /// The reference takes it exactly as the numerical model does.
    #[serde(default)]
    #[schema(default = 0.0)]
    pub tip_velocity: f64,
}
impl Default for ReleaseInput {
    fn default() -> Self {
        Self {
            tip_displacement: default_release(),
            tip_velocity: 0.0,
        }
    }
}
fn default_release() -> f64 {
    1e-3
}

/// Semi-analytic reference settings.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ReferenceInput {
    /// Modes per analytic basis (clamped-free and clamped-spring).
    #[serde(default = "default_reference_modes")]
    #[schema(default = 30, minimum = 1, maximum = 60)]
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
#[schema(as = CantileverOutputInput)]
pub struct OutputInput {
    /// Time between two history samples (s), a whole number of steps; every step when
    /// left out.
    #[schema(exclusive_minimum = 0.0)]
    pub interval: Option<f64>,
    /// How impacts are counted and tabulated; default: every closure is an impact.
    pub impacts: Option<ImpactsInput>,
    /// Equal blocks of the run over which the impact statistics are also computed,
    /// reported as their mean and standard deviation (code_aster's NB_BLOC; 1…100).
    #[schema(minimum = 1, maximum = 100, default = 1)]
    pub blocks: Option<usize>,
    /// What the tip contact and the beam may carry (docs/margins.md): the peak force and
    /// the largest bending stress over them, as utilisation ratios. None by default.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub allowables: TipAllowablesInput,
}

/// Validated inputs, ready to run.
#[derive(Debug)]
pub struct Plan {
    inputs: CantileverInputs,
    basis: ModalBasis,
    /// What `auto` chose for the mesh and the basis; `None` when both were given.
    basis_choice: Option<BasisChoice>,
    contact_stiffness: f64,
    settings: Settings,
    reference: CantileverReference,
    step: StepSize,
}

impl Plan {
    fn model(&self) -> Model<'_> {
        tip_model(&self.inputs, &self.basis, self.contact_stiffness)
    }
}

/// One cantilever released from its tip deflection against a spring at its tip.
fn tip_model<'a>(inputs: &CantileverInputs, basis: &'a ModalBasis, contact_stiffness: f64) -> Model<'a> {
    Model {
        basis,
        pins: 1,
        damping_ratios: inputs.beam.damping_ratios_for(basis.modes()),
        contacts: vec![Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: inputs.beam.length,
            gap: inputs.contact.gap,
            stiffness: contact_stiffness,
            damping: inputs.contact.damping,
            law: inputs.contact.law.law(),
        }],
        initial_tip_displacements: vec![inputs.release.tip_displacement],
        initial_tip_velocities: vec![inputs.release.tip_velocity],
        base_acceleration: None,
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    }
}

/// The results document of `cantilever-impact`.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct CantileverResults {
    pub model: CantileverModel,
    pub numerical: NumericalResults,
    pub basis: BasisReport,
    pub reference: ReferenceResults,
    pub comparison: Comparison,
    pub quality: QualityReport,
}

/// The beam and contact as run.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct CantileverModel {
    /// Contact stiffness Kc (N/m).
    pub contact_stiffness: f64,
    /// Kc L³ / 3EI (dimensionless).
    pub rk: f64,
    /// Mass per unit length (kg/m), added mass included.
    pub mass_per_length: f64,
    /// EI (N·m²).
    pub bending_stiffness: f64,
}

/// The numerical (modal, penalty contact) solution.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct NumericalResults {
    /// Time of the first closure (s), interpolated between steps; null if none.
    pub first_impact_time: Option<f64>,
    /// Impacts, as `output.impacts` counts them (default: closures after a separation,
    /// the reference's count).
    pub impacts: u64,
    /// The contact's impact statistics and peak-force histogram.
    pub impact_statistics: ContactImpacts,
    /// The counting used, the histogram's classes and the ranking (of one contact).
    pub impact_summary: ImpactSummary,
    /// Largest contact force over every step (N).
    pub max_contact_force: f64,
    /// The force the contact may carry (N): `output.allowables.contact_force` or the
    /// law's `allowable_force`; null without one.
    pub allowable_force: Option<f64>,
    /// `max_contact_force` over `allowable_force` (dimensionless; ≥ 1: reached); null
    /// without one.
    pub utilisation: Option<f64>,
    /// The largest bending stress (`max_bending`) over `output.allowables.stress`, where
    /// and when; null without it.
    pub max_stress_utilisation: Option<StressUtilisation>,
    /// The worse of `utilisation` and `max_stress_utilisation` (dimensionless); null
    /// without allowables.
    pub worst_utilisation: Option<f64>,
    /// Its time (s).
    pub max_contact_force_time: f64,
    /// Total time in contact (s).
    pub contact_time: f64,
    /// ∫ F dt (N·s).
    pub impulse: f64,
    /// Lowest tip deflection (m): −gap − largest penetration.
    pub min_tip_displacement: f64,
    /// Step used (s).
    pub time_step: f64,
    /// Critical step with the contact closed (s); null under `exact_modal`, which has no
    /// stability limit.
    pub critical_time_step: Option<f64>,
    /// Steps taken.
    pub steps: u64,
    /// Time between two history samples (s).
    pub output_interval: f64,
    /// Frequencies of the basis (Hz), eigenmodes then pseudo-modes.
    pub frequencies_hz: Vec<f64>,
    pub energy: EnergyReport,
    #[serde(flatten)]
    pub bending: BendingReport,
}

/// The semi-analytic reference (exact up to modal truncation, no contact dashpot).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ReferenceResults {
    /// Time of the first impact (s); null if none.
    pub first_impact_time: Option<f64>,
    /// Impacts.
    pub impacts: usize,
    /// Largest contact force (N).
    pub max_contact_force: f64,
    /// Its time (s).
    pub max_contact_force_time: f64,
    /// Lowest tip deflection (m).
    pub min_tip_displacement: f64,
    /// Every impact and release, in time order.
    pub events: Vec<ReferenceEvent>,
    /// Free (clamped-free) frequencies (Hz).
    pub free_frequencies_hz: Vec<f64>,
    /// In-contact (clamped-spring) frequencies (Hz).
    pub contact_frequencies_hz: Vec<f64>,
    /// Damping ratios of the in-contact modes.
    pub contact_damping_ratios: Vec<f64>,
    /// Modes per analytic basis.
    pub modes: usize,
    /// What the reference leaves out of the numerical model, if anything.
    pub notes: Vec<String>,
}

/// A change of contact state of the reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct ReferenceEvent {
    /// When (s).
    pub time: f64,
    pub kind: ReferenceEventKind,
}

/// `impact` (the contact closes) or `release` (it opens).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceEventKind {
    Impact,
    Release,
}

/// The numerical tip deflection against the reference's (paper eq. 11).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct Comparison {
    /// Spectral error function f_err of the tip deflections.
    pub f_err: f64,
    /// The paper's threshold (0.2).
    pub threshold: f64,
    /// f_err below the threshold.
    pub agrees: bool,
}

/// Checks the contact block; the contact stiffness it gives.
fn contact_stiffness(contact: &ContactInput, tip_stiffness: f64, errors: &mut Vec<FieldError>) -> f64 {
    let mut issues = Vec::new();
    let stiffness = match (contact.rk, contact.stiffness) {
        (Some(_), Some(_)) => {
            issues.push(InputIssue::new(
                "stiffness",
                "give exactly one of `rk` and `stiffness`",
            ));
            0.0
        }
        (rk, None) => {
            let rk = rk.unwrap_or(1.0);
            crate::physics::require_non_negative(&mut issues, "rk", rk);
            if contact.law.exponent.is_some_and(|n| n != 1.0) {
                issues.push(InputIssue::new(
                    "stiffness",
                    "a power law (law.exponent ≠ 1) takes its `stiffness` K in N/mⁿ, not `rk`",
                ));
            }
            rk * tip_stiffness
        }
        (None, Some(stiffness)) => stiffness,
    };
    errors.extend(at("/inputs/contact", issues));
    contact.law.check("/inputs/contact/law", errors);
    contact.law.refuse_wear_in_a_row("/inputs/contact/law", errors);
    stiffness
}

/// Where the user wrote what a path of the one-contact model or its settings names: the
/// contact's values in `contact` (a stiffness derived from `rk` is refused at `rk`, or
/// not at all when the beam it scales is refused), its height and the recorded height at
/// the tip (`beam/length`), the release in `release`, the tip-load shape it needs in
/// `beam/supports`.
fn pointer_of(inputs: &CantileverInputs, path: &str, beam_refused: bool) -> Option<String> {
    let pointer = match model_check::split(path) {
        ("contacts", Some(_), "stiffness") if inputs.contact.stiffness.is_some() => {
            "/inputs/contact/stiffness"
        }
        ("contacts", Some(_), "stiffness") if beam_refused => return None,
        ("contacts", Some(_), "stiffness") => "/inputs/contact/rk",
        ("contacts", Some(_), "gap") => "/inputs/contact/gap",
        ("contacts", Some(_), "damping") => "/inputs/contact/damping",
        ("contacts", Some(_), rest) if rest == "law" || rest.starts_with("law/") => {
            return Some(format!("/inputs/contact/{rest}"));
        }
        ("contacts", Some(_), "height") | ("output_heights", _, _) => "/inputs/beam/length",
        ("contacts", _, _) => "/inputs/contact",
        ("initial_tip_displacements", Some(_), "") => "/inputs/release/tip_displacement",
        ("initial_tip_displacements", None, "") => "/inputs/beam/supports",
        ("initial_tip_velocities", Some(_), "") => "/inputs/release/tip_velocity",
        ("initial_tip_velocities", None, "") => "/inputs/beam/supports",
        ("damping_ratios", mode, _) => {
            return Some(model_check::damping_ratio_pointer(
                &inputs.beam,
                "/inputs/beam",
                mode,
            ));
        }
        _ => return Some(model_check::settings_pointer(path).unwrap_or_else(|| "/inputs".to_owned())),
    };
    Some(pointer.to_owned())
}

/// The reference's own limit: it scans at 1/16 of its shortest period, and its highest
/// root is below (n + ½)π. Too many samples are the duration's fault when even one
/// mode would scan too many, the modes' otherwise.
fn check_reference_scan(reference: &CantileverReference, errors: &mut Vec<FieldError>) {
    use crate::physics::number;
    use crate::physics::reference::MAX_SCAN_SAMPLES;
    let scan_samples = |modes: usize| {
        let lambda = (modes as f64 + 0.5) * std::f64::consts::PI;
        let omega = lambda * lambda * (reference.bending_stiffness() / reference.mass_per_length()).sqrt()
            / reference.length.powi(2);
        reference.duration * 16.0 * omega / std::f64::consts::TAU
    };
    let samples = scan_samples(reference.modes);
    if samples > MAX_SCAN_SAMPLES || samples.is_nan() {
        let (field, advice) = if scan_samples(1) <= MAX_SCAN_SAMPLES {
            ("/inputs/reference/modes", "use fewer modes or a shorter duration")
        } else {
            ("/inputs/solver/duration", "use a shorter duration")
        };
        errors.push(FieldError::new(
            field,
            format!(
                "the reference would scan {} samples over the duration, above its limit of {}: {advice}",
                number(samples),
                number(MAX_SCAN_SAMPLES)
            ),
        ));
    }
}

/// The `cantilever-impact` process.
#[derive(Debug, Default)]
pub struct CantileverImpact;

const HISTORY: &str = "CSV columns time (s), numerical, reference";
const PEAKS: &str = "per output interval, the extreme over every step of the interval (largest magnitude, \
                     signed); CSV columns time (s), numerical, reference (the reference sampled at the \
                     integrator's step)";

impl Simulation for CantileverImpact {
    const ID: &'static str = "cantilever-impact";
    const TITLE: &'static str = "Cantilever impacting a spring: numerical scheme vs semi-analytic reference";
    const DESCRIPTION: &'static str = "Releases a cantilever from its static tip-load shape against a tip spring, integrates it on a \
         truncated modal basis with a penalty contact (central difference or Tchamwa-Wielgosz), solves the \
         same problem semi-analytically (exact up to modal truncation), and compares the tip-deflection \
         spectra with f_err (validity threshold 0.2).";
    const EXAMPLES: &'static [Example] = &[Example {
        file: "cantilever-impact.json",
        body: include_str!("../../../examples/cantilever-impact.json"),
    }];
    const HISTORIES: &'static [HistoryOutput] = &[
        HistoryOutput {
            name: "tip_displacement",
            kind: HistoryKind::Displacement,
            title: "Tip deflection (m)",
            description: HISTORY,
        },
        HistoryOutput {
            name: "contact_force",
            kind: HistoryKind::Force,
            title: "Contact force (N)",
            description: HISTORY,
        },
        HistoryOutput {
            name: "tip_displacement_peaks",
            kind: HistoryKind::Peaks,
            title: "Tip deflection (m), peaks",
            description: PEAKS,
        },
        HistoryOutput {
            name: "contact_force_peaks",
            kind: HistoryKind::Peaks,
            title: "Contact force (N), peaks",
            description: PEAKS,
        },
        impact_report::TABLE_OUTPUT,
    ];

    type Inputs = CantileverInputs;
    type Results = CantileverResults;
    type Plan = Plan;

    /// `numerical` and `reference`: the tip deflection (m) or the contact force (N) of
    /// each solution.
    fn column(output: &str, name: &str, _document: &serde_json::Value) -> Option<Column> {
        let solution = match name {
            "numerical" => "the numerical (modal) scheme",
            "reference" => "the semi-analytic reference",
            _ => return None,
        };
        let (unit, what) = match output.trim_end_matches("_peaks") {
            "tip_displacement" => ("m", "tip deflection w(L), positive away from the spring"),
            "contact_force" => ("N", "tip contact force"),
            _ => return None,
        };
        Some(Column::new(
            name,
            unit,
            columns::of_output(output, format!("{what}, {solution}")),
        ))
    }

    /// One contact (the tip spring) and one beam: the run's figures are under
    /// `numerical`, checked against the reference's.
    fn note(document: &serde_json::Value) -> NoteFacts {
        note(document)
    }

    fn prepare(inputs: CantileverInputs) -> Result<Plan, InvalidInputs> {
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
        let contact_stiffness = contact_stiffness(&inputs.contact, tip_stiffness, &mut errors);
        let solver = common_inputs::solver(&inputs.solver, SOLVER_DEFAULTS, &mut errors);
        common_inputs::check_output_interval(inputs.output.interval, &mut errors);
        let law_allowable = (inputs.contact.law.allowable_force.is_some()).then_some("/inputs/contact/law");
        let fibre = Flexure::fibre(&inputs.beam, None).is_some();
        (inputs.output.allowables).check("/inputs/output/allowables", fibre, law_allowable, &mut errors);
        let mut settings = solver.integration(inputs.output.interval, vec![spec.length]);
        settings.impacts = impact_report::counting(inputs.output.impacts.as_ref(), inputs.output.blocks);
        let stand_in = StandIn::of(&inputs.beam);
        let beam_refused = errors.iter().any(|e| e.pointer.starts_with("/inputs/beam"));
        model_check::check(
            &stand_in,
            &tip_model(&inputs, &stand_in.basis, contact_stiffness),
            &settings,
            |path| pointer_of(&inputs, path, beam_refused),
            &mut errors,
        );
        if !(1..=MAX_MODES).contains(&inputs.reference.modes) {
            errors.push(FieldError::new(
                "/inputs/reference/modes",
                format!("must be between 1 and {MAX_MODES}"),
            ));
        }
        if !errors.is_empty() {
            return Err(InvalidInputs(errors));
        }

        // The contact is at the tip: the static correction, if any, is the tip-load shape.
        let tip = tip_model(&inputs, &stand_in.basis, contact_stiffness).contacts;
        let (basis, basis_choice) =
            inputs
                .beam
                .basis(&tip, &[spec.length], solver.tolerance, 0, "/inputs/beam")?;
        let reference = CantileverReference {
            length: spec.length,
            young_modulus: spec.young_modulus,
            density: spec.density,
            area: spec.section.area(),
            inertia: spec.section.inertia(),
            added_mass_per_length: spec.added_mass_per_length,
            contact_stiffness,
            gap: inputs.contact.gap,
            damping_ratios: inputs.beam.damping_ratios_for(basis.eigenmodes()),
            tip_displacement: inputs.release.tip_displacement,
            tip_velocity: inputs.release.tip_velocity,
            duration: solver.duration,
            modes: inputs.reference.modes,
            max_events: 100_000,
        };
        check_reference_scan(&reference, &mut errors);
        if !errors.is_empty() {
            return Err(InvalidInputs(errors));
        }
        let step = common_inputs::resolve_step(&tip_model(&inputs, &basis, contact_stiffness), &settings)?;
        Ok(Plan {
            inputs,
            basis,
            basis_choice,
            contact_stiffness,
            settings,
            reference,
            step,
        })
    }

    /// One pin of `modes` modes and one contact per step; four histories of three
    /// columns (time, numerical, reference).
    fn estimate(plan: &Plan) -> WorkEstimate {
        let (stepping, samples) = common_inputs::stepping(&plan.settings, &plan.step);
        let stepping = common_inputs::with_auto_note(stepping, plan.basis_choice.as_ref(), "beam");
        let mut history_drivers = vec![
            "/inputs/solver/duration".to_owned(),
            "/inputs/output/interval".to_owned(),
        ];
        if plan.settings.output_interval.is_none() {
            history_drivers.push("/inputs/solver/time_step".to_owned());
        }
        history_drivers.push("/inputs/output/impacts/max_rows".to_owned());
        WorkEstimate {
            modal_dofs: plan.basis.modes() as f64,
            contacts: 1.0,
            history_values: samples * 12.0
                + impact_report::table_values(&plan.settings.impacts, 1, stepping.pass_steps),
            work_drivers: [
                "/inputs/solver/duration",
                "/inputs/solver/time_step",
                "/inputs/beam/modes",
            ]
            .map(str::to_owned)
            .to_vec(),
            history_drivers,
            ..stepping
        }
    }

    /// The beam, released at the tip toward its one contact.
    fn subject(plan: &Plan) -> Subject<'_> {
        Subject {
            switch: plan.inputs.warnings,
            pin: &plan.inputs.beam,
            pin_pointer: "/inputs/beam",
            diameter: None,
            model: plan.model(),
            duration: plan.settings.duration,
            scheme: plan.settings.scheme,
            gap_pointer: Box::new(|_| "/inputs/contact/gap".to_owned()),
            excitation_pointer: "/inputs/release/tip_displacement",
        }
    }

    fn run(plan: Plan, progress: &mut ProgressFn<'_>) -> Result<Output<CantileverResults>, RunError> {
        let model = plan.model();
        let mut numerical_progress = |fraction: f64| progress(0.9 * fraction);
        let assessed =
            integrate::Plan::with_step(&model, &plan.settings, plan.step)?.run(&mut numerical_progress)?;
        let (simulation, quality) = (assessed.simulation, assessed.quality);
        let solution = plan
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
        let every = plan.step.output_every(plan.settings.output_interval);
        let reference_peaks = reference_peaks(&solution, time.len(), interval, every)
            .map_err(|e| RunError::Failed(format!("reference sampling: {e}")))?;
        let numerical_tip = simulation.deflections[0][0].clone();
        let f_err = spectral_error(&numerical_tip, &sampled.tip_deflection)
            .map_err(|e| RunError::Failed(format!("f_err: {e}")))?;

        let stats = &simulation.contact_statistics[0];
        let contact = &plan.inputs.contact;
        let max_force = solution.max_contact_force();
        let mut notes = Vec::new();
        if contact.damping > 0.0 {
            notes.push(format!(
                "the reference has no contact dashpot: contact.damping = {} N·s/m acts on the numerical model only",
                contact.damping
            ));
        }
        let law = &contact.law;
        if law.exponent.is_some_and(|n| n != 1.0)
            || law.hunt_crossley.is_some_and(|a| a > 0.0)
            || law.restitution.is_some()
            || law.friction.is_some()
        {
            notes.push(
                "the reference has the linear spring without damping: contact.law acts on the numerical model only"
                    .to_owned(),
            );
        }
        let spec = plan.inputs.beam.spec();
        let given = &plan.inputs.output.allowables;
        let allowable_force = contact.law.allowable().or(given.contact_force);
        let utilisation = margins::ratio(stats.max_force, allowable_force);
        let bending = BendingReport::of(
            &simulation,
            &Flexures::uniform(Flexure::of(&plan.inputs.beam, None)),
        );
        let max_stress_utilisation = StressUtilisation::of(&bending.max_bending, given.stress);
        let results = CantileverResults {
            model: CantileverModel {
                contact_stiffness: plan.contact_stiffness,
                rk: plan.contact_stiffness * spec.length.powi(3) / (3.0 * spec.bending_stiffness()),
                mass_per_length: spec.mass_per_length(),
                bending_stiffness: spec.bending_stiffness(),
            },
            numerical: NumericalResults {
                first_impact_time: stats.first_impact_time,
                impacts: stats.impacts,
                impact_statistics: impact_report::contact_reports(&simulation).remove(0),
                impact_summary: impact_report::summary(&simulation, &plan.settings.impacts),
                max_contact_force: stats.max_force,
                allowable_force,
                utilisation,
                max_stress_utilisation,
                worst_utilisation: margins::largest([
                    utilisation,
                    max_stress_utilisation.map(|s| s.utilisation),
                ]),
                max_contact_force_time: stats.max_force_time,
                contact_time: stats.contact_time,
                impulse: stats.impulse,
                min_tip_displacement: -contact.gap - stats.max_penetration,
                time_step: simulation.step.time_step,
                critical_time_step: crate::physics::finite(simulation.step.critical_time_step),
                steps: simulation.steps,
                output_interval: simulation.output_interval,
                frequencies_hz: plan.basis.frequencies_hz(),
                energy: simulation.energy.into(),
                bending,
            },
            basis: BasisReport::of(
                &model,
                plan.settings.scheme,
                simulation.step.critical_time_step,
                (&plan.inputs.beam, plan.basis_choice.as_ref()),
            ),
            reference: ReferenceResults {
                first_impact_time: solution.first_impact_time(),
                impacts: solution.impact_count(),
                max_contact_force: max_force.value,
                max_contact_force_time: max_force.time,
                min_tip_displacement: solution.min_tip_deflection().value,
                events: solution
                    .events()
                    .iter()
                    .map(|e| ReferenceEvent {
                        time: e.time,
                        kind: match e.kind {
                            ContactEventKind::Impact => ReferenceEventKind::Impact,
                            ContactEventKind::Release => ReferenceEventKind::Release,
                        },
                    })
                    .collect(),
                free_frequencies_hz: solution.free_frequencies_hz().to_vec(),
                contact_frequencies_hz: solution.contact_frequencies_hz().to_vec(),
                contact_damping_ratios: solution.contact_damping_ratios().to_vec(),
                modes: plan.reference.modes,
                notes,
            },
            comparison: Comparison {
                f_err,
                threshold: AGREEMENT_THRESHOLD,
                agrees: f_err < AGREEMENT_THRESHOLD,
            },
            quality,
        };
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
            impact_report::table_history(&simulation.impact_table),
        ];
        Ok(Output { results, histories })
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

/// The note of a cantilever run: its peaks (the contact force and the tip deflection,
/// each beside the reference's), the agreement of the two, its one contact.
fn note(document: &serde_json::Value) -> NoteFacts {
    use super::note_facts::{
        ContactRow, Figure, Unit, bending_peaks, envelope, fact, margin_facts, solution,
    };
    // The envelope's last node is the tip.
    let tip = document
        .pointer("/numerical/bending_envelope")
        .and_then(serde_json::Value::as_array)
        .and_then(|nodes| nodes.last()?["height"].as_f64())
        .map_or_else(
            || "the tip".to_owned(),
            |l| format!("the tip, {}", columns::metres(l)),
        );
    let tip_contact = format!("tip spring at {tip}");
    let mut peaks: Vec<Fact> = [
        (
            "largest contact force",
            "/numerical/max_contact_force",
            Unit::Newton,
            Some("/numerical/max_contact_force_time"),
        ),
        (
            "largest contact force, reference",
            "/reference/max_contact_force",
            Unit::Newton,
            Some("/reference/max_contact_force_time"),
        ),
        (
            "lowest tip deflection",
            "/numerical/min_tip_displacement",
            Unit::Deflection,
            None,
        ),
        (
            "lowest tip deflection, reference",
            "/reference/min_tip_displacement",
            Unit::Deflection,
            None,
        ),
    ]
    .into_iter()
    .filter_map(|(quantity, pointer, unit, time)| fact(document, quantity, pointer, unit, time, tip.clone()))
    .collect();
    peaks.extend(bending_peaks(document, "/numerical/max_bending", false));
    let checks = [
        (
            "f_err, numerical against reference tip spectra",
            "/comparison/f_err",
        ),
        ("f_err threshold", "/comparison/threshold"),
        ("impacts", "/numerical/impacts"),
        ("impacts, reference", "/reference/impacts"),
    ]
    .into_iter()
    .filter_map(|(quantity, pointer)| {
        fact(
            document,
            quantity,
            pointer,
            Unit::Dimensionless,
            None,
            String::new(),
        )
    })
    .collect();
    // The one contact, from the members `numerical` has for it.
    let at = |member: &str, unit| Figure::at(document, format!("/numerical/{member}"), unit);
    let contacts = at("max_contact_force", Unit::Newton)
        .map(|max_force| ContactRow {
            contact: 0,
            label: tip_contact.clone(),
            max_force,
            max_force_time: at("max_contact_force_time", Unit::Second),
            impacts: at("impacts", Unit::Count),
            impulse: at("impulse", Unit::NewtonSecond),
            allowable_force: at("allowable_force", Unit::Newton),
            utilisation: at("utilisation", Unit::Dimensionless),
        })
        .into_iter()
        .collect();
    let peak = Figure::at(document, "/numerical/max_contact_force_time", Unit::Second).zip(Figure::at(
        document,
        "/numerical/max_contact_force",
        Unit::Newton,
    ));
    NoteFacts {
        peaks,
        margins: margin_facts(document, "/numerical", &|_| tip_contact.clone()),
        checks,
        solution: solution(document, "/numerical"),
        contacts,
        pins: Vec::new(),
        envelope: envelope(document, "/numerical/bending_envelope"),
        plots: vec![
            PlotRequest {
                title: "Tip contact force, numerical and reference: the extreme of each output interval"
                    .into(),
                output: "contact_force_peaks".into(),
                series: vec!["numerical".into(), "reference".into()],
                unit: Unit::Newton,
                peak,
            },
            PlotRequest {
                title: "Tip deflection, numerical and reference".into(),
                output: "tip_displacement".into(),
                series: vec!["numerical".into(), "reference".into()],
                unit: Unit::Deflection,
                peak: None,
            },
        ],
    }
}

#[cfg(test)]
mod tests;
