//! Process `bundle-dynamics`: a row of identical pins (one shared modal basis) between
//! two wrapper walls, with point contacts at given heights, shaken by the wrapper or
//! released from bent shapes. The generator form is expanded to the explicit contact
//! list, which the results echo.

/// The inputs of `bundle-dynamics`: the explicit row or its generator.
pub mod inputs;

use serde::Serialize;
use utoipa::ToSchema;

use super::basis_report::BasisReport;
use super::bending::{Bending, Flexures};
use super::columns;
use super::common_inputs::{self, SolverDefaults, at};
use super::contact_law::LawInput;
use super::excitation::BaseAccelerationInput;
use super::excitation_record::{self, Excitations};
use super::impact_report;
use super::kinds;
use super::margins::PinUtilisation;
use super::model_check::{self, StandIn};
use super::resultants::PinResultants;
use super::run_report::{self, ContactStatistics, LineExtremes, RunSize, RunSummary};
use super::simulation::{HistoryKind, HistoryOutput, Output, Simulation};
use super::warnings::Subject;
use super::{Example, FieldError, History, InvalidInputs, ProgressFn, RunError, WorkEstimate};
use crate::physics::contact::{Body, Contact};
use crate::physics::discretisation::auto::Choice as BasisChoice;
use crate::physics::integrate::{self, Model, Settings, Simulation as Run, StepSize};
use crate::physics::modal::ModalBasis;
use inputs::{BodyInput, BundleInputs, ContactInput};

/// Most pins in one row.
pub const MAX_PINS: usize = 2000;
/// Default history interval (s).
pub const DEFAULT_OUTPUT_INTERVAL: f64 = 1e-4;

/// Validated inputs, ready to run.
#[derive(Debug)]
pub struct Plan {
    inputs: BundleInputs,
    pins: usize,
    contacts: Vec<Contact>,
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

    fn flexure(&self) -> Flexures {
        kinds::flexures(&self.inputs.kinds, &self.inputs.pin, self.pins, None)
    }

    fn model(&self) -> Model<'_> {
        row_model(
            &self.inputs,
            self.pins,
            &self.contacts,
            (&self.basis, Some(&self.kind_bases)),
        )
    }
}

/// The row as the integrator sees it, on the pin's basis and each kind's (the pin's
/// for every kind when they are not built yet: the model's checks).
fn row_model<'a>(
    inputs: &BundleInputs,
    pins: usize,
    contacts: &[Contact],
    (basis, kind_bases): (&'a ModalBasis, Option<&'a [ModalBasis]>),
) -> Model<'a> {
    Model {
        basis,
        pins,
        damping_ratios: inputs.pin.damping_ratios_for(basis.modes()),
        contacts: contacts.to_vec(),
        initial_tip_displacements: inputs.initial.tip_displacements.clone(),
        initial_tip_velocities: inputs.initial.tip_velocities.clone(),
        base_acceleration: inputs.excitation.base_acceleration.as_ref().map(|b| b.physics()),
        walls: inputs.excitation.walls(),
        plane: None,
        point_forces: inputs
            .excitation
            .point_forces
            .iter()
            .map(|f| f.physics())
            .collect(),
        kinds: kinds::body_kinds(&inputs.kinds, &inputs.pin, kind_bases, basis, None),
    }
}

/// Where the user wrote what a path of the row's model or settings names: `contacts/k/…`
/// in `contacts` (the generator's expansion is checked as `bundle`), the release in
/// `initial`, the loads in `excitation`, the recorded heights in `output` (the pin tips
/// by default: its length). `None` for a contact's body when the pin count itself is
/// refused: that is the cause.
fn pointer_of(inputs: &BundleInputs, path: &str, pins_refused: bool) -> Option<String> {
    let generated = inputs.bundle.is_some();
    let pointer = match model_check::split(path) {
        ("pins", None, "") if generated => "/inputs/bundle/pins".to_owned(),
        ("pins", None, "") => "/inputs/pins".to_owned(),
        ("damping_ratios", mode, _) => model_check::damping_ratio_pointer(&inputs.pin, "/inputs/pin", mode),
        ("kinds", Some(k), rest) => return kinds::pointer("/inputs/kinds", k, rest),
        ("contacts", Some(k), rest) if generated && (rest == "law" || rest.starts_with("law/")) => {
            let generator = inputs.bundle.as_ref().expect("generated");
            // Expanded level by level: wall–0, 0–1, …, (n−1)–wall.
            let place = k % (generator.pins + 1);
            let (_, pointer) = generator.families().of(place == 0 || place == generator.pins);
            let member = rest.strip_prefix("law").unwrap_or(rest).trim_start_matches('/');
            model_check::join(pointer, member)
        }
        ("contacts", Some(_), _) if generated => "/inputs/bundle".to_owned(),
        ("contacts", Some(_), "left" | "right") if pins_refused => return None,
        ("contacts", Some(k), rest) => model_check::join(&format!("/inputs/contacts/{k}"), rest),
        ("initial_tip_displacements", None, "") => "/inputs/initial/tip_displacements".to_owned(),
        ("initial_tip_displacements", Some(p), "") => format!("/inputs/initial/tip_displacements/{p}"),
        ("initial_tip_velocities", None, "") => "/inputs/initial/tip_velocities".to_owned(),
        ("initial_tip_velocities", Some(p), "") => format!("/inputs/initial/tip_velocities/{p}"),
        ("base_acceleration", _, _)
            if inputs
                .excitation
                .base_acceleration
                .as_ref()
                .is_some_and(BaseAccelerationInput::is_checked_apart) =>
        {
            return None;
        }
        ("base_acceleration", _, _) => model_check::join("/inputs/excitation", path),
        ("walls", None, "") => match inputs
            .excitation
            .wall_member(false)
            .or(inputs.excitation.wall_member(true))
        {
            Some((member, _)) => format!("/inputs/excitation/{member}"),
            None => "/inputs/excitation".to_owned(),
        },
        ("walls", None, rest) => {
            let (channel, rest) = rest.split_once('/').unwrap_or((rest, ""));
            let excitation = &inputs.excitation;
            match excitation.wall_member(channel == "right_x") {
                Some((_, signal)) if !rest.is_empty() && signal.is_checked_apart() => return None,
                Some((member, _)) => model_check::join(&format!("/inputs/excitation/{member}"), rest),
                // A wall following the feet: a problem of its signal is the base's,
                // reported there; one of its motion, the other wall's.
                None if !rest.is_empty() => return None,
                None => match excitation.wall_member(channel != "right_x") {
                    Some((member, _)) => format!("/inputs/excitation/{member}"),
                    None => "/inputs/excitation".to_owned(),
                },
            }
        }
        // The row's line p is pin p, which the request names.
        ("point_forces", Some(k), "line") => format!("/inputs/excitation/point_forces/{k}/pin"),
        ("point_forces", Some(k), rest) => {
            model_check::join(&format!("/inputs/excitation/point_forces/{k}"), rest)
        }
        ("output_heights", Some(_), "") if inputs.output.heights.is_none() => "/inputs/pin/length".to_owned(),
        ("output_heights", Some(k), "") => format!("/inputs/output/heights/{k}"),
        _ => return Some(model_check::settings_pointer(path).unwrap_or_else(|| "/inputs".to_owned())),
    };
    Some(pointer)
}

/// The results document of `bundle-dynamics`.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct BundleResults {
    /// Every contact (the expanded list for the generator form) and its statistics,
    /// accumulated at every step.
    pub contacts: Vec<ContactResult>,
    /// Per pin, its largest deflection.
    pub pins: Vec<PinResult>,
    #[serde(flatten)]
    pub run: RunSummary,
    /// The generator form's expansion (absent for the explicit form).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expansion: Option<Expansion>,
}

/// One contact and its statistics.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ContactResult {
    #[serde(flatten)]
    pub contact: ContactInput,
    #[serde(flatten)]
    pub statistics: ContactStatistics,
}

/// One pin's largest deflections and bending.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct PinResult {
    pub pin: usize,
    /// Its kind's name (`kinds`); absent for `pin`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    #[serde(flatten)]
    pub extremes: LineExtremes,
    /// Its largest bending over its height and the output samples.
    pub bending: Bending,
    /// Its utilisations against `output.allowables` (null without them).
    #[serde(flatten)]
    pub utilisation: PinUtilisation,
    /// The resultant contact force at each of its contact heights, and the largest.
    #[serde(flatten)]
    pub resultants: PinResultants,
}

/// The explicit model the generator form expands to.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct Expansion {
    pub pins: usize,
    pub contacts: Vec<ContactInput>,
}

impl ContactInput {
    /// Contact `c` in the explicit form, with its law as the user gave it.
    fn echo(c: &Contact, law: LawInput) -> Self {
        ContactInput {
            left: BodyInput::from(c.left),
            right: BodyInput::from(c.right),
            height: c.height,
            gap: c.gap,
            stiffness: c.stiffness,
            damping: c.damping,
            law,
        }
    }
}

/// The `bundle-dynamics` process.
#[derive(Debug, Default)]
pub struct BundleDynamics;

impl Simulation for BundleDynamics {
    const ID: &'static str = "bundle-dynamics";
    const TITLE: &'static str = "Row of pins rattling between two wrapper walls";
    const DESCRIPTION: &'static str = "Integrates a row of identical pins (one shared modal basis) with penalty point contacts between \
         pins and against the walls, under a base acceleration of the wrapper, initial releases and point \
         forces. Returns per-contact statistics (peak force, impacts, contact time, impulse), per-pin \
         extremes, the energy balance, and contact-force and deflection histories.";
    const EXAMPLES: &'static [Example] = &[
        Example {
            file: "bundle-row17.json",
            body: include_str!("../../../examples/bundle-row17.json"),
        },
        Example {
            file: "bundle-row17-proven.json",
            body: include_str!("../../../examples/bundle-row17-proven.json"),
        },
        Example {
            file: "bundle-guide-tube.json",
            body: include_str!("../../../examples/bundle-guide-tube.json"),
        },
        Example {
            file: "bundle-random-gaps.json",
            body: include_str!("../../../examples/bundle-random-gaps.json"),
        },
        Example {
            file: "bundle-local-closure.json",
            body: include_str!("../../../examples/bundle-local-closure.json"),
        },
        Example {
            file: "bundle-sine-auto.json",
            body: include_str!("../../../examples/bundle-sine-auto.json"),
        },
        Example {
            file: "bundle-minimal-sine.json",
            body: include_str!("../../../examples/bundle-minimal-sine.json"),
        },
        Example {
            file: "bundle-minimal-table.json",
            body: include_str!("../../../examples/bundle-minimal-table.json"),
        },
        Example {
            file: "bundle-haversine.json",
            body: include_str!("../../../examples/bundle-haversine.json"),
        },
        Example {
            file: "bundle-earthquake.json",
            body: include_str!("../../../examples/bundle-earthquake.json"),
        },
        Example {
            file: "bundle-row12-shock.json",
            body: include_str!("../../../examples/bundle-row12-shock.json"),
        },
        Example {
            file: "sdnl104c.json",
            body: include_str!("../../../examples/sdnl104c.json"),
        },
        Example {
            file: "sdnl301a.json",
            body: include_str!("../../../examples/sdnl301a.json"),
        },
    ];
    const HISTORIES: &'static [HistoryOutput] = &[
        HistoryOutput {
            name: "contact_forces",
            kind: HistoryKind::Force,
            title: "Contact forces (N)",
            description: "CSV columns time (s), c0, c1, ... in contact order",
        },
        HistoryOutput {
            name: "displacements",
            kind: HistoryKind::Displacement,
            title: "Pin deflections (m)",
            description: "CSV columns time (s), p0, p1, ... (pin tips; `p<pin>@<height>` for other heights)",
        },
        HistoryOutput {
            name: "contact_forces_peaks",
            kind: HistoryKind::Peaks,
            title: "Contact force peaks (N)",
            description: "As contact_forces, each value the largest force reached at any step of its output \
                          interval: the maximum of column c<k> is contact k's max_force",
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

    type Inputs = BundleInputs;
    type Results = BundleResults;
    type Plan = Plan;

    fn column(output: &str, name: &str, document: &serde_json::Value) -> Option<super::Column> {
        column_of(output, name, document)
    }

    /// A row's pins keep their largest deflection at their top level (`LineExtremes`);
    /// their tip columns are `p<pin>`.
    fn note(document: &serde_json::Value) -> super::note_facts::NoteFacts {
        super::note_facts::run_of_pins(
            document,
            &|k| contact_label(document, k),
            super::note_facts::DeflectionMembers {
                value: "/max_abs_deflection",
                height: "/height",
                time: "/time",
            },
            &|pin| vec![format!("p{pin}")],
        )
    }

    fn signals(inputs: &mut BundleInputs) -> Vec<super::signal_input::SignalSlot<'_>> {
        inputs.excitation.signal_references()
    }

    fn prepare(inputs: BundleInputs) -> Result<Plan, InvalidInputs> {
        let length = inputs.pin.length;
        let mut errors: Vec<FieldError> = at("/inputs/pin", inputs.pin.validate());

        let (pins, contacts) = match (&inputs.bundle, inputs.pins, &inputs.contacts) {
            (Some(generator), None, None) => {
                let layout = generator.layout();
                generator.families().check(&mut errors);
                generator.families().refuse_wear_in_a_row(&mut errors);
                match layout.expand(length) {
                    Ok(mut contacts) => {
                        for contact in &mut contacts {
                            let wall = contact.left == Body::Wall || contact.right == Body::Wall;
                            contact.law = generator.families().of(wall).0.law();
                        }
                        (generator.pins, contacts)
                    }
                    Err(issues) => {
                        errors.extend(at("/inputs/bundle", issues));
                        (generator.pins, vec![])
                    }
                }
            }
            (None, Some(pins), contacts) => {
                if !(1..=MAX_PINS).contains(&pins) {
                    errors.push(FieldError::new(
                        "/inputs/pins",
                        format!("must be between 1 and {MAX_PINS}"),
                    ));
                }
                for (k, contact) in contacts.iter().flatten().enumerate() {
                    let pointer = format!("/inputs/contacts/{k}/law");
                    contact.law.check(&pointer, &mut errors);
                    contact.law.refuse_wear_in_a_row(&pointer, &mut errors);
                }
                let contacts = contacts.iter().flatten().map(ContactInput::contact).collect();
                (pins, contacts)
            }
            (Some(_), _, _) => {
                let field = if inputs.pins.is_some() {
                    "/inputs/pins"
                } else {
                    "/inputs/contacts"
                };
                return Err(InvalidInputs(vec![FieldError::new(
                    field,
                    "give either `pins` and `contacts`, or `bundle`, not both",
                )]));
            }
            (None, None, _) => {
                return Err(InvalidInputs(vec![FieldError::new(
                    "/inputs/pins",
                    "is required (or use the `bundle` generator form)",
                )]));
            }
        };
        let fibre = super::bending::Flexure::fibre(&inputs.pin, None).is_some();
        kinds::check(&inputs.kinds, &inputs.pin, "/inputs/kinds", &mut errors);
        inputs.check_allowables(&contacts, fibre, &mut errors);
        if inputs.bundle.is_some() && pins > MAX_PINS {
            errors.push(FieldError::new(
                "/inputs/bundle/pins",
                format!("must be at most {MAX_PINS}"),
            ));
        }

        let solver = common_inputs::solver(&inputs.solver, SolverDefaults::AUTO, &mut errors);
        common_inputs::check_output_interval(inputs.output.interval, &mut errors);
        let heights = inputs.output.heights.clone().unwrap_or_else(|| vec![length]);
        if heights.is_empty() {
            errors.push(FieldError::new(
                "/inputs/output/heights",
                "must list at least one height",
            ));
        }
        let interval = inputs.output.interval.unwrap_or(DEFAULT_OUTPUT_INTERVAL);
        let mut settings = solver.integration(Some(interval), heights);
        settings.impacts = impact_report::counting(inputs.output.impacts.as_ref(), inputs.output.blocks);
        // A synthetic record is checked (and generated) as its inputs, a stored signal was
        // checked when uploaded; the model then sees their tables, whose problems would
        // only restate these.
        let excitation = &inputs.excitation;
        for (member, signal) in [
            ("base_acceleration", &excitation.base_acceleration),
            ("wall_acceleration", &excitation.wall_acceleration),
            ("left_wall_acceleration", &excitation.left_wall_acceleration),
            ("right_wall_acceleration", &excitation.right_wall_acceleration),
        ] {
            if let Some(signal) = signal
                && signal.is_checked_apart()
            {
                errors.extend(at(&format!("/inputs/excitation/{member}"), signal.validate()));
            }
        }
        if excitation.wall_acceleration.is_some() {
            for (member, signal) in [
                ("left_wall_acceleration", &excitation.left_wall_acceleration),
                ("right_wall_acceleration", &excitation.right_wall_acceleration),
            ] {
                if signal.is_some() {
                    errors.push(FieldError::new(
                        format!("/inputs/excitation/{member}"),
                        "give either wall_acceleration (both walls) or each wall's own, not both",
                    ));
                }
            }
        }
        let stand_in = StandIn::of(&inputs.pin);
        let pins_refused = errors.iter().any(|e| e.pointer.ends_with("/pins"));
        model_check::check(
            &stand_in,
            &row_model(&inputs, pins, &contacts, (&stand_in.basis, None)),
            &settings,
            |path| pointer_of(&inputs, path, pins_refused),
            &mut errors,
        );
        if !errors.is_empty() {
            return Err(InvalidInputs(errors));
        }

        // One static correction per distinct contact height, shared by every pin.
        let contact_heights: Vec<f64> = contacts.iter().map(|c| c.height).collect();
        let (basis, basis_choice) =
            inputs
                .pin
                .basis(&contacts, &contact_heights, settings.tolerance, 0, "/inputs/pin")?;
        let kind_bases = kinds::bases(
            &inputs.kinds,
            &inputs.pin,
            &basis,
            &contact_heights,
            "/inputs/kinds",
        )
        .map_err(InvalidInputs)?;
        let model = row_model(&inputs, pins, &contacts, (&basis, Some(&kind_bases)));
        let step = common_inputs::resolve_step(&model, &settings)?;
        Ok(Plan {
            inputs,
            pins,
            contacts,
            basis,
            kind_bases,
            basis_choice,
            settings,
            step,
        })
    }

    /// One line per pin, every contact recorded ([`RunSize::estimate`]).
    fn estimate(plan: &Plan) -> WorkEstimate {
        let (pins, contacts) = match plan.inputs.bundle.is_some() {
            true => ("/inputs/bundle/pins", "/inputs/bundle/levels"),
            false => ("/inputs/pins", "/inputs/contacts"),
        };
        RunSize {
            settings: &plan.settings,
            step: &plan.step,
            choice: plan.basis_choice.as_ref(),
            lines: plan.pins,
            modes: plan.basis.modes(),
            contacts: plan.contacts.len(),
            recorded: plan.contacts.len(),
            work_drivers: &[pins, contacts],
            history_drivers: &[pins],
            heights_given: plan.inputs.output.heights.is_some(),
        }
        .estimate()
    }

    fn metrics(document: &serde_json::Value) -> Vec<(String, serde_json::Value)> {
        bundle_metrics(document)
    }

    /// The pin of the row, its contacts' gaps where the user wrote them.
    fn subject(plan: &Plan) -> Subject<'_> {
        Subject {
            switch: plan.inputs.warnings,
            pin: &plan.inputs.pin,
            pin_pointer: "/inputs/pin",
            diameter: None,
            model: plan.model(),
            duration: plan.settings.duration,
            scheme: plan.settings.scheme,
            gap_pointer: Box::new(|k| plan.inputs.gap_pointer(&plan.contacts[k], k)),
            excitation_pointer: "/inputs/excitation",
        }
    }

    fn run(plan: Plan, progress: &mut ProgressFn<'_>) -> Result<Output<BundleResults>, RunError> {
        let model = plan.model();
        let assessed = integrate::Plan::with_step(&model, &plan.settings, plan.step)?.run(progress)?;
        let (simulation, quality) = (assessed.simulation, assessed.quality);

        let laws: Vec<LawInput> = (plan.contacts.iter().enumerate())
            .map(|(k, c)| plan.inputs.law_of(c, k).0)
            .collect();
        let allowables = plan.inputs.allowable_forces(&plan.contacts, &laws);
        let allowable_stress = plan.inputs.output.allowables.stress;
        let contacts: Vec<ContactResult> = (plan.contacts.iter().zip(&laws))
            .zip(ContactStatistics::of_run(&simulation, &allowables))
            .map(|((c, law), statistics)| ContactResult {
                contact: ContactInput::echo(c, *law),
                statistics,
            })
            .collect();
        let heights = &plan.settings.output_heights;
        let flexure = plan.flexure();
        let mut resultants = PinResultants::by_pin(&simulation, plan.pins).into_iter();
        let pins: Vec<PinResult> = (0..plan.pins)
            .map(|p| {
                let bending = flexure.bending(&simulation.pin_curvatures[p]);
                let on_pin = (contacts.iter())
                    .filter(|c| [c.contact.left, c.contact.right].contains(&BodyInput::Pin(p)))
                    .map(|c| c.statistics.utilisation);
                PinResult {
                    pin: p,
                    kind: kinds::name_of(&plan.inputs.kinds, p),
                    extremes: LineExtremes::of_line(&simulation, heights, p),
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
        let results = BundleResults {
            contacts,
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
            expansion: plan.inputs.bundle.is_some().then(|| Expansion {
                pins: plan.pins,
                contacts: plan
                    .contacts
                    .iter()
                    .zip(&laws)
                    .map(|(c, law)| ContactInput::echo(c, *law))
                    .collect(),
            }),
        };
        let histories = histories(&plan, simulation);
        Ok(Output { results, histories })
    }
}

/// Sweep columns: the scalars of the document, plus the peak force of each contact
/// (`contacts.<k>.max_force`, N) and the largest deflection of each pin
/// (`pins.<p>.max_abs_deflection`, m), and with allowables their utilisations
/// (`contacts.<k>.utilisation`, `pins.<p>.utilisation`).
fn bundle_metrics(document: &serde_json::Value) -> Vec<(String, serde_json::Value)> {
    let mut metrics = super::metrics::flatten_scalars(document);
    let entries = |list: &str, field: &str| {
        document[list]
            .as_array()
            .map(|items| {
                items
                    .iter()
                    .enumerate()
                    .map(|(k, item)| (format!("{list}.{k}.{field}"), item[field].clone()))
                    .collect::<Vec<_>>()
            })
            .unwrap_or_default()
    };
    metrics.extend(entries("contacts", "max_force"));
    metrics.extend(entries("pins", "max_abs_deflection"));
    // With allowables (docs/margins.md), each contact's and pin's utilisation.
    let given = |(_, value): &(String, serde_json::Value)| !value.is_null();
    metrics.extend(entries("contacts", "utilisation").into_iter().filter(given));
    metrics.extend(entries("pins", "utilisation").into_iter().filter(given));
    metrics.extend(super::metrics::item_scalars(
        document,
        "contacts",
        "impact_statistics",
    ));
    metrics
}

fn histories(plan: &Plan, simulation: Run) -> Vec<History> {
    let contacts: Vec<String> = (0..plan.contacts.len()).map(|k| format!("c{k}")).collect();
    let tips_only = plan.inputs.output.heights.is_none();
    let deflections =
        run_report::deflection_names(&plan.settings.output_heights, plan.pins, tips_only, |p| {
            format!("p{p}")
        });
    run_report::histories(
        simulation,
        &contacts,
        &deflections,
        &plan.flexure(),
        &plan.excitations(),
    )
}

/// A column of `bundle-dynamics`: `c<k>` the force (N) of contact k of the results'
/// `contacts`, `p<pin>[@<height>]` a pin's deflection (m).
fn column_of(output: &str, name: &str, document: &serde_json::Value) -> Option<super::Column> {
    let description = match output.trim_end_matches("_peaks") {
        "contact_forces" => {
            let contact = &document["contacts"][columns::contact_index(name)?];
            let height = contact["height"].as_f64()?;
            let (left, right) = (
                columns::body(&contact["left"])?,
                columns::body(&contact["right"])?,
            );
            (
                "N",
                format!("contact {left}–{right} at {}", columns::metres(height)),
            )
        }
        "displacements" => {
            let (pin, _, at) = columns::deflection(name, false)?;
            (
                "m",
                format!("deflection of p{pin} at {at}, toward the right wall, relative to the pin feet"),
            )
        }
        "bending_moments" => {
            let (pin, _, at) = columns::deflection(name, false)?;
            ("N·m", format!("bending moment EI w'' of p{pin} at {at}"))
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
