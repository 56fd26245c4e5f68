//! What an engineer reads first off an accelerogram: its sampling, its peak ground
//! acceleration and its Arias intensity.
//!
//! The record is a [`Table`] (times in s, accelerations in m/s², linear between samples,
//! 0 outside them): every figure here is exact for that piecewise-linear signal.
//!
//! - PGA = maxₖ |aₖ| (m/s²): the largest sample, since a linear segment peaks at an end.
//! - Arias intensity I_A = π/(2g) ∫ a² dt (m/s), g = 9.80665 m/s² (standard gravity).
//!   Over one segment of length h from a₀ to a₁ the integral is exactly
//!   h (a₀² + a₀a₁ + a₁²)/3. For a sine of amplitude A over whole periods, ∫ a² dt = A² T/2
//!   (T the record's length); the sampled record's value is within (ωh)²/6 of it
//!   (relative), from the linear interpolation between samples.
//!   The squares are taken of a/PGA (at most 1 in size) and the sum scaled back by PGA²
//!   at the end: accelerations up to the largest finite number never overflow in the
//!   sum, and the intensity is infinite only when its true value is beyond `f64::MAX`.

use crate::loads::Table;

/// Standard gravity g (m/s²), the g of the Arias intensity.
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// Relative spread of the sample intervals under which a record counts as uniformly
/// sampled (times written as decimals, k·Δt rounded, differ by about this much).
pub const UNIFORM_TOLERANCE: f64 = 1e-6;

/// The summary figures of a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordSummary {
    /// Number of samples.
    pub samples: usize,
    /// Time of the first sample (s).
    pub start: f64,
    /// Last time minus first time (s).
    pub duration: f64,
    /// Mean sample interval (s): duration / (samples − 1).
    pub sampling_interval: f64,
    /// Shortest and longest sample intervals (s).
    pub shortest_interval: f64,
    pub longest_interval: f64,
    /// Whether every interval is within [`UNIFORM_TOLERANCE`] (relative) of the mean.
    pub uniform: bool,
    /// Peak ground acceleration max |a| (m/s²).
    pub pga: f64,
    /// Time of the first sample reaching it (s).
    pub pga_time: f64,
    /// Arias intensity π/(2g) ∫ a² dt (m/s).
    pub arias_intensity: f64,
}

impl RecordSummary {
    /// The summary of a record of at least two samples with strictly increasing times
    /// (a checked record; `None` otherwise).
    pub fn of(record: &Table) -> Option<Self> {
        let (time, values) = (&record.time, &record.values);
        if time.len() < 2 || time.len() != values.len() {
            return None;
        }
        let (mut pga, mut pga_time) = (0.0f64, time[0]);
        for (t, a) in time.iter().zip(values) {
            if a.abs() > pga {
                pga = a.abs();
                pga_time = *t;
            }
        }
        // ∫ (a/PGA)² dt: each scaled sample is at most 1 in size, so no square overflows.
        let scale = if pga > 0.0 { pga } else { 1.0 };
        let (mut shortest, mut longest) = (f64::INFINITY, 0.0f64);
        let mut scaled_square_integral = 0.0;
        for k in 1..time.len() {
            let h = time[k] - time[k - 1];
            if h.is_nan() || h <= 0.0 {
                return None;
            }
            shortest = shortest.min(h);
            longest = longest.max(h);
            let (a0, a1) = (values[k - 1] / scale, values[k] / scale);
            scaled_square_integral += h * (a0 * a0 + a0 * a1 + a1 * a1) / 3.0;
        }
        // π/(2g) · PGA² · ∫ (a/PGA)² dt, multiplied in the order that overflows last.
        let arias_intensity =
            std::f64::consts::PI / (2.0 * STANDARD_GRAVITY) * scaled_square_integral * scale * scale;
        let duration = time[time.len() - 1] - time[0];
        let mean = duration / (time.len() - 1) as f64;
        Some(Self {
            samples: time.len(),
            start: time[0],
            duration,
            sampling_interval: mean,
            shortest_interval: shortest,
            longest_interval: longest,
            uniform: (longest - shortest) <= UNIFORM_TOLERANCE * mean,
            pga,
            pga_time,
            arias_intensity,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(amplitude: f64, frequency: f64, periods: usize, per_period: usize) -> Table {
        let interval = 1.0 / (frequency * per_period as f64);
        let samples = periods * per_period + 1;
        Table {
            time: (0..samples).map(|k| k as f64 * interval).collect(),
            values: (0..samples)
                .map(|k| amplitude * (std::f64::consts::TAU * k as f64 / per_period as f64).sin())
                .collect(),
        }
    }

    /// A sine of amplitude A over whole periods T: PGA = A (a sample sits on each crest
    /// when the samples per period are a multiple of 4) and ∫a² dt = A² T/2, so
    /// I_A = π A² T/(4g), within the interpolation error (ωh)²/6.
    #[test]
    fn a_sine_has_its_amplitude_as_pga_and_the_textbook_arias_intensity() {
        let (amplitude, frequency, periods, per_period) = (3.0, 2.0, 10, 400);
        let summary = RecordSummary::of(&sine(amplitude, frequency, periods, per_period)).unwrap();
        let length = periods as f64 / frequency;
        assert_eq!(summary.samples, periods * per_period + 1);
        assert!(
            (summary.duration - length).abs() < 1e-12,
            "duration {}",
            summary.duration
        );
        assert!(summary.uniform);
        assert!(
            (summary.pga - amplitude).abs() < 1e-12 * amplitude,
            "PGA measured {} vs expected {amplitude}",
            summary.pga
        );
        let expected = std::f64::consts::PI * amplitude * amplitude * length / (4.0 * STANDARD_GRAVITY);
        let omega_h = std::f64::consts::TAU / per_period as f64;
        let bound = omega_h * omega_h / 6.0;
        let relative = (summary.arias_intensity - expected).abs() / expected;
        assert!(
            relative < bound,
            "Arias measured {} vs expected {expected} (relative {relative:e}, bound {bound:e})",
            summary.arias_intensity
        );
    }

    /// Accelerations of 1e154 m/s² square to 1e308, at the edge of `f64`: a constant
    /// record of that size over 2 s still has its exact intensity π A² T/(2g) (finite,
    /// about 1.6e307 m/s), and one whose true intensity is beyond `f64::MAX` is infinite
    /// (never NaN).
    #[test]
    fn huge_accelerations_do_not_overflow_the_arias_intensity() {
        let amplitude = 1e154;
        let record = Table {
            time: vec![0.0, 1.0, 2.0],
            values: vec![amplitude, -amplitude, amplitude],
        };
        let summary = RecordSummary::of(&record).unwrap();
        // Two segments from A to −A: each ∫a² = h (A² − A² + A²)/3 = A²/3.
        let expected = std::f64::consts::PI / (2.0 * STANDARD_GRAVITY) * (2.0 / 3.0) * amplitude * amplitude;
        assert!(expected.is_finite());
        let relative = (summary.arias_intensity - expected).abs() / expected;
        assert!(
            relative < 1e-14,
            "Arias measured {:e} vs expected {expected:e}",
            summary.arias_intensity
        );
        let beyond = Table {
            time: vec![0.0, 1e6],
            values: vec![1e307, 1e307],
        };
        let summary = RecordSummary::of(&beyond).unwrap();
        assert_eq!(summary.arias_intensity, f64::INFINITY, "{summary:?}");
        assert_eq!(summary.pga, 1e307);
    }

    /// On a linear segment the square integral is exact: a ramp 0 → A over h gives A²h/3.
    #[test]
    fn a_ramp_has_the_exact_square_integral() {
        let record = Table {
            time: vec![1.0, 3.0],
            values: vec![0.0, -6.0],
        };
        let summary = RecordSummary::of(&record).unwrap();
        let expected = std::f64::consts::PI / (2.0 * STANDARD_GRAVITY) * 36.0 * 2.0 / 3.0;
        assert!((summary.arias_intensity - expected).abs() < 1e-14 * expected);
        assert_eq!((summary.pga, summary.pga_time, summary.start), (6.0, 3.0, 1.0));
    }

    #[test]
    fn uneven_intervals_are_not_uniform() {
        let record = Table {
            time: vec![0.0, 0.1, 0.3],
            values: vec![0.0, 1.0, 0.0],
        };
        let summary = RecordSummary::of(&record).unwrap();
        assert!(!summary.uniform);
        assert_eq!(summary.shortest_interval, 0.1);
        assert!(
            (summary.longest_interval - 0.2).abs() < 1e-15,
            "{}",
            summary.longest_interval
        );
        assert!(
            RecordSummary::of(&Table {
                time: vec![0.0, 0.0],
                values: vec![1.0, 1.0]
            })
            .is_none()
        );
    }
}
