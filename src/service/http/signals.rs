//! `/signals`: accelerograms uploaded once (CSV or JSON), their metadata, the tenant's
//! list, deletion, the samples streamed back, and their response spectra.
//!
//! An upload may be far larger than an execution request (a 200 000-sample record is
//! about 9 MB of CSV): `POST /signals` has its own body limit (`--max-signal-bytes`) and
//! sample limit (`--max-signal-samples`), both stated in the 413 that refuses more.

use std::sync::Arc;

use axum::Json;
use axum::body::{Body, Bytes};
use axum::extract::rejection::BytesRejection;
use axum::extract::{Extension, Path, Query, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::AppState;
use super::error::ApiError;
use super::extract::ApiQuery;
use super::history_view::Format;
use super::idempotency::{IdempotencyHeader, key_reused, mark_replayed};
use super::jobs::{DEFAULT_LIMIT, MAX_LIMIT};
use super::models::Link;
use super::response_spectra::{parse_spectrum_query, spectra_csv};
use super::signal_models::{DampedSpectrum, SignalList, SignalMetadata, SignalSpectrum};
use crate::annotations::{Annotations, label_fault};
use crate::physics::response_spectrum::{self, log_spaced};
use crate::problem::Problem;
use crate::service::auth::Tenant;
use crate::service::queue::idempotency::{Keyed, KeyedRequest, Kind, RequestHash};
use crate::service::signals::SignalReadError;
use crate::service::signals::create::CreateError;
use crate::service::signals::delete::Deletion;
use crate::signal_record::{self, AccelerationUnit, RecordError, RecordFormat};

/// Rows per chunk of a streamed record.
const STREAM_ROWS: usize = 4096;

/// Query of `POST /signals` (documentation; [`parse_upload_query`] reads it, since
/// `label` repeats).
#[derive(Debug, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct UploadQuery {
    /// Samples per second (Hz, positive) of a CSV record of accelerations alone (one
    /// column); times are then k / sampling_rate from 0.
    pub sampling_rate: Option<f64>,
    /// The unit of a CSV record's accelerations: `m/s2` (default) or `g` (9.80665 m/s²);
    /// the record is stored in m/s². A PEER AT2 file is in g by its format; a JSON record
    /// gives its unit as its `unit` member.
    pub unit: Option<String>,
    /// A label of the signal (repeatable; at most 20, each 1 to 64 characters without
    /// control characters or surrounding spaces): `GET /signals?label=` filters on them.
    #[param(explode = true)]
    pub label: Option<Vec<String>>,
    /// A free-text note (at most 2000 characters), returned with the metadata.
    pub note: Option<String>,
}

/// What `POST /signals` is asked besides the record.
#[derive(Debug, Default)]
struct Upload {
    sampling_rate: Option<f64>,
    unit: Option<AccelerationUnit>,
    labels: Vec<String>,
    note: Option<String>,
}

/// What an idempotency key's request hash covers besides the body (a unit, labels and a
/// note only when given, so that keys stored before them still match).
fn upload_description(upload: &Upload, format: RecordFormat, annotations: &Annotations) -> String {
    let mut text = format!("{format:?} sampling_rate={:?}", upload.sampling_rate);
    if let Some(unit) = upload.unit {
        text.push_str(&format!(" unit={unit:?}"));
    }
    if !annotations.labels.is_empty() || annotations.note.is_some() {
        text.push_str(&format!(
            " labels={:?} note={:?}",
            annotations.labels, annotations.note
        ));
    }
    text
}

/// `sampling_rate`, `unit`, `label` (repeatable) and `note`; anything else is refused.
fn parse_upload_query(pairs: &[(String, String)]) -> Result<Upload, Problem> {
    let mut upload = Upload::default();
    for (key, value) in pairs {
        match key.as_str() {
            "sampling_rate" => {
                upload.sampling_rate = Some(value.parse().map_err(|_| {
                    Problem::invalid_query(format!("`sampling_rate`: `{value}` is not a number"))
                })?)
            }
            "unit" => {
                upload.unit = Some(AccelerationUnit::from_name(value).ok_or_else(|| {
                    Problem::invalid_query(format!("`unit`: `{value}` is not `m/s2` or `g`"))
                })?)
            }
            "label" => upload.labels.push(value.clone()),
            "note" => upload.note = Some(value.clone()),
            other => {
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected sampling_rate, unit, label, note)"
                )));
            }
        }
    }
    Ok(upload)
}

impl From<SignalReadError> for ApiError {
    fn from(error: SignalReadError) -> Self {
        match error {
            SignalReadError::Database(error) => ApiError::Database(error),
            corrupt => ApiError::Internal(corrupt.to_string()),
        }
    }
}

/// The format of an upload from its `Content-Type` (sniffed from the text without one).
fn upload_format(headers: &HeaderMap, text: &str) -> Result<RecordFormat, ApiError> {
    let Some(content_type) = headers.get(header::CONTENT_TYPE) else {
        return Ok(RecordFormat::sniff(text));
    };
    let content_type = content_type.to_str().unwrap_or_default().to_ascii_lowercase();
    let essence = content_type.split(';').next().unwrap_or_default().trim();
    match essence {
        "text/csv" | "application/csv" | "text/plain" => Ok(RecordFormat::Csv),
        "application/json" => Ok(RecordFormat::Json),
        json if json.ends_with("+json") => Ok(RecordFormat::Json),
        other => Err(Problem::unsupported_media_type(format!(
            "a signal is `text/csv` or `application/json`, not `{other}`"
        ))
        .into()),
    }
}

/// Upload a signal
///
/// An accelerogram (m/s²) as CSV, `time,acceleration` (s, m/s²; header optional), or the
/// acceleration alone with `?sampling_rate=` or after a `dt=0.005` header line; a PEER
/// AT2 file (NGA databases, in g, its NPTS and DT read from it); or as JSON,
/// `{"time": [...], "acceleration": [...]}` or `{"sampling_rate": 200, "acceleration":
/// [...]}`, with an optional `"unit": "g"`. `?unit=g` reads a CSV record in g; every
/// record is stored in m/s². Times
/// non-negative and strictly increasing, every value finite, at least 2 samples. Stored
/// once: `201 Created`, `Location: /signals/{id}` and its metadata; jobs refer to it as
/// `{"type": "signal", "id": "<id>", "scale": 1.0}`. A bad record is a 422
/// `invalid-signal` with an error per sample at fault (`/acceleration/17`, the detail
/// naming the CSV line); a body or record over this route's limits is a 413 stating them.
/// A record whose Arias intensity is beyond the largest number (accelerations of order
/// 1e154 m/s² held for seconds) is a 422 at `/acceleration`. A retry with the same
/// `Idempotency-Key` and body gets the same signal back.
#[utoipa::path(post, path = "/signals", operation_id = "createSignal", tag = "Signals",
    params(UploadQuery, ("Idempotency-Key" = Option<String>, Header, description = "Optional, 1 to 255 visible ASCII characters: a retry with the same key and the same request gets the same resource back (same id, `201`, same `Location`, plus `Idempotent-Replayed: true`) instead of creating another; the same key with another request is a 422 `idempotency-key-reused`. Keys are per tenant and kept as long as the resource they created.")),
    request_body(description = "CSV `time,acceleration` (or one column with `sampling_rate`), or JSON `{\"time\", \"acceleration\"}` / `{\"sampling_rate\", \"acceleration\"}`",
        content((String = "text/csv"), (super::openapi::SignalUploadSchema = "application/json"))),
    responses(
        (status = 201, description = "Signal stored", body = SignalMetadata,
            headers(("Location" = String, description = "`/signals/{id}`"))),
        (status = 400, description = "Malformed JSON, bad query parameter, or an invalid `Idempotency-Key` (`invalid-header`)", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 413, description = "Body or record over this route's limits (stated in the detail)", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 415, description = "Neither CSV nor JSON", body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 422, description = "Invalid record (`invalid-signal`): non-numeric or non-finite samples, times not increasing, a sampling rate not positive, an Arias intensity beyond the largest number; or an `Idempotency-Key` first sent with another request (`idempotency-key-reused`)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 503, description = "The storage failed an I/O operation (`storage-unavailable`): nothing stored", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s"))),
        (status = 507, description = "The disk is full (`storage-full`, naming SQLITE_FULL, disk_full or ENOSPC): nothing stored", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s")))))]
pub async fn create(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    query: Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>,
    IdempotencyHeader(key): IdempotencyHeader,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let query = parse_upload_query(&pairs)?;
    // Labels and a note are given in the query (the body is the record): a fault is a
    // 422 at `/labels/k` or `/note`, as in an execution request.
    let labels = serde_json::Value::from(query.labels.clone());
    let note = query.note.clone().map(serde_json::Value::from);
    let annotations = Annotations::parse(Some(&labels), note.as_ref())
        .map_err(|errors| Problem::invalid_inputs(&crate::processes::InvalidInputs(errors)))?;
    if let Some(rate) = query.sampling_rate
        && !(rate.is_finite() && rate > 0.0)
    {
        return Err(Problem::invalid_query(format!(
            "`sampling_rate` must be a positive number of samples per second (got {rate})"
        ))
        .into());
    }
    let bytes = body.map_err(|rejection| -> ApiError {
        if rejection.status() == StatusCode::PAYLOAD_TOO_LARGE {
            Problem::payload_too_large(format!(
                "the record is larger than this service accepts for a signal: {} bytes \
                 (`--max-signal-bytes`)",
                state.max_signal_bytes
            ))
            .into()
        } else {
            Problem::malformed_body(format!("cannot read the request body: {rejection}")).into()
        }
    })?;
    let text = String::from_utf8(bytes.to_vec())
        .map_err(|_| Problem::malformed_body("the body is not valid UTF-8"))?;
    let format = upload_format(&headers, &text)?;
    let keyed = key.map(|key| KeyedRequest {
        key,
        kind: Kind::Signal,
        hash: RequestHash::of_bytes(
            Kind::Signal,
            &upload_description(&query, format, &annotations),
            &bytes,
        ),
    });
    if format == RecordFormat::Json && query.sampling_rate.is_some() {
        return Err(Problem::invalid_query(
            "`sampling_rate` in the query goes with a CSV record; a JSON record gives it as its \
             `sampling_rate` member",
        )
        .into());
    }
    let max_samples = state.max_signal_samples;
    let parsed = tokio::task::spawn_blocking(move || {
        signal_record::parse(&text, format, query.sampling_rate, query.unit, max_samples)
    })
    .await
    .map_err(|e| ApiError::Internal(format!("parsing a signal panicked: {e}")))?;
    let record = parsed.map_err(|error| -> ApiError {
        match error {
            RecordError::Malformed(detail) => Problem::malformed_body(detail).into(),
            RecordError::Invalid(errors) => Problem::invalid_signal(errors).into(),
            RecordError::TooLarge { samples, limit } => Problem::payload_too_large(format!(
                "the record has {samples} samples; this service stores at most {limit} per signal \
                 (`--max-signal-samples`)"
            ))
            .into(),
        }
    })?;
    let created = state
        .signals
        .create(tenant.as_str(), &record, keyed.as_ref(), &annotations)
        .await
        .map_err(|error| match error {
            CreateError::Database(error) => ApiError::Database(error),
            unchecked => ApiError::Internal(unchecked.to_string()),
        })?;
    let mut headers = HeaderMap::new();
    let stored = match created {
        Keyed::Created(stored) => {
            tracing::info!(signal = %stored.id, samples = stored.samples, %tenant, "signal stored");
            stored
        }
        Keyed::Replayed(stored) => {
            tracing::info!(signal = %stored.id, %tenant, "idempotent retry: the key's signal, nothing stored");
            mark_replayed(&mut headers);
            stored
        }
        Keyed::Conflict(conflict) => return Err(key_reused(&conflict)),
    };
    headers.insert(
        header::LOCATION,
        HeaderValue::from_str(&format!("/signals/{}", stored.id)).expect("uuid is a valid header value"),
    );
    Ok((
        StatusCode::CREATED,
        headers,
        Json(SignalMetadata::from_record(&stored)),
    )
        .into_response())
}

/// A signal's metadata
///
/// Samples, duration, sampling, PGA, Arias intensity, upload time, and links to its
/// samples and response spectrum.
#[utoipa::path(get, path = "/signals/{signalId}", operation_id = "getSignal", tag = "Signals",
    params(("signalId" = String, Path, description = "Signal id")),
    responses(
        (status = 200, description = "The signal's metadata", body = SignalMetadata),
        (status = 404, description = "No such signal (`no-such-signal`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn metadata(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(signal_id): Path<String>,
) -> Result<Json<SignalMetadata>, ApiError> {
    let record = state
        .signals
        .get(tenant.as_str(), &signal_id)
        .await?
        .ok_or_else(|| Problem::no_such_signal(&signal_id))?;
    Ok(Json(SignalMetadata::from_record(&record)))
}

/// Query of `GET /signals` (documentation; [`parse_list_query`] reads it, since
/// `label` repeats).
#[derive(Debug, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ListQuery {
    /// Signals per page, 1 to 1000 (default 10).
    #[param(minimum = 1, maximum = 1000)]
    pub limit: Option<u32>,
    /// Opaque position from a `next` link.
    pub cursor: Option<i64>,
    /// Only signals with this label; repeat it for signals with all of them.
    #[param(explode = true)]
    pub label: Option<Vec<String>>,
    /// `json`, or `html` (the dashboard's page): chosen by the service's negotiator
    /// (`format` is an alias); without it, the one `Accept` prefers.
    pub f: Option<String>,
}

/// `limit`, `cursor`, `label` (repeatable); `f` and `format` are the negotiator's.
fn parse_list_query(pairs: &[(String, String)]) -> Result<(u32, Option<i64>, Vec<String>), Problem> {
    let (mut limit, mut cursor, mut labels) = (DEFAULT_LIMIT, None, Vec::new());
    for (key, value) in pairs {
        match key.as_str() {
            "limit" => {
                limit = value
                    .parse()
                    .ok()
                    .filter(|n| (1..=MAX_LIMIT).contains(n))
                    .ok_or_else(|| {
                        Problem::invalid_query(format!("`limit` must be an integer from 1 to {MAX_LIMIT}"))
                    })?
            }
            "cursor" => {
                cursor = Some(value.parse().map_err(|_| {
                    Problem::invalid_query("`cursor` must be the value given in a `next` link")
                })?)
            }
            "label" => {
                if let Some(fault) = label_fault(value) {
                    return Err(Problem::invalid_query(format!("`label` `{value}` {fault}")));
                }
                labels.push(value.clone());
            }
            "f" | "format" => {}
            other => {
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected limit, cursor, label)"
                )));
            }
        }
    }
    Ok((limit, cursor, labels))
}

/// List signals
///
/// The tenant's signals, newest first; `limit` per page, the `next` link gives the
/// following page.
#[utoipa::path(get, path = "/signals", operation_id = "getSignals", tag = "Signals",
    params(ListQuery),
    responses(
        (status = 200, description = "A page of signals", body = SignalList),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn list(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    query: Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>,
) -> Result<Json<SignalList>, ApiError> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let (limit, cursor, labels) = parse_list_query(&pairs)?;
    let mut signals = state
        .signals
        .list(tenant.as_str(), limit + 1, cursor, &labels)
        .await?;
    let more = signals.len() > limit as usize;
    signals.truncate(limit as usize);
    let labels: String = labels
        .iter()
        .map(|label| format!("&label={}", super::sweeps::percent_encoded(label)))
        .collect();
    let href = |cursor: Option<i64>| match cursor {
        Some(cursor) => format!("/signals?limit={limit}&cursor={cursor}{labels}"),
        None => format!("/signals?limit={limit}{labels}"),
    };
    let mut links = vec![Link::new(href(cursor), "self", "application/json")];
    if let (true, Some(last)) = (more, signals.last()) {
        links.push(Link::new(href(Some(last.seq)), "next", "application/json"));
    }
    Ok(Json(SignalList {
        signals: signals.iter().map(SignalMetadata::from_record).collect(),
        links,
    }))
}

/// Delete a signal
///
/// The signal and its samples are gone; finished jobs keep their results. Refused (409
/// `signal-in-use`) while a queued or running job refers to it, so that every job finds
/// its record when it runs.
#[utoipa::path(delete, path = "/signals/{signalId}", operation_id = "deleteSignal", tag = "Signals",
    params(("signalId" = String, Path, description = "Signal id")),
    responses(
        (status = 204, description = "Deleted"),
        (status = 404, description = "No such signal (`no-such-signal`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 409, description = "Queued or running jobs refer to it (`signal-in-use`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 507, description = "The disk is full (`storage-full`, naming the cause): the signal is kept", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json", headers(("Retry-After" = String, description = "s")))))]
pub async fn delete(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(signal_id): Path<String>,
) -> Result<Response, ApiError> {
    match state.signals.delete(tenant.as_str(), &signal_id).await? {
        Deletion::Deleted => {
            tracing::info!(signal = %signal_id, %tenant, "signal deleted");
            Ok(StatusCode::NO_CONTENT.into_response())
        }
        Deletion::NotFound => Err(Problem::no_such_signal(&signal_id).into()),
        Deletion::InUse { jobs } => Err(Problem::signal_in_use(&signal_id, jobs).into()),
    }
}

/// Query of `GET /signals/{signalId}/samples`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct SamplesQuery {
    /// Chosen by the service's negotiator (`f` is an alias): `csv` or `json`; without
    /// it, the one `Accept` prefers (q-values honoured), else JSON.
    #[serde(alias = "f")]
    pub format: Option<String>,
}

/// A signal's samples
///
/// The whole record, streamed, as it was stored (bit for bit: each number the shortest
/// text that reads back as the same double): CSV `time,acceleration` or JSON `{"time":
/// [...], "acceleration": [...]}`, the upload formats.
#[utoipa::path(get, path = "/signals/{signalId}/samples", operation_id = "getSignalSamples", tag = "Signals",
    params(("signalId" = String, Path, description = "Signal id"), SamplesQuery),
    responses(
        (status = 200, description = "The samples", content((String = "text/csv"), (super::openapi::SignalUploadSchema = "application/json"))),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such signal (`no-such-signal`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn samples(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(signal_id): Path<String>,
    // Checks the query; its `format` is the negotiator's (`format: Format`).
    ApiQuery(_): ApiQuery<SamplesQuery>,
    format: Format,
) -> Result<Response, ApiError> {
    let record = state
        .signals
        .record(tenant.as_str(), &signal_id)
        .await?
        .ok_or_else(|| Problem::no_such_signal(&signal_id))?;
    let record = Arc::new(record);
    let chunks: Box<dyn Iterator<Item = String> + Send> = if format == Format::Csv {
        Box::new(signal_record::csv_chunks(record, STREAM_ROWS))
    } else {
        Box::new(signal_record::json_chunks(record, STREAM_ROWS))
    };
    let stream =
        futures_util::stream::iter(chunks.map(|chunk| Ok::<_, std::convert::Infallible>(Bytes::from(chunk))));
    Ok((
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static(format.content_type()),
        )],
        Body::from_stream(stream),
    )
        .into_response())
}

/// A signal's response spectrum
///
/// The pseudo-acceleration response spectrum PSA(f, ξ) = ω² max|u| of the record (m/s²),
/// u the relative displacement of an oscillator ü + 2ξωu̇ + ω²u = −a(t) at rest at the
/// first sample, the maximum taken over the record and one damped period after it (the
/// shock response spectrum of a pulse). Exact stepping between samples
/// (`physics::response_spectrum`, docs/signals.md). Frequencies: `points` log-spaced from
/// `f_min` to `f_max` (Hz; default 200 from 0.1 to 100). `damping`: ratios, repeatable
/// or comma-separated (default 0.05). `format=csv` (or `Accept: text/csv`):
/// `frequency,psa_<damping>...`.
#[utoipa::path(get, path = "/signals/{signalId}/spectrum", operation_id = "getSignalSpectrum", tag = "Signals",
    params(
        ("signalId" = String, Path, description = "Signal id"),
        ("damping" = Option<String>, Query, description = "Damping ratios in [0, 1), repeatable or comma-separated (default 0.05)"),
        ("f_min" = Option<f64>, Query, description = "Lowest frequency (Hz, default 0.1)"),
        ("f_max" = Option<f64>, Query, description = "Highest frequency (Hz, default 100)"),
        ("points" = Option<usize>, Query, description = "Number of log-spaced frequencies, 2 to 2000 (default 200)"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON)"),
    ),
    responses(
        (status = 200, description = "The spectrum", body = SignalSpectrum, content_type = "application/json"),
        (status = 400, description = "Invalid query parameter, or a grid too costly for this record", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such signal (`no-such-signal`)", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json")))]
pub async fn spectrum(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path(signal_id): Path<String>,
    query: Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>,
    format: Format,
) -> Result<Response, ApiError> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let request = parse_spectrum_query(&pairs, &[])?.request;
    let metadata = state
        .signals
        .get(tenant.as_str(), &signal_id)
        .await?
        .ok_or_else(|| Problem::no_such_signal(&signal_id))?;
    let frequencies = log_spaced(request.f_min, request.f_max, request.points);
    let samples = usize::try_from(metadata.samples).unwrap_or(usize::MAX);
    request.check_cost(&frequencies, samples, metadata.duration)?;
    let record = state
        .signals
        .record(tenant.as_str(), &signal_id)
        .await?
        .ok_or_else(|| Problem::no_such_signal(&signal_id))?;
    let dampings = request.dampings.clone();
    let spectra = tokio::task::spawn_blocking(move || {
        dampings
            .iter()
            .map(|&xi| response_spectrum::pseudo_acceleration(&record, &frequencies, xi))
            .collect::<Result<Vec<_>, _>>()
    })
    .await
    .map_err(|e| ApiError::Internal(format!("a response spectrum panicked: {e}")))?
    .map_err(|e| ApiError::Internal(format!("a stored signal's spectrum failed: {e}")))?;
    let frequencies = spectra.first().map(|s| s.frequencies.clone()).unwrap_or_default();
    let document = SignalSpectrum {
        signal: signal_id,
        frequencies,
        pseudo_acceleration: spectra
            .into_iter()
            .map(|s| DampedSpectrum {
                damping: s.damping,
                values: s.pseudo_acceleration,
            })
            .collect(),
        pga: metadata.pga,
    };
    let body = if format == Format::Csv {
        spectra_csv(&document.frequencies, &document.pseudo_acceleration).into_bytes()
    } else {
        serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))?
    };
    Ok((
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static(format.content_type()),
        )],
        body,
    )
        .into_response())
}
