//! A process described by its types: [`Simulation`], and the one adapter that makes any
//! of them a [`Process`] the service and the CLI can drive.
//!
//! A simulation says what its inputs and results are (serde + OpenAPI schema from the
//! same types), how inputs become a validated [`Simulation::Plan`] (every problem with
//! its JSON pointer), what a plan costs, and how it runs. The adapter does the rest, the
//! same way for every process: strict parsing with pointer repair
//! ([`super::common_inputs::parse`]), the absolute cost ceilings ([`CostLimits::ABSOLUTE`]),
//! the OGC descriptions of inputs and outputs, the plausibility warnings
//! ([`super::warnings`]), the results document and its schema.

use serde::Serialize;
use serde::de::DeserializeOwned;
use utoipa::openapi::schema::{AllOfBuilder, ArrayBuilder, ObjectBuilder};
use utoipa::openapi::{RefOr, Schema};
use utoipa::{PartialSchema, ToSchema};

use super::required;
use super::signal_input::{SignalLibrary, SignalSlot};
use super::warnings::{self, Subject, Warning};
use super::{
    Column, CostLimits, History, InvalidInputs, Process, ProgressFn, RunError, RunOutput, Validated,
    WorkEstimate, input_schema,
};

/// One history a simulation writes: served as `/jobs/{id}/results/{name}` (CSV or JSON).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HistoryOutput {
    /// Output name (`tip_displacement`).
    pub name: &'static str,
    /// What its values are.
    pub kind: HistoryKind,
    pub title: &'static str,
    /// Its columns and units.
    pub description: &'static str,
}

/// What the values of a history are: which views of it make sense (a response spectrum
/// is the spectrum of a motion; the per-impact table is no time series at all).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HistoryKind {
    /// Displacements (m), sampled at each output time.
    Displacement,
    /// Forces (N), sampled at each output time.
    Force,
    /// Bending moments (N·m), sampled at each output time.
    Moment,
    /// Accelerations (m/s²): the excitation a run was given.
    Acceleration,
    /// The extreme of each output interval over all steps (a `_peaks` companion).
    Peaks,
    /// Not a time series: one row per event.
    Table,
}

impl HistoryKind {
    /// Its name in the process description's outputs (`kind`).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Displacement => "displacement",
            Self::Force => "force",
            Self::Moment => "moment",
            Self::Acceleration => "acceleration",
            Self::Peaks => "peaks",
            Self::Table => "table",
        }
    }
}

/// What a run of a simulation produces: its typed results and its histories.
#[derive(Debug, Clone, PartialEq)]
pub struct Output<R> {
    pub results: R,
    /// One per [`Simulation::HISTORIES`] entry, by name.
    pub histories: Vec<History>,
}

/// A computation described by types. Implement this (and add one line to
/// [`super::Registry::builtin`]); the blanket `impl Process for S` does the rest.
pub trait Simulation: Send + Sync + std::fmt::Debug + 'static {
    /// Stable identifier used in URLs (`cantilever-impact`).
    const ID: &'static str;
    /// One-line title.
    const TITLE: &'static str;
    /// A paragraph for the process list.
    const DESCRIPTION: &'static str;
    /// The histories a run writes.
    const HISTORIES: &'static [HistoryOutput];
    /// Whether a run of `inputs` shares its steps between the threads `solver.threads`
    /// asks for, where that pays (a worker then grants it up to that many cores;
    /// otherwise two at most, for the run and its check's repetition at once:
    /// [`super::common_inputs::usable_threads`]).
    fn shares_steps(inputs: &serde_json::Value) -> bool {
        let _ = inputs;
        false
    }
    /// Its shipped examples (`examples/`): the dashboard's templates, checked by the tests
    /// that go through every example.
    const EXAMPLES: &'static [super::Example] = &[];

    /// The `inputs` object of an execution request (unknown fields refused).
    type Inputs: DeserializeOwned + ToSchema;
    /// The results document, without its `outputs` links (the adapter adds them).
    type Results: Serialize + ToSchema;
    /// Validated inputs, ready to run (the step resolved, the basis built).
    type Plan: Send;

    /// The stored signals the inputs refer to, with the pointers of their objects: the
    /// adapter attaches their records from a [`SignalLibrary`] before [`Self::prepare`]
    /// (none by default).
    fn signals(inputs: &mut Self::Inputs) -> Vec<SignalSlot<'_>> {
        let _ = inputs;
        Vec::new()
    }
    /// Checks the inputs and builds the plan; every problem found, with its pointer
    /// (starting with `/inputs`).
    fn prepare(inputs: Self::Inputs) -> Result<Self::Plan, InvalidInputs>;
    /// What running the plan will cost (compared with the ceilings before anything runs).
    fn estimate(plan: &Self::Plan) -> WorkEstimate;
    /// What the plausibility checks read of the plan: its pin, model and duration, and
    /// where the user wrote them ([`warnings::assess`] judges them).
    fn subject(plan: &Self::Plan) -> Subject<'_>;
    /// Runs the plan; `progress` gets the fraction done and may cancel.
    fn run(plan: Self::Plan, progress: &mut ProgressFn<'_>) -> Result<Output<Self::Results>, RunError>;
    /// The metric columns of a sweep's results table for one results document: the
    /// numbers and booleans of nested objects ([`super::metrics::flatten_scalars`]) by
    /// default; a simulation adds entries of its arrays worth a column.
    fn metrics(document: &serde_json::Value) -> Vec<(String, serde_json::Value)> {
        super::metrics::flatten_scalars(document)
    }
    /// What the series `name` of the history `output` is (unit, what it measures), read
    /// from the run's results `document`; `None` leaves it undescribed.
    fn column(output: &str, name: &str, document: &serde_json::Value) -> Option<Column> {
        let _ = (output, name, document);
        None
    }
    /// What a calculation note shows of one results `document`: its peaks, margins,
    /// contacts, pins, envelope and plots, each with the pointer it comes from
    /// ([`super::note_facts`]). None by default.
    fn note(document: &serde_json::Value) -> super::note_facts::NoteFacts {
        let _ = document;
        super::note_facts::NoteFacts::default()
    }
}

/// Parses, attaches the stored signals referenced, prepares, checks against the
/// absolute ceilings and assesses plausibility.
fn plan<S: Simulation>(
    json: &serde_json::Value,
    signals: &SignalLibrary,
) -> Result<(S::Plan, Validated), InvalidInputs> {
    let plan = required::prepare::<S::Inputs, S::Plan>(json, |mut inputs| {
        let unresolved: Vec<_> = S::signals(&mut inputs)
            .into_iter()
            .filter_map(|(pointer, signal)| signal.resolve(signals, &pointer).err())
            .collect();
        if !unresolved.is_empty() {
            return Err(InvalidInputs(unresolved));
        }
        S::prepare(inputs)
    })?;
    let estimate = S::estimate(&plan);
    CostLimits::check_absolute(&estimate).map_err(|refused| InvalidInputs(refused.errors))?;
    let warnings = warnings::assess(&S::subject(&plan), estimate.steps);
    Ok((plan, Validated { estimate, warnings }))
}

/// A results document: the simulation's results and the warnings about its inputs.
#[derive(Serialize)]
struct Document<'a, R> {
    #[serde(flatten)]
    results: &'a R,
    warnings: &'a [Warning],
}

impl<S: Simulation> Process for S {
    fn id(&self) -> &'static str {
        S::ID
    }

    fn threads(&self, inputs: &serde_json::Value) -> usize {
        super::common_inputs::usable_threads(inputs, S::shares_steps(inputs))
    }

    fn examples(&self) -> &'static [super::Example] {
        S::EXAMPLES
    }

    fn title(&self) -> &'static str {
        S::TITLE
    }

    fn description(&self) -> &'static str {
        S::DESCRIPTION
    }

    fn inputs_description(&self) -> serde_json::Value {
        input_schema::ogc_inputs(&input_schema::schema_of::<S::Inputs>())
    }

    fn inputs_schema(&self) -> Option<serde_json::Value> {
        Some(input_schema::schema_of::<S::Inputs>())
    }

    fn history_kind(&self, output: &str) -> Option<HistoryKind> {
        S::HISTORIES.iter().find(|h| h.name == output).map(|h| h.kind)
    }

    fn outputs_description(&self) -> serde_json::Value {
        S::HISTORIES
            .iter()
            .map(|h| {
                (
                    h.name.to_owned(),
                    serde_json::json!({"title": h.title, "description": h.description, "kind": h.kind.as_str(),
                                       "schema": {"type": "string", "contentMediaType": "text/csv"}}),
                )
            })
            .collect::<serde_json::Map<_, _>>()
            .into()
    }

    fn validate(&self, inputs: &serde_json::Value) -> Result<Validated, InvalidInputs> {
        self.validate_with(inputs, &SignalLibrary::default())
    }

    fn validate_with(
        &self,
        inputs: &serde_json::Value,
        signals: &SignalLibrary,
    ) -> Result<Validated, InvalidInputs> {
        plan::<S>(inputs, signals).map(|(_, validated)| validated)
    }

    fn run(&self, inputs: &serde_json::Value, progress: &mut ProgressFn<'_>) -> Result<RunOutput, RunError> {
        self.run_with(inputs, &SignalLibrary::default(), progress)
    }

    fn run_with(
        &self,
        inputs: &serde_json::Value,
        signals: &SignalLibrary,
        progress: &mut ProgressFn<'_>,
    ) -> Result<RunOutput, RunError> {
        let (plan, Validated { warnings, .. }) = plan::<S>(inputs, signals)?;
        let output = S::run(plan, progress)?;
        let document = serde_json::to_value(Document {
            results: &output.results,
            warnings: &warnings,
        })
        .map_err(|e| RunError::Failed(format!("results document: {e}")))?;
        debug_assert_eq!(
            output
                .histories
                .iter()
                .map(|h| h.name.as_str())
                .collect::<Vec<_>>(),
            S::HISTORIES.iter().map(|h| h.name).collect::<Vec<_>>(),
            "{} writes the histories it declares",
            S::ID
        );
        Ok(RunOutput {
            document,
            histories: output.histories,
            warnings,
        })
    }

    fn summary_metrics(&self, document: &serde_json::Value) -> Vec<(String, serde_json::Value)> {
        S::metrics(document)
    }

    fn history_columns(&self, output: &str, names: &[String], document: &serde_json::Value) -> Vec<Column> {
        std::iter::once(Column::time())
            .chain(
                names
                    .iter()
                    .map(|name| S::column(output, name, document).unwrap_or_else(|| Column::unknown(name))),
            )
            .collect()
    }

    fn note_facts(&self, document: &serde_json::Value) -> super::note_facts::NoteFacts {
        S::note(document)
    }

    fn schemas(&self, schemas: &mut Vec<(String, RefOr<Schema>)>) {
        schemas.push((S::Inputs::name().into_owned(), S::Inputs::schema()));
        S::Inputs::schemas(schemas);
        schemas.push((
            S::Results::name().into_owned(),
            with_warnings(S::Results::schema()),
        ));
        S::Results::schemas(schemas);
        schemas.push((Warning::name().into_owned(), Warning::schema()));
        Warning::schemas(schemas);
    }
}

/// A results schema with the document's `warnings` member (see [`Document`]).
fn with_warnings(results: RefOr<Schema>) -> RefOr<Schema> {
    let warnings = ObjectBuilder::new()
        .property(
            "warnings",
            ArrayBuilder::new()
                .items(RefOr::Ref(
                    utoipa::openapi::Ref::from_schema_name(Warning::name()),
                ))
                .description(Some(
                    "Plausibility warnings about the inputs (valid, but they look like a mistake); \
                     empty with `\"warnings\": \"off\"`",
                )),
        )
        .required("warnings");
    AllOfBuilder::new().item(results).item(warnings).into()
}
