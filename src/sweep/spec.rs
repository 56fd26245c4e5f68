//! From a [`SweepRequest`] to a [`SweepSpec`]: the checks serde cannot make, every
//! problem reported with a JSON pointer into the request body (`/axes/0/linspace`,
//! `/samples`, ...), all of them at once.

use serde::Deserialize;
use serde_json::{Map, Number, Value};

use super::member::Member;
use super::pointer;
use super::request::{AxisKind, Bounds, Design, InvalidRuns, Policy, Spacing, SweepAxis, SweepRequest};
use super::sampling::Law;
use super::table;
use crate::processes::FieldError;

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
    /// The axis as written in the request (kept in the sweep's definition).
    pub given: SweepAxis,
}

impl Axis {
    /// A generated number as JSON: an integer when the target is one.
    pub fn number(&self, value: f64) -> Value {
        number(self.integer, value)
    }
}

fn number(integer: bool, value: f64) -> Value {
    if integer && value.is_finite() && value.abs() < 9.0e15 {
        Value::from(value.round() as i64)
    } else {
        Number::from_f64(value).map_or(Value::Null, Value::Number)
    }
}

/// A checked sweep request.
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

/// Parses a sweep request body; refuses more than `max_runs` runs.
pub fn parse(body: &Value, max_runs: usize) -> Result<SweepSpec, SweepError> {
    // Reading a request fails only on a body that is no object: its members are `Member`s.
    let request = SweepRequest::deserialize(body)
        .map_err(|_| SweepError::Invalid(vec![FieldError::new("", "the body must be a JSON object")]))?;
    SweepSpec::from_request(request, max_runs)
}

impl SweepSpec {
    /// Checks a request; refuses more than `max_runs` runs.
    pub fn from_request(request: SweepRequest, max_runs: usize) -> Result<Self, SweepError> {
        let mut errors = Vec::new();
        for key in request.unknown.keys() {
            errors.push(FieldError::new(
                format!("/{key}"),
                format!("unknown member (expected {})", SweepRequest::MEMBERS.join(", ")),
            ));
        }
        let process = match request.process {
            Member::Typed(id) => id,
            Member::Missing | Member::Mistyped(_) => {
                errors.push(FieldError::new(
                    "/process",
                    "is required: a process id, e.g. `cantilever-impact`",
                ));
                String::new()
            }
        };
        let inputs = match request.inputs {
            Member::Typed(inputs) => Value::Object(inputs),
            Member::Mistyped(_) => {
                errors.push(FieldError::new(
                    "/inputs",
                    "must be an object (the base inputs of every run)",
                ));
                Value::Object(Map::new())
            }
            Member::Missing => {
                errors.push(FieldError::new(
                    "/inputs",
                    "is required: the base inputs of every run",
                ));
                Value::Object(Map::new())
            }
        };
        let mut axes: Vec<Axis> = Vec::new();
        match request.axes {
            Member::Typed(list) if !list.is_empty() => {
                for (index, axis) in list.into_iter().enumerate() {
                    if let Some(axis) = check_axis(axis, index, &inputs, &mut errors) {
                        if axes.iter().any(|a| a.pointer == axis.pointer) {
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
        let design = match request.design {
            Member::Missing => Some(if any_random {
                Design::MonteCarlo
            } else {
                Design::Grid
            }),
            Member::Typed(design) => Some(design),
            Member::Mistyped(_) => {
                errors.push(FieldError::new(
                    "/design",
                    "must be `grid`, `monte_carlo` or `latin_hypercube`",
                ));
                None
            }
        };
        match design {
            Some(Design::Grid) if any_random => errors.push(FieldError::new(
                "/design",
                "a grid takes list axes only (`values`, `linspace`, `logspace`); random axes need `monte_carlo` or `latin_hypercube`",
            )),
            Some(Design::MonteCarlo | Design::LatinHypercube) if !any_random && !axes.is_empty() => errors
                .push(FieldError::new(
                    "/design",
                    "a random design needs at least one random axis (`uniform`, `normal`, `lognormal`)",
                )),
            _ => {}
        }
        let samples = match request.samples {
            Member::Missing if any_random => {
                errors.push(FieldError::new(
                    "/samples",
                    "is required with random axes: the number of draws",
                ));
                None
            }
            Member::Missing => None,
            _ if !any_random => {
                errors.push(FieldError::new(
                    "/samples",
                    "only applies to random axes; a grid runs every cell once",
                ));
                None
            }
            Member::Typed(n) if n >= 1 => Some(usize::try_from(n).unwrap_or(usize::MAX)),
            Member::Typed(_) | Member::Mistyped(_) => {
                errors.push(FieldError::new("/samples", "must be a positive integer"));
                None
            }
        };
        let seed = match request.seed {
            Member::Missing => 0,
            Member::Typed(seed) => seed,
            Member::Mistyped(_) => {
                errors.push(FieldError::new("/seed", "must be an integer from 0 to 2^64 - 1"));
                0
            }
        };
        let policy = match request.policy {
            Member::Missing => Policy::Continue,
            Member::Typed(policy) => policy,
            Member::Mistyped(_) => {
                errors.push(FieldError::new("/policy", "must be `continue` or `fail_fast`"));
                Policy::Continue
            }
        };
        let invalid_runs = match request.invalid_runs {
            Member::Missing => InvalidRuns::Refuse,
            Member::Typed(invalid_runs) => invalid_runs,
            Member::Mistyped(_) => {
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
}

/// `value` rounded to 15 significant digits: inner `linspace`/`logspace` values read
/// as written (10, not 9.999999999999998; 0.3, not 0.30000000000000004), and are the
/// same on every platform whatever the last bit of its `powf`.
fn significant(value: f64) -> f64 {
    format!("{value:.14e}").parse().unwrap_or(value)
}

fn is_integer(number: &Number) -> bool {
    number.is_i64() || number.is_u64()
}

/// The axis at `/axes/{index}`, or `None` with its problems added to `errors`.
fn check_axis(
    member: Member<SweepAxis>,
    index: usize,
    inputs: &Value,
    errors: &mut Vec<FieldError>,
) -> Option<Axis> {
    let at = |member: &str| format!("/axes/{index}{member}");
    let Member::Typed(given) = member else {
        errors.push(FieldError::new(
            at(""),
            "must be an object with a `pointer` and its values",
        ));
        return None;
    };
    for key in given.unknown.keys() {
        errors.push(FieldError::new(
            at(&format!("/{key}")),
            format!(
                "unknown member (expected pointer and one of {})",
                AxisKind::names()
            ),
        ));
    }
    let Member::Typed(target) = &given.pointer else {
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
    let kinds = given.kinds();
    let [kind] = kinds.as_slice() else {
        errors.push(FieldError::new(
            at(""),
            format!("needs exactly one of {}, not {}", AxisKind::names(), kinds.len()),
        ));
        return None;
    };
    let here = at(&format!("/{}", kind.name()));
    // A law's unknown members are named at their own pointer.
    let law = match kind {
        AxisKind::Normal => Some(&given.normal),
        AxisKind::Lognormal => Some(&given.lognormal),
        _ => None,
    };
    if let Some(parameters) = law.and_then(Member::typed)
        && !parameters.unknown.is_empty()
    {
        for key in parameters.unknown.keys() {
            errors.push(FieldError::new(
                format!("{here}/{key}"),
                "unknown member (expected mean, std)",
            ));
        }
        return None;
    }
    // Integer targets (a seed, an integer in the base, or integer bounds for a new member)
    // get integers.
    let seed = table::is_seed(target);
    let base_is_integer = seed || base.as_ref().is_some_and(|v| v.is_i64() || v.is_u64());
    let integer_target = |bounds: [&Number; 2]| match &base {
        Some(_) => base_is_integer,
        None => seed || bounds.iter().all(|n| is_integer(n)),
    };
    let checked = match kind {
        AxisKind::Values => match &given.values {
            Member::Typed(list) if !list.is_empty() => Ok((AxisValues::List(list.clone()), base_is_integer)),
            _ => Err("must be a non-empty list of values".to_owned()),
        },
        AxisKind::Linspace | AxisKind::Logspace => {
            let spacing = match kind {
                AxisKind::Linspace => &given.linspace,
                _ => &given.logspace,
            };
            spaced(spacing, *kind == AxisKind::Logspace).map(|(values, bounds)| {
                let integer = integer_target(bounds);
                let values = values.into_iter().map(|v| number(integer, v)).collect();
                (AxisValues::List(values), integer)
            })
        }
        AxisKind::Uniform => match &given.uniform {
            Member::Typed(Bounds(low_given, high_given)) => match (low_given.as_f64(), high_given.as_f64()) {
                (Some(low), Some(high)) if low.is_finite() && high.is_finite() && low < high => Ok((
                    AxisValues::Random(Law::Uniform { low, high }),
                    integer_target([low_given, high_given]),
                )),
                _ => Err("must be [low, high] with finite low < high".to_owned()),
            },
            _ => Err("must be [low, high] with finite low < high".to_owned()),
        },
        AxisKind::Normal | AxisKind::Lognormal => {
            let parameters = law.and_then(Member::typed);
            let mean = parameters.and_then(|p| p.mean.typed()).and_then(Number::as_f64);
            let std = parameters.and_then(|p| p.std.typed()).and_then(Number::as_f64);
            match (mean, std) {
                (Some(mean), Some(std)) if mean.is_finite() && std.is_finite() && std >= 0.0 => {
                    let law = if *kind == AxisKind::Normal {
                        Law::Normal { mean, std }
                    } else {
                        Law::LogNormal { mean, std }
                    };
                    Ok((AxisValues::Random(law), base_is_integer))
                }
                _ => Err(if *kind == AxisKind::Normal {
                    "must be {\"mean\", \"std\"} with finite mean and std >= 0".to_owned()
                } else {
                    "must be {\"mean\", \"std\"} of the natural logarithm of the value, finite, std >= 0"
                        .to_owned()
                }),
            }
        }
    };
    match checked {
        Ok((values, integer)) => Some(Axis {
            pointer: target.clone(),
            values,
            integer,
            given,
        }),
        Err(detail) => {
            errors.push(FieldError::new(here, detail));
            None
        }
    }
}

/// The values of `linspace` (or `logspace` when `logarithmic`), with the start and stop
/// as written; `Err` says what is wrong.
fn spaced(spacing: &Member<Spacing>, logarithmic: bool) -> Result<(Vec<f64>, [&Number; 2]), String> {
    let Member::Typed(Spacing(start_given, stop_given, count)) = spacing else {
        return Err("must be [start, stop, count]".into());
    };
    let (Member::Typed(start_given), Member::Typed(stop_given)) = (start_given, stop_given) else {
        return Err("start and stop must be numbers".into());
    };
    let (Some(start), Some(stop)) = (start_given.as_f64(), stop_given.as_f64()) else {
        return Err("start and stop must be numbers".into());
    };
    let count = match count {
        Member::Typed(n) if (1..=1_000_000).contains(n) => *n as usize,
        _ => return Err("count must be an integer from 1 to 1000000".into()),
    };
    if !(start.is_finite() && stop.is_finite()) {
        return Err("start and stop must be finite".into());
    }
    if logarithmic && !(start > 0.0 && stop > 0.0) {
        return Err(
            "start and stop must be positive: logspace spaces the values (not exponents) geometrically"
                .into(),
        );
    }
    let values = (0..count)
        .map(|i| {
            let fraction = if count == 1 {
                0.0
            } else {
                i as f64 / (count - 1) as f64
            };
            match (i, logarithmic) {
                (0, _) => start,
                (i, _) if i == count - 1 => stop,
                (_, false) => significant(start + (stop - start) * fraction),
                // Through decimal exponents weighed by whole numbers, so that decades
                // land on exact powers of ten (0.1 … 1e6 in 8 gives 1e5, not
                // 99999.99999999991 from start × ratio^fraction).
                (i, true) => {
                    let last = (count - 1) as f64;
                    let exponent = (start.log10() * (last - i as f64) + stop.log10() * i as f64) / last;
                    significant(10f64.powf(exponent))
                }
            }
        })
        .collect();
    Ok((values, [start_given, stop_given]))
}
