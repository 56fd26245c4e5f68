//! Pseudo-acceleration response spectra: how hard a signal shakes a single-degree-of-
//! freedom oscillator of each natural frequency, the way earthquake and shock
//! specifications state loads (the shock response spectrum of a pulse is the same thing).
//!
//! For a base acceleration a(t) and an oscillator of natural frequency f (ω = 2πf) and
//! damping ratio ξ ∈ [0, 1), the relative displacement obeys
//!   ü + 2ξω u̇ + ω² u = −a(t),  u(t₀) = u̇(t₀) = 0,
//! and the pseudo-acceleration is PSA(f, ξ) = ω² maxₜ |u(t)| (m/s²), the maximum taken
//! over the signal and the free vibration after it (the residual response, which holds the
//! maximum of a short pulse). For ξ = 0 it is also the peak absolute acceleration.
//!
//! # Exact stepping
//! Between two samples the signal is linear (the [`Table`] convention), so each step has
//! an exact solution (Nigam & Jennings 1969): with forcing f = −a going from f₀ to f₁
//! over h, the particular solution is α + βt with β = (f₁ − f₀)/(ω²h),
//! α = (f₀ − 2ξωβ)/ω², and the rest is the free damped motion of (u − α, u̇ − β):
//!   u(h) = α + βh + a₁₁(u − α) + a₁₂(u̇ − β),  u̇(h) = β + a₂₁(u − α) + a₂₂(u̇ − β),
//!   a₁₁ = E(C + ξωS/ω_d), a₁₂ = E S/ω_d, a₂₁ = −E ω² S/ω_d, a₂₂ = E(C − ξωS/ω_d),
//! with ω_d = ω√(1 − ξ²), E = e^{−ξωh}, S = sin ω_d h, C = cos ω_d h. The response is
//! exact at every step; only the maximum is sampled: each sample interval is cut into
//! sub-steps of at most 1/[`STEPS_PER_PERIOD`] of the oscillator's period, so the peak is
//! low by at most 1 − cos(π/64) ≈ 0.12 %. After the last sample the signal is 0 (again
//! the table's convention) and the free vibration is followed for one damped period,
//! which holds its largest excursion (successive extrema decay by e^{−πξω/ω_d}).
//!
//! The elementary functions are [`crate::portable`]'s, so a spectrum is the same bit for
//! bit on every machine (the spectrum-compatible generator iterates on it).

use crate::loads::Table;
use crate::portable;

/// Sub-steps per oscillator period at least (module doc): the sampled peak is low by at
/// most 1 − cos(π/64) ≈ 0.12 %.
pub const STEPS_PER_PERIOD: f64 = 64.0;

/// Why a response spectrum could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResponseSpectrumError {
    /// Fewer than two samples.
    #[error("a signal needs at least 2 samples, got {0}")]
    TooShort(usize),
    /// Times and values differ in length.
    #[error("{times} times but {values} values")]
    LengthMismatch { times: usize, values: usize },
    /// A time is not finite or not above the previous one.
    #[error("time {index} ({value} s) is not finite or not above the previous time")]
    NotIncreasing { index: usize, value: f64 },
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite ({value})")]
    NonFinite { index: usize, value: f64 },
    /// A frequency is not finite and positive.
    #[error("frequency {index} must be finite and > 0 Hz, got {value}")]
    InvalidFrequency { index: usize, value: f64 },
    /// The damping ratio is outside [0, 1).
    #[error("damping ratio must be in [0, 1), got {0}")]
    InvalidDamping(f64),
    /// The sample interval of a uniform record is not finite and positive.
    #[error("sample interval must be finite and > 0 s, got {0}")]
    InvalidSampleInterval(f64),
}

/// The pseudo-acceleration spectrum of one signal at one damping ratio.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseSpectrum {
    /// Damping ratio ξ of the oscillators (dimensionless).
    pub damping: f64,
    /// Oscillator frequencies (Hz).
    pub frequencies: Vec<f64>,
    /// PSA = ω² max|u| at each frequency (m/s² for an acceleration in m/s²).
    pub pseudo_acceleration: Vec<f64>,
}

/// `count` frequencies from `low` to `high` (Hz) with a constant ratio between
/// neighbours, both ends included exactly (`count` ≥ 2, 0 < low < high assumed).
pub fn log_spaced(low: f64, high: f64, count: usize) -> Vec<f64> {
    if count < 2 {
        return vec![low; count];
    }
    let span = portable::ln(high / low);
    (0..count)
        .map(|k| match k {
            0 => low,
            k if k == count - 1 => high,
            k => low * portable::exp(span * k as f64 / (count - 1) as f64),
        })
        .collect()
}

/// The exact step of the module doc for one oscillator and one step length.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    h: f64,
    omega_squared: f64,
    two_xi_omega: f64,
    a11: f64,
    a12: f64,
    a21: f64,
    a22: f64,
}

impl Step {
    pub(crate) fn new(omega: f64, xi: f64, h: f64) -> Self {
        let omega_d = omega * (1.0 - xi * xi).sqrt();
        let decay = portable::exp(-xi * omega * h);
        let (s, c) = portable::sin_cos(omega_d * h);
        let s_over = decay * s / omega_d;
        Self {
            h,
            omega_squared: omega * omega,
            two_xi_omega: 2.0 * xi * omega,
            a11: decay * c + xi * omega * s_over,
            a12: s_over,
            a21: -omega * omega * s_over,
            a22: decay * c - xi * omega * s_over,
        }
    }

    /// (u, u̇) after one step under the forcing f = −a going linearly from `f0` to `f1`.
    pub(crate) fn advance(&self, u: f64, v: f64, f0: f64, f1: f64) -> (f64, f64) {
        let beta = (f1 - f0) / (self.omega_squared * self.h);
        let alpha = (f0 - self.two_xi_omega * beta) / self.omega_squared;
        let (du, dv) = (u - alpha, v - beta);
        (
            alpha + beta * self.h + self.a11 * du + self.a12 * dv,
            beta + self.a21 * du + self.a22 * dv,
        )
    }
}

/// One oscillator driven through a signal: its state, its largest |u|, and the step of
/// the last sample interval seen (reused while the interval does not change).
#[derive(Debug)]
struct Oscillator {
    omega: f64,
    xi: f64,
    u: f64,
    v: f64,
    peak: f64,
    cached: Option<(f64, usize, Step)>,
}

impl Oscillator {
    fn new(frequency: f64, xi: f64) -> Self {
        Self {
            omega: std::f64::consts::TAU * frequency,
            xi,
            u: 0.0,
            v: 0.0,
            peak: 0.0,
            cached: None,
        }
    }

    /// Follows the signal over one interval of `interval` (s) where a goes linearly from
    /// `a0` to `a1`, in sub-steps of at most a 1/STEPS_PER_PERIOD period.
    fn interval(&mut self, interval: f64, a0: f64, a1: f64) {
        let (substeps, step) = match self.cached {
            // Intervals equal to 1e-9 relative share their step: a uniform record whose
            // times are k·Δt in floating point would otherwise recompute it every sample.
            Some((h, substeps, step)) if (h - interval).abs() <= 1e-9 * h => (substeps, step),
            _ => {
                let period = std::f64::consts::TAU / self.omega;
                let substeps = (interval * STEPS_PER_PERIOD / period).ceil().max(1.0) as usize;
                let step = Step::new(self.omega, self.xi, interval / substeps as f64);
                self.cached = Some((interval, substeps, step));
                (substeps, step)
            }
        };
        let mut f0 = -a0;
        for j in 1..=substeps {
            let f1 = if j == substeps {
                -a1
            } else {
                -(a0 + (a1 - a0) * j as f64 / substeps as f64)
            };
            (self.u, self.v) = step.advance(self.u, self.v, f0, f1);
            self.peak = self.peak.max(self.u.abs());
            f0 = f1;
        }
    }

    /// One damped period of free vibration after the signal.
    fn free_vibration(&mut self) {
        let omega_d = self.omega * (1.0 - self.xi * self.xi).sqrt();
        let period = std::f64::consts::TAU / omega_d;
        let step = Step::new(self.omega, self.xi, period / STEPS_PER_PERIOD);
        for _ in 0..STEPS_PER_PERIOD as usize {
            (self.u, self.v) = step.advance(self.u, self.v, 0.0, 0.0);
            self.peak = self.peak.max(self.u.abs());
        }
    }

    fn pseudo_acceleration(&self) -> f64 {
        self.omega * self.omega * self.peak
    }
}

fn check_frequencies_and_damping(frequencies: &[f64], damping: f64) -> Result<(), ResponseSpectrumError> {
    if !(damping.is_finite() && (0.0..1.0).contains(&damping)) {
        return Err(ResponseSpectrumError::InvalidDamping(damping));
    }
    match frequencies.iter().position(|f| !(f.is_finite() && *f > 0.0)) {
        Some(index) => Err(ResponseSpectrumError::InvalidFrequency {
            index,
            value: frequencies[index],
        }),
        None => Ok(()),
    }
}

fn check_samples(values: &[f64]) -> Result<(), ResponseSpectrumError> {
    if values.len() < 2 {
        return Err(ResponseSpectrumError::TooShort(values.len()));
    }
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(ResponseSpectrumError::NonFinite {
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// PSA(f, ξ) at each of `frequencies` (Hz) of a signal given as a table (times in s,
/// linear between samples, 0 after the last; the oscillator is at rest at the first).
pub fn pseudo_acceleration(
    signal: &Table,
    frequencies: &[f64],
    damping: f64,
) -> Result<ResponseSpectrum, ResponseSpectrumError> {
    check_frequencies_and_damping(frequencies, damping)?;
    let (times, values) = (&signal.time, &signal.values);
    if times.len() != values.len() {
        return Err(ResponseSpectrumError::LengthMismatch {
            times: times.len(),
            values: values.len(),
        });
    }
    check_samples(values)?;
    for (index, pair) in times.windows(2).enumerate() {
        if !(pair[0].is_finite() && pair[1].is_finite() && pair[1] > pair[0]) {
            return Err(ResponseSpectrumError::NotIncreasing {
                index: index + 1,
                value: pair[1],
            });
        }
    }
    let pseudo_acceleration = frequencies
        .iter()
        .map(|&f| {
            let mut oscillator = Oscillator::new(f, damping);
            for k in 1..times.len() {
                oscillator.interval(times[k] - times[k - 1], values[k - 1], values[k]);
            }
            oscillator.free_vibration();
            oscillator.pseudo_acceleration()
        })
        .collect();
    Ok(ResponseSpectrum {
        damping,
        frequencies: frequencies.to_vec(),
        pseudo_acceleration,
    })
}

/// PSA(f, ξ) of a record sampled every `interval` (s) from t = 0: the same as
/// [`pseudo_acceleration`] on the table of times k·`interval`, without building it.
pub fn pseudo_acceleration_uniform(
    samples: &[f64],
    interval: f64,
    frequencies: &[f64],
    damping: f64,
) -> Result<ResponseSpectrum, ResponseSpectrumError> {
    check_frequencies_and_damping(frequencies, damping)?;
    check_samples(samples)?;
    if !(interval.is_finite() && interval > 0.0) {
        return Err(ResponseSpectrumError::InvalidSampleInterval(interval));
    }
    let pseudo_acceleration = frequencies
        .iter()
        .map(|&f| {
            let mut oscillator = Oscillator::new(f, damping);
            for pair in samples.windows(2) {
                oscillator.interval(interval, pair[0], pair[1]);
            }
            oscillator.free_vibration();
            oscillator.pseudo_acceleration()
        })
        .collect();
    Ok(ResponseSpectrum {
        damping,
        frequencies: frequencies.to_vec(),
        pseudo_acceleration,
    })
}

#[cfg(test)]
mod tests;
