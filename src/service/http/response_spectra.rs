//! Pseudo-acceleration response spectra over HTTP: the query both routes share (damping
//! ratios, the log-spaced frequency grid, its cost ceiling, the CSV form), and
//! `GET /jobs/{jobId}/results/{output}/response_spectrum`, the spectrum of a point of the
//! model from one column of a displacement history (an in-structure response spectrum).
//! `/signals/{id}/spectrum` (`signals.rs`) is the spectrum of a stored record.

use axum::extract::{Extension, Path, Query, State};
use axum::http::HeaderMap;
use axum::response::Response;
use serde::Serialize;
use utoipa::ToSchema;

use super::AppState;
use super::error::ApiError;
use super::history_view::{Format, respond};
use super::signal_models::DampedSpectrum;
use crate::physics::acceleration::acceleration_of_displacement;
use crate::physics::loads::Table;
use crate::physics::response_spectrum::{self, log_spaced};
use crate::physics::synthetic::TargetSpectrum;
use crate::problem::Problem;
use crate::processes::{HistoryKind, columns_csv};
use crate::service::auth::Tenant;
use crate::service::{store, thinning};

/// Default frequency grid of a spectrum (Hz, points).
pub const DEFAULT_F_MIN: f64 = 0.1;
pub const DEFAULT_F_MAX: f64 = 100.0;
pub const DEFAULT_POINTS: usize = 200;
/// Most frequencies and damping ratios of one spectrum request.
pub const MAX_POINTS: usize = 2000;
pub const MAX_DAMPINGS: usize = 10;
/// Most oscillator sub-steps one spectrum request may take (about 10 s of computing):
/// each frequency f steps through every sample interval, in sub-steps of at most 1/64
/// of its period.
pub const MAX_SPECTRUM_STEPS: f64 = 2e9;

/// What a response-spectrum request asks for (`/signals/{id}/spectrum`,
/// `/jobs/{id}/results/{output}/response_spectrum`).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct SpectrumRequest {
    /// Damping ratios ξ (dimensionless, in [0, 1)).
    pub dampings: Vec<f64>,
    /// Lowest and highest frequency of the grid (Hz).
    pub f_min: f64,
    pub f_max: f64,
    /// Frequencies of the grid, log-spaced.
    pub points: usize,
}

/// A parsed response-spectrum query: the request, and the values of the route's own
/// parameters (`extra` of [`parse_spectrum_query`]) in the order given.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct SpectrumQuery {
    pub request: SpectrumRequest,
    pub extra: Vec<(String, String)>,
}

impl SpectrumRequest {
    /// 400 when the grid would take more than [`MAX_SPECTRUM_STEPS`] oscillator steps on a
    /// record of `samples` samples over `duration` (s): each frequency f steps through
    /// every sample, plus 64 sub-steps per period where its period is shorter than the
    /// sample interval.
    pub fn check_cost(&self, frequencies: &[f64], samples: usize, duration: f64) -> Result<(), Problem> {
        let steps = self.dampings.len() as f64
            * frequencies
                .iter()
                .map(|f| samples as f64 + 64.0 * f * duration)
                .sum::<f64>();
        if steps > MAX_SPECTRUM_STEPS {
            return Err(Problem::invalid_query(format!(
                "this grid takes about {steps:.2e} oscillator steps on this record ({samples} samples over \
                 {duration} s), more than the limit of {MAX_SPECTRUM_STEPS:.0e}: ask for fewer `points`, fewer \
                 damping ratios or a lower `f_max`"
            )));
        }
        Ok(())
    }
}

/// Parses `damping` (repeatable or comma-separated; default 0.05), `f_min`, `f_max`,
/// `points`, `format`, and the route's own parameters named in `extra` (kept as given);
/// anything else is refused.
pub(super) fn parse_spectrum_query(
    pairs: &[(String, String)],
    extra: &[&str],
) -> Result<SpectrumQuery, Problem> {
    let number = |name: &str, text: &str| -> Result<f64, Problem> {
        text.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| Problem::invalid_query(format!("`{name}`: `{text}` is not a finite number")))
    };
    let mut request = SpectrumRequest {
        dampings: Vec::new(),
        f_min: DEFAULT_F_MIN,
        f_max: DEFAULT_F_MAX,
        points: DEFAULT_POINTS,
    };
    let mut own = Vec::new();
    for (key, value) in pairs {
        match key.as_str() {
            key if extra.contains(&key) => own.push((key.to_owned(), value.clone())),
            "damping" => {
                for text in value.split(',').filter(|s| !s.trim().is_empty()) {
                    let xi = number("damping", text)?;
                    if !(0.0..1.0).contains(&xi) {
                        return Err(Problem::invalid_query(format!(
                            "`damping`: {xi} is not a damping ratio in [0, 1)"
                        )));
                    }
                    request.dampings.push(xi);
                }
            }
            "f_min" => request.f_min = number("f_min", value)?,
            "f_max" => request.f_max = number("f_max", value)?,
            "points" => {
                request.points = value
                    .parse()
                    .ok()
                    .filter(|n| (2..=MAX_POINTS).contains(n))
                    .ok_or_else(|| {
                        Problem::invalid_query(format!("`points` must be an integer from 2 to {MAX_POINTS}"))
                    })?;
            }
            // The negotiator's (`super::negotiation`), checked there.
            "format" | "f" => {}
            other => {
                let expected: Vec<&str> = ["damping", "f_min", "f_max", "points", "format"]
                    .into_iter()
                    .chain(extra.iter().copied())
                    .collect();
                return Err(Problem::invalid_query(format!(
                    "unknown query parameter `{other}` (expected {})",
                    expected.join(", ")
                )));
            }
        }
    }
    if request.dampings.is_empty() {
        request.dampings.push(0.05);
    }
    if request.dampings.len() > MAX_DAMPINGS {
        return Err(Problem::invalid_query(format!(
            "`damping`: at most {MAX_DAMPINGS} damping ratios per request"
        )));
    }
    if !(request.f_min > 0.0 && request.f_max > request.f_min) {
        return Err(Problem::invalid_query(format!(
            "the frequency grid needs 0 < f_min < f_max (got f_min {} Hz, f_max {} Hz)",
            request.f_min, request.f_max
        )));
    }
    Ok(SpectrumQuery { request, extra: own })
}

/// `frequency,psa_<damping>...`: one row per frequency (Hz), one column per damping ratio
/// (m/s²).
pub(super) fn spectra_csv(frequencies: &[f64], spectra: &[DampedSpectrum]) -> String {
    columns_csv("frequency", frequencies, &spectra_columns(spectra))
}

/// The CSV columns `psa_<damping>` of `spectra`.
fn spectra_columns(spectra: &[DampedSpectrum]) -> Vec<(String, Vec<f64>)> {
    spectra
        .iter()
        .map(|s| (format!("psa_{}", s.damping), s.values.clone()))
        .collect()
}

/// A synthetic earthquake's target beside the spectrum of its stored record.
#[derive(Debug, Serialize, ToSchema)]
pub struct SpectrumTarget {
    /// Damping ratio of the target (dimensionless).
    pub damping: f64,
    /// The target at each of `frequencies` (m/s², straight between its points on log–log
    /// axes); null outside its band.
    pub pseudo_acceleration: Vec<Option<f64>>,
    /// Largest |PSA/target − 1| over the frequencies within the band, of the spectrum at
    /// the target's damping (dimensionless); null when that damping was not asked for or
    /// no frequency lies in the band.
    pub max_deviation: Option<f64>,
    /// Where it occurs (Hz).
    pub deviation_frequency: Option<f64>,
    /// The deviation the request allowed (dimensionless).
    pub tolerance: f64,
}

/// The pseudo-acceleration response spectrum of one column of a displacement or
/// acceleration history.
#[derive(Debug, Serialize, ToSchema)]
pub struct HistoryResponseSpectrum {
    /// Output name, e.g. `displacements`.
    pub output: String,
    /// The column, e.g. `p0` (a pin tip), `numerical`.
    pub series: String,
    /// Mean sample interval of the history (s); the acceleration is read well up to
    /// about a tenth of the sampling rate, 1/(10 × this).
    pub sample_interval: f64,
    /// Samples of the acceleration record: a displacement history's but its first and
    /// last; an acceleration history's, all.
    pub samples: usize,
    /// Largest |acceleration| of the record (m/s²): the spectrum tends to it at high
    /// frequency (the zero-period acceleration).
    pub peak_acceleration: f64,
    /// Oscillator frequencies (Hz), log-spaced from `f_min` to `f_max`.
    pub frequencies: Vec<f64>,
    /// One spectrum per damping ratio asked for, in the order asked.
    pub pseudo_acceleration: Vec<DampedSpectrum>,
    /// For a synthetic earthquake's column of `excitation`, its target (the results'
    /// `generated_records`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target: Option<SpectrumTarget>,
}

/// Response spectrum of a displacement or acceleration history
///
/// The pseudo-acceleration response spectrum PSA(f, ξ) = ω² max|u| (m/s²) of the motion
/// of one column of a displacement history: the acceleration at each interior sample by
/// second divided differences of the displacement (`physics::acceleration`), then the
/// oscillators of `physics::response_spectrum` as for a signal (at rest at the first
/// acceleration sample, followed one damped period after the last). The histories are in
/// the frame of the pin feet: for a run with a base excitation this is the spectrum of
/// the motion relative to the feet. Of a column of an acceleration history (the
/// `excitation` a run was given), the spectrum of the stored samples themselves; for a
/// synthetic earthquake's column, `target` holds its target and the deviation from it,
/// and the defaults are the target's damping and band. Only displacement and
/// acceleration histories (`kind` in the process description) have one: another output
/// is a 404. `series`: the column (default the first); `damping`, `f_min`, `f_max`,
/// `points`: as for a signal's spectrum; `format=csv` (or `Accept: text/csv`):
/// `frequency,psa_<damping>...`, then `target` when every frequency lies in the target's
/// band.
#[utoipa::path(get, path = "/jobs/{jobId}/results/{output}/response_spectrum", operation_id = "getResultResponseSpectrum",
    tag = "Results",
    params(
        ("jobId" = String, Path, description = "Job id"),
        ("output" = String, Path, description = "A displacement or acceleration history, e.g. `displacements`, `excitation`", example = "displacements"),
        ("series" = Option<String>, Query, description = "The column, e.g. `p0` (default: the first)"),
        ("damping" = Option<String>, Query, description = "Damping ratios in [0, 1), repeatable or comma-separated (default 0.05; a synthetic earthquake's: its target's)"),
        ("f_min" = Option<f64>, Query, description = "Lowest frequency (Hz, default 0.1; a synthetic earthquake's: its target's lowest)"),
        ("f_max" = Option<f64>, Query, description = "Highest frequency (Hz, default 100; a synthetic earthquake's: its target's highest)"),
        ("points" = Option<usize>, Query, description = "Number of log-spaced frequencies, 2 to 2000 (default 200)"),
        ("format" = Option<String>, Query, description = "`csv` or `json` (default from `Accept`, else JSON)"),
    ),
    responses(
        (status = 200, description = "The spectrum (frequencies in Hz, PSA in m/s²)",
            content(
                (HistoryResponseSpectrum = "application/json"),
                (String = "text/csv")
            ),
            headers(("ETag" = String))),
        (status = 304, description = "Unchanged since the `If-None-Match` tag"),
        (status = 400, description = "Invalid query parameter, an unknown column, or a grid too costly for this history",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 404, description = "No such job or displacement or acceleration history, or results not ready",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json"),
        (status = 422, description = "The history is too short (fewer than 4 samples)",
            body = super::openapi::ProblemSchema, content_type = "application/problem+json")))]
pub async fn response_spectrum(
    State(state): State<AppState>,
    Extension(tenant): Extension<Tenant>,
    Path((job_id, output)): Path<(String, String)>,
    query: Result<Query<Vec<(String, String)>>, axum::extract::rejection::QueryRejection>,
    headers: HeaderMap,
    format: Format,
) -> Result<Response, ApiError> {
    let Query(pairs) = query.map_err(|e| Problem::invalid_query(e.body_text()))?;
    let SpectrumQuery { request, extra } = parse_spectrum_query(&pairs, &["series"])?;
    let given = |name: &str| pairs.iter().any(|(key, _)| key == name);
    let defaults = Defaults {
        damping: !given("damping"),
        f_min: !given("f_min"),
        f_max: !given("f_max"),
    };
    let series = match extra.as_slice() {
        [] => None,
        [(_, name)] if !name.is_empty() && !name.contains(',') => Some(name.clone()),
        _ => return Err(Problem::invalid_query("`series` names one column, once").into()),
    };
    let job = state
        .queue
        .get(tenant.as_str(), &job_id)
        .await?
        .ok_or_else(|| Problem::no_such_job(&job_id))?;
    let kind = state
        .registry
        .get(&job.process_id)
        .and_then(|process| process.history_kind(&output));
    let motion = match kind {
        Some(HistoryKind::Displacement) => Motion::Displacement,
        Some(HistoryKind::Acceleration) => Motion::Acceleration,
        _ => {
            let mut problem = Problem::no_such_output(&job_id, &format!("{output}/response_spectrum"));
            problem.detail = match kind {
                Some(kind) => format!(
                    "`{output}` of job `{job_id}` is a {} history: only displacement and acceleration histories \
                     have a response spectrum",
                    kind.as_str()
                ),
                None => format!("job `{job_id}` has no displacement or acceleration history `{output}`"),
            };
            return Err(problem.into());
        }
    };
    respond(
        &state,
        &tenant,
        &job_id,
        &output,
        &headers,
        format,
        "computing a response spectrum",
        move |stored, outcome| {
            render(
                stored,
                (series.as_deref(), motion),
                (request, defaults),
                outcome.results.as_deref(),
                format,
            )
        },
    )
    .await
}

/// What the values of a history's column are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Motion {
    Displacement,
    Acceleration,
}

/// Which of the grid's parameters were left to their defaults (a synthetic
/// earthquake's are its target's).
#[derive(Debug, Clone, Copy)]
struct Defaults {
    damping: bool,
    f_min: bool,
    f_max: bool,
}

/// The target of the synthetic earthquake whose member is `series`, from a results
/// document's `generated_records`.
fn generated_target(results: Option<&str>, series: &str) -> Option<(TargetSpectrum, f64)> {
    let document: serde_json::Value = serde_json::from_str(results?).ok()?;
    let record = document["generated_records"]
        .as_array()?
        .iter()
        .find(|record| record["member"] == series)?;
    let numbers = |value: &serde_json::Value| -> Option<Vec<f64>> {
        value.as_array()?.iter().map(serde_json::Value::as_f64).collect()
    };
    let target = &record["target"];
    Some((
        TargetSpectrum {
            frequencies: numbers(&target["frequencies"])?,
            accelerations: numbers(&target["accelerations"])?,
            damping: target["damping"].as_f64()?,
        },
        record["tolerance"].as_f64()?,
    ))
}

/// The target beside the spectra `spectra` at `frequencies`.
fn compare(
    (target, tolerance): &(TargetSpectrum, f64),
    frequencies: &[f64],
    spectra: &[DampedSpectrum],
) -> SpectrumTarget {
    let (low, high) = target.band();
    let slack = 1e-12;
    let values: Vec<Option<f64>> = frequencies
        .iter()
        .map(|&f| (f >= low * (1.0 - slack) && f <= high * (1.0 + slack)).then(|| target.at(f)))
        .collect();
    let at_damping = spectra.iter().find(|s| s.damping == target.damping);
    let worst = at_damping.and_then(|spectrum| {
        (spectrum.values.iter().zip(&values).zip(frequencies))
            .filter_map(|((psa, wanted), f)| wanted.map(|w| ((psa / w - 1.0).abs(), *f)))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    });
    SpectrumTarget {
        damping: target.damping,
        pseudo_acceleration: values,
        max_deviation: worst.map(|w| w.0),
        deviation_frequency: worst.map(|w| w.1),
        tolerance: *tolerance,
    }
}

fn render(
    stored: &store::StoredHistory,
    (series, motion): (Option<&str>, Motion),
    (mut request, defaults): (SpectrumRequest, Defaults),
    results: Option<&str>,
    format: Format,
) -> Result<Vec<u8>, ApiError> {
    let history = store::decode(stored).map_err(|e| ApiError::Internal(e.to_string()))?;
    let name = series
        .map(str::to_owned)
        .or_else(|| history.series.first().map(|(name, _)| name.clone()))
        .unwrap_or_default();
    let history = thinning::pick_series(history, Some(&name)).map_err(Problem::invalid_query)?;
    let (name, values) = history
        .series
        .into_iter()
        .next()
        .ok_or_else(|| Problem::invalid_query(format!("`{}` has no column", history.name)))?;
    let too_short = |e: String| {
        Problem::from_status(
            422,
            "Unprocessable Content",
            format!("`{}` column `{name}`: {e}", history.name),
        )
    };
    let (record, target) = match motion {
        Motion::Displacement => (
            acceleration_of_displacement(&history.time, &values).map_err(|e| too_short(e.to_string()))?,
            None,
        ),
        Motion::Acceleration => {
            if history.time.len() < 2 {
                return Err(too_short("fewer than 2 samples".to_owned()).into());
            }
            let target = generated_target(results, &name);
            if let Some((target, _)) = &target {
                let (low, high) = target.band();
                if defaults.damping {
                    request.dampings = vec![target.damping];
                }
                if defaults.f_min {
                    request.f_min = low;
                }
                if defaults.f_max {
                    request.f_max = high;
                }
                if request.f_min >= request.f_max {
                    return Err(Problem::invalid_query(format!(
                        "the frequency grid needs f_min < f_max (got f_min {} Hz, f_max {} Hz; the target's band \
                         is {low} to {high} Hz)",
                        request.f_min, request.f_max
                    ))
                    .into());
                }
            }
            let record = Table {
                time: history.time.clone(),
                values,
            };
            (record, target)
        }
    };
    let duration = record.time.last().unwrap_or(&0.0) - record.time.first().unwrap_or(&0.0);
    let frequencies = log_spaced(request.f_min, request.f_max, request.points);
    request.check_cost(&frequencies, record.time.len(), duration)?;
    let spectra = request
        .dampings
        .iter()
        .map(|&xi| response_spectrum::pseudo_acceleration(&record, &frequencies, xi))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| ApiError::Internal(format!("the response spectrum of a stored history failed: {e}")))?;
    let spectra: Vec<DampedSpectrum> = spectra
        .into_iter()
        .map(|s| DampedSpectrum {
            damping: s.damping,
            values: s.pseudo_acceleration,
        })
        .collect();
    let target = target.map(|target| compare(&target, &frequencies, &spectra));
    if format == Format::Csv {
        let mut series = spectra_columns(&spectra);
        if let Some(values) = target.as_ref().and_then(|t| {
            t.pseudo_acceleration
                .iter()
                .copied()
                .collect::<Option<Vec<f64>>>()
        }) {
            series.push(("target".to_owned(), values));
        }
        return Ok(columns_csv("frequency", &frequencies, &series).into_bytes());
    }
    let document = HistoryResponseSpectrum {
        output: history.name,
        series: name,
        sample_interval: (history.time[history.time.len() - 1] - history.time[0])
            / (history.time.len() - 1) as f64,
        samples: record.time.len(),
        peak_acceleration: record.values.iter().fold(0.0, |peak: f64, a| peak.max(a.abs())),
        frequencies,
        pseudo_acceleration: spectra,
        target,
    };
    serde_json::to_vec(&document).map_err(|e| ApiError::Internal(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(items: &[(&str, &str)]) -> Vec<(String, String)> {
        items.iter().map(|(k, v)| ((*k).into(), (*v).into())).collect()
    }

    #[test]
    fn dampings_may_be_repeated_or_comma_separated() {
        let request = parse_spectrum_query(
            &pairs(&[("damping", "0.02,0.05"), ("damping", "0.1"), ("points", "50")]),
            &[],
        )
        .unwrap()
        .request;
        assert_eq!(request.dampings, vec![0.02, 0.05, 0.1]);
        assert_eq!(request.points, 50);
        assert_eq!(
            parse_spectrum_query(&[], &[]).unwrap().request.dampings,
            vec![0.05]
        );
    }

    #[test]
    fn bad_spectrum_queries_are_refused() {
        for bad in [
            &[("damping", "1.0")][..],
            &[("damping", "abc")],
            &[("f_min", "0")],
            &[("f_min", "10"), ("f_max", "5")],
            &[("points", "1")],
            &[("dampnig", "0.05")],
        ] {
            assert!(parse_spectrum_query(&pairs(bad), &[]).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_route_names_its_own_parameters() {
        let query =
            parse_spectrum_query(&pairs(&[("series", "p0"), ("damping", "0.02")]), &["series"]).unwrap();
        assert_eq!(query.extra, vec![("series".to_owned(), "p0".to_owned())]);
        assert_eq!(query.request.dampings, vec![0.02]);
        let refused = parse_spectrum_query(&pairs(&[("series", "p0")]), &[]).unwrap_err();
        assert!(refused.detail.contains("`series`"), "{}", refused.detail);
        let refused = parse_spectrum_query(&pairs(&[("serie", "p0")]), &["series"]).unwrap_err();
        assert!(refused.detail.ends_with("format, series)"), "{}", refused.detail);
    }
}
