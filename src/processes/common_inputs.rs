//! Input pieces shared by the processes: the beam/pin description, the solver block,
//! parsing with JSON-pointer errors, and self-contained JSON schemas for process
//! descriptions.
//!
//! Parsing is strict: unknown fields are refused (a typo must not silently fall back
//! to a default), and every serde failure is reported at the pointer where it happened.

use serde::Deserialize;
use serde::de::DeserializeOwned;
use utoipa::ToSchema;

use super::{FieldError, InvalidInputs};
use crate::physics::InputIssue;
use crate::physics::beam::{BeamSpec, Section, Support};
use crate::physics::contact::Contact;
use crate::physics::discretisation::auto::{self, Count};
use crate::physics::integrate::quality::PEAK_TOLERANCE_FACTOR;
use crate::physics::integrate::{Check, DEFAULT_TOLERANCE, Settings, TimeStep};
use crate::physics::stability::Scheme;

// The bounds of `length`, `young_modulus`, `density` and of the section's sizes are
// `physics::beam::PLAUSIBLE_RANGES`: far outside any structure, and inside them the modal
// analysis stays within the range of doubles (`tests/schema_contract` holds them equal).
/// A uniform, slender Euler–Bernoulli beam (one fuel pin) and its modal truncation.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct BeamInput {
    /// Length L (m), from the foot (x = 0) to the top (x = L).
    #[schema(minimum = 1e-6, maximum = 1e5)]
    pub length: f64,
    /// Young's modulus E (Pa).
    #[schema(minimum = 1.0, maximum = 1e15)]
    pub young_modulus: f64,
    /// Density ρ of the material (kg/m³).
    #[schema(minimum = 1e-3, maximum = 1e9)]
    pub density: f64,
    /// Cross-section: a circular tube, or its area and second moment of area.
    pub section: SectionInput,
    /// Added mass per unit length (kg/m): fuel column, surrounding fluid.
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0, maximum = 1e9)]
    pub added_mass_per_length: f64,
    /// Number of Hermite beam elements along the length (count, 1 to 400), or `"auto"`:
    /// the coarsest mesh, doubling from 40 up to 200, whose impact probes put the peak
    /// contact force within 10 × `solver.tolerance` (docs/accuracy.md, "`auto` mesh and
    /// basis").
    #[serde(default = "default_elements")]
    #[schema(value_type = super::input_schema::ElementsInput, default = 40)]
    pub elements: CountInput,
    /// Number of modes kept in the modal basis (count): at most the free degrees of
    /// freedom of the mesh (two per node, less those the supports hold: 2 × `elements`
    /// for a clamped foot and a free top); or `"auto"`: the fewest modes whose impact
    /// probes put the peak contact force within 10 × `solver.tolerance`.
    #[serde(default = "default_modes")]
    #[schema(value_type = super::input_schema::ModesInput, default = 10)]
    pub modes: CountInput,
    /// Modal damping ratio ξ (dimensionless, in [0, 1)): one value for every mode, or
    /// one per mode (a shorter list repeats its last value; pseudo-modes take the last).
    #[serde(default = "default_damping")]
    #[schema(default = 0.01)]
    pub damping_ratio: DampingInput,
    /// Boundary conditions at the two ends.
    #[serde(default)]
    #[schema(default = json!({"foot": "clamped", "top": "free"}))]
    pub supports: SupportsInput,
    /// Static correction of the truncated basis: `contacts` adds one pseudo-mode per
    /// distinct contact height (the static response to a unit force there,
    /// M-orthonormalised against the modes), `none` keeps the modes alone
    /// (docs/static-correction.md).
    #[serde(default)]
    #[schema(default = "contacts")]
    pub static_correction: StaticCorrectionInput,
    /// Shear deformation and rotary inertia: a Timoshenko beam (stubby spans, tubes on
    /// close supports), with the interdependent interpolation element; absent, the beam
    /// is Euler–Bernoulli.
    #[serde(default)]
    pub timoshenko: Option<TimoshenkoInput>,
}

/// What a Timoshenko beam needs beyond Euler–Bernoulli: G = E / 2(1 + ν) and the shear
/// coefficient κ of its section.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TimoshenkoInput {
    /// Poisson's ratio ν (dimensionless, between −1 and 0.5).
    #[serde(default = "default_poisson_ratio")]
    #[schema(default = 0.3, exclusive_minimum = -1.0, exclusive_maximum = 0.5)]
    pub poisson_ratio: f64,
    /// Shear coefficient κ (dimensionless, in (0, 1]); default for a tube, Cowper's
    /// 6(1 + ν)(1 + m²)² / ((7 + 6ν)(1 + m²)² + (20 + 12ν)m²), m = inner / outer diameter
    /// (0.886 for a solid rod at ν = 0.3, 0.53 for a thin tube); required for an
    /// explicit section.
    #[schema(exclusive_minimum = 0.0, maximum = 1.0)]
    pub shear_coefficient: Option<f64>,
}

fn default_poisson_ratio() -> f64 {
    0.3
}

/// Static correction of the modal basis: `none` or `contacts`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum StaticCorrectionInput {
    /// The eigenmodes only.
    None,
    /// One pseudo-mode per distinct contact height: the residual flexibility of the
    /// dropped modes at the contacts. Its frequency is above the last mode's, and the
    /// critical step accounts for it. Pseudo-modes take the damping ratio rule of the
    /// modes (a uniform ratio applies to them; a list's last value repeats).
    #[default]
    Contacts,
}

/// A count (of elements, of modes) given as a number, or `"auto"` (its schemas:
/// [`super::input_schema`]).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a count or \"auto\"")]
pub enum CountInput {
    Given(usize),
    Keyword(AutoKeyword),
}

impl CountInput {
    /// The count of the physics' choice.
    pub fn count(self) -> Count {
        match self {
            CountInput::Given(n) => Count::Given(n),
            CountInput::Keyword(AutoKeyword::Auto) => Count::Auto,
        }
    }

    /// The number given, `None` for `auto`.
    pub fn given(self) -> Option<usize> {
        match self {
            CountInput::Given(n) => Some(n),
            CountInput::Keyword(_) => None,
        }
    }

    /// `given` or `auto`, as the results say it.
    pub fn rule(self) -> &'static str {
        match self {
            CountInput::Given(_) => "given",
            CountInput::Keyword(_) => "auto",
        }
    }
}

fn default_elements() -> CountInput {
    CountInput::Given(40)
}
fn default_modes() -> CountInput {
    CountInput::Given(10)
}
fn default_damping() -> DampingInput {
    DampingInput::Uniform(0.01)
}

/// Cross-section: `tube` (diameters) or `explicit` (area and second moment of area).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SectionInput {
    /// Circular tube.
    Tube {
        /// Outer diameter (m); a hexagonal bundle's clad diameter D.
        #[schema(minimum = 1e-7, maximum = 1e3)]
        outer_diameter: f64,
        /// Inner diameter (m), smaller than the outer one; 0 for a solid rod.
        #[schema(minimum = 0.0)]
        inner_diameter: f64,
    },
    /// Any section, by its area and second moment of area.
    Explicit {
        /// Area A (m²).
        #[schema(minimum = 1e-15, maximum = 1e6)]
        area: f64,
        /// Second moment of area I about the bending axis (m⁴).
        #[schema(minimum = 1e-30, maximum = 1e12)]
        inertia: f64,
    },
}

/// Modal damping ratio: a number for every mode, or a list, one per mode (its schema:
/// [`super::input_schema`]).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a damping ratio or a list of damping ratios")]
pub enum DampingInput {
    Uniform(f64),
    PerMode(Vec<f64>),
}

/// Boundary condition at one end: `free`, `pinned` (deflection held) or `clamped`
/// (deflection and rotation held).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SupportInput {
    Free,
    Pinned,
    Clamped,
}

/// Supports at the foot (x = 0) and the top (x = L): together they must prevent
/// rigid-body motion (clamp one end, or pin both).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SupportsInput {
    /// Support at the foot (x = 0).
    #[serde(default = "clamped")]
    #[schema(default = "clamped")]
    pub foot: SupportInput,
    /// Support at the top (x = L).
    #[serde(default = "free")]
    #[schema(default = "free")]
    pub top: SupportInput,
}

impl Default for SupportsInput {
    fn default() -> Self {
        Self {
            foot: SupportInput::Clamped,
            top: SupportInput::Free,
        }
    }
}
fn clamped() -> SupportInput {
    SupportInput::Clamped
}
fn free() -> SupportInput {
    SupportInput::Free
}

impl SupportInput {
    /// The input keyword.
    pub fn name(self) -> &'static str {
        match self {
            SupportInput::Free => "free",
            SupportInput::Pinned => "pinned",
            SupportInput::Clamped => "clamped",
        }
    }
}

impl From<SupportInput> for Support {
    fn from(value: SupportInput) -> Self {
        match value {
            SupportInput::Free => Support::Free,
            SupportInput::Pinned => Support::Pinned,
            SupportInput::Clamped => Support::Clamped,
        }
    }
}

impl BeamInput {
    pub fn spec(&self) -> BeamSpec {
        BeamSpec {
            length: self.length,
            young_modulus: self.young_modulus,
            density: self.density,
            section: match self.section {
                SectionInput::Tube {
                    outer_diameter,
                    inner_diameter,
                } => Section::Tube {
                    outer_diameter,
                    inner_diameter,
                },
                SectionInput::Explicit { area, inertia } => Section::Explicit { area, inertia },
            },
            added_mass_per_length: self.added_mass_per_length,
            elements: self.elements.given().unwrap_or(auto::START_ELEMENTS),
            foot: self.supports.foot.into(),
            top: self.supports.top.into(),
            shear: self.timoshenko.map(|t| crate::physics::beam::Shear {
                coefficient: t.shear_coefficient.unwrap_or(match self.section {
                    SectionInput::Tube {
                        outer_diameter,
                        inner_diameter,
                    } => crate::physics::beam::tube_shear_coefficient(
                        outer_diameter,
                        inner_diameter,
                        t.poisson_ratio,
                    ),
                    // Refused in `validate` (`timoshenko/shear_coefficient` is required).
                    SectionInput::Explicit { .. } => 1.0,
                }),
                poisson_ratio: t.poisson_ratio,
            }),
        }
    }

    /// Damping ratio of each of the `basis_modes` entries of the basis actually used
    /// (eigenmodes, then pseudo-modes): a uniform ratio everywhere; a list one per mode
    /// in order, its last value repeated past its end.
    pub fn damping_ratios_for(&self, basis_modes: usize) -> Vec<f64> {
        match &self.damping_ratio {
            DampingInput::Uniform(xi) => vec![*xi; basis_modes],
            DampingInput::PerMode(list) => {
                let last = list.last().copied().unwrap_or(0.0);
                (0..basis_modes)
                    .map(|i| list.get(i).copied().unwrap_or(last))
                    .collect()
            }
        }
    }

    /// The modal basis of this beam for `contacts` (the model's, on pins of this beam),
    /// with its static correction at `correction_heights` (m) when asked; `elements` and
    /// `modes` chosen by [`auto::choose`] where they are `auto`, for the verdict's bound
    /// 10 × `tolerance`, from `min_elements` at least (the coarsest mesh the model
    /// admits). A failure is a 422 under `pointer` (the beam's own pointer). The choice
    /// is `None` when both counts are given.
    pub fn basis(
        &self,
        contacts: &[Contact],
        correction_heights: &[f64],
        tolerance: f64,
        min_elements: usize,
        pointer: &str,
    ) -> Result<(crate::physics::modal::ModalBasis, Option<auto::Choice>), InvalidInputs> {
        use crate::physics::modal::ModalError;
        let spec = self.spec();
        let correction = self.static_correction == StaticCorrectionInput::Contacts;
        let modal_error = |e: ModalError| {
            let field = match e {
                ModalError::StaticCorrection(_) => format!("{pointer}/supports"),
                _ => format!("{pointer}/modes"),
            };
            let detail = match e {
                ModalError::StaticCorrection(_) => format!(
                    "{e}; supports: foot {}, top {}",
                    self.supports.foot.name(),
                    self.supports.top.name()
                ),
                _ => e.to_string(),
            };
            InvalidInputs(vec![FieldError::new(field, detail)])
        };
        let automatic = self.elements.given().is_none() || self.modes.given().is_none();
        let choice = if automatic {
            let request = auto::Request {
                elements: self.elements.count(),
                min_elements,
                modes: self.modes.count(),
                static_correction: correction,
                target: PEAK_TOLERANCE_FACTOR * tolerance,
            };
            let probes = auto::design_contacts(contacts, spec.length);
            Some(
                auto::choose(&spec, &request, &probes, correction_heights).map_err(|e| match e {
                    auto::AutoError::Modal(e) => modal_error(e),
                    mesh @ auto::AutoError::Mesh { .. } => InvalidInputs(vec![FieldError::new(
                        format!("{pointer}/elements"),
                        format!(
                            "auto: {mesh}; raise solver.tolerance (the bound is 10 × it) or give \
                             elements and modes (the verdict then judges them)"
                        ),
                    )]),
                })?,
            )
        } else {
            None
        };
        let (elements, modes) = match choice {
            Some(c) => (c.elements, c.modes),
            None => (spec.elements, self.modes.given().unwrap_or(0)),
        };
        let spec = crate::physics::beam::BeamSpec { elements, ..spec };
        let basis =
            auto::basis_of(&spec, modes, correction.then_some(correction_heights)).map_err(modal_error)?;
        Ok((basis, choice))
    }

    /// Every problem with the beam and its truncation, as physics issues relative to it.
    pub fn validate(&self) -> Vec<InputIssue> {
        let spec = self.spec();
        let mut issues: Vec<InputIssue> = spec
            .validate()
            .into_iter()
            .map(|issue| match issue.field.as_str() {
                "shear/coefficient" => InputIssue::new("timoshenko/shear_coefficient", issue.reason),
                "shear/poisson_ratio" => InputIssue::new("timoshenko/poisson_ratio", issue.reason),
                _ => issue,
            })
            .collect();
        if let (Some(t), SectionInput::Explicit { .. }) = (self.timoshenko, self.section)
            && t.shear_coefficient.is_none()
        {
            issues.push(InputIssue::new(
                "timoshenko/shear_coefficient",
                "is required with an explicit section (its shape sets κ: 0.886 for a solid rod, 0.53 for a thin \
                 tube)",
            ));
        }
        if let CountInput::Given(modes) = self.modes
            && spec.elements >= 1
            && (modes == 0 || modes > spec.free_dof_count())
        {
            issues.push(InputIssue::new(
                "modes",
                format!(
                    "must be between 1 and {} (the free DOFs of {} elements)",
                    spec.free_dof_count(),
                    spec.elements
                ),
            ));
        }
        let ratios: Vec<(String, f64)> = match &self.damping_ratio {
            DampingInput::Uniform(xi) => vec![("damping_ratio".into(), *xi)],
            DampingInput::PerMode(list) if list.is_empty() => {
                issues.push(InputIssue::new("damping_ratio", "must not be an empty list"));
                vec![]
            }
            DampingInput::PerMode(list) => list
                .iter()
                .enumerate()
                .map(|(i, xi)| (format!("damping_ratio/{i}"), *xi))
                .collect(),
        };
        for (field, xi) in ratios {
            if !(xi.is_finite() && (0.0..1.0).contains(&xi)) {
                issues.push(InputIssue::new(
                    field,
                    format!("must be in [0, 1) (got {})", crate::physics::number(xi)),
                ));
            }
        }
        issues
    }
}

/// Integration scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SchemeInput {
    /// Central difference (explicit, second order, no numerical damping).
    #[default]
    CentralDifference,
    /// Tchamwa–Wielgosz (explicit, first order, damps high frequencies; parameter `phi`).
    Tchamwa,
    /// Every mode propagated exactly over the step, the contact forces implicit (second
    /// order, no stability limit: the step follows the contacts and the excitation, not
    /// the top of the basis, so more modes and the static correction do not shorten it).
    /// Every process; not with friction nor with walls that have their own motion.
    ExactModal,
}

/// A time step in seconds, or `"auto"`: chosen for accuracy (the tolerance) within
/// stability, dividing the output interval (its schema: [`super::input_schema`]).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a time step in seconds or \"auto\"")]
pub enum TimeStepInput {
    Seconds(f64),
    Keyword(AutoKeyword),
}

/// The keyword `auto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum AutoKeyword {
    Auto,
}

/// The accuracy check of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum CheckInput {
    /// Repeat the whole run at twice the step where that proves the result as strictly
    /// as halving (1.5 times the cost), else at half the step (3 times);
    /// `quality.step_halving` says which and why.
    #[default]
    Auto,
    /// Repeat the whole run at half the step and compare the peaks and the impact count
    /// (triples the cost; `quality.step_halving`).
    StepHalving,
    /// No repeated run: the verdict rests on the energy balance and the steps per period.
    None,
}

impl From<CheckInput> for Check {
    fn from(value: CheckInput) -> Self {
        match value {
            CheckInput::Auto => Check::Auto,
            CheckInput::StepHalving => Check::StepHalving,
            CheckInput::None => Check::None,
        }
    }
}

/// Default relative tolerance of `solver.tolerance`.
pub fn default_tolerance() -> f64 {
    DEFAULT_TOLERANCE
}

/// The most threads one run may ask for.
pub const MAX_THREADS: usize = 64;

fn one_thread() -> usize {
    1
}

/// The threads `inputs` ask for (`solver.threads`, 1 when absent; validated inputs hold
/// 1 to [`MAX_THREADS`]).
pub fn requested_threads(inputs: &serde_json::Value) -> usize {
    inputs
        .pointer("/solver/threads")
        .and_then(serde_json::Value::as_u64)
        .map_or(1, |n| {
            usize::try_from(n).unwrap_or(MAX_THREADS).clamp(1, MAX_THREADS)
        })
}

/// The threads a run of `inputs` can use: those it asks for where it shares its steps
/// (`shares_steps`); otherwise at most two where its step check repeats the run (the run
/// and the repetition compute at once), one with `check: "none"`.
pub fn usable_threads(inputs: &serde_json::Value, shares_steps: bool) -> usize {
    let asked = requested_threads(inputs);
    let checked = inputs
        .pointer("/solver/check")
        .and_then(serde_json::Value::as_str)
        != Some("none");
    match (shares_steps, checked) {
        (true, _) => asked,
        (false, true) => asked.min(2),
        (false, false) => 1,
    }
}

/// Explicit integration settings (every process's `solver` block; each process states
/// its own defaults for `time_step` and `duration`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SolverInput {
    /// Integration scheme.
    #[serde(default)]
    #[schema(default = "central_difference")]
    pub scheme: SchemeInput,
    /// Tchamwa–Wielgosz parameter φ (dimensionless), with the `tchamwa` scheme only (refused with
    /// `central_difference`); 1.1 when left out.
    #[schema(minimum = 1.0, maximum = 2.0)]
    pub phi: Option<f64>,
    /// Time step (s), or "auto": chosen for accuracy at `tolerance` within stability, a
    /// whole number of steps per output interval. A given step must not exceed the
    /// critical step of the model with every contact closed.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = TimeStepInput)]
    pub time_step: Option<TimeStepInput>,
    /// Simulated duration (s), from t = 0.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = f64, exclusive_minimum = 0.0)]
    pub duration: Option<f64>,
    /// Relative accuracy target (dimensionless, in (0, 1)): `auto` picks its step so that
    /// the energy balance closes within it and peaks are within 10 × it, and
    /// `quality.verdict` judges against it. Larger values trade accuracy for speed (sweeps).
    #[serde(default = "default_tolerance")]
    #[schema(default = 1e-3, exclusive_minimum = 0.0, exclusive_maximum = 1.0)]
    pub tolerance: f64,
    /// Accuracy check: `auto` (the run repeated at 2Δt where that proves the result,
    /// 1.5 times the cost, else at Δt/2), `step_halving` (always at Δt/2, three times the
    /// cost) or `none` (cheap sweeps).
    #[serde(default)]
    #[schema(default = "auto")]
    pub check: CheckInput,
    /// Threads (count, 1 to 64) the run may use: with two or more, the run and its step
    /// check's repetition compute at once (one thread for the repetition, the others for
    /// the run); `hex-bundle-dynamics` also shares each step of the run between its
    /// threads (level deflections, closed contacts, x and y modal updates), while the row
    /// processes' steps are too short to share (they use two at most, none past one
    /// with `check: "none"`). A worker grants at most the cores it has free, so a run may
    /// get fewer. Results are the same, bit for bit, whatever the count. It pays on
    /// cores nobody else uses.
    #[serde(default = "one_thread")]
    #[schema(default = 1, minimum = 1, maximum = 64)]
    pub threads: usize,
}

impl Default for SolverInput {
    fn default() -> Self {
        Self {
            scheme: SchemeInput::default(),
            phi: None,
            time_step: None,
            duration: None,
            tolerance: default_tolerance(),
            check: CheckInput::default(),
            threads: 1,
        }
    }
}

/// A field that may be left out (`None`, the process's default) but not given as null.
fn present<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(
    deserializer: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(deserializer).map(Some)
}

/// A process's defaults for the fields of [`SolverInput`] left out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverDefaults {
    pub time_step: TimeStepInput,
    pub duration: f64,
}

impl SolverDefaults {
    /// `auto` over 0.2 s.
    pub const AUTO: SolverDefaults = SolverDefaults {
        time_step: TimeStepInput::Keyword(AutoKeyword::Auto),
        duration: 0.2,
    };
}

/// Builds the physics scheme, checking `phi` (pointers relative to the solver block).
pub fn scheme(scheme: SchemeInput, phi: Option<f64>, issues: &mut Vec<InputIssue>) -> Scheme {
    match scheme {
        SchemeInput::CentralDifference => {
            if phi.is_some() {
                issues.push(InputIssue::new("phi", "only applies to the `tchamwa` scheme"));
            }
            Scheme::CentralDifference
        }
        SchemeInput::Tchamwa => {
            let phi = phi.unwrap_or(1.1);
            if !(phi.is_finite() && (1.0..=2.0).contains(&phi)) {
                issues.push(InputIssue::new(
                    "phi",
                    format!("must be between 1 and 2 (got {})", crate::physics::number(phi)),
                ));
            }
            Scheme::Tchamwa { phi }
        }
        SchemeInput::ExactModal => {
            if phi.is_some() {
                issues.push(InputIssue::new("phi", "only applies to the `tchamwa` scheme"));
            }
            Scheme::ExactModal
        }
    }
}

/// Checks a time step and duration (pointers relative to the solver block). How many
/// steps they make is a cost, checked with the others ([`super::cost`]).
pub fn time_step(step: TimeStepInput, duration: f64, issues: &mut Vec<InputIssue>) -> TimeStep {
    crate::physics::require_positive(issues, "duration", duration);
    match step {
        TimeStepInput::Keyword(AutoKeyword::Auto) => TimeStep::Auto,
        TimeStepInput::Seconds(dt) => {
            crate::physics::require_positive(issues, "time_step", dt);
            TimeStep::Fixed(dt)
        }
    }
}

/// What a `solver` block sets, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    pub scheme: Scheme,
    pub time_step: TimeStep,
    pub duration: f64,
    pub tolerance: f64,
    pub check: Check,
    pub threads: usize,
}

impl SolverSettings {
    /// The integration settings of this solver block, recording every pin's deflection
    /// at `output_heights` (m) each `output_interval` (s; every step when `None`).
    pub fn integration(&self, output_interval: Option<f64>, output_heights: Vec<f64>) -> Settings {
        Settings {
            scheme: self.scheme,
            time_step: self.time_step,
            tolerance: self.tolerance,
            check: self.check,
            duration: self.duration,
            output_interval,
            output_heights,
            recorded_contacts: None,
            impacts: Default::default(),
            threads: self.threads,
        }
    }
}

/// The settings of a `solver` block (`defaults` for the fields left out), its problems
/// reported under `/inputs/solver`.
pub fn solver(input: &SolverInput, defaults: SolverDefaults, errors: &mut Vec<FieldError>) -> SolverSettings {
    let mut issues = Vec::new();
    let scheme = scheme(input.scheme, input.phi, &mut issues);
    let duration = input.duration.unwrap_or(defaults.duration);
    let time_step = time_step(
        input.time_step.unwrap_or(defaults.time_step),
        duration,
        &mut issues,
    );
    if !(input.tolerance.is_finite() && input.tolerance > 0.0 && input.tolerance < 1.0) {
        issues.push(InputIssue::new(
            "tolerance",
            format!(
                "must be a relative tolerance between 0 and 1, both excluded (got {})",
                crate::physics::number(input.tolerance)
            ),
        ));
    }
    if !(1..=MAX_THREADS).contains(&input.threads) {
        issues.push(InputIssue::new(
            "threads",
            format!("must be 1 to {MAX_THREADS} (got {})", input.threads),
        ));
    }
    errors.extend(at("/inputs/solver", issues));
    SolverSettings {
        scheme,
        time_step,
        duration,
        tolerance: input.tolerance,
        check: input.check.into(),
        threads: input.threads,
    }
}

/// Checks `output.interval` (s) when given: a positive number of seconds.
pub fn check_output_interval(interval: Option<f64>, errors: &mut Vec<FieldError>) {
    if let Some(interval) = interval
        && !(interval.is_finite() && interval > 0.0)
    {
        errors.push(FieldError::new(
            "/inputs/output/interval",
            "must be a positive number of seconds",
        ));
    }
}

/// The step a run will use, or a 422 on `/inputs/solver/time_step` naming both values
/// when a given step exceeds the critical one. The processes check their inputs first:
/// a model the physics still refuses is a 422 on the whole `/inputs`.
pub fn resolve_step(
    model: &crate::physics::integrate::Model<'_>,
    settings: &crate::physics::integrate::Settings,
) -> Result<crate::physics::integrate::StepSize, InvalidInputs> {
    use crate::physics::integrate::{Plan, SimulationError};
    Plan::new(model, settings).map(|plan| *plan.step()).map_err(|e| {
        let field = match &e {
            // What the scheme cannot integrate (the plane, moving walls, friction under
            // `exact_modal`) is the scheme's fault.
            SimulationError::InvalidSettings(issues) if issues.iter().all(|i| i.field == "scheme") => {
                return InvalidInputs(
                    issues
                        .iter()
                        .map(|i| FieldError::new("/inputs/solver/scheme", i.reason.clone()))
                        .collect(),
                );
            }
            SimulationError::InvalidModel(_) | SimulationError::InvalidSettings(_) => "/inputs",
            _ => "/inputs/solver/time_step",
        };
        InvalidInputs(vec![FieldError::new(field, e.to_string())])
    })
}

/// The time-stepping part of a run's [`super::WorkEstimate`]: the steps of one pass and
/// of the whole run (the step check repeats it at 2Δt: 1.5 times the steps, or at Δt/2:
/// three times), and what set the step; with the samples each history column holds. The
/// caller adds its DOFs, contacts, history columns and drivers.
pub fn stepping(
    settings: &crate::physics::integrate::Settings,
    step: &crate::physics::integrate::StepSize,
) -> (super::WorkEstimate, f64) {
    let (steps, every) =
        crate::physics::integrate::step_counts(settings.duration, step, settings.output_interval);
    // `auto` at 2Δt when it is valid: a run whose comparison at 2Δt does not prove it is
    // repeated at Δt/2 too (3.5 passes), which the estimate does not count.
    let passes = match settings.check {
        Check::Auto if step.doubled().is_ok() => 1.5,
        Check::Auto | Check::StepHalving => 3.0,
        Check::None => 1.0,
    };
    // Saturated counts (a step far below the duration) must not overflow.
    let samples = (steps / every) as f64 + 1.0;
    let estimate = super::WorkEstimate {
        steps: passes * steps as f64,
        pass_steps: settings.duration / step.time_step,
        step_note: step_hint(step, settings.tolerance),
        ..super::WorkEstimate::default()
    };
    (estimate, samples)
}

/// `estimate` with, when `auto` chose the mesh or the basis, what it chose and why
/// added to its refusals (`beam`: the member name, `pin` or `beam`).
pub fn with_auto_note(
    mut estimate: super::WorkEstimate,
    choice: Option<&auto::Choice>,
    beam: &str,
) -> super::WorkEstimate {
    if let Some(c) = choice {
        estimate.step_note.push_str(&format!(
            " ({beam}.modes/elements \"auto\" chose {} modes on {} elements to keep the peak \
             contact force within {:e} (10 × solver.tolerance): a larger tolerance needs fewer)",
            c.modes, c.elements, c.target
        ));
    }
    estimate
}

/// What to add to a "too many steps" refusal: under `auto`, what set the step and what
/// would lengthen it.
pub fn step_hint(step: &crate::physics::integrate::StepSize, tolerance: f64) -> String {
    use crate::physics::integrate::StepLimit;
    match step.limited_by {
        StepLimit::Given => String::new(),
        StepLimit::FastestMotion | StepLimit::Stability => format!(
            " (time_step \"auto\" chose this step for solver.tolerance {tolerance:e}: a larger tolerance takes fewer steps)"
        ),
        StepLimit::Excitation => {
            " (time_step \"auto\" resolves the excitation: its shortest sample interval or \
             pulse sets this step)"
                .to_owned()
        }
    }
}

/// Turns physics issues into field errors under `prefix` (a JSON pointer).
pub fn at(prefix: &str, issues: Vec<InputIssue>) -> Vec<FieldError> {
    issues
        .into_iter()
        .map(|i| FieldError::new(join_pointer(prefix, &i.field), i.reason))
        .collect()
}

fn join_pointer(prefix: &str, field: &str) -> String {
    if field.is_empty() {
        prefix.to_owned()
    } else {
        format!("{prefix}/{field}")
    }
}

/// Deserializes process inputs strictly; a failure names its JSON pointer (under `/inputs`).
pub fn parse<T: DeserializeOwned + ToSchema>(inputs: &serde_json::Value) -> Result<T, InvalidInputs> {
    serde_path_to_error::deserialize(super::strict_json::Strict(inputs)).map_err(|error| {
        let mut pointer = format!("/inputs{}", crate::pointer::pointer_of(error.path()));
        let detail = error.into_inner().to_string();
        // An unknown member is reported at the member when serde tracked its key, but at
        // an enclosing object when it could not (inside internally tagged enums, which
        // serde buffers): point at the member, found in that object.
        if let Some(field) = detail
            .strip_prefix("unknown field `")
            .and_then(|rest| rest.split_once('`'))
            .map(|(field, _)| field)
        {
            let within = pointer.strip_prefix("/inputs").unwrap_or_default().to_owned();
            if let Some(holder) = inputs
                .pointer(&within)
                .and_then(|scope| object_holding(scope, field, &within))
            {
                pointer = format!("/inputs{holder}/{}", field.replace('~', "~0").replace('/', "~1"));
            }
            return InvalidInputs(vec![FieldError::new(pointer, detail)]);
        }
        // serde reports a missing member at its parent: point at the member itself
        // (unless the parent is no object at all, e.g. a list where a tagged object goes).
        if let Some(field) = detail
            .strip_prefix("missing field `")
            .and_then(|rest| rest.strip_suffix('`'))
        {
            let within = pointer.strip_prefix("/inputs").unwrap_or_default();
            if inputs.pointer(within).is_some_and(|v| !v.is_object()) {
                return InvalidInputs(vec![FieldError::new(
                    pointer,
                    format!("must be an object with a `{field}` member"),
                )]);
            }
            pointer.push('/');
            pointer.push_str(field);
            return InvalidInputs(vec![FieldError::new(pointer, "is required")]);
        }
        // A wrong value inside a tagged object is reported at the object: point at the
        // member whose value does not fit its type.
        let within = pointer.strip_prefix("/inputs").unwrap_or_default();
        if let Some(member) = super::misfit::locate(&super::input_schema::schema_of::<T>(), inputs, within) {
            pointer = format!("/inputs{member}");
        }
        InvalidInputs(vec![FieldError::new(pointer, plain(&detail))])
    })
}

/// serde's type errors in words (`invalid type: string "abc", expected f64` → `must be
/// a number (got the string "abc")`); any other message as it is.
pub fn plain(detail: &str) -> String {
    let Some(rest) = detail
        .strip_prefix("invalid type: ")
        .or_else(|| detail.strip_prefix("invalid value: "))
    else {
        return detail.to_owned();
    };
    let Some((got, expected)) = rest.rsplit_once(", expected ") else {
        return detail.to_owned();
    };
    let want = match expected.trim() {
        "f64" | "f32" => "a number",
        "u8" | "u16" | "u32" | "u64" | "usize" => "a whole number, 0 or more",
        "i8" | "i16" | "i32" | "i64" | "isize" => "a whole number",
        "a boolean" => "true or false",
        "a sequence" => "a list",
        "a map" => "an object",
        other if other.starts_with("struct ") || other.starts_with("internally tagged enum") => "an object",
        other => other,
    };
    let unquote = |text: &str| text.trim_matches('`').to_owned();
    let got = if let Some(text) = got.strip_prefix("string ") {
        format!("the string {text}")
    } else if let Some(number) = got
        .strip_prefix("integer ")
        .or_else(|| got.strip_prefix("floating point "))
    {
        unquote(number)
    } else if let Some(value) = got.strip_prefix("boolean ") {
        unquote(value)
    } else {
        match got {
            "sequence" => "a list".to_owned(),
            "map" => "an object".to_owned(),
            other => other.to_owned(),
        }
    };
    format!("must be {want} (got {got})")
}

/// The pointer of the first object in `scope` (itself included, depth first) that has a
/// member `field`; `at` is the pointer of `scope`.
fn object_holding(scope: &serde_json::Value, field: &str, at: &str) -> Option<String> {
    match scope {
        serde_json::Value::Object(map) if map.contains_key(field) => Some(at.to_owned()),
        serde_json::Value::Object(map) => map.iter().find_map(|(key, child)| {
            let escaped = key.replace('~', "~0").replace('/', "~1");
            object_holding(child, field, &format!("{at}/{escaped}"))
        }),
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(index, child)| object_holding(child, field, &format!("{at}/{index}"))),
        _ => None,
    }
}

#[cfg(test)]
mod plain_tests {
    use serde_json::json;

    use super::parse;
    use crate::processes::bundle_dynamics::inputs::BundleInputs;

    fn detail(inputs: serde_json::Value) -> (String, String) {
        let error = parse::<BundleInputs>(&inputs).expect_err("refused").0.remove(0);
        (error.pointer, error.detail)
    }

    /// serde's type errors reach users in words, at the member, with what was given.
    #[test]
    fn type_errors_say_what_was_expected_in_words() {
        let pin = json!({"length": "abc", "young_modulus": 2.1e11, "density": 7800.0,
                         "section": {"type": "tube", "outer_diameter": 0.01, "inner_diameter": 0.009}});
        let (pointer, text) = detail(json!({"pin": pin, "pins": 2, "contacts": []}));
        assert_eq!(pointer, "/inputs/pin/length");
        assert_eq!(text, r#"must be a number (got the string "abc")"#);
        let mut pin = pin;
        pin["length"] = json!(1.0);
        let (pointer, text) = detail(json!({"pin": pin, "pins": -2, "contacts": []}));
        assert_eq!(pointer, "/inputs/pins");
        assert_eq!(text, "must be a whole number, 0 or more (got -2)");
        let (_, text) = detail(json!({"pin": pin, "pins": 2, "contacts": {}}));
        assert_eq!(text, "must be a list (got an object)");
    }
}
