//! `/jobs/{jobId}/results/{output}/spectrum`: the power spectral density of each series
//! of a stored history (the periodogram of `physics::spectrum`), and the spectral error
//! f_err between the first two series, the figure `cantilever-impact` reports.

use axum::extract::{Extension, Path, State};
use axum::http::HeaderMap;
use axum::response::Response;
use serde::Serialize;
use utoipa::ToSchema;

use super::AppState;
use super::error::ApiError;
use super::extract::ApiQuery;
use super::history_view::{Format, capped_max_points, require_finite, respond};
use super::models::Series;
use crate::physics::spectrum::spectral_error;
use crate::problem::Problem;
use crate::service::auth::Tenant;
use crate::service::spectrum_table::SpectrumTable;
use crate::service::{store, thinning};

/// Query of `GET /jobs/{jobId}/results/{output}/spectrum`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct SpectrumQuery {
    /// Chosen by the service's negotiator (`f` is an alias): `csv` or `json`; without
    /// it, the one `Accept` prefers (q-values honoured), else JSON.
    #[serde(alias = "f")]
    pub format: Option<String>,
    /// Lowest frequency kept (Hz), inclusive.
    pub f_min: Option<f64>,
    /// Highest frequency kept (Hz), inclusive.
    pub f_max: Option<f64>,
    /// Thin the kept bins to at most this many rows (at least 2 per series), keeping each
    /// series' minimum and maximum of every bucket so that peaks survive.
    pub max_points: Option<usize>,
    /// Only these series, comma-separated and in this order; default: all.
    pub series: Option<String>,
}

/// f_err between the first two series of a spectrum.
#[derive(Debug, Serialize, ToSchema)]
pub struct SpectrumComparison {
    /// The two series compared, e.g. `["numerical", "reference"]`.
    pub series: [String; 2],
    /// f_err = max_f |Γ_a − Γ_b| / max(max_f Γ_a, max_f Γ_b) over every bin of the whole
    /// history (dimensionless, 0 to 1; below 0.2 the paper calls the signals identical).
    pub f_err: f64,
    /// Frequency of the bin where |Γ_a − Γ_b| is largest (Hz).
    pub frequency: f64,
}

/// The one-sided power spectral density of each series of a history.
#[derive(Debug, Serialize, ToSchema)]
pub struct SpectrumDocument {
    /// Output name, e.g. `tip_displacement`.
    pub output: String,
    /// Sample interval of the history Δt (s).
    pub sample_interval: f64,
    /// Samples of the history the spectrum is computed from.
    pub samples: usize,
    /// Bins in this document.
    pub points: usize,
    /// Bins of the whole spectrum, f_k = k/(nΔt) for k = 0..=n/2.
    pub total_points: usize,
    /// Whether min/max thinning was applied (`max_points`).
    pub thinned: bool,
    /// Bin frequencies (Hz), increasing.
    pub frequency: Vec<f64>,
    /// Γ(f) of each series (the output's unit² per Hz, e.g. m²/Hz): rectangular window
    /// after removing the mean, scaled so that Σ Γ Δf is the variance (Parseval).
    pub series: Vec<Series>,
    /// f_err between the first two series (absent with fewer than two).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub comparison: Option<SpectrumComparison>,
}

/// Spectrum of a history
///
/// The power spectral density Γ(f) of each series of a history (one-sided periodogram,
/// mean removed, rectangular window), computed from the full-resolution history, and
/// f_err between its first two series (`comparison`): for `cantilever-impact`'s
/// `tip_displacement`, the numerical and reference spectra and the f_err of the results
/// document. Optionally restricted to `f_min <= f <= f_max` (Hz), to the `series`
/// named, and thinned to `max_points` rows with min/max buckets.
#[utoipa::path(get, path = "/jobs/{jobId}/results/{output}/spectrum", operation_id = "getResultSpectrum",
    tag = "Results",
    params(
        ("jobId" = String, Path, description = "Job id"),
        ("output" = String, Path, description = "Output name, e.g. `tip_displacement`", example = "tip_displacement"),
        SpectrumQuery,
    ),
    responses(
        (status = 200, description = "The spectrum (frequency in Hz; Γ in the output's unit² per Hz)",
            content(
                (SpectrumDocument = "application/json"),
                (String = "text/csv")
            ),
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "Invalid query parameter", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 404, description = "No such job or output, or results not ready", body = super::openapi::ProblemSchema,
            content_type = "application/problem+json"),
        (status = 422, description = "The history has fewer than 2 samples or a non-finite value",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn spectrum(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path((job_id, output)): Path<(String, String)>,
    ApiQuery(mut query): ApiQuery<SpectrumQuery>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    require_finite([("f_min", query.f_min), ("f_max", query.f_max)], "Hz")?;
    // The per-impact table is no time series.
    if output == crate::processes::impact_report::TABLE {
        return Err(Problem::no_such_output(&job_id, &format!("{output}/spectrum")).into());
    }
    // A response holds at most the service's cap of rows, as for histories.
    query.max_points = Some(capped_max_points(query.max_points, state.max_history_points)?);
    respond(
        &state,
        &tenant,
        &job_id,
        &output,
        &headers,
        format,
        "computing a spectrum",
        move |stored, _| render(stored, &query, format),
    )
    .await
}

/// Histories are uniformly sampled (every process records at a fixed output interval).
fn sample_interval(time: &[f64]) -> f64 {
    match (time.first(), time.last()) {
        (Some(first), Some(last)) if time.len() > 1 => (last - first) / (time.len() - 1) as f64,
        _ => f64::NAN,
    }
}

fn unprocessable(detail: String) -> ApiError {
    Problem::from_status(422, "Unprocessable Content", detail).into()
}

fn render(stored: &store::StoredHistory, query: &SpectrumQuery, format: Format) -> Result<Vec<u8>, ApiError> {
    let history = store::decode(stored).map_err(|e| ApiError::Internal(e.to_string()))?;
    let history = thinning::pick_series(history, query.series.as_deref()).map_err(Problem::invalid_query)?;
    let dt = sample_interval(&history.time);
    let spectrum = SpectrumTable::of(&history, dt).map_err(unprocessable)?;
    let comparison = match history.series.as_slice() {
        [(a, first), (b, second), ..] => {
            let f_err = spectral_error(first, second)
                .map_err(|e| unprocessable(format!("`{}`: {e}", history.name)))?;
            Some(SpectrumComparison {
                series: [a.clone(), b.clone()],
                f_err,
                frequency: spectrum.largest_difference().unwrap_or(0.0),
            })
        }
        _ => None,
    };
    let selected = spectrum.select(query.f_min, query.f_max, query.max_points);
    if format == Format::Csv {
        return Ok(selected.to_csv().into_bytes());
    }
    let in_window = thinning::count_in_window(&spectrum.frequency, query.f_min, query.f_max);
    let document = SpectrumDocument {
        output: selected.name,
        sample_interval: dt,
        samples: history.time.len(),
        points: selected.frequency.len(),
        total_points: spectrum.frequency.len(),
        thinned: selected.frequency.len() < in_window,
        frequency: selected.frequency,
        series: Series::from_columns(selected.series),
        comparison,
    };
    serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))
}
