//! Processes: the named computations the service and the CLI run.
//!
//! A process owns its input schema, its validation (every problem reported with a JSON
//! pointer into the execution request body, e.g. `/inputs/beam/modes`), and the mapping
//! from validated inputs to the physics core and back to a results document plus
//! time histories. It knows nothing about HTTP, the queue or the database: the service
//! and the CLI drive it through [`Process`].

// The processes, one folder each (inputs, pipeline, tests): a process uses the shared
// modules below and never another process's module (`src/architecture_tests.rs`).
pub mod bundle_dynamics;
pub mod cantilever_impact;
pub mod hex_bundle_dynamics;

// What the processes share.
pub mod basis_report;
/// Bending moments, stresses and strains from the run's curvatures.
pub mod bending;
/// What each column of a history is: name, unit, what it measures.
pub mod columns;
/// The inputs every process shares: the beam, the solver, the step, parsing helpers.
pub mod common_inputs;
pub mod contact_law;
pub mod cost;
/// The excitations the processes share (base accelerations, signals in the plane).
pub mod excitation;
pub mod excitation_record;
pub mod impact_report;
pub mod input_schema;
/// Pins of several kinds in one model (`kinds`).
pub mod kinds;
/// Allowables and the utilisation ratios they give (docs/margins.md).
pub mod margins;
pub mod metrics;
/// The member at fault when a tagged object fails to parse.
pub mod misfit;
pub mod model_check;
/// What a calculation note reads of a results document (peaks, margins, worst contacts
/// and pins, the bending envelope, the histories to plot).
pub mod note_facts;
/// The laws of random gaps the generators share.
pub mod random_gaps;
/// The shared parts of results documents (quality, energy) as serialized types.
pub mod report;
/// Every missing member at once, with the other problems of the inputs.
pub mod required;
/// The resultant contact force on each pin at each contact height.
pub mod resultants;
/// What every run of pins with point contacts reports: per contact, per line, the run.
pub mod run_report;
/// The `signal` base acceleration: a stored accelerogram by id, or a file for the CLI.
pub mod signal_input;
/// A process described by its types, and the one adapter to [`Process`].
pub mod simulation;
pub mod strict_json;
/// The `spectrum_compatible` base acceleration: a synthetic earthquake as an input.
pub mod synthetic_input;
/// Plausibility warnings about valid inputs, the same for every process.
pub mod warnings;

#[cfg(test)]
mod excitation_tests;
#[cfg(test)]
mod robustness_tests;
#[cfg(test)]
mod simulation_tests;
#[cfg(test)]
mod static_correction_tests;

use std::ops::ControlFlow;
use std::sync::Arc;

pub use columns::Column;
pub use cost::{CostLimits, TooCostly, WorkEstimate};
pub use simulation::{HistoryKind, HistoryOutput, Output, Simulation};
pub use warnings::Warning;

/// A shipped example of a process: its file in `examples/` and the execution request it
/// holds (`{"inputs": …}`), embedded in the binary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Example {
    pub file: &'static str,
    pub body: &'static str,
}

/// One problem with the inputs: where (JSON pointer into the request body) and why.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FieldError {
    /// JSON pointer into the execution request body, e.g. `/inputs/beam/modes`.
    pub pointer: String,
    /// Human-readable reason, e.g. `must be between 1 and 78`.
    pub detail: String,
}

impl FieldError {
    pub fn new(pointer: impl Into<String>, detail: impl Into<String>) -> Self {
        Self {
            pointer: pointer.into(),
            detail: detail.into(),
        }
    }
}

/// Every problem found in one set of inputs (never empty).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid inputs: {}", .0.iter().map(|e| format!("{}: {}", e.pointer, e.detail)).collect::<Vec<_>>().join("; "))]
pub struct InvalidInputs(pub Vec<FieldError>);

/// A sampled time history: one shared time column and named series of equal length.
#[derive(Debug, Clone, PartialEq)]
pub struct History {
    /// Output name, used in URLs and file names (`tip_displacement`).
    pub name: String,
    /// Sample times (s), strictly increasing.
    pub time: Vec<f64>,
    /// Named columns (`numerical`, `reference`, `c0`, ...), each `time.len()` long.
    pub series: Vec<(String, Vec<f64>)>,
}

impl History {
    /// CSV text with a `time,<series...>` header, full precision.
    pub fn to_csv(&self) -> String {
        columns_csv("time", &self.time, &self.series)
    }
}

/// CSV text of a key column (`time`, `frequency`) and named series of equal length, with
/// a `<key>,<series...>` header; each number as [`crate::csv_format`] writes it.
pub fn columns_csv(key: &str, keys: &[f64], series: &[(String, Vec<f64>)]) -> String {
    let mut out = String::with_capacity(keys.len() * (series.len() + 1) * 24);
    out.push_str(key);
    for (name, _) in series {
        out.push(',');
        out.push_str(name);
    }
    out.push('\n');
    for (row, k) in keys.iter().enumerate() {
        crate::csv_format::push_number(&mut out, *k);
        for (_, values) in series {
            out.push(',');
            crate::csv_format::push_number(&mut out, values[row]);
        }
        out.push('\n');
    }
    out
}

/// [`columns_csv`]'s rows (without its header line) written to `out` one by one, so that
/// the text of a long history is never whole in memory: the same bytes.
pub fn write_columns_csv_rows(
    out: &mut dyn std::io::Write,
    keys: &[f64],
    series: &[(String, Vec<f64>)],
) -> std::io::Result<()> {
    let mut line = String::with_capacity((series.len() + 1) * 24);
    for (row, k) in keys.iter().enumerate() {
        line.clear();
        crate::csv_format::push_number(&mut line, *k);
        for (_, values) in series {
            line.push(',');
            crate::csv_format::push_number(&mut line, values[row]);
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// What a successful run produces.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// Results document without its `outputs` links (the caller adds those, since
    /// only it knows where histories are served from); its `warnings` are
    /// [`RunOutput::warnings`].
    pub document: serde_json::Value,
    /// Time histories, served as `/jobs/{id}/results/{name}` or written as CSV.
    pub histories: Vec<History>,
    /// Plausibility warnings about the inputs.
    pub warnings: Vec<Warning>,
}

/// Inputs a process accepts: what running them will cost, and what looks implausible
/// about them (warnings, not refusals).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Validated {
    pub estimate: WorkEstimate,
    pub warnings: Vec<Warning>,
}

impl RunOutput {
    /// The results document with its `outputs` links (`{name: {href}}`), `href` giving
    /// where each history is served from.
    pub fn document_with_outputs(self, href: impl Fn(&str) -> String) -> serde_json::Value {
        let mut document = self.document;
        let outputs: serde_json::Map<String, serde_json::Value> = self
            .histories
            .iter()
            .map(|h| (h.name.clone(), serde_json::json!({ "href": href(&h.name) })))
            .collect();
        if let serde_json::Value::Object(map) = &mut document {
            map.insert("outputs".into(), serde_json::Value::Object(outputs));
        }
        document
    }
}

/// Why a run did not produce results.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// The progress callback asked to stop.
    #[error("cancelled")]
    Cancelled,
    /// The inputs were invalid (only when `run` is called without `validate`).
    #[error(transparent)]
    Invalid(#[from] InvalidInputs),
    /// A deterministic failure of the computation (divergence, ...): retrying will not help.
    #[error("{0}")]
    Failed(String),
}

impl From<crate::physics::integrate::SimulationError> for RunError {
    /// Cancelled stays cancelled; any other failure of the integration (divergence, ...)
    /// is deterministic.
    fn from(error: crate::physics::integrate::SimulationError) -> Self {
        match error {
            crate::physics::integrate::SimulationError::Cancelled => RunError::Cancelled,
            other => RunError::Failed(other.to_string()),
        }
    }
}

/// Progress and cancellation: called with the fraction done (0..=1); returning
/// `ControlFlow::Break(())` stops the run promptly with [`RunError::Cancelled`].
pub type ProgressFn<'a> = dyn FnMut(f64) -> ControlFlow<()> + 'a;

/// A computation the service can queue and the CLI can run: any [`Simulation`] is one;
/// implement this directly only for a process that is not typed (the tests' fakes).
pub trait Process: Send + Sync + std::fmt::Debug {
    /// Stable identifier used in URLs (`cantilever-impact`).
    fn id(&self) -> &'static str;
    /// One-line title.
    fn title(&self) -> &'static str;
    /// Its shipped examples (none by default).
    fn examples(&self) -> &'static [Example] {
        &[]
    }
    /// A paragraph for the process list.
    fn description(&self) -> &'static str;
    /// OGC process description `inputs` object: `{name: {title, description, schema}}`.
    fn inputs_description(&self) -> serde_json::Value;
    /// The self-contained JSON schema of the `inputs` object, if the process has one
    /// (a sweep's axis pointers are checked against it).
    fn inputs_schema(&self) -> Option<serde_json::Value> {
        None
    }
    /// OGC process description `outputs` object: `{name: {title, description, schema}}`
    /// (and `kind`, [`HistoryKind::as_str`], when the process declares it).
    fn outputs_description(&self) -> serde_json::Value;
    /// What the values of history `output` are; `None` for an output the process does
    /// not declare a kind for (then no view that needs one, like a response spectrum,
    /// is offered).
    fn history_kind(&self, output: &str) -> Option<HistoryKind> {
        let _ = output;
        None
    }
    /// What each column of the history `output` is, read from the run's results
    /// `document`: the `time` column, then one per series of `names`, in order. Default:
    /// the series undescribed.
    fn history_columns(&self, output: &str, names: &[String], document: &serde_json::Value) -> Vec<Column> {
        let _ = (output, document);
        std::iter::once(Column::time())
            .chain(names.iter().map(Column::unknown))
            .collect()
    }
    /// Parses and checks the `inputs` object of an execution request, and estimates what
    /// running it will cost (a service compares that with its [`CostLimits`]). Pointers in
    /// the errors start with `/inputs`. Accepted inputs come with their plausibility
    /// warnings.
    fn validate(&self, inputs: &serde_json::Value) -> Result<Validated, InvalidInputs>;
    /// The threads a run of `inputs` can use (a worker grants it up to that many of its
    /// free cores and runs it in a pool of those). Default: 1.
    fn threads(&self, inputs: &serde_json::Value) -> usize {
        let _ = inputs;
        1
    }
    /// Runs the computation on inputs that passed [`Process::validate`].
    fn run(&self, inputs: &serde_json::Value, progress: &mut ProgressFn<'_>) -> Result<RunOutput, RunError>;
    /// [`Process::validate`], the stored signals the inputs refer to (`{"type":
    /// "signal", "id"}`) taken from `signals`; an unknown one is an invalid input at its
    /// pointer. Default: a process that takes no signal ignores them.
    fn validate_with(
        &self,
        inputs: &serde_json::Value,
        signals: &signal_input::SignalLibrary,
    ) -> Result<Validated, InvalidInputs> {
        let _ = signals;
        self.validate(inputs)
    }
    /// [`Process::run`] with the stored signals of [`Process::validate_with`].
    fn run_with(
        &self,
        inputs: &serde_json::Value,
        signals: &signal_input::SignalLibrary,
        progress: &mut ProgressFn<'_>,
    ) -> Result<RunOutput, RunError> {
        let _ = signals;
        self.run(inputs, progress)
    }
    /// The scalar results of a results document as `(dotted.name, value)` pairs: the
    /// metric columns of a sweep's results table. Default: the numbers and booleans of
    /// nested objects ([`metrics::flatten_scalars`]); a process adds entries
    /// of its arrays worth a column.
    fn summary_metrics(&self, document: &serde_json::Value) -> Vec<(String, serde_json::Value)> {
        metrics::flatten_scalars(document)
    }
    /// What a calculation note shows of one of its results documents (`GET
    /// /jobs/{jobId}/report`, `chocmodal run --report`): nothing by default.
    fn note_facts(&self, document: &serde_json::Value) -> note_facts::NoteFacts {
        let _ = document;
        note_facts::NoteFacts::default()
    }
    /// The OpenAPI schemas of its inputs and results documents, with every schema they
    /// reference, for the service's OpenAPI document (none by default).
    fn schemas(&self, schemas: &mut Vec<(String, utoipa::openapi::RefOr<utoipa::openapi::Schema>)>) {
        let _ = schemas;
    }
}

/// The processes this build offers, looked up by id.
#[derive(Debug, Clone)]
pub struct Registry {
    processes: Vec<Arc<dyn Process>>,
}

impl Registry {
    /// A registry of exactly these processes (tests use their own).
    pub fn new(processes: Vec<Arc<dyn Process>>) -> Self {
        Self { processes }
    }

    /// The processes shipped with chocmodal.
    pub fn builtin() -> Self {
        Self::new(vec![
            Arc::new(cantilever_impact::CantileverImpact),
            Arc::new(bundle_dynamics::BundleDynamics),
            Arc::new(hex_bundle_dynamics::HexBundleDynamics),
        ])
    }

    pub fn get(&self, id: &str) -> Option<Arc<dyn Process>> {
        self.processes.iter().find(|p| p.id() == id).cloned()
    }

    pub fn all(&self) -> &[Arc<dyn Process>] {
        &self.processes
    }
}
