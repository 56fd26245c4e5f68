//! Plausibility warnings: inputs that are valid but look like a mistake (a unit slip, a
//! model nothing moves, a run too short to show anything), reported with the job and
//! never refused.
//!
//! Every process gets the same checks from the one adapter ([`super::simulation`]): a
//! process only says where its pin, contacts and excitation are ([`Subject`]), and
//! [`assess`] judges them. The bounds are wide on purpose: a warning must not cry wolf
//! on a sensible model (the shipped examples get none, `tests/api/warnings.rs`), and a
//! unit slip moves a value by a factor of 1000 or more, far past them. A request turns
//! them off with `"warnings": "off"` among its inputs (sweeps over a range that is
//! implausible on purpose).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::common_inputs::{BeamInput, SectionInput};
use crate::physics::integrate::Model;
use crate::physics::modal::ModalBasis;
use crate::physics::number;

/// Slenderness L/D below which a pin is too stocky for a beam (a diameter in mm typed
/// as m?). Euler–Bernoulli beams want slender members; code_aster's `sdnl104c` beam
/// (L/D = 5, `examples/sdnl104c.json`) is still one, so the bound sits below it.
pub const MIN_SLENDERNESS: f64 = 4.0;
/// Slenderness L/D above which a pin is implausibly thin (a length in mm typed as m?);
/// fuel pins are about 200.
pub const MAX_SLENDERNESS: f64 = 2000.0;
/// Lowest plausible first frequency of a pin (Hz).
pub const MIN_FIRST_FREQUENCY: f64 = 0.1;
/// Highest plausible first frequency of a pin (Hz).
pub const MAX_FIRST_FREQUENCY: f64 = 1000.0;
/// Young's modulus below which the material is softer than any structural solid (Pa):
/// MPa or GPa typed as Pa?
pub const MIN_YOUNG_MODULUS: f64 = 1e9;
/// A duration below this fraction of the first period ends before the pin's slowest
/// mode has moved (it reaches its first extreme after a quarter period). Shock studies
/// of a row of pins rightly stop well within the first period (the pins hit their
/// neighbours first: `examples/sweep-gaps.json` runs 6 % of it): the bound is below.
pub const MIN_PERIODS: f64 = 0.01;
/// A duration above this many first periods is probably in the wrong unit.
pub const MAX_PERIODS: f64 = 1e4;
/// Time steps of a whole run (every pass of the accuracy check) above which the step or
/// the duration is probably in the wrong unit.
pub const MAX_STEPS: f64 = 1e8;
/// Clad diameter above which a slenderness below [`MIN_SLENDERNESS`] is blamed on the
/// diameter rather than on the length (m).
const LARGE_DIAMETER: f64 = 0.1;
/// Length above which a slenderness above [`MAX_SLENDERNESS`] is blamed on the length
/// rather than on the diameter (m).
const LONG_PIN: f64 = 10.0;
/// Largest ratio of the critical steps without and with the static correction before
/// [`WarningCode::CostlyStaticCorrection`].
const MAX_CORRECTION_COST: f64 = 4.0;
/// Most gap warnings of one run (one per input field).
const MAX_GAP_WARNINGS: usize = 5;

/// What a warning is about (a stable identifier scripts can filter on).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum WarningCode {
    /// Slenderness L/D outside 4…2000.
    Slenderness,
    /// First frequency of the pin above 1 kHz or below 0.1 Hz.
    FirstFrequency,
    /// Young's modulus below 1e9 Pa.
    SoftMaterial,
    /// A contact gap larger than the pin diameter.
    GapOverDiameter,
    /// The duration is below 1 % of the first period.
    ShortDuration,
    /// The duration is above 1e4 first periods.
    LongDuration,
    /// No excitation, release or point force: nothing moves.
    NothingExcites,
    /// More than 1e8 time steps in the run.
    ManySteps,
    /// The static correction's pseudo-modes make the critical step over 4 times smaller
    /// than the eigenmodes' alone (contacts at many heights).
    CostlyStaticCorrection,
    /// The run ends before its base (or wall) acceleration does: the rest of the record
    /// is never applied, and its peaks may come later.
    ExcitationOutlastsRun,
}

/// A plausibility note about valid inputs: where (JSON pointer into the request body)
/// and why it looks like a mistake.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct Warning {
    pub code: WarningCode,
    /// JSON pointer into the execution request body, e.g. `/inputs/pin/length`.
    pub pointer: String,
    /// What looks wrong, with the values and the bound.
    pub message: String,
}

impl Warning {
    fn new(code: WarningCode, pointer: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            code,
            pointer: pointer.into(),
            message: message.into(),
        }
    }
}

/// The `warnings` input: plausibility warnings `on` (default) or `off`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum WarningsInput {
    /// Report plausibility warnings with the job and its results.
    #[default]
    On,
    /// No plausibility warnings (e.g. a sweep over a deliberately odd range).
    Off,
}

/// What the checks read of a process's plan, and where the user wrote it.
#[allow(missing_debug_implementations)] // a closure: nothing to show
pub struct Subject<'a> {
    /// The request's `warnings` input.
    pub switch: WarningsInput,
    /// The pin (every pin of the model) and its pointer (`/inputs/pin`).
    pub pin: &'a BeamInput,
    pub pin_pointer: &'static str,
    /// The clad diameter D (m) and its pointer when the inputs give it apart from the
    /// section (`bundle.pin_diameter`); otherwise the section's.
    pub diameter: Option<(f64, &'static str)>,
    /// The model as it will run (its basis gives the first frequency).
    pub model: Model<'a>,
    /// Simulated duration (s).
    pub duration: f64,
    /// The integration scheme (the static correction costs step only to the explicit
    /// ones).
    pub scheme: crate::physics::stability::Scheme,
    /// Where the user wrote the gap of contact k.
    pub gap_pointer: Box<dyn Fn(usize) -> String + 'a>,
    /// Where to add an excitation when nothing excites the model.
    pub excitation_pointer: &'static str,
}

impl Subject<'_> {
    /// The clad diameter D (m) and its pointer: a tube's outer diameter, or for an
    /// explicit section the solid circle's of the same radius of gyration (4 √(I/A)).
    fn diameter(&self) -> Option<(f64, String)> {
        if let Some((diameter, pointer)) = self.diameter {
            return Some((diameter, pointer.to_owned()));
        }
        match self.pin.section {
            SectionInput::Tube { outer_diameter, .. } => Some((
                outer_diameter,
                format!("{}/section/outer_diameter", self.pin_pointer),
            )),
            SectionInput::Explicit { area, inertia } => {
                let diameter = 4.0 * (inertia / area).sqrt();
                (diameter.is_finite() && diameter > 0.0)
                    .then(|| (diameter, format!("{}/section", self.pin_pointer)))
            }
        }
    }

    fn basis(&self) -> &ModalBasis {
        self.model.basis
    }

    fn excited(&self) -> bool {
        let model = &self.model;
        model.base_acceleration.is_some()
            || model
                .plane
                .as_ref()
                .is_some_and(|plane| plane.base_acceleration_y.is_some())
            || !model.point_forces.is_empty()
            || model.initial_tip_displacements.iter().any(|u| *u != 0.0)
            || model.initial_tip_velocities.iter().any(|v| *v != 0.0)
            || model.walls.is_some()
    }
}

/// Every plausibility warning about `subject`, whose run takes `steps` time steps (all
/// passes); none when its switch is off.
pub fn assess(subject: &Subject<'_>, steps: f64) -> Vec<Warning> {
    if subject.switch == WarningsInput::Off {
        return Vec::new();
    }
    let mut warnings = Vec::new();
    let pin = subject.pin;
    let at = |field: &str| format!("{}/{field}", subject.pin_pointer);
    let diameter = subject.diameter();
    // Which field a pin that is off in its proportions is blamed on.
    let mut proportions: Option<String> = None;

    if let Some((diameter, diameter_pointer)) = &diameter {
        let slenderness = pin.length / diameter;
        let (pointer, bound) = if slenderness < MIN_SLENDERNESS {
            let blamed = if *diameter > LARGE_DIAMETER {
                diameter_pointer.clone()
            } else {
                at("length")
            };
            (Some(blamed), format!("below {MIN_SLENDERNESS}"))
        } else if slenderness > MAX_SLENDERNESS {
            let blamed = if pin.length > LONG_PIN {
                at("length")
            } else {
                diameter_pointer.clone()
            };
            (Some(blamed), format!("above {MAX_SLENDERNESS}"))
        } else {
            (None, String::new())
        };
        if let Some(pointer) = pointer {
            warnings.push(Warning::new(
                WarningCode::Slenderness,
                &pointer,
                format!(
                    "the slenderness L/D = {} m / {} m = {} is {bound}: a length or a diameter in mm typed as m?",
                    number(pin.length),
                    number(*diameter),
                    number(slenderness)
                ),
            ));
            proportions = Some(pointer);
        }
    }

    if pin.young_modulus < MIN_YOUNG_MODULUS {
        warnings.push(Warning::new(
            WarningCode::SoftMaterial,
            at("young_modulus"),
            format!(
                "Young's modulus {} Pa is below {} Pa, softer than any structural solid: MPa or GPa typed as Pa?",
                number(pin.young_modulus),
                number(MIN_YOUNG_MODULUS)
            ),
        ));
        proportions = Some(at("young_modulus"));
    }

    let first_frequency = subject
        .basis()
        .angular_frequencies()
        .first()
        .map(|omega| omega / std::f64::consts::TAU);
    if let Some(frequency) = first_frequency.filter(|f| *f > 0.0) {
        let bound = if frequency > MAX_FIRST_FREQUENCY {
            Some(format!("above {} Hz", number(MAX_FIRST_FREQUENCY)))
        } else if frequency < MIN_FIRST_FREQUENCY {
            Some(format!("below {} Hz", number(MIN_FIRST_FREQUENCY)))
        } else {
            None
        };
        if let Some(bound) = bound {
            warnings.push(Warning::new(
                WarningCode::FirstFrequency,
                proportions.clone().unwrap_or_else(|| at("length")),
                format!(
                    "the pin's first frequency {} Hz is {bound}, far from any fuel pin's: check the units of \
                     its length, section and material",
                    number(frequency)
                ),
            ));
        }
        let period = 1.0 / frequency;
        let periods = subject.duration / period;
        if periods < MIN_PERIODS {
            warnings.push(Warning::new(
                WarningCode::ShortDuration,
                "/inputs/solver/duration",
                format!(
                    "the duration {} s is {} of the pin's first period ({} s), below {} %: the run ends \
                     before the pin has moved",
                    number(subject.duration),
                    percent(periods),
                    number(period),
                    number(100.0 * MIN_PERIODS)
                ),
            ));
        } else if periods > MAX_PERIODS {
            warnings.push(Warning::new(
                WarningCode::LongDuration,
                "/inputs/solver/duration",
                format!(
                    "the duration {} s is {} first periods of the pin ({} s each), above {}: a duration in ms \
                     typed as s?",
                    number(subject.duration),
                    number(periods),
                    number(period),
                    number(MAX_PERIODS)
                ),
            ));
        }
    }

    if let Some((diameter, _)) = &diameter {
        warnings.extend(gap_warnings(subject, *diameter));
    }

    if !subject.excited() {
        warnings.push(Warning::new(
            WarningCode::NothingExcites,
            subject.excitation_pointer,
            "nothing excites the model (no base acceleration, initial displacement or velocity, or point \
             force): every history will be zero",
        ));
    }

    if let Some(warning) = static_correction_cost(subject) {
        warnings.push(warning);
    }

    if let Some(warning) = excitation_outlasts_run(subject) {
        warnings.push(warning);
    }

    if steps > MAX_STEPS {
        warnings.push(Warning::new(
            WarningCode::ManySteps,
            "/inputs/solver/time_step",
            format!(
                "the run takes {} time steps, above {}: a time step or a duration in the wrong unit?",
                number(steps.round()),
                number(MAX_STEPS)
            ),
        ));
    }
    warnings
}

/// A warning when a base or wall acceleration goes on after the run's end (by more than
/// rounding): the latest of them, with its end. Point forces are left alone: a table
/// that runs past the end is how a held load is written.
fn excitation_outlasts_run(subject: &Subject<'_>) -> Option<Warning> {
    let model = &subject.model;
    let walls = model.walls.as_ref();
    let (name, end) = [
        ("the base acceleration", model.base_acceleration.as_ref()),
        (
            "the base acceleration along y",
            model
                .plane
                .as_ref()
                .and_then(|plane| plane.base_acceleration_y.as_ref()),
        ),
        (
            "the left wall's acceleration",
            walls.and_then(|w| w.left_x.as_ref()),
        ),
        (
            "the right wall's acceleration",
            walls.and_then(|w| w.right_x.as_ref()),
        ),
        (
            "the walls' acceleration along y",
            walls.and_then(|w| w.y.as_ref()),
        ),
    ]
    .into_iter()
    .filter_map(|(name, signal)| signal.map(|s| (name, s.end())))
    .max_by(|a, b| a.1.total_cmp(&b.1))?;
    (end > subject.duration * (1.0 + 1e-9)).then(|| {
        Warning::new(
            WarningCode::ExcitationOutlastsRun,
            "/inputs/solver/duration",
            format!(
                "the run ends at {} s, before {name} does ({} s): the last {} of it is never applied, and \
                 the largest response may come in it; run for {} s",
                number(subject.duration),
                number(end),
                percent(1.0 - subject.duration / end),
                number(end)
            ),
        )
    })
}

/// The critical step of the model with its pseudo-modes against its eigenmodes alone:
/// a warning when they make it over [`MAX_CORRECTION_COST`] times smaller.
fn static_correction_cost(subject: &Subject<'_>) -> Option<Warning> {
    use crate::physics::integrate::critical_time_step;
    use crate::physics::stability::Scheme;
    if !subject.scheme.is_explicit() {
        return None;
    }
    let correction = subject.basis().static_correction()?;
    let modes_only = subject.basis().without_static_correction();
    let lean = Model {
        basis: &modes_only,
        damping_ratios: subject.model.damping_ratios[..modes_only.modes()].to_vec(),
        ..subject.model.clone()
    };
    let scheme = Scheme::CentralDifference;
    let ratio = critical_time_step(&lean, scheme) / critical_time_step(&subject.model, scheme);
    (ratio > MAX_CORRECTION_COST).then(|| {
        let top = subject.basis().frequencies_hz().last().copied().unwrap_or(0.0);
        Warning::new(
            WarningCode::CostlyStaticCorrection,
            format!("{}/static_correction", subject.pin_pointer),
            format!(
                "the static correction adds {} pseudo-modes (one per contact height, up to {} Hz): \
                 the critical time step is {} times smaller than with the modes alone, and the run as \
                 much longer; with contacts at this many heights, \"none\" may be the better trade",
                correction.heights.len(),
                number(top),
                number(ratio)
            ),
        )
    })
}

/// One warning per input field that holds gaps larger than the pin diameter (at most
/// [`MAX_GAP_WARNINGS`]), counting the contacts concerned.
fn gap_warnings(subject: &Subject<'_>, diameter: f64) -> Vec<Warning> {
    let contacts = &subject.model.contacts;
    let wide: Vec<(usize, f64)> = contacts
        .iter()
        .enumerate()
        .filter(|(_, c)| c.gap > diameter)
        .map(|(k, c)| (k, c.gap))
        .collect();
    let mut pointers: Vec<(String, f64)> = Vec::new();
    for (k, gap) in &wide {
        let pointer = (subject.gap_pointer)(*k);
        if pointers.iter().all(|(p, _)| *p != pointer) {
            pointers.push((pointer, *gap));
        }
    }
    let concerned = if contacts.len() == 1 {
        String::new()
    } else {
        format!(" ({} of {} contacts)", wide.len(), contacts.len())
    };
    pointers
        .into_iter()
        .take(MAX_GAP_WARNINGS)
        .map(|(pointer, gap)| {
            Warning::new(
                WarningCode::GapOverDiameter,
                pointer,
                format!(
                    "a gap of {} m is larger than the pin diameter {} m{concerned}: a gap in mm typed as m?",
                    number(gap),
                    number(diameter)
                ),
            )
        })
        .collect()
}

/// A fraction as a percentage for a message (`0.5 %`).
fn percent(fraction: f64) -> String {
    format!("{} %", number(100.0 * fraction))
}
