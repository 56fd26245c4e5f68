//! The `spectrum_compatible` base acceleration: a synthetic earthquake drawn from a seed
//! to match a target response spectrum (`physics::synthetic`), generated while the
//! inputs are checked and handed to the integrator as a table.
//!
//! Generation is deterministic and costs tens to hundreds of milliseconds, and a plan
//! asks for its excitation more than once (checking, each run of the step-halving check):
//! the record is generated once per parsed input and kept with it.

use std::sync::{Arc, OnceLock};

use serde::Deserialize;
use utoipa::ToSchema;

use super::input_schema::PositiveNumber;
use crate::physics::InputIssue;
use crate::physics::loads::Table;
use crate::physics::synthetic::{self, Accelerogram, SpectrumCompatible, TargetSpectrum};

/// A synthetic earthquake matching a target pseudo-acceleration spectrum: stationary
/// random phases drawn from `seed`, a Jennings envelope (quadratic build-up, `strong_motion`
/// plateau, exponential decay to 0 at `duration`), Fourier amplitudes corrected until the
/// spectrum at the target's damping is within `tolerance` of the target over its band,
/// velocity and displacement brought back to 0 at the end. The same seed gives the same
/// record, bit for bit, on every machine (docs/signals.md).
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SpectrumCompatibleInput {
    /// The response spectrum the record must match.
    pub target: TargetSpectrumInput,
    /// Record length (s); the record is 0 after it.
    #[schema(exclusive_minimum = 0.0)]
    pub duration: f64,
    /// Length of the envelope's plateau (s), shorter than `duration`; the strong motion
    /// must last two periods of the target's lowest frequency.
    #[schema(exclusive_minimum = 0.0)]
    pub strong_motion: f64,
    /// Seed of the random phases (any integer from 0 to 2⁶⁴ − 1): a sweep axis over seeds
    /// is a Monte Carlo campaign over earthquakes.
    pub seed: u64,
    /// Build-up time of the envelope (s), shorter than duration − strong_motion; a
    /// quarter of duration − strong_motion when left out.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = f64, exclusive_minimum = 0.0)]
    pub rise: Option<f64>,
    /// Sampling interval of the record (s), at most 1/(5 f_max), f_max the target's
    /// highest frequency; min(0.005, 1/(5 f_max)) when left out.
    #[serde(default, deserialize_with = "present")]
    #[schema(value_type = f64, exclusive_minimum = 0.0)]
    pub time_step: Option<f64>,
    /// Largest relative deviation of the record's spectrum from the target over the
    /// target's band (dimensionless); a record that cannot reach it is refused.
    #[serde(default = "default_tolerance")]
    #[schema(default = 0.1, exclusive_minimum = 0.0, exclusive_maximum = 1.0)]
    pub tolerance: f64,
    /// Most correction rounds.
    #[serde(default = "default_max_iterations")]
    #[schema(default = 40, minimum = 1, maximum = 100)]
    pub max_iterations: usize,
    /// The record, generated once (not an input).
    #[serde(skip)]
    record: Record,
}

/// The target response spectrum.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TargetSpectrumInput {
    /// Frequencies (Hz), at least two, strictly increasing; the first and last bound the
    /// band the record must match, the first at least 2/strong_motion (the strong motion
    /// lasts two periods of it). Straight lines between points on log–log axes.
    #[schema(value_type = Vec<PositiveNumber>)]
    pub frequencies: Vec<f64>,
    /// Pseudo-acceleration at each frequency (m/s²).
    #[schema(value_type = Vec<PositiveNumber>)]
    pub accelerations: Vec<f64>,
    /// Damping ratio of the spectrum (dimensionless).
    #[serde(default = "default_damping")]
    #[schema(default = 0.05, exclusive_minimum = 0.0, exclusive_maximum = 1.0)]
    pub damping: f64,
}

fn default_tolerance() -> f64 {
    synthetic::DEFAULT_TOLERANCE
}
fn default_max_iterations() -> usize {
    synthetic::DEFAULT_MAX_ITERATIONS
}
fn default_damping() -> f64 {
    0.05
}

/// A field that may be left out but not given as null.
fn present<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(
    deserializer: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(deserializer).map(Some)
}

/// The generated record or why there is none, computed on first use. Shared by clones of
/// the same input; it is derived data, so it takes no part in equality.
#[derive(Debug, Clone, Default)]
struct Record(Arc<OnceLock<Result<Accelerogram, Vec<InputIssue>>>>);

impl PartialEq for Record {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl SpectrumCompatibleInput {
    /// The physics request.
    pub fn request(&self) -> SpectrumCompatible {
        SpectrumCompatible {
            target: TargetSpectrum {
                frequencies: self.target.frequencies.clone(),
                accelerations: self.target.accelerations.clone(),
                damping: self.target.damping,
            },
            duration: self.duration,
            strong_motion: self.strong_motion,
            rise: self.rise,
            time_step: self.time_step,
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            seed: self.seed,
        }
    }

    fn record(&self) -> &Result<Accelerogram, Vec<InputIssue>> {
        self.record.0.get_or_init(|| self.request().generate())
    }

    /// The generated record (its samples, the rounds taken, the deviation reached);
    /// `None` for a request that was refused.
    pub fn generated(&self) -> Option<&Accelerogram> {
        self.record().as_ref().ok()
    }

    /// Every problem with the request (fields relative to the excitation object), the
    /// record generated on the way.
    pub fn validate(&self) -> Vec<InputIssue> {
        match self.record() {
            Ok(_) => Vec::new(),
            Err(issues) => issues.clone(),
        }
    }

    /// The record (time in s, acceleration in m/s²). Only meaningful on an input that
    /// passed [`Self::validate`]: a refused request has no record, and gives an empty
    /// table (no excitation).
    pub fn table(&self) -> Table {
        match self.record() {
            Ok(record) => record.table(),
            Err(_) => Table {
                time: Vec::new(),
                values: Vec::new(),
            },
        }
    }
}
