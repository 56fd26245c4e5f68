//! The one way into the time loop. [`Plan::new`] checks the model and the settings
//! ([`Model::validate`], [`Settings::validate`]) and resolves the step
//! ([`super::step_size`]); [`Plan::run`] integrates and assesses the result
//! ([`super::quality`]): the run, the check `settings.check` asks for, the verdict.

use std::ops::ControlFlow;

use super::quality::{self, Check};
use super::{Assessed, Model, Settings, SimulationError, StepSize, step_size, stepper};
use crate::InputIssue;

/// A checked model, its settings and the step it runs with.
#[derive(Debug, Clone, Copy)]
pub struct Plan<'a> {
    model: &'a Model<'a>,
    settings: &'a Settings,
    step: StepSize,
}

impl<'a> Plan<'a> {
    /// Checks `model` and `settings` and resolves the step: a given step above the
    /// critical one is refused, `auto` picks one for the tolerance.
    pub fn new(model: &'a Model<'a>, settings: &'a Settings) -> Result<Self, SimulationError> {
        check(model, settings)?;
        let step = step_size::resolve(model, settings)?;
        Ok(Self {
            model,
            settings,
            step,
        })
    }

    /// [`Plan::new`] with the step an earlier plan of the same model and settings
    /// resolved (a caller that costs a plan and runs it later need not solve the
    /// stability eigenproblem twice). The model and settings are checked again, and a
    /// step above its critical step is refused.
    pub fn with_step(
        model: &'a Model<'a>,
        settings: &'a Settings,
        step: StepSize,
    ) -> Result<Self, SimulationError> {
        check(model, settings)?;
        if !(step.time_step.is_finite() && step.time_step > 0.0) {
            return Err(SimulationError::InvalidSettings(vec![InputIssue::new(
                "time_step",
                format!("must be a positive number of seconds (got {})", step.time_step),
            )]));
        }
        if step.time_step > step.critical_time_step * (1.0 + 1e-12) {
            return Err(SimulationError::TimeStepAboveCritical {
                time_step: step.time_step,
                critical_time_step: step.critical_time_step,
            });
        }
        Ok(Self {
            model,
            settings,
            step,
        })
    }

    /// The step the run uses and its stability limit.
    pub fn step(&self) -> &StepSize {
        &self.step
    }

    /// Integrates the model and assesses the result: the check of `settings.check` (the
    /// whole run again at 2Δt or Δt/2, see [`super::quality`]), then the verdict. `progress` is called
    /// every few thousand steps with the fraction done (the check included);
    /// `ControlFlow::Break` stops the run with [`SimulationError::Cancelled`].
    pub fn run(&self, progress: &mut dyn FnMut(f64) -> ControlFlow<()>) -> Result<Assessed, SimulationError> {
        self.run_on(pulp::Arch::new(), progress)
    }

    /// [`Plan::run`] at the SIMD level `arch` (tests compare the vector and scalar
    /// layouts).
    pub(super) fn run_on(
        &self,
        arch: pulp::Arch,
        progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
    ) -> Result<Assessed, SimulationError> {
        let (model, settings, step) = (self.model, self.settings, &self.step);
        // Shares of the progress: the run, then the check's repetitions (at 2Δt half the
        // run's steps, at Δt/2 twice).
        let doubled = match settings.check {
            Check::Auto => Some(step.doubled()),
            Check::StepHalving | Check::None => None,
        };
        let share = match (settings.check, &doubled) {
            (Check::None, _) => 1.0,
            (_, Some(Ok(_))) => 2.0 / 3.0,
            _ => 1.0 / 3.0,
        };
        let simulation = stepper::integrate(arch, model, settings, step, &mut |f| progress(share * f))?;
        let figures = quality::KeyFigures::of(&simulation);
        let started = std::time::Instant::now();
        // A repeated run is only compared by its key figures, which the step tracks at
        // every step (peaks, impacts, wear): one sample at its last step keeps them whole
        // and records nothing else (no histories, envelopes or extremes per sample, which
        // cost as much as the step itself where every step is a sample).
        let mut repeat = |at: &StepSize, (from, to): (f64, f64)| {
            let settings = Settings {
                output_interval: Some(at.steps(settings.duration) as f64 * at.time_step),
                ..settings.clone()
            };
            stepper::integrate(arch, model, &settings, at, &mut |f| {
                progress(from + (to - from) * f)
            })
        };
        let step_halving = match (settings.check, doubled) {
            (Check::None, _) => None,
            (_, Some(Ok(twice))) => {
                let coarse = repeat(&twice, (share, 0.8))?;
                let against_double = quality::compare(
                    settings.scheme,
                    (quality::StepComparison::DoubleStep, &twice),
                    figures,
                    quality::KeyFigures::of(&coarse),
                    (coarse.steps, simulation.steps, started.elapsed().as_secs_f64()),
                );
                if against_double.proves(settings.scheme, settings.tolerance) {
                    Some(against_double)
                } else {
                    let half = step.halved();
                    let fine = repeat(&half, (0.8, 1.0))?;
                    Some(quality::StepHalving {
                        why_half_step: Some(format!(
                            "the comparison with 2Δt did not prove the result (peak contact force \
                             change {:.2} %, peak deflection change {:.2} %, impact count change {:.2} %)",
                            100.0 * against_double.peak_force_change,
                            100.0 * against_double.peak_displacement_change,
                            100.0 * against_double.impact_count_change
                        )),
                        ..quality::compare(
                            settings.scheme,
                            (quality::StepComparison::HalfStep, &half),
                            figures,
                            quality::KeyFigures::of(&fine),
                            (
                                coarse.steps + fine.steps,
                                simulation.steps,
                                started.elapsed().as_secs_f64(),
                            ),
                        )
                    })
                }
            }
            (check, doubled) => {
                let half = step.halved();
                let fine = repeat(&half, (share, 1.0))?;
                let why = match (check, doubled) {
                    (_, Some(Err(why))) => why,
                    _ => "asked for (solver.check \"step_halving\")".to_owned(),
                };
                Some(quality::StepHalving {
                    why_half_step: Some(why),
                    ..quality::compare(
                        settings.scheme,
                        (quality::StepComparison::HalfStep, &half),
                        figures,
                        quality::KeyFigures::of(&fine),
                        (fine.steps, simulation.steps, started.elapsed().as_secs_f64()),
                    )
                })
            }
        };
        let peaks: Vec<f64> = simulation
            .contact_statistics
            .iter()
            .map(|s| s.max_force)
            .collect();
        let mut findings = force_scales(model, settings, step, &peaks);
        // A probe that cannot be computed (the complete basis of a mesh that neither form
        // of the eigenproblem solves) leaves the basis and the mesh unmeasured: the run
        // stands, its verdict cannot be `good`.
        let basis = crate::discretisation::assess(model, &peaks).unwrap_or_else(|e| {
            findings.push(quality::Finding {
                poor: false,
                reason: format!(
                    "the errors due to the modal basis and the mesh were not measured: their \
                     impact probes (the complete basis of this mesh and of one twice as fine) \
                     could not be computed ({e}); fewer elements can be probed"
                ),
            });
            crate::discretisation::BasisErrors::unmeasured()
        });
        let quality = quality::assess(
            &simulation,
            step,
            settings.tolerance,
            (step_halving, &basis),
            findings,
        );
        Ok(Assessed { simulation, quality })
    }

    /// A checked plan at step `dt` whatever the critical step (tests probe instability
    /// with it).
    #[cfg(test)]
    pub(crate) fn unchecked(
        model: &'a Model<'a>,
        settings: &'a Settings,
        dt: f64,
    ) -> Result<Self, SimulationError> {
        check(model, settings)?;
        let auto = Settings {
            time_step: super::TimeStep::Auto,
            ..settings.clone()
        };
        let step = StepSize {
            time_step: dt,
            ..step_size::resolve(model, &auto)?
        };
        Ok(Self {
            model,
            settings,
            step,
        })
    }
}

/// The power laws (n > 1) whose peak force passed the force their tangent stiffness
/// sized the step with: `doubtful` (the step rules saw a softer contact), `poor` when
/// the step is above the critical step with those contacts as stiff as at their peaks.
fn force_scales(
    model: &Model<'_>,
    settings: &Settings,
    step: &StepSize,
    peaks: &[f64],
) -> Vec<quality::Finding> {
    let exceeded: Vec<(usize, f64)> = model
        .contacts
        .iter()
        .zip(peaks)
        .enumerate()
        .filter(|(_, (c, peak))| c.law.exponent > 1.0 && **peak > c.law.force_scale)
        .map(|(k, (_, peak))| (k, *peak))
        .collect();
    let Some(&(worst, peak)) = exceeded.iter().max_by(|a, b| {
        let ratio = |(k, peak): &(usize, f64)| peak / model.contacts[*k].law.force_scale;
        ratio(a).total_cmp(&ratio(b))
    }) else {
        return Vec::new();
    };
    let mut stiffer = model.clone();
    for &(k, peak) in &exceeded {
        stiffer.contacts[k].law.force_scale = peak;
    }
    let critical = step_size::critical_time_step(&stiffer, settings.scheme);
    let unstable = step.time_step > critical;
    let scale = model.contacts[worst].law.force_scale;
    vec![quality::Finding {
        poor: unstable,
        reason: format!(
            "the peak force of contact {worst}, {} N, exceeds its force_scale {} N, whose tangent \
             stiffness sized the time step{} ({} contacts past their scale): raise force_scale to \
             at least the peak",
            crate::number(peak),
            crate::number(scale),
            if unstable {
                format!(
                    ", and the step is above the critical step at that force ({} s)",
                    crate::number(critical)
                )
            } else {
                String::new()
            },
            exceeded.len()
        ),
    }]
}

/// Refuses a model or settings that cannot be integrated.
fn check(model: &Model<'_>, settings: &Settings) -> Result<(), SimulationError> {
    let issues = model.validate();
    if !issues.is_empty() {
        return Err(SimulationError::InvalidModel(issues));
    }
    let issues = settings.validate(model.basis.length(), model.contacts.len());
    if !issues.is_empty() {
        return Err(SimulationError::InvalidSettings(issues));
    }
    Ok(())
}
