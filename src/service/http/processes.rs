//! `/processes`: what can run, and execution (validate, then queue a job).

use std::sync::Arc;

use axum::Json;
use axum::extract::{Extension, Path, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::error::ApiError;
use super::extract::ExecutionInputs;
use super::idempotency::{IdempotencyHeader, key_reused, mark_replayed};
use super::models::{ExecuteRequest, Link, ProcessDescription, ProcessList, ProcessSummary, StatusInfo};
use crate::annotations::Annotations;
use crate::json_body::ExecutionRequest;
use crate::problem::Problem;
use crate::processes::{InvalidInputs, Process};
use crate::service::auth::Tenant;
use crate::service::callbacks::Subscriber;
use crate::service::queue::Admission;
use crate::service::queue::idempotency::{KeyedRequest, Kind, RequestHash};

/// The idempotency hash of an execution request: its inputs alone without a subscriber
/// (as before subscribers were stored), else its inputs and subscriber, so that a key
/// reused with another subscriber is a conflict.
fn request_hash(
    process_id: &str,
    inputs: &serde_json::Value,
    subscriber: Option<&Subscriber>,
    labels: Option<&serde_json::Value>,
    note: Option<&serde_json::Value>,
) -> RequestHash {
    // The members besides `inputs` that make another request (none: the inputs alone,
    // as keys were hashed before callbacks and labels existed).
    let mut request = serde_json::Map::new();
    if let Some(subscriber) = subscriber {
        request.insert("subscriber".to_owned(), subscriber.to_json());
    }
    for (name, value) in [("labels", labels), ("note", note)] {
        if let Some(value) = value.filter(|v| !v.is_null()) {
            request.insert(name.to_owned(), value.clone());
        }
    }
    if request.is_empty() {
        return RequestHash::of_json(Kind::Job, process_id, inputs);
    }
    request.insert("inputs".to_owned(), inputs.clone());
    RequestHash::of_json(Kind::Job, process_id, &serde_json::Value::Object(request))
}

/// `Preference-Applied` (RFC 7240): which `Prefer` preference the answer honours.
const PREFERENCE_APPLIED: header::HeaderName = header::HeaderName::from_static("preference-applied");

/// Whether the request's `Prefer` headers ask for `respond-async` (OGC API – Processes:
/// the server says it applied it). Every execution is asynchronous, so `respond-sync`
/// is not applied: the answer is a job all the same, without the header.
fn prefers_async(headers: &HeaderMap) -> bool {
    headers
        .get_all("prefer")
        .iter()
        .filter_map(|value| value.to_str().ok())
        .flat_map(|value| value.split(','))
        .any(|preference| {
            let token = preference.split(';').next().unwrap_or_default().trim();
            token.eq_ignore_ascii_case("respond-async")
        })
}

fn summary(process: &dyn Process) -> ProcessSummary {
    let href = format!("/processes/{}", process.id());
    ProcessSummary {
        id: process.id().to_owned(),
        title: process.title().to_owned(),
        description: process.description().to_owned(),
        version: env!("CARGO_PKG_VERSION"),
        job_control_options: vec!["async-execute", "dismiss"],
        links: vec![
            Link::new(&href, "self", "application/json").titled("Process description"),
            Link::new(
                format!("{href}/execution"),
                "http://www.opengis.net/def/rel/ogc/1.0/execute",
                "application/json",
            )
            .titled("Execute (POST)"),
        ],
    }
}

/// List the processes
#[utoipa::path(get, path = "/processes", operation_id = "getProcesses", tag = "Processes",
    responses((status = 200, description = "Every process this service runs", body = ProcessList)))]
pub async fn list(State(state): State<AppState>) -> Json<ProcessList> {
    Json(ProcessList {
        processes: state.registry.all().iter().map(|p| summary(p.as_ref())).collect(),
        links: vec![Link::new("/processes", "self", "application/json")],
    })
}

/// Describe a process
///
/// Its inputs (JSON Schema, with SI units in the descriptions) and outputs.
#[utoipa::path(get, path = "/processes/{processId}", operation_id = "getProcessDescription", tag = "Processes",
    params(("processId" = String, Path, description = "Process id, e.g. `cantilever-impact`", example = "cantilever-impact")),
    responses(
        (status = 200, description = "The process description", body = ProcessDescription),
        (status = 404, description = "No such process (`no-such-process`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn describe(
    State(state): State<AppState>,
    Path(process_id): Path<String>,
) -> Result<Json<ProcessDescription>, ApiError> {
    let process = state
        .registry
        .get(&process_id)
        .ok_or_else(|| Problem::no_such_process(&process_id))?;
    Ok(Json(ProcessDescription {
        summary: summary(process.as_ref()),
        inputs: process.inputs_description(),
        outputs: process.outputs_description(),
    }))
}

/// Execute a process (asynchronously)
///
/// Validates the inputs and queues a job: `201 Created`, `Location: /jobs/{jobId}` and the
/// job's status. Invalid inputs never reach a worker: 422 with one `errors` entry per
/// field, each with a JSON pointer into the request body (`/inputs/beam/modes`). A run
/// whose estimated cost is above this service's ceilings: 422 `too-costly`, pointing at
/// the fields that drive the cost. Too many queued jobs already: 429 with `Retry-After`.
/// A retry with the same `Idempotency-Key` and inputs gets the same job back. The disk
/// full: 507 `storage-full` with `Retry-After`, nothing queued.
#[utoipa::path(post, path = "/processes/{processId}/execution", operation_id = "execute", tag = "Processes",
    params(("processId" = String, Path, description = "Process id, e.g. `cantilever-impact`", example = "cantilever-impact"),
        ("Prefer" = Option<String>, Header, description = "`respond-async` is applied (`Preference-Applied: respond-async`); `respond-sync` is not: every execution is asynchronous, answered with a job"),
        ("Idempotency-Key" = Option<String>, Header, description = "Optional, 1 to 255 visible ASCII characters: a retry with the same key and the same request gets the same resource back (same id, `201`, same `Location`, plus `Idempotent-Replayed: true`) instead of creating another; the same key with another request is a 422 `idempotency-key-reused`. Keys are per tenant and kept as long as the resource they created.")),
    request_body(content = ExecuteRequest, description = "`{\"inputs\": {...}}`, see the process description"),
    responses(
        (status = 201, description = "Job queued (with `Prefer: respond-sync` too: every execution is a job)", body = StatusInfo,
            headers(("Location" = String, description = "`/jobs/{jobId}`"),
                ("Preference-Applied" = String, description = "`respond-async` when the request's `Prefer` asked for it (RFC 7240)"))),
        (status = 400, description = "Malformed JSON, or an invalid `Idempotency-Key` (`invalid-header`)", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such process", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 413, description = "Body over the size limit", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 415, description = "Body not declared as JSON", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 422, description = "Invalid inputs (`invalid-inputs`; a `subscriber` URI that is not absolute http(s) or whose host the operator does not allow is refused at its pointer, e.g. `/subscriber/successUri`), or a run above the cost ceilings (`too-costly`), with `errors` pointers; or an `Idempotency-Key` first sent with another request (`idempotency-key-reused`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 429, description = "Too many queued jobs (`too-many-queued-jobs`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s"))),
        (status = 503, description = "The storage failed an I/O operation (`storage-unavailable`): nothing queued", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s"))),
        (status = 507, description = "The disk is full (`storage-full`, naming SQLITE_FULL, disk_full or ENOSPC): nothing queued", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s")))))]
pub async fn execute(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(process_id): Path<String>,
    IdempotencyHeader(key): IdempotencyHeader,
    request_headers: HeaderMap,
    body: Result<ExecutionInputs, ApiError>,
) -> Result<Response, ApiError> {
    // An unknown process is reported before anything about the body.
    let process = state
        .registry
        .get(&process_id)
        .ok_or_else(|| Problem::no_such_process(&process_id))?;
    let ExecutionInputs(ExecutionRequest {
        inputs,
        subscriber,
        labels,
        note,
    }) = body?;
    let subscriber = Subscriber::parse(subscriber.as_ref(), &state.callbacks, tenant.as_str());
    let annotations = Annotations::parse(labels.as_ref(), note.as_ref());
    let keyed = key.map(|key| KeyedRequest {
        key,
        kind: Kind::Job,
        hash: request_hash(
            &process_id,
            &inputs,
            subscriber.as_ref().ok().and_then(Option::as_ref),
            labels.as_ref(),
            note.as_ref(),
        ),
    });
    // The stored signals the inputs refer to, the tenant's only: resolved now, so that an
    // unknown or foreign id is refused at its pointer before anything is queued.
    let signals = state.signals.library(tenant.as_str(), &inputs).await?;
    let inputs = Arc::new(inputs);
    // Validation may expand generators and check large inputs: keep it off the runtime.
    let validated = {
        let inputs = inputs.clone();
        tokio::task::spawn_blocking(move || process.validate_with(&inputs, &signals))
            .await
            .map_err(|e| ApiError::Internal(format!("validation panicked: {e}")))?
    };
    // Every refusal at once: the inputs', the subscriber's, the labels' and the note's.
    let (validated, subscriber, annotations) = match (validated, subscriber, annotations) {
        (Ok(validated), Ok(subscriber), Ok(annotations)) => (validated, subscriber, annotations),
        (validated, subscriber, annotations) => {
            let mut errors = Vec::new();
            if let Err(invalid) = validated {
                errors.extend(invalid.0);
            }
            if let Err(refused) = subscriber {
                errors.extend(refused.0);
            }
            if let Err(faults) = annotations {
                errors.extend(faults);
            }
            return Err(Problem::invalid_inputs(&InvalidInputs(errors)).into());
        }
    };
    state
        .limits
        .check(&validated.estimate)
        .map_err(|refused| Problem::too_costly(&refused))?;
    let admission = state
        .queue
        .enqueue(
            tenant.as_str(),
            &process_id,
            &inputs,
            &validated.warnings,
            state.max_queued_jobs,
            keyed.as_ref(),
            subscriber.as_ref(),
            &annotations,
        )
        .await?;
    let mut headers = HeaderMap::new();
    let job = match admission {
        Admission::Admitted(job) => {
            state.wake.notify_one();
            tracing::info!(job = %job.id, process = %process_id, %tenant, callbacks = subscriber.is_some(), "job queued");
            job
        }
        Admission::Replayed(job) => {
            tracing::info!(job = %job.id, %tenant, "idempotent retry: the key's job, nothing queued");
            mark_replayed(&mut headers);
            job
        }
        Admission::KeyConflict(conflict) => return Err(key_reused(&conflict)),
        Admission::QueueFull { queued } => {
            return Err(ApiError::queue_full(
                queued,
                1,
                state.max_queued_jobs.unwrap_or(0),
            ));
        }
    };
    headers.insert(
        header::LOCATION,
        HeaderValue::from_str(&format!("/jobs/{}", job.id)).expect("uuid is a valid header value"),
    );
    if prefers_async(&request_headers) {
        headers.insert(PREFERENCE_APPLIED, HeaderValue::from_static("respond-async"));
    }
    Ok((StatusCode::CREATED, headers, Json(StatusInfo::from_record(&job))).into_response())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prefer(values: &[&str]) -> HeaderMap {
        let mut headers = HeaderMap::new();
        for value in values {
            headers.append("prefer", HeaderValue::from_str(value).unwrap());
        }
        headers
    }

    #[test]
    fn respond_async_is_found_among_other_preferences() {
        assert!(prefers_async(&prefer(&["respond-async"])));
        assert!(prefers_async(&prefer(&[
            "return=minimal, Respond-Async; wait=10"
        ])));
        assert!(prefers_async(&prefer(&["wait=5", "respond-async"])));
        assert!(!prefers_async(&prefer(&["respond-sync"])));
        assert!(!prefers_async(&prefer(&[])));
    }
}
