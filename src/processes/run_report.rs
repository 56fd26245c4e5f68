//! What every run of pins with point contacts reports, whatever built the pins: the
//! statistics of each contact, the extremes of each deflection line, the run's summary
//! (peaks, impacts, energy, step, quality, basis), its histories and what it costs. A
//! process flattens these into its own results (`#[serde(flatten)]`) beside what only it
//! knows (a contact's bodies, a pin's place in its lattice).

use serde::Serialize;
use utoipa::ToSchema;

use super::basis_report::BasisReport;
use super::bending::{self, BendingReport, Flexures};
use super::contact_law;
use super::excitation_record::{Excitations, GeneratedRecord};
use super::impact_report::{self, ContactImpacts, ImpactSummary};
use super::margins::{self, RunMargins};
use super::report::{EnergyReport, QualityReport};
use super::resultants::RunResultant;
use super::simulation::{HistoryKind, HistoryOutput};
use super::{History, WorkEstimate, common_inputs};
use crate::physics::discretisation::auto::Choice as BasisChoice;
use crate::physics::integrate::{PeakDeflection, Settings, Simulation, StepSize};

/// One contact's statistics, accumulated at every step.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ContactStatistics {
    /// Largest force (N), along the contact's normal.
    pub max_force: f64,
    /// Its time (s); 0 when the contact never closed.
    pub max_force_time: f64,
    /// Impacts, as `output.impacts` counts them (default: closures after a separation).
    pub impacts: u64,
    /// Total time closed (s).
    pub contact_time: f64,
    /// ∫ F dt (N·s), along the contact's normal.
    pub impulse: f64,
    /// Time of the first closure (s), interpolated between steps; null if none.
    pub first_impact_time: Option<f64>,
    /// Largest penetration (m); ≤ 0 when the contact never closed (smallest clearance).
    pub max_penetration: f64,
    /// Its impacts as `output.impacts` counts them (`impacts` above is their number).
    pub impact_statistics: ContactImpacts,
    /// The force it may carry (N): `output.allowables.contact_force` or its law's
    /// `allowable_force`; null without one.
    pub allowable_force: Option<f64>,
    /// `max_force` over `allowable_force` (dimensionless; ≥ 1: reached); null without one.
    pub utilisation: Option<f64>,
}

impl ContactStatistics {
    /// Every contact's statistics in contact order; `allowables` the allowable force of
    /// each contact's law.
    pub fn of_run(run: &Simulation, allowables: &[Option<f64>]) -> Vec<Self> {
        run.contact_statistics
            .iter()
            .zip(impact_report::contact_reports(run))
            .zip(allowables)
            .map(|((s, impact_statistics), allowable)| Self {
                max_force: s.max_force,
                max_force_time: s.max_force_time,
                impacts: s.impacts,
                contact_time: s.contact_time,
                impulse: s.impulse,
                first_impact_time: s.first_impact_time,
                max_penetration: s.max_penetration,
                impact_statistics,
                allowable_force: *allowable,
                utilisation: margins::ratio(s.max_force, *allowable),
            })
            .collect()
    }
}

/// The largest contact force of the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct PeakForce {
    /// Contact index.
    pub contact: usize,
    /// Force (N).
    pub force: f64,
    /// Time (s).
    pub time: f64,
}

/// One deflection line's largest deflections (a pin of a row, a pin along x or y).
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct LineExtremes {
    /// max |w| (m) over the mesh nodes at every output time.
    pub max_abs_deflection: f64,
    /// Height where it occurred (m).
    pub height: f64,
    /// When (s).
    pub time: f64,
    /// Per output height, the deflection of largest magnitude over every step (the
    /// extreme of its `displacements_peaks` column).
    pub peak_deflections: Vec<PeakDeflectionResult>,
}

impl LineExtremes {
    /// Line `line`'s extremes in `run`, whose recorded heights are `heights`.
    pub fn of_line(run: &Simulation, heights: &[f64], line: usize) -> Self {
        let extreme = &run.pin_extremes[line];
        Self {
            max_abs_deflection: extreme.max_abs_deflection,
            height: extreme.height,
            time: extreme.time,
            peak_deflections: PeakDeflectionResult::of_line(heights, &run.peak_deflections, line),
        }
    }
}

/// The deflection of largest magnitude at one height, over every step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct PeakDeflectionResult {
    /// Height (m).
    pub height: f64,
    /// Signed deflection (m).
    pub deflection: f64,
    /// The end of the output interval that holds it (s).
    pub time: f64,
}

impl PeakDeflectionResult {
    /// Line `line`'s peak at each output height of a run.
    pub fn of_line(heights: &[f64], peaks: &[Vec<PeakDeflection>], line: usize) -> Vec<Self> {
        heights
            .iter()
            .zip(peaks)
            .map(|(height, per_line)| Self {
                height: *height,
                deflection: per_line[line].deflection,
                time: per_line[line].time,
            })
            .collect()
    }
}

/// What the run as a whole reports.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct RunSummary {
    /// The largest force over all contacts; null without contacts.
    pub max_contact_force: Option<PeakForce>,
    /// The largest resultant contact force on a pin at a contact height (the vector sum
    /// of the contacts acting on it there, every step): which pin, where, when; null
    /// without contacts.
    pub max_resultant_force: Option<RunResultant>,
    /// The run's worst utilisations (docs/margins.md): `max_utilisation`,
    /// `max_stress_utilisation`, `worst_utilisation`; null without allowables.
    #[serde(flatten)]
    pub margins: RunMargins,
    /// Impacts over all contacts, as `output.impacts` counts them.
    pub impacts: u64,
    /// The run's impacts: counting, totals, histogram, contacts ranked.
    pub impact_summary: ImpactSummary,
    pub energy: EnergyReport,
    /// Step used (s).
    pub time_step: f64,
    /// Critical step with every contact closed (s); null under `exact_modal`, which has
    /// no stability limit.
    pub critical_time_step: Option<f64>,
    /// Steps taken.
    pub steps: u64,
    /// Time between two history samples (s).
    pub output_interval: f64,
    pub quality: QualityReport,
    /// Frequencies of the pin's basis (Hz), eigenmodes then pseudo-modes (the same in
    /// every bending direction).
    pub frequencies_hz: Vec<f64>,
    pub basis: BasisReport,
    #[serde(flatten)]
    pub bending: BendingReport,
    /// The synthetic earthquakes (`spectrum_compatible`) the run was given: what each
    /// reached against its target; empty without one.
    pub generated_records: Vec<GeneratedRecord>,
}

impl RunSummary {
    /// The summary of `run`, judged `quality`, counted as `settings` asks, with the
    /// allowable force of each contact and the allowable stress (Pa) of the pins, the
    /// report of its basis, its pins' flexure and its excitations.
    pub fn of(
        run: &Simulation,
        quality: QualityReport,
        settings: &Settings,
        (allowables, allowable_stress): (&[Option<f64>], Option<f64>),
        (basis, frequencies_hz): (BasisReport, Vec<f64>),
        flexures: &Flexures,
        excitations: &Excitations,
    ) -> Self {
        let peaks: Vec<f64> = run.contact_statistics.iter().map(|s| s.max_force).collect();
        let bending = BendingReport::of(run, flexures);
        Self {
            max_contact_force: run
                .contact_statistics
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.max_force.total_cmp(&b.1.max_force))
                .map(|(k, s)| PeakForce {
                    contact: k,
                    force: s.max_force,
                    time: s.max_force_time,
                }),
            max_resultant_force: RunResultant::of(run),
            margins: RunMargins::of(
                contact_law::worst(&peaks, allowables),
                &bending.max_bending,
                allowable_stress,
            ),
            impacts: run.contact_statistics.iter().map(|s| s.impacts).sum(),
            impact_summary: impact_report::summary(run, &settings.impacts),
            energy: run.energy.into(),
            time_step: run.step.time_step,
            critical_time_step: crate::physics::finite(run.step.critical_time_step),
            steps: run.steps,
            output_interval: run.output_interval,
            quality,
            frequencies_hz,
            basis,
            bending,
            generated_records: excitations.generated_records(),
        }
    }
}

/// The names of the deflection columns, height by height and line by line (the order of
/// the run's deflections): `<line>` at the tips, `<line>@<height>` elsewhere.
pub fn deflection_names(
    heights: &[f64],
    lines: usize,
    tips_only: bool,
    line: impl Fn(usize) -> String,
) -> Vec<String> {
    let mut names = Vec::with_capacity(heights.len() * lines);
    for height in heights {
        for l in 0..lines {
            names.push(match tips_only {
                true => line(l),
                false => format!("{}@{height}", line(l)),
            });
        }
    }
    names
}

/// The bending moments at the output heights, a history every run of pins gives.
pub const MOMENTS_OUTPUT: HistoryOutput = HistoryOutput {
    name: "bending_moments",
    kind: HistoryKind::Moment,
    title: "Bending moments (N·m)",
    description: "CSV columns time (s), then the columns of displacements: the bending moment EI w'' of each \
                  pin (and direction) at each output height, signed as the curvature (positive bends the pin \
                  concave toward +x, or +y)",
};

/// The histories every run of pins gives: `contact_forces`, `displacements`, their
/// `_peaks`, `bending_moments`, the impact table and the `excitation` of
/// `excitations`, with the columns named `contacts` (one per recorded contact) and
/// `deflections` ([`deflection_names`]; the moments' as the deflections'), the moments
/// of pins of `flexure`.
pub fn histories(
    run: Simulation,
    contacts: &[String],
    deflections: &[String],
    flexures: &Flexures,
    excitations: &Excitations,
) -> Vec<History> {
    let moments = bending::moment_columns(&run, flexures);
    let named = |names: &[String], columns: Vec<Vec<f64>>| -> Vec<(String, Vec<f64>)> {
        names.iter().cloned().zip(columns).collect()
    };
    let history = |name: &str, series| History {
        name: name.into(),
        time: run.time.clone(),
        series,
    };
    let table = impact_report::table_history(&run.impact_table);
    let excitation = excitations.history(&run.time);
    vec![
        history("contact_forces", named(contacts, run.contact_forces)),
        history(
            "displacements",
            named(deflections, run.deflections.into_iter().flatten().collect()),
        ),
        history("contact_forces_peaks", named(contacts, run.contact_force_peaks)),
        history(
            "displacements_peaks",
            named(deflections, run.deflection_peaks.into_iter().flatten().collect()),
        ),
        history("bending_moments", named(deflections, moments)),
        table,
        excitation,
    ]
}

/// What a run of pins costs, and what drives it.
#[derive(Debug)]
pub struct RunSize<'a> {
    pub settings: &'a Settings,
    pub step: &'a StepSize,
    /// What `auto` chose for the basis (its note joins a refusal).
    pub choice: Option<&'a BasisChoice>,
    /// Deflection lines (pins × bending directions).
    pub lines: usize,
    /// Modes per line.
    pub modes: usize,
    /// Contacts evaluated at each step.
    pub contacts: usize,
    /// Contacts whose force histories are recorded.
    pub recorded: usize,
    /// The members that drive the work besides the duration, the step and the modes.
    pub work_drivers: &'a [&'a str],
    /// The members that drive the history values besides the duration, the interval,
    /// the output heights and the impact table.
    pub history_drivers: &'a [&'a str],
    /// Whether `output.heights` was given.
    pub heights_given: bool,
}

impl RunSize<'_> {
    /// Lines × modes modal DOFs and every contact at each step; histories
    /// `contact_forces` (time + one column per recorded contact) and `displacements`
    /// (time + one column per line and output height), their peaks, the moments (as the
    /// displacements), and the impact table.
    pub fn estimate(&self) -> WorkEstimate {
        let (stepping, samples) = common_inputs::stepping(self.settings, self.step);
        let stepping = common_inputs::with_auto_note(stepping, self.choice, "pin");
        // Forces and their peaks; deflections, their peaks and the moments.
        let columns = 2 * (1 + self.recorded) + 3 * (1 + self.lines * self.settings.output_heights.len());
        let mut history_drivers = vec![
            "/inputs/solver/duration".to_owned(),
            "/inputs/output/interval".to_owned(),
        ];
        history_drivers.extend(self.history_drivers.iter().map(|d| d.to_string()));
        if self.heights_given {
            history_drivers.push("/inputs/output/heights".to_owned());
        }
        history_drivers.push("/inputs/output/impacts/max_rows".to_owned());
        let table = impact_report::table_values(&self.settings.impacts, self.contacts, stepping.pass_steps);
        let mut work_drivers = vec![
            "/inputs/solver/duration".to_owned(),
            "/inputs/solver/time_step".to_owned(),
            "/inputs/pin/modes".to_owned(),
        ];
        work_drivers.extend(self.work_drivers.iter().map(|d| d.to_string()));
        WorkEstimate {
            modal_dofs: (self.lines * self.modes) as f64,
            contacts: self.contacts as f64,
            history_values: samples * columns as f64 + table,
            work_drivers,
            history_drivers,
            ..stepping
        }
    }
}
