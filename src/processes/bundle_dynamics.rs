//! Process `bundle-dynamics`: a row of identical pins (one shared modal basis) between
//! two wrapper walls, with point contacts at given heights, shaken by the wrapper or
//! released from bent shapes. The generator form is expanded to the explicit contact
//! list, which the results echo.

use serde_json::json;

use super::basis_report::BasisReport;
use super::bundle_inputs::{BundleInputs, ContactInput, body_json};
use super::inputs::{self, at};
use super::{FieldError, History, InvalidInputs, Process, ProgressFn, RunError, RunOutput, WorkEstimate};
use crate::physics::contact::Contact;
use crate::physics::integrate::{Check, Model, Settings, StepSize, step_counts};
use crate::physics::modal::ModalBasis;

/// Most pins in one row.
pub const MAX_PINS: usize = 2000;
/// Largest pins × modes × steps (about a minute of computation).
pub const MAX_WORK: f64 = 2e11;
/// Largest number of history values (samples × columns) per history.
pub const MAX_HISTORY_VALUES: f64 = 5e7;
/// Default history interval (s).
pub const DEFAULT_OUTPUT_INTERVAL: f64 = 1e-4;

#[derive(Debug)]
struct Prepared {
    inputs: BundleInputs,
    pins: usize,
    contacts: Vec<Contact>,
    basis: ModalBasis,
    settings: Settings,
}

impl Prepared {
    fn model(&self) -> Model<'_> {
        let tips = &self.inputs.initial.tip_displacements;
        Model {
            basis: &self.basis,
            pins: self.pins,
            damping_ratios: self.inputs.pin.damping_ratios_for(self.basis.modes()),
            contacts: self.contacts.clone(),
            initial_tip_displacements: tips.clone(),
            base_acceleration: self
                .inputs
                .excitation
                .base_acceleration
                .as_ref()
                .map(|b| b.physics()),
            point_forces: self
                .inputs
                .excitation
                .point_forces
                .iter()
                .map(|f| f.physics())
                .collect(),
        }
    }

    /// What the run costs: pins × modes modal DOFs and every contact at each step;
    /// histories `contact_forces` (time + one column per contact) and `displacements`
    /// (time + one column per pin and output height).
    fn estimate(&self, step: &StepSize) -> WorkEstimate {
        let (steps, every) = step_counts(self.settings.duration, step, self.settings.output_interval);
        // Each history and its peaks.
        let columns = 2 * ((1 + self.contacts.len()) + (1 + self.pins * self.settings.output_heights.len()));
        // The step-halving check takes twice the steps of the run.
        let check = match self.settings.check {
            Check::StepHalving => 3.0,
            Check::None => 1.0,
        };
        let generated = self.inputs.bundle.is_some();
        let (pins, contacts) = if generated {
            ("/inputs/bundle/pins", "/inputs/bundle/levels")
        } else {
            ("/inputs/pins", "/inputs/contacts")
        };
        let mut history_drivers = vec![
            "/inputs/solver/duration".to_owned(),
            "/inputs/output/interval".to_owned(),
            pins.to_owned(),
        ];
        if self.inputs.output.heights.is_some() {
            history_drivers.push("/inputs/output/heights".to_owned());
        }
        WorkEstimate {
            steps: check * steps as f64,
            modal_dofs: (self.pins * self.basis.modes()) as f64,
            contacts: self.contacts.len() as f64,
            history_values: (steps / every + 1) as f64 * columns as f64,
            work_drivers: [
                "/inputs/solver/duration",
                "/inputs/solver/time_step",
                "/inputs/pin/modes",
                pins,
                contacts,
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
    let inputs: BundleInputs = inputs::parse(json)?;
    let length = inputs.pin.length;
    let mut errors: Vec<FieldError> = at("/inputs/pin", inputs.pin.validate());

    let (pins, contacts) = match (&inputs.bundle, inputs.pins, &inputs.contacts) {
        (Some(generator), None, None) => {
            let layout = generator.layout();
            match layout.expand(length) {
                Ok(contacts) => (generator.pins, contacts),
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
            let contacts: Vec<Contact> = contacts.iter().flatten().map(ContactInput::contact).collect();
            if pins >= 1 {
                for (k, contact) in contacts.iter().enumerate() {
                    errors.extend(at(
                        &format!("/inputs/contacts/{k}"),
                        contact.validate(pins, length),
                    ));
                }
            }
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
    if pins > MAX_PINS {
        errors.push(FieldError::new(
            "/inputs/bundle/pins",
            format!("must be at most {MAX_PINS}"),
        ));
    }

    let tips = &inputs.initial.tip_displacements;
    if !tips.is_empty() && tips.len() != pins {
        errors.push(FieldError::new(
            "/inputs/initial/tip_displacements",
            format!("needs one value per pin ({pins}), got {}", tips.len()),
        ));
    }
    for (p, tip) in tips.iter().enumerate() {
        if !tip.is_finite() {
            errors.push(FieldError::new(
                format!("/inputs/initial/tip_displacements/{p}"),
                "must be a finite number",
            ));
        }
    }
    if tips.iter().any(|t| *t != 0.0) && inputs.pin.supports.top != super::inputs::SupportInput::Free {
        errors.push(FieldError::new(
            "/inputs/initial/tip_displacements",
            "a tip release needs a free top",
        ));
    }
    if let Some(base) = &inputs.excitation.base_acceleration {
        errors.extend(at(
            "/inputs/excitation/base_acceleration",
            base.physics().validate(),
        ));
    }
    for (k, force) in inputs.excitation.point_forces.iter().enumerate() {
        let prefix = format!("/inputs/excitation/point_forces/{k}");
        if force.pin >= pins {
            errors.push(FieldError::new(
                format!("{prefix}/pin"),
                format!("pin {} does not exist", force.pin),
            ));
        }
        if !(force.height.is_finite() && (0.0..=length).contains(&force.height)) {
            errors.push(FieldError::new(
                format!("{prefix}/height"),
                format!("must be within the pin, 0 to {length} m"),
            ));
        }
        errors.extend(at(&prefix, force.physics().force.validate("force")));
    }

    let solver = inputs::solver(inputs.solver.fields(), &mut errors);
    inputs::check_output_interval(inputs.output.interval, &mut errors);
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
    if !errors.is_empty() {
        return Err(InvalidInputs(errors));
    }

    // One static correction per distinct contact height, shared by every pin.
    let contact_heights: Vec<f64> = contacts.iter().map(|c| c.height).collect();
    let basis = inputs.pin.basis(&contact_heights, "/inputs/pin")?;
    let settings = Settings {
        scheme: solver.scheme,
        time_step: solver.time_step,
        tolerance: solver.tolerance,
        check: solver.check,
        duration: inputs.solver.duration,
        output_interval: Some(inputs.output.interval.unwrap_or(DEFAULT_OUTPUT_INTERVAL)),
        output_heights: heights,
    };
    let prepared = Prepared {
        inputs,
        pins,
        contacts,
        basis,
        settings,
    };
    let step = check_costs(&prepared)?;
    Ok(Plan { prepared, step })
}

fn check_costs(prepared: &Prepared) -> Result<StepSize, InvalidInputs> {
    let model = prepared.model();
    let step = inputs::resolve_step(&model, &prepared.settings)?;
    let dt = step.time_step;
    let duration = prepared.settings.duration;
    let steps = duration / dt;
    let mut errors = Vec::new();
    let work = steps * (prepared.pins * prepared.basis.modes() + prepared.contacts.len()) as f64;
    if steps > inputs::MAX_STEPS || work > MAX_WORK {
        errors.push(FieldError::new(
            "/inputs/solver/duration",
            format!(
                "{steps:.3e} steps of {dt:e} s over this row is too much work ({work:.3e} > {MAX_WORK:e}){}",
                inputs::step_hint(&step, prepared.settings.tolerance)
            ),
        ));
    }
    let interval = prepared.settings.output_interval.unwrap_or(dt).max(dt);
    let columns =
        (prepared.contacts.len()).max(prepared.pins * prepared.settings.output_heights.len()) as f64;
    if duration / interval * columns > MAX_HISTORY_VALUES {
        errors.push(FieldError::new(
            "/inputs/output/interval",
            format!(
                "histories would hold {:.3e} values, above {MAX_HISTORY_VALUES:e}: sample less often",
                duration / interval * columns
            ),
        ));
    }
    if errors.is_empty() {
        Ok(step)
    } else {
        Err(InvalidInputs(errors))
    }
}

/// The `bundle-dynamics` process.
#[derive(Debug, Default)]
pub struct BundleDynamics;

impl Process for BundleDynamics {
    fn id(&self) -> &'static str {
        "bundle-dynamics"
    }

    fn title(&self) -> &'static str {
        "Row of pins rattling between two wrapper walls"
    }

    fn description(&self) -> &'static str {
        "Integrates a row of identical pins (one shared modal basis) with penalty point contacts between \
         pins and against the walls, under a base acceleration of the wrapper, initial releases and point \
         forces. Returns per-contact statistics (peak force, impacts, contact time, impulse), per-pin \
         extremes, the energy balance, and contact-force and deflection histories."
    }

    fn inputs_description(&self) -> serde_json::Value {
        inputs::ogc_inputs(&inputs::schema_of::<BundleInputs>())
    }

    fn outputs_description(&self) -> serde_json::Value {
        json!({
            "contact_forces": {"title": "Contact forces (N)", "description": "CSV columns time (s), c0, c1, ... in contact order",
                               "schema": {"type": "string", "contentMediaType": "text/csv"}},
            "displacements": {"title": "Pin deflections (m)", "description": "CSV columns time (s), p0, p1, ... (pin tips; `p<pin>@<height>` for other heights)",
                              "schema": {"type": "string", "contentMediaType": "text/csv"}},
            "contact_forces_peaks": {"title": "Contact force peaks (N)", "description": "As contact_forces, each value the largest force reached at any step of its output interval: the maximum of column c<k> is contact k's max_force",
                               "schema": {"type": "string", "contentMediaType": "text/csv"}},
            "displacements_peaks": {"title": "Pin deflection peaks (m)", "description": "As displacements, each value the deflection of largest magnitude (signed) reached at any step of its output interval",
                              "schema": {"type": "string", "contentMediaType": "text/csv"}},
        })
    }

    fn validate(&self, inputs: &serde_json::Value) -> Result<WorkEstimate, InvalidInputs> {
        prepare(inputs).map(|plan| plan.prepared.estimate(&plan.step))
    }

    fn summary_metrics(&self, document: &serde_json::Value) -> Vec<(String, serde_json::Value)> {
        bundle_metrics(document)
    }

    fn run(&self, inputs: &serde_json::Value, progress: &mut ProgressFn<'_>) -> Result<RunOutput, RunError> {
        let Plan { prepared, step } = prepare(inputs)?;
        let model = prepared.model();
        let assessed =
            crate::physics::integrate::Plan::with_step(&model, &prepared.settings, step)?.run(progress)?;
        let (simulation, quality) = (assessed.simulation, assessed.quality);

        let contacts: Vec<serde_json::Value> = prepared
            .contacts
            .iter()
            .zip(&simulation.contact_statistics)
            .map(|(c, s)| {
                json!({
                    "left": body_json(c.left), "right": body_json(c.right), "height": c.height, "gap": c.gap,
                    "stiffness": c.stiffness, "damping": c.damping,
                    "max_force": s.max_force, "max_force_time": s.max_force_time, "impacts": s.impacts,
                    "contact_time": s.contact_time, "impulse": s.impulse, "first_impact_time": s.first_impact_time,
                    "max_penetration": s.max_penetration,
                })
            })
            .collect();
        let peak = simulation
            .contact_statistics
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.max_force.total_cmp(&b.1.max_force))
            .map(|(k, s)| json!({"contact": k, "force": s.max_force, "time": s.max_force_time}));
        let pins: Vec<serde_json::Value> = simulation
            .pin_extremes
            .iter()
            .enumerate()
            .map(|(p, e)| {
                // Per output height, the deflection of largest magnitude over every step
                // (the extreme of its `displacements_peaks` column).
                let peaks: Vec<serde_json::Value> = prepared
                    .settings
                    .output_heights
                    .iter()
                    .zip(&simulation.peak_deflections)
                    .map(|(height, per_pin)| {
                        json!({"height": height, "deflection": per_pin[p].deflection, "time": per_pin[p].time})
                    })
                    .collect();
                json!({"pin": p, "max_abs_deflection": e.max_abs_deflection, "height": e.height, "time": e.time,
                       "peak_deflections": peaks})
            })
            .collect();
        let mut document = json!({
            "contacts": contacts,
            "max_contact_force": peak,
            "impacts": simulation.contact_statistics.iter().map(|s| s.impacts).sum::<u64>(),
            "pins": pins,
            "energy": {
                "kinetic": simulation.energy.kinetic, "strain": simulation.energy.strain,
                "contact": simulation.energy.contact, "dissipated_modal": simulation.energy.dissipated_modal,
                "dissipated_contact": simulation.energy.dissipated_contact,
                "external_work": simulation.energy.external_work, "initial": simulation.energy.initial,
                "residual": simulation.energy.residual(), "relative_residual": simulation.energy.relative_residual(),
            },
            "time_step": simulation.step.time_step,
            "critical_time_step": simulation.step.critical_time_step,
            "steps": simulation.steps,
            "output_interval": simulation.output_interval,
            "quality": quality,
            "frequencies_hz": prepared.basis.frequencies_hz(),
            "basis": BasisReport::of(&model, prepared.settings.scheme, simulation.step.critical_time_step),
        });
        if prepared.inputs.bundle.is_some() {
            let explicit: Vec<serde_json::Value> = prepared
                .contacts
                .iter()
                .map(|c| {
                    json!({"left": body_json(c.left), "right": body_json(c.right), "height": c.height,
                                "gap": c.gap, "stiffness": c.stiffness, "damping": c.damping})
                })
                .collect();
            document["expansion"] = json!({"pins": prepared.pins, "contacts": explicit});
        }
        Ok(RunOutput {
            document,
            histories: histories(&prepared, simulation),
        })
    }
}

/// Sweep columns: the scalars of the document, plus the peak force of each contact
/// (`contacts.<k>.max_force`, N) and the largest deflection of each pin
/// (`pins.<p>.max_abs_deflection`, m).
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
    metrics
}

fn histories(prepared: &Prepared, simulation: crate::physics::integrate::Simulation) -> Vec<History> {
    let tips_only = prepared.inputs.output.heights.is_none();
    let mut displacement_series = Vec::new();
    for (h, per_pin) in simulation.deflections.into_iter().enumerate() {
        let height = prepared.settings.output_heights[h];
        for (p, values) in per_pin.into_iter().enumerate() {
            let name = if tips_only {
                format!("p{p}")
            } else {
                format!("p{p}@{height}")
            };
            displacement_series.push((name, values));
        }
    }
    let named = |prefix: &str, columns: Vec<Vec<f64>>| -> Vec<(String, Vec<f64>)> {
        columns
            .into_iter()
            .enumerate()
            .map(|(c, v)| (format!("{prefix}{c}"), v))
            .collect()
    };
    let peak_series = displacement_series
        .iter()
        .map(|(name, _)| name.clone())
        .zip(simulation.deflection_peaks.into_iter().flatten())
        .collect();
    let history = |name: &str, series| History {
        name: name.into(),
        time: simulation.time.clone(),
        series,
    };
    vec![
        history("contact_forces", named("c", simulation.contact_forces)),
        history("displacements", displacement_series),
        history("contact_forces_peaks", named("c", simulation.contact_force_peaks)),
        history("displacements_peaks", peak_series),
    ]
}

#[cfg(test)]
#[path = "bundle_dynamics_tests.rs"]
mod tests;
