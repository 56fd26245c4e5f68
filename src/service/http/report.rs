//! `/jobs/{jobId}/report`: a successful job's calculation note, one printable HTML page
//! ([`crate::calculation_note`]), drawn from its results document, its inputs, its
//! record (labels, note, dates) and the histories its process names for plotting.

use axum::extract::{Extension, Path, State};
use axum::http::HeaderMap;
use axum::response::Response;

use super::AppState;
use super::conditional::tagged;
use super::error::ApiError;
use super::negotiation::Format;
use super::results::{successful, with_retry_after};
use super::streamed::working_bytes;
use crate::calculation_note::{self, Identification, Note, Plot};
use crate::problem::Problem;
use crate::processes::History;
use crate::service::auth::Tenant;
use crate::service::clock::rfc3339;
use crate::service::queue::read::JobOutcome;
use crate::service::store::{self, StoredHistory};

/// A job's calculation note
///
/// One self-contained, printable HTML page (A4 in print; no script, plots as inline
/// SVG) with the job's identification (process, solver version, build, inputs SHA-256,
/// labels, note, dates), its quality verdict and every reason, the warnings, the peaks
/// with their times and places, the margins (utilisations), the worst contacts and pins,
/// the bending stress envelope along the height, the key histories as plots, how it was
/// solved, and the inputs. Every number carries the results member it comes from
/// (`data-pointer`). Immutable once there: strong `ETag`, `304` on `If-None-Match`. A job
/// not finished yet: 404 `result-not-ready` (with `Retry-After`); a failed job: its error.
#[utoipa::path(get, path = "/jobs/{jobId}/report", operation_id = "getReport", tag = "Results",
    params(
        ("jobId" = String, Path, description = "Job id"),
        ("format" = Option<String>, Query, description = "`html`, the only format (`f` is an alias); \
            any other is a 400 naming it", pattern = "^html$"),
    ),
    responses(
        (status = 200, description = "The calculation note (HTML, UTF-8)", body = String, content_type = "text/html",
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "A `format` other than `html`", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such job, job not finished (`result-not-ready`), or dismissed",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 406, description = "`Accept` excludes HTML", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 422, description = "The job failed (`job-failed`, e.g. divergence)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 500, description = "The job crashed or lost its worker too many times",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 503, description = "The histories to plot do not fit the response memory now (`server-busy`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn report(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(job_id): Path<String>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    with_retry_after(
        async {
            let outcome = successful(&job_id, state.queue.outcome(tenant.as_str(), &job_id).await?)?;
            let inputs = state
                .queue
                .inputs(tenant.as_str(), &job_id)
                .await?
                .ok_or_else(|| Problem::no_such_job(&job_id))?;
            let process = state.registry.get(&outcome.record.process_id);
            let document = parse(outcome.results.as_deref().unwrap_or("{}"), "results document")?;
            let facts = process
                .as_ref()
                .map(|p| p.note_facts(&document))
                .unwrap_or_default();
            // The histories to plot, each decoded within the response memory budget.
            let mut stored = Vec::new();
            let mut permits = Vec::new();
            for request in &facts.plots {
                let history = state
                    .queue
                    .history(tenant.as_str(), &job_id, &request.output)
                    .await?;
                if let Some(history) = &history {
                    permits.push(state.response_memory.admit(working_bytes(history))?);
                }
                stored.push(history);
            }
            let title = process.as_ref().map_or("", |p| p.title()).to_owned();
            let body = tokio::task::spawn_blocking(move || {
                let inputs = parse(&inputs, "inputs")?;
                let plots = facts
                    .plots
                    .iter()
                    .zip(&stored)
                    .map(|(request, history)| {
                        let decoded = history.as_ref().map(decode).transpose()?;
                        let href = format!(
                            "/jobs/{}/results/{}?format=csv&series={}",
                            outcome.record.id,
                            request.output,
                            request.series.join(",")
                        );
                        Ok(Plot::of(request, decoded.as_ref(), href))
                    })
                    .collect::<Result<Vec<_>, ApiError>>()?;
                let envelope_href = format!(
                    "/jobs/{}/results#{}",
                    outcome.record.id,
                    facts.envelope.as_ref().map_or("", |e| e.pointer.as_str())
                );
                let note = Note {
                    identification: identification(&outcome, title),
                    inputs: &inputs,
                    document: &document,
                    facts,
                    plots,
                    envelope_href,
                };
                drop(permits);
                Ok::<_, ApiError>(calculation_note::render(&note).into_bytes())
            })
            .await
            .map_err(|e| ApiError::Internal(format!("drawing a calculation note panicked: {e}")))??;
            Ok(tagged(&headers, format.content_type(), body, HeaderMap::new()))
        }
        .await,
    )
}

fn parse(text: &str, what: &str) -> Result<serde_json::Value, ApiError> {
    serde_json::from_str(text).map_err(|e| ApiError::Internal(format!("stored {what} unreadable: {e}")))
}

fn decode(stored: &StoredHistory) -> Result<History, ApiError> {
    store::decode(stored).map_err(|e| ApiError::Internal(e.to_string()))
}

/// What the job's record says of it: process, status, labels, note, dates, links.
fn identification(outcome: &JobOutcome, process_title: String) -> Identification {
    let job = &outcome.record;
    let dates = [
        ("Created", Some(job.created_at)),
        ("Started", job.started_at),
        ("Finished", job.finished_at),
    ]
    .into_iter()
    .filter_map(|(what, ms)| Some((what.to_owned(), rfc3339(ms?))))
    .collect();
    let href = format!("/jobs/{}", job.id);
    Identification {
        job_id: Some(job.id.clone()),
        process_id: job.process_id.clone(),
        process_title,
        status_message: job.message.clone(),
        labels: job.labels.clone(),
        note: job.note.clone(),
        dates,
        links: vec![
            ("Job status".into(), href.clone()),
            ("Results document".into(), format!("{href}/results")),
        ],
    }
}
