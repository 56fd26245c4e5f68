//! The OpenAPI document, generated from the handlers' annotations and the models.
//!
//! Committed as `openapi/openapi.json`; a test (`tests/api/capabilities.rs`) fails when
//! the committed file differs from [`json`]. Regenerate it with
//! `UPDATE_OPENAPI=1 cargo test --test api openapi`.
//!
//! Security: every operation but `/healthz` takes a bearer token (the `bearer` scheme)
//! and may answer 401; [`BearerSecurity`] adds both to the generated document, so a
//! new route is covered without annotating it. [`ResourceLinks`] adds OpenAPI links
//! (a created job's id to its status, results and dismissal, ...), which generic
//! clients and stateful API fuzzers (`scripts/fuzz.sh`) follow.

use utoipa::openapi::RefOr;
use utoipa::openapi::link::LinkBuilder;
use utoipa::openapi::path::Operation;
use utoipa::openapi::security::{HttpAuthScheme, HttpBuilder, SecurityRequirement, SecurityScheme};
use utoipa::openapi::{ContentBuilder, Ref, ResponseBuilder};
use utoipa::{Modify, OpenApi};

use super::{
    contacts, impacts, job_inputs, jobs, landing, models, processes, report, response_spectra, results,
    signal_models, signals, spectra, sweep_models, sweep_statistics, sweeps,
};
use crate::processes::Registry;
use crate::service::queue::JobStatus;

/// A field at fault in an execution request.
#[derive(Debug, utoipa::ToSchema)]
#[schema(as = FieldError)]
#[allow(dead_code)]
pub struct FieldErrorSchema {
    /// JSON pointer into the request body, e.g. `/inputs/beam/modes`.
    pointer: String,
    /// Why, e.g. `must be between 1 and 78`.
    detail: String,
}

/// An RFC 9457 problem document (`application/problem+json`).
#[derive(Debug, utoipa::ToSchema)]
#[schema(as = Problem)]
#[allow(dead_code)]
pub struct ProblemSchema {
    /// URI of the problem type, e.g.
    /// `http://www.opengis.net/def/exceptions/ogcapi-processes-1/1.0/no-such-job`.
    #[schema(rename = "type")]
    kind: String,
    /// Short summary of the problem type.
    title: String,
    /// HTTP status code.
    status: u16,
    /// What went wrong in this occurrence.
    detail: String,
    /// Invalid inputs (422): every field at fault.
    #[schema(required = false)]
    errors: Vec<FieldErrorSchema>,
    /// A run above the cost ceilings (422 `too-costly`): each ceiling exceeded.
    #[schema(required = false)]
    exceeded: Vec<ExcessSchema>,
}

/// A signal (accelerogram) as JSON: `time` with `acceleration`, or `sampling_rate` with
/// `acceleration` (the samples of `GET /signals/{id}/samples` come as `time` and
/// `acceleration`).
#[derive(Debug, utoipa::ToSchema)]
#[schema(as = SignalUpload)]
#[allow(dead_code)]
pub struct SignalUploadSchema {
    /// Sample times (s), non-negative and strictly increasing.
    #[schema(required = false)]
    time: Vec<f64>,
    /// Samples per second (Hz, positive), instead of `time`: times k / sampling_rate.
    #[schema(required = false)]
    sampling_rate: f64,
    /// Accelerations (m/s²), finite, one per time.
    acceleration: Vec<f64>,
}

/// What `GET /jobs/{jobId}/results/{output}` answers as JSON: a time history, or, for
/// the output named `impacts` (which also has its own path,
/// `/jobs/{jobId}/results/impacts`), a page of the per-impact table. A client that
/// matches URLs against the generic path gets a schema its answer follows either way.
#[derive(Debug, serde::Serialize, utoipa::ToSchema)]
#[serde(untagged)]
#[schema(as = ResultOutput)]
#[allow(dead_code)]
pub enum ResultOutputSchema {
    /// A time history.
    History(models::HistoryDocument),
    /// A page of the per-impact table (`output` is `impacts`).
    Impacts(impacts::ImpactPage),
}

/// A cost ceiling a run exceeds.
#[derive(Debug, utoipa::ToSchema)]
#[schema(as = Excess)]
#[allow(dead_code)]
pub struct ExcessSchema {
    /// `work` (updates: steps × (pins × modes + contacts)) or `history_values`
    /// (samples × columns of the histories).
    quantity: String,
    /// The run's estimate.
    estimate: f64,
    /// The service's ceiling.
    limit: f64,
}

/// Adds the `bearer` security scheme, requires it everywhere but `/healthz`, and
/// documents the 401 answer of every secured operation.
#[derive(Debug)]
pub struct BearerSecurity;

impl Modify for BearerSecurity {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        let components = openapi.components.get_or_insert_with(Default::default);
        components.add_security_scheme(
            "bearer",
            SecurityScheme::Http(
                HttpBuilder::new()
                    .scheme(HttpAuthScheme::Bearer)
                    .description(Some(
                        "A token of the service's auth file (`--auth-file`), as `Authorization: Bearer \
                         <token>`. Not needed when the service runs without an auth file (one \
                         implicit tenant), nor for `/healthz` and `/readyz`, nor for `/metrics` with `--metrics-public`.",
                    ))
                    .build(),
            ),
        );
        openapi.security = Some(vec![SecurityRequirement::new("bearer", Vec::<String>::new())]);
        let unauthorized = ResponseBuilder::new()
            .description("No valid bearer token (`unauthorized`; `WWW-Authenticate: Bearer`)")
            .content(
                "application/problem+json",
                ContentBuilder::new()
                    .schema(Some(Ref::from_schema_name("Problem")))
                    .build(),
            )
            .build();
        for (path, item) in openapi.paths.paths.iter_mut() {
            let operations: [&mut Option<Operation>; 4] =
                [&mut item.get, &mut item.put, &mut item.post, &mut item.delete];
            for operation in operations.into_iter().flatten() {
                if path == "/healthz" || path == "/readyz" {
                    // An empty requirement: no authentication.
                    operation.security = Some(vec![SecurityRequirement::default()]);
                } else {
                    operation
                        .responses
                        .responses
                        .insert("401".into(), unauthorized.clone().into());
                }
            }
        }
    }
}

/// Links from the responses that name a resource to the operations on it.
#[derive(Debug)]
pub struct ResourceLinks;

/// (path, method, status, link name, target operation id, parameter, runtime expression).
#[rustfmt::skip]
const LINKS: &[(&str, &str, &str, &str, &str, &str, &str)] = &[
    ("/processes", "get", "200", "describe", "getProcessDescription", "processId", "$response.body#/processes/0/id"),
    ("/processes", "get", "200", "execute", "execute", "processId", "$response.body#/processes/0/id"),
    ("/processes/{processId}/execution", "post", "201", "status", "getStatus", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "results", "getResult", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "history", "getResultOutput", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "spectrum", "getResultSpectrum", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "response_spectrum", "getResultResponseSpectrum", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "inputs", "getJobInputs", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "report", "getReport", "jobId", "$response.body#/jobID"),
    ("/processes/{processId}/execution", "post", "201", "dismiss", "dismiss", "jobId", "$response.body#/jobID"),
    ("/sweeps", "post", "201", "status", "getSweep", "sweepId", "$response.body#/sweepID"),
    ("/sweeps", "post", "201", "results", "getSweepResults", "sweepId", "$response.body#/sweepID"),
    ("/sweeps", "post", "201", "dismiss", "dismissSweep", "sweepId", "$response.body#/sweepID"),
    ("/sweeps", "post", "201", "runs", "getJobs", "sweepID", "$response.body#/sweepID"),
    ("/signals", "post", "201", "metadata", "getSignal", "signalId", "$response.body#/id"),
    ("/signals", "post", "201", "samples", "getSignalSamples", "signalId", "$response.body#/id"),
    ("/signals", "post", "201", "spectrum", "getSignalSpectrum", "signalId", "$response.body#/id"),
    ("/signals", "post", "201", "delete", "deleteSignal", "signalId", "$response.body#/id"),
];

impl Modify for ResourceLinks {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        for (path, method, status, name, target, parameter, expression) in LINKS {
            let Some(item) = openapi.paths.paths.get_mut(*path) else {
                continue;
            };
            let operation = match *method {
                "get" => item.get.as_mut(),
                "post" => item.post.as_mut(),
                _ => None,
            };
            let Some(RefOr::T(response)) = operation.and_then(|op| op.responses.responses.get_mut(*status))
            else {
                continue;
            };
            response.links.insert(
                (*name).to_owned(),
                LinkBuilder::new()
                    .operation_id(*target)
                    .parameter(*parameter, *expression)
                    .build()
                    .into(),
            );
        }
    }
}

#[derive(Debug, OpenApi)]
#[openapi(
    modifiers(&BearerSecurity, &ResourceLinks),
    info(
        title = "chocmodal",
        description = "Modal multi-contact dynamics of slender beam bundles, run as asynchronous \
            jobs (OGC API – Processes, Part 1: Core). Submit with `POST /processes/{processId}/execution`, \
            poll `GET /jobs/{jobId}`, fetch `GET /jobs/{jobId}/results` and its histories. Errors are \
            RFC 9457 problem documents. Units are SI throughout (m, s, N, kg).",
        license(name = "MIT OR Apache-2.0")
    ),
    paths(
        landing::landing,
        landing::conformance,
        landing::openapi_document,
        landing::healthz,
        landing::readyz,
        landing::metrics,
        processes::list,
        processes::describe,
        processes::execute,
        jobs::list,
        jobs::status,
        jobs::dismiss,
        job_inputs::inputs,
        results::results,
        results::output,
        impacts::impacts,
        contacts::contacts,
        contacts::pins,
        contacts::resultants,
        report::report,
        spectra::spectrum,
        response_spectra::response_spectrum,
        sweeps::create,
        sweeps::list,
        sweeps::status,
        sweeps::dismiss,
        sweeps::results,
        sweep_statistics::statistics,
        sweep_statistics::contacts,
        sweep_statistics::pins,
        sweep_statistics::convergence,
        sweep_statistics::runs_needed,
        signals::create,
        signals::list,
        signals::metadata,
        signals::delete,
        signals::samples,
        signals::spectrum,
    ),
    components(schemas(
        ProblemSchema,
        FieldErrorSchema,
        ExcessSchema,
        JobStatus,
        models::Link,
        models::StatusInfo,
        models::JobList,
        models::ProcessSummary,
        models::ProcessList,
        models::ProcessDescription,
        models::ExecuteRequest,
        models::SubscriberDocument,
        models::Results,
        crate::processes::report::QualityReport,
        crate::provenance::Provenance,
        crate::processes::report::StepHalvingReport,
        crate::physics::integrate::StepComparison,
        models::HistoryDocument,
        models::Series,
        ResultOutputSchema,
        impacts::ImpactPage,
        crate::contact_table::ContactTable,
        crate::contact_table::PinTable,
        crate::contact_table::ResultantTable,
        spectra::SpectrumDocument,
        spectra::SpectrumComparison,
        response_spectra::HistoryResponseSpectrum,
        models::LandingPage,
        models::Conformance,
        models::Health,
        models::Readiness,
        sweep_models::SweepState,
        sweep_models::RunCounts,
        sweep_models::SweepStatus,
        sweep_models::SweepList,
        crate::sweep::SweepAxis,
        crate::sweep::SweepRequest,
        sweep_models::SweepResults,
        sweep_models::SweepStatistics,
        sweep_models::SweepStatisticsKind,
        sweep_models::RunsNeeded,
        sweep_models::RankRuns,
        SignalUploadSchema,
        signal_models::SignalMetadata,
        signal_models::SignalList,
        signal_models::SignalSpectrum,
        signal_models::DampedSpectrum,
        // The `inputs` of each shipped process (also served by `/processes/{id}`).
    )),
    tags(
        (name = "Capabilities", description = "What this service is and offers"),
        (name = "Processes", description = "The computations, and their execution as jobs"),
        (name = "Jobs", description = "Queued, running and finished jobs"),
        (name = "Results", description = "Results documents and time histories"),
        (name = "Sweeps", description = "Many runs of a process over axes of its inputs, as one resource with aggregated results"),
        (name = "Signals", description = "Accelerograms stored once and referenced by jobs and sweeps (`{\"type\": \"signal\", \"id\"}`), with their response spectra"),
        (name = "Operations", description = "Health and metrics"),
    )
)]
pub struct ApiDoc;

/// The OpenAPI document of a service offering `registry`'s processes: the routes, and
/// each process's inputs and results schemas (from their types) in the components.
pub fn document(registry: &Registry) -> utoipa::openapi::OpenApi {
    let mut openapi = ApiDoc::openapi();
    let mut schemas = Vec::new();
    for process in registry.all() {
        process.schemas(&mut schemas);
    }
    let components = openapi.components.get_or_insert_with(Default::default);
    for (name, schema) in schemas {
        components.schemas.entry(name).or_insert(schema);
    }
    openapi
}

/// The OpenAPI document of the builtin processes as pretty JSON, ending with a newline
/// (the committed file's form).
pub fn json() -> String {
    json_for(&Registry::builtin())
}

/// [`document`] as pretty JSON, ending with a newline.
pub fn json_for(registry: &Registry) -> String {
    let mut text = document(registry)
        .to_pretty_json()
        .expect("the OpenAPI document serializes");
    text.push('\n');
    text
}
