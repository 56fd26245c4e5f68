//! Process `hex-bundle-dynamics`: a wire-wrapped hexagonal bundle (7 to 271 identical
//! pins on one shared modal basis, bending along x and y) in its wrapper tube, built from
//! a dozen numbers (`physics::hex`): each wire touches a neighbour's clad or the wrapper
//! once every H/12, each contact with its normal in the transverse plane. Shaken by the
//! wrapper in any horizontal direction, pushed by point forces or released from bent
//! shapes (`loads`). Statistics for every contact, full force histories for a
//! selection.

/// The inputs of `hex-bundle-dynamics`.
pub mod inputs;
/// Point forces and tip releases of `hex-bundle-dynamics`, per deflection line.
pub mod loads;

use serde::Serialize;
use utoipa::ToSchema;

use super::basis_report::BasisReport;
use super::bending::{Bending, Flexures};
use super::columns;
use super::common_inputs::{self, SectionInput, SolverDefaults, at};
use super::contact_law::{FrictionReport, LawInput, WearDepth, WearReport};
use super::excitation::{PlaneSignal, plane_signal};
use super::excitation_record::{self, Excitations};
use super::impact_report;
use super::kinds;
use super::margins::PinUtilisation;
use super::model_check;
use super::resultants::PinResultants;
use super::run_report::{self, ContactStatistics, LineExtremes, RunSize, RunSummary};
use super::simulation::{HistoryKind, HistoryOutput, Output, Simulation};
use super::warnings::Subject;
use super::{Example, FieldError, History, InvalidInputs, ProgressFn, RunError, WorkEstimate};
use crate::physics::contact::{Body as RowBody, Contact};
use crate::physics::discretisation::auto::{self, Choice as BasisChoice};
use crate::physics::hex::{Aim, Body, HexBundle, HexContact, pair_count};
use crate::physics::integrate::{self, Model, Plane, Settings, StepSize, WallMotion};
use crate::physics::loads::BaseAcceleration;
use crate::physics::modal::ModalBasis;
use crate::physics::{InputIssue, require_non_negative};
use inputs::{ContactSelectionInput, HexExcitationInput, HexInputs};
use loads::PlaneLoads;

/// The fewest modal DOFs whose step is worth sharing between threads: on the 2-core
/// machine two threads ran a 19-pin bundle's steps (760 DOFs) 1.05× faster than one, a
/// 61-pin bundle's (2 440) 1.23× faster, a 217-pin bundle's (8 680) 1.43× faster
/// (`scripts/threads-bench.py`, `check: "none"`, 2026-11-27). Smaller bundles are
/// granted threads only for their step check, as the rows (the run then shares its
/// steps with the check's core once the check is done: the core is held anyway).
pub const MIN_SHARED_STEP_DOFS: u64 = 2000;

/// Default history interval (s).
pub const DEFAULT_OUTPUT_INTERVAL: f64 = 1e-4;

/// Validated inputs, ready to run.
#[derive(Debug)]
pub struct Plan {
    inputs: HexInputs,
    bundle: HexBundle,
    geometry: Vec<HexContact>,
    contacts: Vec<Contact>,
    normals: Vec<[f64; 2]>,
    excitation: (Option<BaseAcceleration>, Option<BaseAcceleration>),
    walls: Option<WallMotion>,
    loads: PlaneLoads,
    basis: ModalBasis,
    /// The modal basis of each of `inputs.kinds`.
    kind_bases: Vec<ModalBasis>,
    /// What `auto` chose for the mesh and the basis; `None` when both were given.
    basis_choice: Option<BasisChoice>,
    settings: Settings,
    step: StepSize,
}

impl Plan {
    /// The accelerations the run is given, member by member.
    fn excitations(&self) -> Excitations {
        Excitations::of(self.inputs.excitation.accelerations())
    }

    /// The pins' flexure: D may be given apart from an explicit section.
    fn flexure(&self) -> Flexures {
        kinds::flexures(
            &self.inputs.kinds,
            &self.inputs.pin,
            self.bundle.pin_count(),
            self.inputs.pin_diameter(),
        )
    }

    fn model(&self) -> Model<'_> {
        plane_model(
            &self.inputs,
            self.bundle.pin_count(),
            (&self.contacts, &self.normals),
            (&self.excitation, &self.walls),
            &self.loads,
            (&self.basis, &self.kind_bases),
        )
    }
}

/// The bundle as the integrator sees it: the wire pin is the contact's left body, the
/// touched clad (or the wall) its right body, the normal from left to right; releases
/// and point forces on the pins' x and y lines.
fn plane_model<'a>(
    inputs: &HexInputs,
    pins: usize,
    (contacts, normals): (&[Contact], &[[f64; 2]]),
    ((x, y), walls): (
        &(Option<BaseAcceleration>, Option<BaseAcceleration>),
        &Option<WallMotion>,
    ),
    loads: &PlaneLoads,
    (basis, kind_bases): (&'a ModalBasis, &'a [ModalBasis]),
) -> Model<'a> {
    Model {
        basis,
        pins,
        damping_ratios: inputs.pin.damping_ratios_for(basis.modes()),
        contacts: contacts.to_vec(),
        initial_tip_displacements: loads.initial_tip_displacements.clone(),
        initial_tip_velocities: loads.initial_tip_velocities.clone(),
        base_acceleration: x.clone(),
        point_forces: loads.point_forces.clone(),
        walls: walls.clone(),
        plane: Some(Plane {
            normals: normals.to_vec(),
            base_acceleration_y: y.clone(),
        }),
        kinds: kinds::body_kinds(
            &inputs.kinds,
            &inputs.pin,
            Some(kind_bases),
            basis,
            inputs.pin_diameter(),
        ),
    }
}

/// The results document of `hex-bundle-dynamics`.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct HexResults {
    /// The bundle the inputs describe: counts, clearances, levels.
    pub geometry: GeometryReport,
    /// Every contact (bodies, level, normal, gap) and its statistics, accumulated at
    /// every step.
    pub contacts: Vec<HexContactResult>,
    /// The contact worn deepest after `output.service_time`; absent without wear laws.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_wear_depth: Option<WearDepth>,
    /// Contacts whose force histories were recorded (`c<k>` columns), in column order.
    pub recorded_contacts: Vec<usize>,
    /// Per pin: position and largest deflections along x and y.
    pub pins: Vec<HexPinResult>,
    #[serde(flatten)]
    pub run: RunSummary,
}

/// The generated bundle.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct GeometryReport {
    /// Pins, 3n(n + 1) + 1.
    pub pins: usize,
    pub rings: usize,
    /// Neighbour pairs, 9n² + 3n.
    pub neighbour_pairs: usize,
    /// P (m).
    pub pitch: f64,
    /// D, the clad's outer diameter (m).
    pub pin_diameter: f64,
    /// d_w (m).
    pub wire_diameter: f64,
    /// H (m).
    pub wire_lead: f64,
    /// F, inner flat-to-flat distance of the wrapper (m).
    pub wrapper_flat_to_flat: f64,
    /// Potential contacts over the pin length.
    pub contacts: usize,
    /// Nominal wire-to-clad clearance P − D − d_w (m).
    pub pin_clearance: f64,
    /// Nominal wire-to-wrapper clearance F/2 − n·P·√3/2 − D/2 − d_w (m).
    pub wall_clearance: f64,
    /// Contact levels from the lowest (one every H/12).
    pub levels: Vec<LevelReport>,
}

/// One contact level: where every wire points.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct LevelReport {
    /// Height from the pin feet (m).
    pub height: f64,
    /// Direction of every wire there (degrees, counter-clockwise from +x).
    pub wire_angle: f64,
    /// The lattice direction (0..6) of the neighbours touched, or null on a wall level.
    pub neighbour_direction: Option<usize>,
    /// The flat (0..6) touched by the pins facing it, or null on a pin–pin level.
    pub flat: Option<usize>,
}

/// One contact and its statistics.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct HexContactResult {
    /// Level index (`geometry.levels`).
    pub level: usize,
    /// Height from the pin feet (m).
    pub height: f64,
    /// The pin whose wire touches.
    pub wire_pin: usize,
    /// The pin whose clad is touched; null for a wall contact.
    pub touched_pin: Option<usize>,
    /// The wrapper flat touched; null for a pin–pin contact.
    pub touched_flat: Option<usize>,
    /// Unit normal (x, y) from the wire pin toward what it touches.
    pub normal: [f64; 2],
    /// Gap at rest (m).
    pub gap: f64,
    #[serde(flatten)]
    pub statistics: ContactStatistics,
    /// Wear work rate (1/T) ∫ F·|v_t| dt (W), v_t the sliding velocity across the normal,
    /// over the steps the contact slips when its law has friction (code_aster's
    /// PUIS_USURE), over every closed step without: the P of Archard's wear.
    pub wear_work_rate: f64,
    /// Its friction (absent when its law has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionReport>,
    /// Its Archard wear after `output.service_time` (absent when its law has none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wear: Option<WearReport>,
}

/// One pin's position and largest deflections.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct HexPinResult {
    pub pin: usize,
    /// Its kind's name (`kinds`); absent for `pin`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// Ring (0 = the centre pin).
    pub ring: usize,
    /// Centre (x, y) in the wrapper (m).
    pub position: [f64; 2],
    /// Bending along x.
    pub x: LineExtremes,
    /// Bending along y.
    pub y: LineExtremes,
    /// Its largest resultant deflection √(x² + y²) (m) over the mesh nodes at every
    /// output time, where and when.
    pub deflection: ResultantDeflection,
    /// Its largest bending (the resultant of x and y) over its height and the output
    /// samples.
    pub bending: Bending,
    /// Its utilisations against `output.allowables` (null without them).
    #[serde(flatten)]
    pub utilisation: PinUtilisation,
    /// The resultant contact force at each of its contact heights (wire on a clad, the
    /// neighbours' wires on it, the wrapper), and the largest.
    #[serde(flatten)]
    pub resultants: PinResultants,
}

/// A pin's largest resultant deflection.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct ResultantDeflection {
    /// max √(x² + y²) (m).
    pub max_deflection: f64,
    /// Height where it occurred (m).
    pub height: f64,
    /// When (s): an output sample.
    pub time: f64,
}

impl ResultantDeflection {
    fn of(extreme: &crate::physics::integrate::PinExtreme) -> Self {
        Self {
            max_deflection: extreme.max_abs_deflection,
            height: extreme.height,
            time: extreme.time,
        }
    }
}

/// The `hex-bundle-dynamics` process.
#[derive(Debug, Default)]
pub struct HexBundleDynamics;

impl Simulation for HexBundleDynamics {
    const ID: &'static str = "hex-bundle-dynamics";
    const TITLE: &'static str = "Wire-wrapped hexagonal bundle shaken in the transverse plane";
    const DESCRIPTION: &'static str = "Builds a wire-wrapped hexagonal bundle (7 to 271 identical pins, one shared modal basis \
         bending along x and y) in its wrapper from a dozen numbers: each spacer wire touches a \
         neighbour's clad or the wrapper once every H/12, with its normal in the transverse plane. \
         Integrates it under a base acceleration in any horizontal direction, point forces and tip \
         releases with penalty contacts. \
         Returns every contact with its statistics (peak force, impacts, contact time, impulse, wear \
         work rate), per-pin extremes, the energy balance, force histories of a selection of \
         contacts and the pins' deflection histories.";
    const EXAMPLES: &'static [Example] = &[
        Example {
            file: "hex217.json",
            body: include_str!("../../../examples/hex217.json"),
        },
        Example {
            file: "hex7-loads.json",
            body: include_str!("../../../examples/hex7-loads.json"),
        },
        Example {
            file: "hex7-fretting.json",
            body: include_str!("../../../examples/hex7-fretting.json"),
        },
    ];
    const HISTORIES: &'static [HistoryOutput] = &[
        HistoryOutput {
            name: "contact_forces",
            kind: HistoryKind::Force,
            title: "Contact forces (N)",
            description: "CSV columns time (s), c<k> for each recorded contact k (results recorded_contacts)",
        },
        HistoryOutput {
            name: "displacements",
            kind: HistoryKind::Displacement,
            title: "Pin deflections (m)",
            description: "CSV columns time (s), p<pin>x, p<pin>y, ... (pin tips; `p<pin>x@<height>` for other heights)",
        },
        HistoryOutput {
            name: "contact_forces_peaks",
            kind: HistoryKind::Peaks,
            title: "Contact force peaks (N)",
            description: "As contact_forces, each value the largest force reached at any step of its output interval",
        },
        HistoryOutput {
            name: "displacements_peaks",
            kind: HistoryKind::Peaks,
            title: "Pin deflection peaks (m)",
            description: "As displacements, each value the deflection of largest magnitude (signed) reached at \
                          any step of its output interval",
        },
        run_report::MOMENTS_OUTPUT,
        impact_report::TABLE_OUTPUT,
        excitation_record::OUTPUT,
    ];

    /// Bundles of at least [`MIN_SHARED_STEP_DOFS`] modal DOFs (two lines of `modes`
    /// per pin, the static correction's pseudo-modes aside; `auto` counts as enough).
    fn shares_steps(inputs: &serde_json::Value) -> bool {
        let rings = inputs
            .pointer("/bundle/rings")
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(0);
        let modes = match inputs.pointer("/pin/modes") {
            None => 10,
            Some(serde_json::Value::String(_)) => MIN_SHARED_STEP_DOFS,
            Some(modes) => modes.as_u64().unwrap_or(0),
        };
        let pins = 3 * rings * (rings + 1) + 1;
        (2 * pins).saturating_mul(modes) >= MIN_SHARED_STEP_DOFS
    }

    type Inputs = HexInputs;
    type Results = HexResults;
    type Plan = Plan;

    fn column(output: &str, name: &str, document: &serde_json::Value) -> Option<super::Column> {
        column_of(output, name, document)
    }

    /// A pin's largest deflection is the resultant of x and y (`deflection`); its tip
    /// columns are `p<pin>x` and `p<pin>y`.
    fn note(document: &serde_json::Value) -> super::note_facts::NoteFacts {
        super::note_facts::run_of_pins(
            document,
            &|k| contact_label(document, k),
            super::note_facts::DeflectionMembers {
                value: "/deflection/max_deflection",
                height: "/deflection/height",
                time: "/deflection/time",
            },
            &|pin| vec![format!("p{pin}x"), format!("p{pin}y")],
        )
    }

    fn signals(inputs: &mut HexInputs) -> Vec<super::signal_input::SignalSlot<'_>> {
        inputs.excitation.signal_references()
    }

    fn prepare(inputs: HexInputs) -> Result<Plan, InvalidInputs> {
        let length = inputs.pin.length;
        // `auto` starts from the coarsest mesh with an element between levels (H/6).
        let coarsest = (6.0 * length / inputs.bundle.wire_lead * (1.0 - 1e-9)).ceil();
        let elements = inputs.pin.elements.given().unwrap_or_else(|| {
            let fits = coarsest.is_finite() && coarsest >= 1.0 && coarsest <= auto::MAX_ELEMENTS as f64;
            auto::START_ELEMENTS.max(if fits { coarsest as usize } else { 0 })
        });
        let pin_issues = inputs.pin.validate();
        let pin_ok = pin_issues.is_empty();
        let mut errors: Vec<FieldError> = at("/inputs/pin", pin_issues);

        let diameter = inputs.pin_diameter();
        if diameter.is_none() {
            errors.push(FieldError::new(
                "/inputs/bundle/pin_diameter",
                "is required with an explicit pin section (the clad diameter D)",
            ));
        }
        let bundle = diameter.and_then(|d| match HexBundle::new(inputs.layout(d), length, elements) {
            Ok(bundle) => Some(bundle),
            Err(issues) => {
                errors.extend(geometry_errors(&inputs, issues, pin_ok));
                None
            }
        });
        errors.extend(contact_law_errors(&inputs));
        kinds::check(&inputs.kinds, &inputs.pin, "/inputs/kinds", &mut errors);
        // The wire-wrap geometry is the pin's clad diameter: a kind keeps it.
        for (k, kind) in inputs.kinds.iter().enumerate() {
            if let (SectionInput::Tube { outer_diameter, .. }, Some(d)) = (kind.section, diameter)
                && (outer_diameter - d).abs() > 1e-9 * d
            {
                errors.push(FieldError::new(
                    format!("/inputs/kinds/{k}/section"),
                    format!(
                        "its outer_diameter must be the pins' clad diameter D = {} m: the wire-wrap \
                         geometry is the pin's (another inner diameter, material or mass is a kind)",
                        crate::physics::number(d)
                    ),
                ));
            }
        }
        // D is required above: without it, the stress is refused there, not here.
        let allowables = &inputs.output.allowables;
        allowables.check(
            "/inputs/output/allowables",
            true,
            &inputs.contact.law_allowables(),
            &mut errors,
        );
        errors.extend(
            inputs
                .closure_issues()
                .into_iter()
                .map(|(pointer, reason)| FieldError::new(pointer, reason)),
        );
        let excitation = excitation(&inputs.excitation, &mut errors);
        let walls = wrapper_motion(&inputs.excitation, &excitation, &mut errors);
        let loads = loads::plane_loads(&inputs, &mut errors);
        let solver = common_inputs::solver(&inputs.solver, SolverDefaults::AUTO, &mut errors);
        common_inputs::check_output_interval(inputs.output.interval, &mut errors);
        let counting = impact_report::counting(inputs.output.impacts.as_ref(), inputs.output.blocks);
        errors.extend(impact_report::errors(&counting));
        let heights = output_heights(&inputs, &mut errors);

        let Some(bundle) = bundle else {
            return Err(InvalidInputs(errors));
        };
        let geometry = bundle.contacts();
        let gaps = match inputs.gaps().gaps(&bundle, &geometry) {
            Ok(gaps) => gaps,
            Err(issues) => {
                errors.extend(at("/inputs", issues));
                Vec::new()
            }
        };
        let recorded = recorded_contacts(&inputs, &bundle, &geometry, &mut errors);
        inputs.contact.check_laws(&mut errors, inputs.output.service_time);
        if !errors.is_empty() {
            return Err(InvalidInputs(errors));
        }

        let law = &inputs.contact;
        let contacts: Vec<Contact> = geometry
            .iter()
            .zip(&gaps)
            .map(|(c, gap)| {
                let right = match c.touched {
                    Body::Pin(pin) => RowBody::Pin(pin),
                    Body::Flat(_) => RowBody::Wall,
                };
                let (stiffness, damping, family, _) = law.family(right == RowBody::Wall);
                Contact {
                    left: RowBody::Pin(c.wire_pin),
                    right,
                    height: c.height,
                    gap: *gap,
                    stiffness,
                    damping,
                    law: family.law(),
                }
            })
            .collect();
        let normals: Vec<[f64; 2]> = geometry.iter().map(|c| [c.normal.x, c.normal.y]).collect();
        // One static correction per distinct contact height (one per level), shared by
        // every pin and both directions.
        let levels: Vec<f64> = bundle.levels().iter().map(|l| l.height).collect();
        let (basis, basis_choice) =
            inputs
                .pin
                .basis(&contacts, &levels, solver.tolerance, elements, "/inputs/pin")?;
        let settings = Settings {
            recorded_contacts: Some(recorded),
            impacts: counting,
            ..solver.integration(
                Some(inputs.output.interval.unwrap_or(DEFAULT_OUTPUT_INTERVAL)),
                heights,
            )
        };
        let kind_bases = kinds::bases(&inputs.kinds, &inputs.pin, &basis, &levels, "/inputs/kinds")
            .map_err(InvalidInputs)?;
        let model = plane_model(
            &inputs,
            bundle.pin_count(),
            (&contacts, &normals),
            (&excitation, &walls),
            &loads,
            (&basis, &kind_bases),
        );
        // The kinds' pins and damping (the physics' checks), at their members.
        let kind_issues = match inputs.kinds.is_empty() {
            true => Vec::new(),
            false => model.validate(),
        };
        let refused: Vec<FieldError> = kind_issues
            .into_iter()
            .filter(|issue| issue.field.starts_with("kinds/"))
            .filter_map(|issue| {
                let (_, k, rest) = model_check::split(&issue.field);
                kinds::pointer("/inputs/kinds", k?, rest)
                    .map(|pointer| FieldError::new(pointer, issue.reason))
            })
            .collect();
        if !refused.is_empty() {
            return Err(InvalidInputs(refused));
        }
        // The pins' supports the wrapper's motion cannot carry (a pin held by its top
        // alone): the wrapper's, said at its member.
        if walls.is_some() {
            let refused: Vec<FieldError> = model
                .validate()
                .into_iter()
                .filter(|issue| issue.field.starts_with("walls"))
                .map(|issue| FieldError::new("/inputs/excitation/wrapper_acceleration", issue.reason))
                .collect();
            if !refused.is_empty() {
                return Err(InvalidInputs(refused));
            }
        }
        let step = common_inputs::resolve_step(&model, &settings)?;
        Ok(Plan {
            inputs,
            bundle,
            geometry,
            contacts,
            normals,
            excitation,
            walls,
            loads,
            basis,
            kind_bases,
            basis_choice,
            settings,
            step,
        })
    }

    /// Two lines (x and y) per pin, the recorded contacts' histories
    /// ([`RunSize::estimate`]).
    fn estimate(plan: &Plan) -> WorkEstimate {
        RunSize {
            settings: &plan.settings,
            step: &plan.step,
            choice: plan.basis_choice.as_ref(),
            lines: 2 * plan.bundle.pin_count(),
            modes: plan.basis.modes(),
            contacts: plan.contacts.len(),
            recorded: plan.settings.recorded_contacts.as_ref().map_or(0, Vec::len),
            work_drivers: &["/inputs/bundle/rings", "/inputs/bundle/wire_lead"],
            history_drivers: &["/inputs/output/contacts", "/inputs/bundle/rings"],
            heights_given: plan.inputs.output.heights.is_some(),
        }
        .estimate()
    }

    /// The pin of the bundle (D may be given apart from its section), its contacts'
    /// gaps where the user wrote them.
    fn subject(plan: &Plan) -> Subject<'_> {
        Subject {
            switch: plan.inputs.warnings,
            pin: &plan.inputs.pin,
            pin_pointer: "/inputs/pin",
            diameter: plan
                .inputs
                .bundle
                .pin_diameter
                .map(|d| (d, "/inputs/bundle/pin_diameter")),
            model: plan.model(),
            duration: plan.settings.duration,
            scheme: plan.settings.scheme,
            gap_pointer: Box::new(|k| plan.inputs.gap_pointer(&plan.contacts[k], k)),
            excitation_pointer: "/inputs/excitation",
        }
    }

    fn run(plan: Plan, progress: &mut ProgressFn<'_>) -> Result<Output<HexResults>, RunError> {
        let model = plan.model();
        let assessed = integrate::Plan::with_step(&model, &plan.settings, plan.step)?.run(progress)?;
        let (simulation, quality) = (assessed.simulation, assessed.quality);
        let duration = plan.settings.duration;

        let laws: Vec<&LawInput> = (plan.contacts.iter())
            .map(|c| plan.inputs.contact.family(c.right == RowBody::Wall).2)
            .collect();
        let given = &plan.inputs.output.allowables;
        let allowables: Vec<Option<f64>> = (plan.contacts.iter())
            .map(|c| {
                plan.inputs
                    .contact
                    .allowable_force(c.right == RowBody::Wall, given)
            })
            .collect();
        let allowable_stress = given.stress;
        let service_time = plan.inputs.output.service_time.unwrap_or(0.0);
        let contacts: Vec<HexContactResult> = (plan.geometry.iter().zip(&plan.contacts))
            .zip(ContactStatistics::of_run(&simulation, &allowables))
            .enumerate()
            .map(|(k, ((g, c), statistics))| {
                let wear_work_rate = simulation.wear_work.get(k).copied().unwrap_or(0.0) / duration;
                HexContactResult {
                    level: g.level,
                    height: g.height,
                    wire_pin: g.wire_pin,
                    touched_pin: g.touched_pin(),
                    touched_flat: match g.touched {
                        Body::Flat(flat) => Some(flat.index()),
                        Body::Pin(_) => None,
                    },
                    normal: [g.normal.x, g.normal.y],
                    gap: c.gap,
                    wear_work_rate,
                    friction: c.law.friction.is_on().then(|| {
                        FrictionReport::of(
                            &simulation.friction_statistics[k],
                            statistics.contact_time,
                            duration,
                        )
                    }),
                    wear: (laws[k].wear.as_ref())
                        .map(|wear| WearReport::of(wear, wear_work_rate, service_time)),
                    statistics,
                }
            })
            .collect();
        let max_wear_depth = contacts
            .iter()
            .enumerate()
            .filter_map(|(contact, c)| {
                c.wear.map(|w| WearDepth {
                    contact,
                    depth: w.depth,
                })
            })
            .max_by(|a, b| a.depth.total_cmp(&b.depth));
        let pin_count = plan.bundle.pin_count();
        let heights = &plan.settings.output_heights;
        let flexure = plan.flexure();
        let mut resultants = PinResultants::by_pin(&simulation, pin_count).into_iter();
        let pins: Vec<HexPinResult> = (0..pin_count)
            .map(|p| {
                let position = plan.bundle.position(p);
                let bending = flexure.bending(&simulation.pin_curvatures[p]);
                let on_pin = (contacts.iter())
                    .filter(|c| c.wire_pin == p || c.touched_pin == Some(p))
                    .map(|c| c.statistics.utilisation);
                HexPinResult {
                    pin: p,
                    kind: kinds::name_of(&plan.inputs.kinds, p),
                    ring: plan.bundle.lattice().ring(p),
                    position: [position.x, position.y],
                    x: LineExtremes::of_line(&simulation, heights, p),
                    y: LineExtremes::of_line(&simulation, heights, pin_count + p),
                    deflection: ResultantDeflection::of(&simulation.resultant_extremes[p]),
                    utilisation: PinUtilisation::of(&bending, allowable_stress, on_pin),
                    bending,
                    resultants: resultants.next().expect("one per pin"),
                }
            })
            .collect();
        let basis = BasisReport::of(
            &model,
            plan.settings.scheme,
            simulation.step.critical_time_step,
            (&plan.inputs.pin, plan.basis_choice.as_ref()),
        );
        let results = HexResults {
            geometry: geometry_report(&plan.bundle, plan.geometry.len()),
            contacts,
            max_wear_depth,
            recorded_contacts: plan.settings.recorded_contacts.clone().unwrap_or_default(),
            pins,
            run: RunSummary::of(
                &simulation,
                quality,
                &plan.settings,
                (&allowables, allowable_stress),
                (basis, plan.basis.frequencies_hz()),
                &flexure,
                &plan.excitations(),
            ),
        };
        let histories = histories(&plan, simulation);
        Ok(Output { results, histories })
    }
}

/// The layout's issues at the user's pointers: the geometry under `/inputs/bundle`, D at
/// the field that gave it, the pin's length and elements under `/inputs/pin` (unless the
/// pin's own checks already refused them).
fn geometry_errors(inputs: &HexInputs, issues: Vec<InputIssue>, pin_ok: bool) -> Vec<FieldError> {
    issues
        .into_iter()
        .filter_map(|issue| {
            let pointer = match issue.field.as_str() {
                "pin_length" | "elements" if !pin_ok => return None,
                "pin_length" => "/inputs/pin/length".to_owned(),
                "elements" => "/inputs/pin/elements".to_owned(),
                "pin_diameter" if inputs.bundle.pin_diameter.is_none() => {
                    "/inputs/pin/section/outer_diameter".to_owned()
                }
                field => format!("/inputs/bundle/{field}"),
            };
            Some(FieldError::new(pointer, issue.reason))
        })
        .collect()
}

fn contact_law_errors(inputs: &HexInputs) -> Vec<FieldError> {
    let law = &inputs.contact;
    let mut issues = Vec::new();
    require_non_negative(&mut issues, "stiffness", law.stiffness);
    require_non_negative(&mut issues, "damping", law.damping);
    if let Some(k) = law.wall_stiffness {
        require_non_negative(&mut issues, "wall_stiffness", k);
    }
    if let Some(c) = law.wall_damping {
        require_non_negative(&mut issues, "wall_damping", c);
    }
    at("/inputs/contact", issues)
}

/// The (x, y) components of the base acceleration, or the errors: one signal with an
/// optional direction, or two components, not both.
fn excitation(
    input: &HexExcitationInput,
    errors: &mut Vec<FieldError>,
) -> (Option<BaseAcceleration>, Option<BaseAcceleration>) {
    plane_signal(
        PlaneSignal {
            single: ("base_acceleration", &input.base_acceleration),
            direction: ("direction", input.direction, input.direction.is_some()),
            x: ("base_acceleration_x", &input.base_acceleration_x),
            y: ("base_acceleration_y", &input.base_acceleration_y),
        },
        errors,
    )
}

/// The wrapper's own motion, when given: its (x, y) components as for the base (the
/// direction defaults to the base's), a component not given following the feet.
fn wrapper_motion(
    input: &HexExcitationInput,
    base: &(Option<BaseAcceleration>, Option<BaseAcceleration>),
    errors: &mut Vec<FieldError>,
) -> Option<WallMotion> {
    let given = input.wrapper_acceleration.is_some()
        || input.wrapper_acceleration_x.is_some()
        || input.wrapper_acceleration_y.is_some();
    if !given {
        if input.wrapper_direction.is_some() {
            errors.push(FieldError::new(
                "/inputs/excitation/wrapper_direction",
                "is the direction of wrapper_acceleration, which is not given",
            ));
        }
        return None;
    }
    let (x, y) = plane_signal(
        PlaneSignal {
            single: ("wrapper_acceleration", &input.wrapper_acceleration),
            direction: (
                "wrapper_direction",
                input.wrapper_direction.or(input.direction),
                input.wrapper_direction.is_some(),
            ),
            x: ("wrapper_acceleration_x", &input.wrapper_acceleration_x),
            y: ("wrapper_acceleration_y", &input.wrapper_acceleration_y),
        },
        errors,
    );
    let single = input.wrapper_acceleration.is_some();
    let follow = |own: Option<BaseAcceleration>, given: bool, base: &Option<BaseAcceleration>| {
        if given || single { own } else { base.clone() }
    };
    Some(WallMotion::rigid(
        follow(x, input.wrapper_acceleration_x.is_some(), &base.0),
        follow(y, input.wrapper_acceleration_y.is_some(), &base.1),
    ))
}

fn output_heights(inputs: &HexInputs, errors: &mut Vec<FieldError>) -> Vec<f64> {
    let length = inputs.pin.length;
    let heights = inputs.output.heights.clone().unwrap_or_else(|| vec![length]);
    if heights.is_empty() {
        errors.push(FieldError::new(
            "/inputs/output/heights",
            "must list at least one height",
        ));
    }
    for (k, h) in heights.iter().enumerate() {
        if !(h.is_finite() && (0.0..=length).contains(h)) {
            errors.push(FieldError::new(
                format!("/inputs/output/heights/{k}"),
                format!("must be within the pin, 0 to {length} m"),
            ));
        }
    }
    heights
}

/// The contacts `output.contacts` selects, in contact order (a list keeps its order).
fn recorded_contacts(
    inputs: &HexInputs,
    bundle: &HexBundle,
    contacts: &[HexContact],
    errors: &mut Vec<FieldError>,
) -> Vec<usize> {
    let pointer = "/inputs/output/contacts";
    let selection = inputs
        .output
        .contacts
        .clone()
        .unwrap_or(ContactSelectionInput::Walls {});
    let indices = |keep: &dyn Fn(&HexContact) -> bool| -> Vec<usize> {
        contacts
            .iter()
            .enumerate()
            .filter(|(_, c)| keep(c))
            .map(|(k, _)| k)
            .collect()
    };
    let mut range = |first: usize, last: usize, count: usize, what: &str| -> bool {
        let mut ok = true;
        for (end, index) in [("first", first), ("last", last)] {
            if index >= count {
                errors.push(FieldError::new(
                    format!("{pointer}/{end}"),
                    format!(
                        "{what} {index} is outside the bundle: must be ≤ {} ({count} {what}s, from 0)",
                        count.saturating_sub(1)
                    ),
                ));
                ok = false;
            }
        }
        if first > last {
            errors.push(FieldError::new(
                format!("{pointer}/last"),
                format!("must be ≥ first ({first}), got {last}"),
            ));
            ok = false;
        }
        ok
    };
    match selection {
        ContactSelectionInput::All {} => (0..contacts.len()).collect(),
        ContactSelectionInput::None {} => Vec::new(),
        ContactSelectionInput::Walls {} => indices(&|c| matches!(c.touched, Body::Flat(_))),
        ContactSelectionInput::List { contacts: list } => {
            for (i, k) in list.iter().enumerate() {
                if *k >= contacts.len() {
                    errors.push(FieldError::new(
                        format!("{pointer}/contacts/{i}"),
                        format!(
                            "contact {k} does not exist: the bundle has {} contacts (0..{})",
                            contacts.len(),
                            contacts.len().saturating_sub(1)
                        ),
                    ));
                }
            }
            list
        }
        ContactSelectionInput::Levels { first, last } => {
            if range(first, last, bundle.levels().len(), "level") {
                indices(&|c| (first..=last).contains(&c.level))
            } else {
                Vec::new()
            }
        }
        ContactSelectionInput::Rings { first, last } => {
            if range(first, last, bundle.layout().rings + 1, "ring") {
                let lattice = bundle.lattice();
                let in_rings = |pin: usize| (first..=last).contains(&lattice.ring(pin));
                indices(&|c| in_rings(c.wire_pin) || c.touched_pin().is_some_and(in_rings))
            } else {
                Vec::new()
            }
        }
    }
}

fn geometry_report(bundle: &HexBundle, contacts: usize) -> GeometryReport {
    let layout = bundle.layout();
    let rings = layout.rings;
    GeometryReport {
        pins: bundle.pin_count(),
        rings,
        neighbour_pairs: pair_count(rings),
        pitch: layout.pitch,
        pin_diameter: layout.pin_diameter,
        wire_diameter: layout.wire_diameter,
        wire_lead: layout.wire_lead,
        wrapper_flat_to_flat: layout.wrapper_flat_to_flat,
        contacts,
        pin_clearance: bundle.pin_clearance(),
        wall_clearance: bundle.wall_clearance(),
        levels: bundle
            .levels()
            .iter()
            .map(|level| LevelReport {
                height: level.height,
                wire_angle: level.aim.twelfth() as f64 * 30.0,
                neighbour_direction: match level.aim {
                    Aim::Neighbour(direction) => Some(direction.index()),
                    Aim::Flat(_) => None,
                },
                flat: match level.aim {
                    Aim::Flat(flat) => Some(flat.index()),
                    Aim::Neighbour(_) => None,
                },
            })
            .collect(),
    }
}

fn histories(plan: &Plan, simulation: integrate::Simulation) -> Vec<History> {
    let tips_only = plan.inputs.output.heights.is_none();
    let pins = plan.bundle.pin_count();
    let deflections = run_report::deflection_names(
        &plan.settings.output_heights,
        2 * pins,
        tips_only,
        |line| match line < pins {
            true => format!("p{line}x"),
            false => format!("p{}y", line - pins),
        },
    );
    let contacts: Vec<String> = (plan.settings.recorded_contacts.iter().flatten())
        .map(|k| format!("c{k}"))
        .collect();
    run_report::histories(
        simulation,
        &contacts,
        &deflections,
        &plan.flexure(),
        &plan.excitations(),
    )
}

/// A column of `hex-bundle-dynamics`: `c<k>` the force (N, along the contact's normal) of
/// contact k of the results' `contacts`, `p<pin><x|y>[@<height>]` a pin's deflection (m).
fn column_of(output: &str, name: &str, document: &serde_json::Value) -> Option<super::Column> {
    let description = match output.trim_end_matches("_peaks") {
        "contact_forces" => {
            let contact = &document["contacts"][columns::contact_index(name)?];
            let height = contact["height"].as_f64()?;
            let wire = contact["wire_pin"].as_u64()?;
            let touched = match (contact["touched_pin"].as_u64(), contact["touched_flat"].as_u64()) {
                (Some(pin), _) => format!("the clad of p{pin}"),
                (None, Some(flat)) => format!("wrapper flat {flat}"),
                (None, None) => return None,
            };
            (
                "N",
                format!(
                    "contact of p{wire}'s wire on {touched} at {}",
                    columns::metres(height)
                ),
            )
        }
        "displacements" => {
            let (pin, axis, at) = columns::deflection(name, true)?;
            (
                "m",
                format!(
                    "deflection of p{pin} along {} at {at}, relative to the pin feet",
                    axis.unwrap_or('x')
                ),
            )
        }
        "bending_moments" => {
            let (pin, axis, at) = columns::deflection(name, true)?;
            (
                "N·m",
                format!(
                    "bending moment EI w'' of p{pin} bending along {} at {at}",
                    axis.unwrap_or('x')
                ),
            )
        }
        "excitation" => ("m/s²", excitation_record::column_description(name, document)),
        _ => return None,
    };
    Some(super::Column::new(
        name,
        description.0,
        columns::of_output(output, description.1),
    ))
}

/// Contact k in words, as its force history's column describes it.
fn contact_label(document: &serde_json::Value, k: usize) -> String {
    column_of("contact_forces", &format!("c{k}"), document)
        .and_then(|column| column.description)
        .unwrap_or_else(|| format!("contact {k}"))
}

#[cfg(test)]
mod tests;
