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
        // The check's first repetition: at 2Δt where it is valid (`auto`), else at Δt/2
        // with the reason.
        let first = match (
            settings.check,
            (settings.check == Check::Auto).then(|| step.doubled()),
        ) {
            (Check::None, _) => None,
            (_, Some(Ok(twice))) => Some((quality::StepComparison::DoubleStep, twice, None)),
            (check, doubled) => Some((
                quality::StepComparison::HalfStep,
                step.halved(),
                Some(match (check, doubled) {
                    (_, Some(Err(why))) => why,
                    _ => "asked for (solver.check \"step_halving\")".to_owned(),
                }),
            )),
        };
        // Shares of the progress, in proportion to the steps: the run, then the check's
        // repetition (at 2Δt half the run's steps, at Δt/2 twice). A fallback to Δt/2
        // after 2Δt adds two runs to the 1.5 done: the progress then steps back to
        // 1.5/3.5 and goes on from there, so that the time left extrapolated from it
        // (job status, CLI) holds.
        let weight = match &first {
            None => 0.0,
            Some((quality::StepComparison::DoubleStep, ..)) => 0.5,
            Some((quality::StepComparison::HalfStep, ..)) => 2.0,
        };
        let fallback_starts = (1.0 + weight) / (1.0 + weight + 2.0);
        let threads = settings.threads.clamp(1, rayon::current_num_threads().max(1));
        // A repeated run is only compared by its key figures, which the step tracks at
        // every step (peaks, impacts, wear): one sample at its last step keeps them whole
        // and records nothing else (no histories, envelopes or extremes per sample, which
        // cost as much as the step itself where every step is a sample).
        let repeat = |at: &StepSize, threads: usize, progress: &mut dyn FnMut(f64) -> ControlFlow<()>| {
            let settings = Settings {
                output_interval: Some(at.steps(settings.duration) as f64 * at.time_step),
                threads,
                ..settings.clone()
            };
            let started = std::time::Instant::now();
            stepper::integrate(arch, model, &settings, at, progress).map(|run| (run, started.elapsed()))
        };
        let run = |threads: usize, progress: &mut dyn FnMut(f64) -> ControlFlow<()>| {
            let settings = Settings {
                threads,
                ..settings.clone()
            };
            stepper::integrate(arch, model, &settings, step, progress)
        };
        let scale = |from: f64, to: f64, progress: &mut dyn FnMut(f64) -> ControlFlow<()>, f: f64| {
            progress(from + (to - from) * f)
        };
        // The run and the check's first repetition are independent: given two threads or
        // more, they run at once (the shorter on one thread, the longer on the others),
        // each computing exactly what it computes alone. The shorter of the two then
        // computes the impact probes of every contact that could push, on its thread,
        // and its thread then joins the longer one's steps where they are shared
        // (`stepper::integrate`).
        let (simulation, first_run, prepared) = match &first {
            None => (run(threads, &mut |f| progress(f))?, None, None),
            Some((comparison, at, _)) if threads >= 2 => {
                let prepare = || crate::discretisation::prepare(model);
                let (simulation, repeated, prepared) = match comparison {
                    // The longer run reports the progress: it runs here.
                    quality::StepComparison::DoubleStep => {
                        let (simulation, (repeated, prepared)) = at_once(
                            [1.0, weight],
                            &mut |f| progress(f),
                            |p| run(threads, p),
                            |p| Ok((repeat(at, 1, p)?, prepare())),
                        )?;
                        (simulation, repeated, prepared)
                    }
                    quality::StepComparison::HalfStep => {
                        let (repeated, (simulation, prepared)) = at_once(
                            [weight, 1.0],
                            &mut |f| progress(f),
                            |p| repeat(at, threads, p),
                            |p| Ok((run(1, p)?, prepare())),
                        )?;
                        (simulation, repeated, prepared)
                    }
                };
                (simulation, Some(repeated), prepared)
            }
            Some((_, at, _)) => {
                let share = 1.0 / (1.0 + weight);
                let simulation = run(threads, &mut |f| scale(0.0, share, progress, f))?;
                let repeated = repeat(at, threads, &mut |f| scale(share, 1.0, progress, f))?;
                (simulation, Some(repeated), None)
            }
        };
        let figures = quality::KeyFigures::of(&simulation);
        let step_halving = match (first, first_run) {
            (Some((comparison, at, why)), Some((repeated, took))) => {
                let compared = quality::compare(
                    settings.scheme,
                    (comparison, &at),
                    figures,
                    quality::KeyFigures::of(&repeated),
                    (repeated.steps, simulation.steps, took.as_secs_f64()),
                );
                if comparison == quality::StepComparison::HalfStep {
                    Some(quality::StepHalving {
                        why_half_step: why,
                        ..compared
                    })
                } else if compared.proves(settings.scheme, settings.tolerance) {
                    Some(compared)
                } else {
                    let half = step.halved();
                    let (fine, also) =
                        repeat(&half, threads, &mut |f| scale(fallback_starts, 1.0, progress, f))?;
                    Some(quality::StepHalving {
                        why_half_step: Some(format!(
                            "the comparison with 2Δt did not prove the result (peak contact force \
                             change {:.2} %, peak deflection change {:.2} %, impact count change {:.2} %)",
                            100.0 * compared.peak_force_change,
                            100.0 * compared.peak_displacement_change,
                            100.0 * compared.impact_count_change
                        )),
                        ..quality::compare(
                            settings.scheme,
                            (quality::StepComparison::HalfStep, &half),
                            figures,
                            quality::KeyFigures::of(&fine),
                            (
                                repeated.steps + fine.steps,
                                simulation.steps,
                                (took + also).as_secs_f64(),
                            ),
                        )
                    })
                }
            }
            _ => None,
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
        let basis = match prepared {
            Some(Ok(probes)) => Ok(crate::discretisation::assess_prepared(model, &peaks, &probes)),
            // Computed again from the run's peaks (an error where no contact pushed is
            // none), or for the first time.
            Some(Err(_)) | None => crate::discretisation::assess(model, &peaks),
        };
        let basis = basis.unwrap_or_else(|e| {
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

/// Progress reports of a run: `ControlFlow::Break` stops it.
pub(super) type Progress<'p> = &'p mut dyn FnMut(f64) -> ControlFlow<()>;

/// Two independent runs at once: `here` on this thread, `there` on another thread of the
/// pool the caller runs in (or after `here` on this one, when no thread is free).
/// `progress` hears, from this thread, the fractions of both weighted by `weights` (the
/// other thread's through an atomic). A cancellation or an error of either stops the
/// other at its next report; the first real error wins over the cancellation it caused.
pub(super) fn at_once<A: Send, B: Send>(
    weights: [f64; 2],
    progress: Progress<'_>,
    here: impl FnOnce(Progress<'_>) -> Result<A, SimulationError>,
    there: impl FnOnce(Progress<'_>) -> Result<B, SimulationError> + Send,
) -> Result<(A, B), SimulationError> {
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    let stop = AtomicBool::new(false);
    let done_there = AtomicU64::new(0f64.to_bits());
    let total = weights[0] + weights[1];
    let mut from_there = None;
    let from_here = rayon::in_place_scope(|scope| {
        let (stop, done_there, from_there) = (&stop, &done_there, &mut from_there);
        scope.spawn(move |_| {
            let result = there(&mut |f| {
                done_there.store(f.to_bits(), Ordering::Relaxed);
                if stop.load(Ordering::Relaxed) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            });
            if result.is_err() {
                stop.store(true, Ordering::Relaxed);
            }
            *from_there = Some(result);
        });
        let result = here(&mut |f| {
            let other = f64::from_bits(done_there.load(Ordering::Relaxed));
            if stop.load(Ordering::Relaxed) {
                return ControlFlow::Break(());
            }
            let flow = progress((weights[0] * f + weights[1] * other) / total);
            if flow.is_break() {
                stop.store(true, Ordering::Relaxed);
            }
            flow
        });
        if result.is_err() {
            stop.store(true, Ordering::Relaxed);
        }
        result
    });
    let from_there = from_there.expect("the scope waits for its spawned run");
    match (from_here, from_there) {
        (Ok(a), Ok(b)) => Ok((a, b)),
        (Err(SimulationError::Cancelled), Err(error)) | (Err(error), _) | (_, Err(error)) => Err(error),
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
    let mut issues = settings.validate(model.basis.length(), model.contacts.len());
    if settings.scheme == crate::stability::Scheme::ExactModal {
        if model.walls.is_some() {
            issues.push(InputIssue::new(
                "scheme",
                "`exact_modal` does not take walls with their own motion; use `central_difference`",
            ));
        }
        if model.contacts.iter().any(|c| c.law.friction.is_on()) {
            issues.push(InputIssue::new(
                "scheme",
                "`exact_modal` does not take friction; use `central_difference`",
            ));
        }
    }
    if !issues.is_empty() {
        return Err(SimulationError::InvalidSettings(issues));
    }
    Ok(())
}
