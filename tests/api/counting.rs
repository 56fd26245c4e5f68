//! `count-steps`: a small but real process for the service tests.
//!
//! It counts `steps` steps (sleeping or spinning `step_ms` ms in each), reports progress
//! after every step and honours cancellation; it sums the step numbers (the document's
//! `sum` is n(n+1)/2) and records a history `signal` with a sine `value` column and a
//! `square` column (step²), with optional one-sample spikes. It can be told to fail
//! deterministically or to panic at a given step, and it validates its inputs with JSON
//! pointers like the real processes. It takes `solver.threads` as the real processes do
//! and records the threads its worker gave it. A [`Probe`] shared with the test records
//! what ran.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use chocmodal::processes::{
    FieldError, History, InvalidInputs, Process, ProgressFn, RunError, RunOutput, Validated, WorkEstimate,
};
use serde_json::{Value, json};

pub const ID: &str = "count-steps";

/// What the test can observe of the runs.
#[derive(Debug, Default)]
pub struct Probe {
    /// Runs started.
    pub started: AtomicUsize,
    /// Runs that stopped because the progress callback said so.
    pub cancelled: AtomicUsize,
    /// When the last run stopped on cancellation.
    pub cancelled_at: Mutex<Option<Instant>>,
    /// Step counts of the runs started, in order.
    pub runs: Mutex<Vec<u64>>,
    /// Threads of the pool each run started in, in order.
    pub threads: Mutex<Vec<usize>>,
}

impl Probe {
    pub fn started(&self) -> usize {
        self.started.load(Ordering::SeqCst)
    }
}

#[derive(Debug)]
pub struct CountSteps {
    pub probe: Arc<Probe>,
}

struct Inputs {
    steps: u64,
    step_ms: f64,
    busy: bool,
    fail_at: Option<u64>,
    panic_at: Option<u64>,
    spikes: Vec<(u64, f64)>,
}

fn parse(inputs: &Value) -> Result<Inputs, InvalidInputs> {
    let mut errors = Vec::new();
    let object = inputs.as_object().cloned().unwrap_or_default();
    for key in object.keys() {
        if !matches!(
            key.as_str(),
            "steps" | "step_ms" | "busy" | "fail_at" | "panic_at" | "spikes" | "solver"
        ) {
            errors.push(FieldError::new(format!("/inputs/{key}"), "unknown input"));
        }
    }
    let steps = match object.get("steps").map(Value::as_u64) {
        Some(Some(n)) if (1..=1_000_000).contains(&n) => n,
        Some(_) => {
            errors.push(FieldError::new(
                "/inputs/steps",
                "must be an integer between 1 and 1000000",
            ));
            0
        }
        None => {
            errors.push(FieldError::new("/inputs/steps", "is required"));
            0
        }
    };
    let step_ms = match object.get("step_ms") {
        None => 0.0,
        Some(v) => match v.as_f64() {
            Some(ms) if (0.0..=1000.0).contains(&ms) => ms,
            _ => {
                errors.push(FieldError::new(
                    "/inputs/step_ms",
                    "must be a number of ms between 0 and 1000",
                ));
                0.0
            }
        },
    };
    let optional_step = |name: &str, errors: &mut Vec<FieldError>| match object.get(name) {
        None => None,
        Some(v) => v.as_u64().or_else(|| {
            errors.push(FieldError::new(
                format!("/inputs/{name}"),
                "must be a step number",
            ));
            None
        }),
    };
    let fail_at = optional_step("fail_at", &mut errors);
    let panic_at = optional_step("panic_at", &mut errors);
    let spikes = object
        .get("spikes")
        .and_then(Value::as_array)
        .map(|list| {
            list.iter()
                .filter_map(|pair| Some((pair.get(0)?.as_u64()?, pair.get(1)?.as_f64()?)))
                .collect()
        })
        .unwrap_or_default();
    if errors.is_empty() {
        Ok(Inputs {
            steps,
            step_ms,
            busy: object.get("busy").and_then(Value::as_bool).unwrap_or(false),
            fail_at,
            panic_at,
            spikes,
        })
    } else {
        Err(InvalidInputs(errors))
    }
}

impl Process for CountSteps {
    fn id(&self) -> &'static str {
        ID
    }

    fn title(&self) -> &'static str {
        "Count steps"
    }

    fn description(&self) -> &'static str {
        "Counts steps, slowly if asked; a test process."
    }

    /// As a process that shares its steps: what `solver.threads` asks.
    fn threads(&self, inputs: &Value) -> usize {
        chocmodal::processes::common_inputs::requested_threads(inputs)
    }

    fn inputs_description(&self) -> Value {
        json!({"steps": {"title": "Steps", "description": "number of steps", "schema": {"type": "integer", "minimum": 1}}})
    }

    fn outputs_description(&self) -> Value {
        json!({"signal": {"title": "Signal", "description": "a sine per step", "schema": {"type": "object"}}})
    }

    /// The estimate: one "modal DOF" per step, histories of three columns.
    fn validate(&self, inputs: &Value) -> Result<Validated, InvalidInputs> {
        parse(inputs)
            .map(|inputs| WorkEstimate {
                steps: inputs.steps as f64,
                modal_dofs: 1.0,
                contacts: 0.0,
                history_values: 3.0 * inputs.steps as f64,
                work_drivers: vec!["/inputs/steps".into()],
                history_drivers: vec!["/inputs/steps".into()],
                ..WorkEstimate::default()
            })
            .map(|estimate| Validated {
                estimate,
                warnings: Vec::new(),
            })
    }

    fn run(&self, inputs: &Value, progress: &mut ProgressFn<'_>) -> Result<RunOutput, RunError> {
        let inputs = parse(inputs)?;
        self.probe.started.fetch_add(1, Ordering::SeqCst);
        self.probe.runs.lock().unwrap().push(inputs.steps);
        self.probe
            .threads
            .lock()
            .unwrap()
            .push(rayon::current_num_threads());
        let step = Duration::from_secs_f64(inputs.step_ms / 1000.0);
        let (mut time, mut value, mut square) = (Vec::new(), Vec::new(), Vec::new());
        let mut sum: u64 = 0;
        for i in 1..=inputs.steps {
            if inputs.fail_at == Some(i) {
                return Err(RunError::Failed(format!("diverged at step {i}")));
            }
            if inputs.panic_at == Some(i) {
                panic!("the test process panics at step {i}");
            }
            if inputs.busy {
                let until = Instant::now() + step;
                while Instant::now() < until {
                    std::hint::spin_loop();
                }
            } else if !step.is_zero() {
                std::thread::sleep(step);
            }
            sum += i;
            time.push(i as f64 * 1e-3);
            let spike = inputs.spikes.iter().find(|(at, _)| *at == i).map(|(_, v)| *v);
            value.push(spike.unwrap_or((i as f64 * 0.05).sin()));
            square.push((i * i) as f64);
            if progress(i as f64 / inputs.steps as f64).is_break() {
                self.probe.cancelled.fetch_add(1, Ordering::SeqCst);
                *self.probe.cancelled_at.lock().unwrap() = Some(Instant::now());
                return Err(RunError::Cancelled);
            }
        }
        Ok(RunOutput {
            document: json!({"steps": inputs.steps, "sum": sum}),
            histories: vec![History {
                name: "signal".into(),
                time,
                series: vec![("value".into(), value), ("square".into(), square)],
            }],
            warnings: Vec::new(),
        })
    }
}
