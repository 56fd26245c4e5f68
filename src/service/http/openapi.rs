//! The OpenAPI document, generated from the handlers' annotations and the models.
//!
//! Committed as `openapi/openapi.json`; a test (`tests/api/capabilities.rs`) fails when
//! the committed file differs from [`json`]. Regenerate it with
//! `UPDATE_OPENAPI=1 cargo test --test api openapi`.

use utoipa::OpenApi;

use super::{job_inputs, jobs, landing, models, processes, results, spectra, sweep_models, sweeps};
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
}

#[derive(Debug, OpenApi)]
#[openapi(
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
        spectra::spectrum,
        sweeps::create,
        sweeps::list,
        sweeps::status,
        sweeps::dismiss,
        sweeps::results,
    ),
    components(schemas(
        ProblemSchema,
        FieldErrorSchema,
        JobStatus,
        models::Link,
        models::StatusInfo,
        models::JobList,
        models::ProcessSummary,
        models::ProcessList,
        models::ProcessDescription,
        models::ExecuteRequest,
        models::Results,
        models::HistoryDocument,
        models::Series,
        spectra::SpectrumDocument,
        spectra::SpectrumComparison,
        models::LandingPage,
        models::Conformance,
        models::Health,
        sweep_models::SweepState,
        sweep_models::RunCounts,
        sweep_models::SweepStatus,
        sweep_models::SweepList,
        sweep_models::SweepAxisSchema,
        sweep_models::SweepRequestSchema,
        sweep_models::SweepResults,
        // The `inputs` of each shipped process (also served by `/processes/{id}`).
        crate::processes::cantilever_impact::CantileverInputs,
        crate::processes::bundle_inputs::BundleInputs,
    )),
    tags(
        (name = "Capabilities", description = "What this service is and offers"),
        (name = "Processes", description = "The computations, and their execution as jobs"),
        (name = "Jobs", description = "Queued, running and finished jobs"),
        (name = "Results", description = "Results documents and time histories"),
        (name = "Sweeps", description = "Many runs of a process over axes of its inputs, as one resource with aggregated results"),
        (name = "Operations", description = "Health and metrics"),
    )
)]
pub struct ApiDoc;

/// The OpenAPI document as pretty JSON, ending with a newline (the committed file's form).
pub fn json() -> String {
    let mut text = ApiDoc::openapi()
        .to_pretty_json()
        .expect("the OpenAPI document serializes");
    text.push('\n');
    text
}
