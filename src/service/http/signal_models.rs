//! The documents of `/signals`: a stored signal's metadata, the signal list, and a
//! response spectrum.

use serde::Serialize;
use utoipa::ToSchema;

use super::models::Link;
use crate::service::clock::rfc3339;
use crate::service::signals::SignalRecord;

/// A stored accelerogram: its sampling, peak ground acceleration and Arias intensity.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct SignalMetadata {
    /// Signal id: reference it from a job as `{"type": "signal", "id": "<id>", "scale": 1.0}`.
    pub id: String,
    /// Number of samples.
    pub samples: i64,
    /// Time of the first sample (s).
    pub start: f64,
    /// Last time minus first time (s).
    pub duration: f64,
    /// Mean sample interval (s).
    pub sampling_interval: f64,
    /// 1 / sampling_interval (samples per second, Hz).
    pub sampling_rate: f64,
    /// Whether every interval equals the mean (to 1e-6 relative).
    pub uniform: bool,
    /// Shortest sample interval (s).
    pub shortest_interval: f64,
    /// Longest sample interval (s).
    pub longest_interval: f64,
    /// Peak ground acceleration max |a| (m/s²).
    pub pga: f64,
    /// Time of the first sample reaching the PGA (s).
    pub pga_time: f64,
    /// Arias intensity π/(2g) ∫ a² dt (m/s), g = 9.80665 m/s², exact for the record
    /// linear between samples.
    pub arias_intensity: f64,
    /// When it was uploaded (RFC 3339, UTC).
    pub created: String,
    /// The labels given at upload (empty when none): `GET /signals?label=` filters on them.
    pub labels: Vec<String>,
    /// The note given at upload.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// `self`, the samples (CSV and JSON), the response spectrum.
    pub links: Vec<Link>,
}

impl SignalMetadata {
    pub fn from_record(record: &SignalRecord) -> Self {
        let href = format!("/signals/{}", record.id);
        Self {
            id: record.id.clone(),
            samples: record.samples,
            start: record.start_time,
            duration: record.duration,
            sampling_interval: record.sampling_interval,
            sampling_rate: 1.0 / record.sampling_interval,
            uniform: record.uniform,
            shortest_interval: record.shortest_interval,
            longest_interval: record.longest_interval,
            pga: record.pga,
            pga_time: record.pga_time,
            arias_intensity: record.arias_intensity,
            created: rfc3339(record.created_at),
            labels: record.labels.0.clone(),
            note: record.note.clone(),
            links: vec![
                Link::new(&href, "self", "application/json"),
                Link::new(format!("{href}/samples"), "data", "text/csv").titled("The samples as CSV"),
                Link::new(format!("{href}/samples"), "data", "application/json")
                    .titled("The samples as JSON"),
                Link::new(format!("{href}/spectrum"), "describedby", "application/json")
                    .titled("Pseudo-acceleration response spectrum (5 % damping by default)"),
            ],
        }
    }
}

/// A page of the tenant's signals, newest first.
#[derive(Debug, Serialize, ToSchema)]
pub struct SignalList {
    pub signals: Vec<SignalMetadata>,
    /// `self`, and `next` while older signals remain.
    pub links: Vec<Link>,
}

/// The spectrum at one damping ratio.
#[derive(Debug, Serialize, ToSchema)]
pub struct DampedSpectrum {
    /// Damping ratio ξ of the oscillators (dimensionless).
    pub damping: f64,
    /// PSA = ω² max|u| at each frequency (m/s²).
    pub values: Vec<f64>,
}

/// The pseudo-acceleration response spectrum of a signal.
#[derive(Debug, Serialize, ToSchema)]
pub struct SignalSpectrum {
    /// The signal's id.
    pub signal: String,
    /// Oscillator frequencies (Hz), log-spaced from `f_min` to `f_max`.
    pub frequencies: Vec<f64>,
    /// One spectrum per damping ratio asked for, in the order asked.
    pub pseudo_acceleration: Vec<DampedSpectrum>,
    /// The signal's peak ground acceleration (m/s²): the spectrum tends to it at high
    /// frequency.
    pub pga: f64,
}
