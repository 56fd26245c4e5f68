//! Sweep admission: from a request body to the runs to queue, or the reason why none is.
//!
//! A sweep is admitted whole or not at all. Its request is checked ([`spec::parse`]),
//! its process looked up, each axis pointer checked against the process's inputs schema
//! ([`input_schema`]: a typo would otherwise fail every run; the problems of the base
//! inputs come in the same 422, from the first run without those axes), its axes
//! expanded into runs, and every run's inputs validated
//! by the process as an execution request's would be, its estimated cost compared with
//! the service's ceilings. A run above a ceiling refuses the sweep; an invalid run
//! refuses it too, unless the request says `invalid_runs: record` (the run is then
//! kept, failed, with its problem, and never reaches a worker). The runs are validated
//! in parallel, one chunk per core: a sweep has up to thousands of them.
//!
//! No IO, no async: the HTTP layer runs this off its runtime and turns a [`Refusal`]
//! into its problem document.

use std::collections::HashMap;

use serde_json::Value;

use super::input_schema;
use super::spec::{self, SweepError, SweepSpec};
use super::{InvalidRuns, Run};
use crate::processes::cost::Excess;
use crate::processes::signal_input::SignalLibrary;
use crate::processes::{CostLimits, FieldError, InvalidInputs, Process, Registry, TooCostly, Warning};

/// At most this many field errors are reported for the runs of one sweep.
pub const MAX_RUN_ERRORS: usize = 100;

/// What a service accepts in one sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdmissionLimits {
    /// Most runs in one sweep.
    pub max_runs: usize,
    /// Ceilings on each run's estimated cost.
    pub cost: CostLimits,
}

/// An admitted sweep: its checked request and every run, in run order.
#[derive(Debug, Clone)]
pub struct Admitted {
    pub spec: SweepSpec,
    pub runs: Vec<AdmittedRun>,
}

/// One run of an admitted sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct AdmittedRun {
    /// The run's complete inputs.
    pub inputs: Value,
    /// Why the process refuses them, for a run recorded as failed (`invalid_runs: record`).
    pub invalid: Option<InvalidInputs>,
    /// Plausibility warnings about them (none for an invalid run).
    pub warnings: Vec<Warning>,
}

/// Why a sweep is not admitted; each variant's doc says its HTTP status and problem type.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    /// 422 `invalid-inputs` (the request, by pointers into it) or `sweep-too-large`.
    Request(SweepError),
    /// 404 `no-such-process`: no process with this id.
    NoSuchProcess(String),
    /// 422 `invalid-inputs`: generated runs the process refuses (`invalid_runs: refuse`).
    InvalidRuns(RefusedRuns),
    /// 422 `too-costly`: runs above the cost ceilings, with the ceilings the first one
    /// exceeds.
    TooCostly {
        runs: RefusedRuns,
        exceeded: Vec<Excess>,
    },
}

/// The refused runs of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct RefusedRuns {
    /// How many runs are refused,
    pub refused: usize,
    /// of how many in the sweep;
    pub runs: usize,
    /// the number of the first one refused.
    pub first: usize,
    /// Their errors, pointed into the sweep (`/runs/{run}/inputs/...`), each detail
    /// naming the run's axis values; at most [`MAX_RUN_ERRORS`].
    pub errors: Vec<FieldError>,
}

/// Admits the sweep requested by `body`, or says why not; `signals` holds the stored
/// signals its runs may refer to.
pub fn admit(
    body: &Value,
    registry: &Registry,
    limits: &AdmissionLimits,
    signals: &SignalLibrary,
) -> Result<Admitted, Refusal> {
    let spec = spec::parse(body, limits.max_runs).map_err(Refusal::Request)?;
    let process = registry
        .get(&spec.process)
        .ok_or_else(|| Refusal::NoSuchProcess(spec.process.clone()))?;
    if let Err(mut errors) = check_pointers(&spec, process.as_ref()) {
        errors.extend(first_run_errors(&spec, process.as_ref(), &errors, signals));
        return Err(Refusal::Request(SweepError::Invalid(errors)));
    }
    let runs = admit_runs(&spec, process.as_ref(), &limits.cost, signals)?;
    Ok(Admitted { spec, runs })
}

/// Every axis whose pointer names no input of `process` (one error at
/// `/axes/{k}/pointer` each), when the process has an inputs schema.
fn check_pointers(spec: &SweepSpec, process: &dyn Process) -> Result<(), Vec<FieldError>> {
    let Some(schema) = process.inputs_schema() else {
        return Ok(());
    };
    let errors: Vec<FieldError> = spec
        .axes
        .iter()
        .enumerate()
        .filter_map(|(index, axis)| {
            let why = input_schema::check(&schema, &axis.pointer).err()?;
            Some(FieldError::new(format!("/axes/{index}/pointer"), why))
        })
        .collect();
    if errors.is_empty() { Ok(()) } else { Err(errors) }
}

/// The problems of the first run of `spec` without the axes whose pointer is refused
/// (`refused`, at `/axes/{k}/pointer`): those of the base inputs and the other axes,
/// reported with the refused pointers rather than once they are fixed.
fn first_run_errors(
    spec: &SweepSpec,
    process: &dyn Process,
    refused: &[FieldError],
    signals: &SignalLibrary,
) -> Vec<FieldError> {
    let mut kept = spec.clone();
    kept.axes = spec
        .axes
        .iter()
        .enumerate()
        .filter(|(k, _)| refused.iter().all(|e| e.pointer != format!("/axes/{k}/pointer")))
        .map(|(_, axis)| axis.clone())
        .collect();
    let Some(first) = kept.expand().into_iter().next() else {
        return Vec::new();
    };
    match process.validate_with(&first.inputs, signals) {
        Ok(_) => Vec::new(),
        Err(invalid) => run_errors(
            &kept,
            std::slice::from_ref(&first),
            std::iter::once((0, invalid.0.as_slice())),
        ),
    }
}

/// Why the process does not take a generated run as it is.
#[derive(Debug)]
enum RunProblem {
    Invalid(InvalidInputs),
    TooCostly(TooCostly),
}

/// Every run of `spec`, or the refusal naming the runs above the cost ceilings (always
/// refused) or the invalid ones (unless they are to be recorded).
fn admit_runs(
    spec: &SweepSpec,
    process: &dyn Process,
    limits: &CostLimits,
    signals: &SignalLibrary,
) -> Result<Vec<AdmittedRun>, Refusal> {
    let runs = spec.expand();
    let outcomes = validate_in_parallel(&runs, process, limits, signals);
    let mut invalid: Vec<(usize, InvalidInputs)> = Vec::new();
    let mut costly: Vec<(usize, TooCostly)> = Vec::new();
    let mut warnings: HashMap<usize, Vec<Warning>> = HashMap::new();
    for (index, outcome) in outcomes {
        match outcome {
            Ok(found) => {
                warnings.insert(index, found);
            }
            Err(RunProblem::Invalid(inputs)) => invalid.push((index, inputs)),
            Err(RunProblem::TooCostly(refused)) => costly.push((index, refused)),
        }
    }
    if !costly.is_empty() {
        costly.sort_by_key(|(index, _)| *index);
        let exceeded = costly[0].1.exceeded.clone();
        let runs = refused_runs(
            spec,
            &runs,
            costly
                .iter()
                .map(|(index, refused)| (*index, refused.errors.as_slice())),
        );
        return Err(Refusal::TooCostly { runs, exceeded });
    }
    if invalid.is_empty() || spec.invalid_runs == InvalidRuns::Record {
        let mut invalid: HashMap<usize, InvalidInputs> = invalid.into_iter().collect();
        return Ok(runs
            .into_iter()
            .map(|run| AdmittedRun {
                invalid: invalid.remove(&run.index),
                warnings: warnings.remove(&run.index).unwrap_or_default(),
                inputs: run.inputs,
            })
            .collect());
    }
    invalid.sort_by_key(|(index, _)| *index);
    Err(Refusal::InvalidRuns(refused_runs(
        spec,
        &runs,
        invalid
            .iter()
            .map(|(index, inputs)| (*index, inputs.0.as_slice())),
    )))
}

/// By run number (in no particular order), the warnings about each run the process
/// accepts within the ceilings, or its problem; one chunk of runs per core.
fn validate_in_parallel(
    runs: &[Run],
    process: &dyn Process,
    limits: &CostLimits,
    signals: &SignalLibrary,
) -> Vec<(usize, Result<Vec<Warning>, RunProblem>)> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(runs.len().max(1));
    let chunk = runs.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        let handles: Vec<_> = runs
            .chunks(chunk)
            .map(|runs| {
                scope.spawn(move || {
                    runs.iter()
                        .map(|run| {
                            let outcome = match process.validate_with(&run.inputs, signals) {
                                Err(invalid) => Err(RunProblem::Invalid(invalid)),
                                Ok(validated) => match limits.check(&validated.estimate) {
                                    Ok(()) => Ok(validated.warnings),
                                    Err(refused) => Err(RunProblem::TooCostly(refused)),
                                },
                            };
                            (run.index, outcome)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            // A process's validation that panics is a bug: the caller sees the panic.
            .flat_map(|handle| {
                handle
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    })
}

/// The refused runs `refused` (by run number, in order, with their errors) of `runs`.
fn refused_runs<'a>(
    spec: &SweepSpec,
    runs: &[Run],
    refused: impl ExactSizeIterator<Item = (usize, &'a [FieldError])> + Clone,
) -> RefusedRuns {
    let count = refused.len();
    let first = refused.clone().next().map_or(0, |(index, _)| index);
    RefusedRuns {
        refused: count,
        runs: runs.len(),
        first,
        errors: run_errors(spec, runs, refused),
    }
}

/// The errors of generated runs, re-pointed into the sweep (`/runs/{run}/inputs/...`)
/// with each run's axis values in the detail; at most [`MAX_RUN_ERRORS`].
fn run_errors<'a>(
    spec: &SweepSpec,
    runs: &[Run],
    refused: impl Iterator<Item = (usize, &'a [FieldError])>,
) -> Vec<FieldError> {
    refused
        .flat_map(|(index, errors)| {
            let values: Vec<String> = spec
                .axes
                .iter()
                .map(|axis| {
                    let value = runs[index]
                        .inputs
                        .pointer(&axis.pointer)
                        .cloned()
                        .unwrap_or(Value::Null);
                    format!("{} = {value}", axis.pointer)
                })
                .collect();
            errors.iter().map(move |error| {
                let within = error.pointer.strip_prefix("/inputs").unwrap_or(&error.pointer);
                FieldError::new(
                    format!("/runs/{index}/inputs{within}"),
                    format!("{} (run {index}: {})", error.detail, values.join(", ")),
                )
            })
        })
        .take(MAX_RUN_ERRORS)
        .collect()
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    fn calibration() -> Value {
        serde_json::from_str(include_str!("../../examples/sweep-calibration.json")).unwrap()
    }

    fn limits() -> AdmissionLimits {
        AdmissionLimits {
            max_runs: 10_000,
            cost: CostLimits::default(),
        }
    }

    /// `logspace` values are the decades when the range spans whole decades
    /// ([0.1, 1e6, 8]: 0.1, 1, 10, …, 1e6 exactly, not 99999.9999999999), and read as
    /// written between them ([1, 100, 5]: 3.16227766016838, 10, 31.6227766016838).
    #[test]
    fn logspace_lands_on_the_decades() {
        let values = |start: f64, stop: f64, count: usize| {
            let mut body = calibration();
            body["axes"] = json!([{"pointer": "/contact/rk", "logspace": [start, stop, count]}]);
            let admitted = admit(&body, &Registry::builtin(), &limits(), &SignalLibrary::default()).unwrap();
            admitted
                .runs
                .iter()
                .map(|run| run.inputs["contact"]["rk"].as_f64().unwrap())
                .collect::<Vec<f64>>()
        };
        assert_eq!(values(0.1, 1e6, 8), [0.1, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6]);
        let between = values(1.0, 100.0, 5);
        let expected = [1.0, 10f64.sqrt(), 10.0, 1000f64.sqrt(), 100.0];
        for (value, exact) in between.iter().zip(expected) {
            assert!((value - exact).abs() <= 1e-14 * exact, "{value} vs {exact}");
        }
    }

    #[test]
    fn every_run_is_admitted_in_order_and_invalid_ones_are_recorded() {
        let admitted = admit(
            &calibration(),
            &Registry::builtin(),
            &limits(),
            &SignalLibrary::default(),
        )
        .unwrap();
        assert_eq!(admitted.runs.len(), 32);
        assert_eq!(admitted.runs[5].inputs["solver"]["time_step"], json!(1e-5));
        assert_eq!(admitted.runs[5].inputs["contact"]["rk"], json!(1.0));
        let invalid = admitted.runs.iter().filter(|run| run.invalid.is_some()).count();
        assert!(
            (1..32).contains(&invalid),
            "{invalid} of 32 runs invalid: the grid crosses the stability limit"
        );
    }

    #[test]
    fn invalid_runs_refuse_the_sweep_unless_recorded_naming_each_run() {
        let mut body = calibration();
        body["invalid_runs"] = json!("refuse");
        let Err(Refusal::InvalidRuns(refused)) =
            admit(&body, &Registry::builtin(), &limits(), &SignalLibrary::default())
        else {
            panic!("the calibration grid has invalid runs");
        };
        assert_eq!(refused.runs, 32);
        let first = format!("/runs/{}/inputs/", refused.first);
        assert!(
            refused.errors[0].pointer.starts_with(&first),
            "{:?}",
            refused.errors[0]
        );
        assert!(
            refused.errors[0].detail.contains("/contact/rk = "),
            "{:?}",
            refused.errors[0]
        );
    }

    #[test]
    fn a_run_above_a_ceiling_always_refuses_the_sweep() {
        let limits = AdmissionLimits {
            cost: CostLimits {
                max_work: 1.0,
                ..CostLimits::default()
            },
            ..limits()
        };
        let valid = admit(
            &calibration(),
            &Registry::builtin(),
            &super::tests::limits(),
            &SignalLibrary::default(),
        )
        .unwrap()
        .runs
        .iter()
        .filter(|run| run.invalid.is_none())
        .count();
        let Err(Refusal::TooCostly { runs, exceeded }) = admit(
            &calibration(),
            &Registry::builtin(),
            &limits,
            &SignalLibrary::default(),
        ) else {
            panic!("every valid run is above a work ceiling of 1 update");
        };
        // Invalid runs have no estimate: the valid ones are refused, even when recorded.
        assert_eq!((runs.refused, runs.runs, runs.first), (valid, 32, 0));
        assert!(runs.errors.len() <= MAX_RUN_ERRORS);
        assert!(runs.errors.iter().all(|e| e.pointer.starts_with("/runs/")));
        assert_eq!(exceeded[0].quantity, "work");
    }

    #[test]
    fn an_axis_pointer_that_names_no_input_refuses_the_sweep_at_that_axis() {
        let mut body = calibration();
        body["axes"][1]["pointer"] = json!("/contact/rkk");
        body["axes"][0]["pointer"] = json!("/reference/mode");
        let Err(Refusal::Request(SweepError::Invalid(errors))) =
            admit(&body, &Registry::builtin(), &limits(), &SignalLibrary::default())
        else {
            panic!("both pointers name no input");
        };
        assert_eq!(
            errors,
            vec![
                FieldError::new(
                    "/axes/0/pointer",
                    "no input `mode` under /reference; valid: modes"
                ),
                FieldError::new(
                    "/axes/1/pointer",
                    "no input `rkk` under /contact; valid: damping, gap, law, rk, stiffness"
                ),
            ]
        );
    }

    #[test]
    fn the_pointers_of_the_shipped_sweeps_name_inputs() {
        for example in [
            include_str!("../../examples/sweep-calibration.json"),
            include_str!("../../examples/sweep-gaps.json"),
            include_str!("../../examples/sweep-static-correction.json"),
        ] {
            let body: Value = serde_json::from_str(example).unwrap();
            let spec = spec::parse(&body, 10_000).unwrap();
            let process = Registry::builtin().get(&spec.process).unwrap();
            assert_eq!(
                check_pointers(&spec, process.as_ref()),
                Ok(()),
                "{}",
                spec.process
            );
        }
    }

    #[test]
    fn the_request_is_checked_before_the_process_is_looked_up() {
        let mut body = calibration();
        body["process"] = json!("no-such");
        assert_eq!(
            admit(&body, &Registry::builtin(), &limits(), &SignalLibrary::default()).unwrap_err(),
            Refusal::NoSuchProcess("no-such".into())
        );
        body["samples"] = json!(3);
        assert!(matches!(
            admit(&body, &Registry::builtin(), &limits(), &SignalLibrary::default()),
            Err(Refusal::Request(SweepError::Invalid(_)))
        ));
        let small = AdmissionLimits {
            max_runs: 10,
            ..limits()
        };
        assert_eq!(
            admit(
                &calibration(),
                &Registry::builtin(),
                &small,
                &SignalLibrary::default()
            )
            .unwrap_err(),
            Refusal::Request(SweepError::TooLarge { runs: 32, limit: 10 })
        );
    }
}
