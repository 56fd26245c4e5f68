//! Parsing a sweep request, every problem reported with a JSON pointer into its body
//! (`/axes/0/linspace`, `/samples`, ...).
//!
//! ```json
//! {"process": "cantilever-impact", "inputs": {...},
//!  "axes": [{"pointer": "/contact/rk", "logspace": [0.1, 100, 4]},
//!           {"pointer": "/solver/time_step", "values": [1e-5, 5e-5]}],
//!  "design": "grid", "samples": 100, "seed": 7, "policy": "continue"}
//! ```

use serde_json::{Map, Value};

use super::pointer;
use super::sampling::Law;
use crate::processes::FieldError;

/// How the runs are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Design {
    /// Cartesian product of list axes (no random axis).
    Grid,
    /// Independent draws of the random axes.
    MonteCarlo,
    /// Stratified draws: each random axis hits each of its `samples` equal-probability strata once.
    LatinHypercube,
}

impl Design {
    pub fn as_str(self) -> &'static str {
        match self {
            Design::Grid => "grid",
            Design::MonteCarlo => "monte_carlo",
            Design::LatinHypercube => "latin_hypercube",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        [Design::Grid, Design::MonteCarlo, Design::LatinHypercube]
            .into_iter()
            .find(|d| d.as_str() == text)
    }
}

/// What a failed run does to the rest of the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Policy {
    /// The other runs go on; the sweep ends `successful` once every run ended.
    Continue,
    /// The first failed run dismisses the runs not finished; the sweep is `failed`.
    FailFast,
}

impl Policy {
    pub fn as_str(self) -> &'static str {
        match self {
            Policy::Continue => "continue",
            Policy::FailFast => "fail_fast",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        [Policy::Continue, Policy::FailFast]
            .into_iter()
            .find(|p| p.as_str() == text)
    }
}

/// The values an axis takes.
#[derive(Debug, Clone, PartialEq)]
pub enum AxisValues {
    /// Explicit values (from `values`, `linspace` or `logspace`).
    List(Vec<Value>),
    /// Draws of a law.
    Random(Law),
}

/// One axis of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// JSON pointer into the process inputs, e.g. `/contact/rk`.
    pub pointer: String,
    pub values: AxisValues,
    /// Generated numbers are rounded to integers (the target holds an integer).
    pub integer: bool,
}

impl Axis {
    /// A generated number as JSON: an integer when the target is one.
    pub fn number(&self, value: f64) -> Value {
        if self.integer && value.is_finite() && value.abs() < 9.0e15 {
            Value::from(value.round() as i64)
        } else {
            serde_json::Number::from_f64(value).map_or(Value::Null, Value::Number)
        }
    }
}

/// What happens to generated runs whose inputs the process refuses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InvalidRuns {
    /// The whole sweep is refused (422), nothing is queued.
    Refuse,
    /// The sweep is queued; each invalid run is recorded as a `failed` job with its
    /// `invalid-inputs` problem and never reaches a worker (calibration maps that cross
    /// the stability limit: such cells are simply not valid).
    Record,
}

impl InvalidRuns {
    pub fn as_str(self) -> &'static str {
        match self {
            InvalidRuns::Refuse => "refuse",
            InvalidRuns::Record => "record",
        }
    }
}

/// A parsed sweep request.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSpec {
    pub process: String,
    /// Base inputs: every run starts from them.
    pub inputs: Value,
    pub axes: Vec<Axis>,
    pub design: Design,
    /// Draws per grid cell (random designs only).
    pub samples: Option<usize>,
    pub seed: u64,
    pub policy: Policy,
    pub invalid_runs: InvalidRuns,
}

/// Why a sweep request is refused.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepError {
    /// 422: problems with the request, by JSON pointer into its body.
    Invalid(Vec<FieldError>),
    /// 422: more runs than the service accepts in one sweep.
    TooLarge { runs: u128, limit: usize },
}

const KEYS: [&str; 8] = [
    "process",
    "inputs",
    "axes",
    "samples",
    "seed",
    "design",
    "policy",
    "invalid_runs",
];
const AXIS_KEYS: [&str; 6] = ["values", "linspace", "logspace", "uniform", "normal", "lognormal"];

/// Parses a sweep request body; refuses more than `max_runs` runs.
pub fn parse(body: &Value, max_runs: usize) -> Result<SweepSpec, SweepError> {
    let mut errors = Vec::new();
    let Some(object) = body.as_object() else {
        return Err(SweepError::Invalid(vec![FieldError::new(
            "",
            "the body must be a JSON object",
        )]));
    };
    for key in object.keys().filter(|k| !KEYS.contains(&k.as_str())) {
        errors.push(FieldError::new(
            format!("/{key}"),
            format!("unknown member (expected {})", KEYS.join(", ")),
        ));
    }
    let process = match object.get("process").and_then(Value::as_str) {
        Some(id) => id.to_owned(),
        None => {
            errors.push(FieldError::new(
                "/process",
                "is required: a process id, e.g. `cantilever-impact`",
            ));
            String::new()
        }
    };
    let inputs = match object.get("inputs") {
        Some(inputs @ Value::Object(_)) => inputs.clone(),
        Some(_) => {
            errors.push(FieldError::new(
                "/inputs",
                "must be an object (the base inputs of every run)",
            ));
            Value::Object(Map::new())
        }
        None => {
            errors.push(FieldError::new(
                "/inputs",
                "is required: the base inputs of every run",
            ));
            Value::Object(Map::new())
        }
    };
    let mut axes = Vec::new();
    match object.get("axes").and_then(Value::as_array) {
        Some(list) if !list.is_empty() => {
            for (index, axis) in list.iter().enumerate() {
                if let Some(axis) = parse_axis(axis, index, &inputs, &mut errors) {
                    if axes.iter().any(|a: &Axis| a.pointer == axis.pointer) {
                        errors.push(FieldError::new(
                            format!("/axes/{index}/pointer"),
                            format!("`{}` is already the pointer of another axis", axis.pointer),
                        ));
                    }
                    axes.push(axis);
                }
            }
        }
        _ => errors.push(FieldError::new("/axes", "is required: a non-empty list of axes")),
    }
    let any_random = axes.iter().any(|a| matches!(a.values, AxisValues::Random(_)));
    let design = match object.get("design") {
        None => Some(if any_random {
            Design::MonteCarlo
        } else {
            Design::Grid
        }),
        Some(value) => value.as_str().and_then(Design::parse).or_else(|| {
            errors.push(FieldError::new(
                "/design",
                "must be `grid`, `monte_carlo` or `latin_hypercube`",
            ));
            None
        }),
    };
    match design {
        Some(Design::Grid) if any_random => errors.push(FieldError::new(
            "/design",
            "a grid takes list axes only (`values`, `linspace`, `logspace`); random axes need `monte_carlo` or `latin_hypercube`",
        )),
        Some(Design::MonteCarlo | Design::LatinHypercube) if !any_random && !axes.is_empty() => {
            errors.push(FieldError::new(
                "/design",
                "a random design needs at least one random axis (`uniform`, `normal`, `lognormal`)",
            ))
        }
        _ => {}
    }
    let samples = match object.get("samples") {
        None if any_random => {
            errors.push(FieldError::new(
                "/samples",
                "is required with random axes: the number of draws",
            ));
            None
        }
        None => None,
        Some(_) if !any_random => {
            errors.push(FieldError::new(
                "/samples",
                "only applies to random axes; a grid runs every cell once",
            ));
            None
        }
        Some(value) => match value.as_u64() {
            Some(n) if n >= 1 => Some(usize::try_from(n).unwrap_or(usize::MAX)),
            _ => {
                errors.push(FieldError::new("/samples", "must be a positive integer"));
                None
            }
        },
    };
    let seed = match object.get("seed") {
        None => 0,
        Some(value) => value.as_u64().unwrap_or_else(|| {
            errors.push(FieldError::new("/seed", "must be an integer from 0 to 2^64 - 1"));
            0
        }),
    };
    let policy = match object.get("policy") {
        None => Policy::Continue,
        Some(value) => value.as_str().and_then(Policy::parse).unwrap_or_else(|| {
            errors.push(FieldError::new("/policy", "must be `continue` or `fail_fast`"));
            Policy::Continue
        }),
    };
    let invalid_runs = match object.get("invalid_runs").map(Value::as_str) {
        None | Some(Some("refuse")) => InvalidRuns::Refuse,
        Some(Some("record")) => InvalidRuns::Record,
        Some(_) => {
            errors.push(FieldError::new("/invalid_runs", "must be `refuse` or `record`"));
            InvalidRuns::Refuse
        }
    };
    if !errors.is_empty() {
        return Err(SweepError::Invalid(errors));
    }
    let spec = SweepSpec {
        process,
        inputs,
        axes,
        design: design.unwrap_or(Design::Grid),
        samples,
        seed,
        policy,
        invalid_runs,
    };
    // Counted in u128 so that a huge product cannot overflow before it is refused.
    let runs: u128 = spec
        .axes
        .iter()
        .filter_map(|a| match &a.values {
            AxisValues::List(values) => Some(values.len() as u128),
            AxisValues::Random(_) => None,
        })
        .product::<u128>()
        * spec.samples_per_cell() as u128;
    if runs > max_runs as u128 {
        return Err(SweepError::TooLarge {
            runs,
            limit: max_runs,
        });
    }
    Ok(spec)
}

/// `value` rounded to 15 significant digits: inner `linspace`/`logspace` values read
/// as written (10, not 9.999999999999998; 0.3, not 0.30000000000000004), and are the
/// same on every platform whatever the last bit of its `powf`.
fn significant(value: f64) -> f64 {
    format!("{value:.14e}").parse().unwrap_or(value)
}

fn parse_axis(axis: &Value, index: usize, inputs: &Value, errors: &mut Vec<FieldError>) -> Option<Axis> {
    let at = |member: &str| format!("/axes/{index}{member}");
    let Some(object) = axis.as_object() else {
        errors.push(FieldError::new(
            at(""),
            "must be an object with a `pointer` and its values",
        ));
        return None;
    };
    for key in object.keys() {
        if key != "pointer" && !AXIS_KEYS.contains(&key.as_str()) {
            errors.push(FieldError::new(
                at(&format!("/{key}")),
                format!(
                    "unknown member (expected pointer and one of {})",
                    AXIS_KEYS.join(", ")
                ),
            ));
        }
    }
    let Some(target) = object.get("pointer").and_then(Value::as_str) else {
        errors.push(FieldError::new(
            at("/pointer"),
            "is required: a JSON pointer into the inputs, e.g. `/contact/rk`",
        ));
        return None;
    };
    // The pointer must exist in the base inputs or be creatable there.
    let base = inputs.pointer(target).cloned();
    if let Err(why) = pointer::set(&mut inputs.clone(), target, Value::Null) {
        errors.push(FieldError::new(at("/pointer"), why));
        return None;
    }
    let given: Vec<&str> = AXIS_KEYS
        .iter()
        .copied()
        .filter(|k| object.contains_key(*k))
        .collect();
    let [kind] = given.as_slice() else {
        errors.push(FieldError::new(
            at(""),
            format!(
                "needs exactly one of {}, not {}",
                AXIS_KEYS.join(", "),
                given.len()
            ),
        ));
        return None;
    };
    let member = &object[*kind];
    let here = at(&format!("/{kind}"));
    let is_integer = |v: &Value| v.is_i64() || v.is_u64();
    // A law's unknown members are named at their own pointer.
    if matches!(*kind, "normal" | "lognormal")
        && let Some(law) = member.as_object()
    {
        let unknown: Vec<&String> = law.keys().filter(|k| *k != "mean" && *k != "std").collect();
        for key in &unknown {
            errors.push(FieldError::new(
                format!("{here}/{key}"),
                "unknown member (expected mean, std)",
            ));
        }
        if !unknown.is_empty() {
            return None;
        }
    }
    let mut fail = |detail: &str| {
        errors.push(FieldError::new(here.clone(), detail));
        None
    };
    // Integer targets (an integer in the base, or integer bounds for a new member) get integers.
    let integer_target = |bounds: &[&Value]| match &base {
        Some(value) => is_integer(value),
        None => bounds.iter().all(|v| is_integer(v)),
    };
    let values = match *kind {
        "values" => match member.as_array() {
            Some(list) if !list.is_empty() => AxisValues::List(list.clone()),
            _ => return fail("must be a non-empty list of values"),
        },
        "linspace" | "logspace" => {
            let triple = member.as_array().filter(|a| a.len() == 3);
            let Some(triple) = triple else {
                return fail("must be [start, stop, count]");
            };
            let (Some(start), Some(stop)) = (triple[0].as_f64(), triple[1].as_f64()) else {
                return fail("start and stop must be numbers");
            };
            let count = match triple[2].as_u64() {
                Some(n) if (1..=1_000_000).contains(&n) => n as usize,
                _ => return fail("count must be an integer from 1 to 1000000"),
            };
            if !(start.is_finite() && stop.is_finite()) {
                return fail("start and stop must be finite");
            }
            let logarithmic = *kind == "logspace";
            if logarithmic && !(start > 0.0 && stop > 0.0) {
                return fail(
                    "start and stop must be positive: logspace spaces the values (not exponents) geometrically",
                );
            }
            let axis = Axis {
                pointer: target.to_owned(),
                values: AxisValues::List(Vec::new()),
                integer: integer_target(&[&triple[0], &triple[1]]),
            };
            let values = (0..count)
                .map(|i| {
                    let fraction = if count == 1 {
                        0.0
                    } else {
                        i as f64 / (count - 1) as f64
                    };
                    let value = match (i, logarithmic) {
                        (0, _) => start,
                        (i, _) if i == count - 1 => stop,
                        (_, false) => significant(start + (stop - start) * fraction),
                        (_, true) => significant(start * (stop / start).powf(fraction)),
                    };
                    axis.number(value)
                })
                .collect();
            return Some(Axis {
                values: AxisValues::List(values),
                ..axis
            });
        }
        "uniform" => {
            let pair = member.as_array().filter(|a| a.len() == 2);
            let bounds = pair.and_then(|p| Some((p[0].as_f64()?, p[1].as_f64()?)));
            match bounds {
                Some((low, high)) if low.is_finite() && high.is_finite() && low < high => {
                    let pair = pair.expect("checked");
                    return Some(Axis {
                        pointer: target.to_owned(),
                        values: AxisValues::Random(Law::Uniform { low, high }),
                        integer: integer_target(&[&pair[0], &pair[1]]),
                    });
                }
                _ => return fail("must be [low, high] with finite low < high"),
            }
        }
        "normal" | "lognormal" => {
            let mean = member.get("mean").and_then(Value::as_f64);
            let std = member.get("std").and_then(Value::as_f64);
            match (mean, std) {
                (Some(mean), Some(std)) if mean.is_finite() && std.is_finite() && std >= 0.0 => {
                    if *kind == "normal" {
                        AxisValues::Random(Law::Normal { mean, std })
                    } else {
                        AxisValues::Random(Law::LogNormal { mean, std })
                    }
                }
                _ => {
                    return fail(if *kind == "normal" {
                        "must be {\"mean\", \"std\"} with finite mean and std >= 0"
                    } else {
                        "must be {\"mean\", \"std\"} of the natural logarithm of the value, finite, std >= 0"
                    });
                }
            }
        }
        _ => unreachable!("kind is one of AXIS_KEYS"),
    };
    Some(Axis {
        pointer: target.to_owned(),
        values,
        integer: base.as_ref().is_some_and(is_integer),
    })
}
