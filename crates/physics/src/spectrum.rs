//! Power spectra of uniformly sampled signals and the spectral error function f_err
//! of the paper (eq. 11, BRIEF §6), used to compare a numerical tip history with the
//! reference.
//!
//! Γ is the one-sided periodogram with a rectangular window after removing the mean:
//! Γ(f_k) = c_k Δt/n |Σⱼ (xⱼ − x̄) e^{−2πi jk/n}|², f_k = k/(nΔt), k = 0..=⌊n/2⌋,
//! c_k = 2 except at f = 0 and at the Nyquist bin of an even n (c_k = 1), so that
//! Σ Γ Δf equals the variance of the signal (Parseval).
//! f_err(a, b) = max_f |Γ_a − Γ_b| / max(max_f Γ_a, max_f Γ_b).

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

/// Why a spectrum could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectrumError {
    /// Fewer than two samples: no frequency content.
    #[error("a signal needs at least 2 samples, got {0}")]
    TooShort(usize),
    /// The two signals are not on the same grid.
    #[error("signals have different lengths: {0} and {1}")]
    LengthMismatch(usize, usize),
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite ({value})")]
    NonFinite { index: usize, value: f64 },
    /// The sample interval is not a finite positive number.
    #[error("sample interval must be finite and > 0 s, got {0}")]
    InvalidSampleInterval(f64),
}

/// A one-sided power spectral density.
#[derive(Debug, Clone, PartialEq)]
pub struct Periodogram {
    /// Bin frequencies f_k = k/(nΔt) (Hz), k = 0..=⌊n/2⌋.
    pub frequencies: Vec<f64>,
    /// Γ(f_k) (signal unit² / Hz).
    pub power_density: Vec<f64>,
}

fn check_finite(signal: &[f64]) -> Result<(), SpectrumError> {
    if signal.len() < 2 {
        return Err(SpectrumError::TooShort(signal.len()));
    }
    match signal.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(SpectrumError::NonFinite {
            index,
            value: signal[index],
        }),
        None => Ok(()),
    }
}

/// |DFT|² of the mean-removed signal divided by `scale`², one-sided, with the
/// one-sided factor c_k applied (no Δt/n factor).
fn one_sided_power(signal: &[f64], scale: f64) -> Vec<f64> {
    let n = signal.len();
    let mean = signal.iter().sum::<f64>() / n as f64;
    let mut buffer: Vec<Complex<f64>> = signal
        .iter()
        .map(|x| Complex::new((x - mean) / scale, 0.0))
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buffer);
    let half = n / 2;
    buffer[..=half]
        .iter()
        .enumerate()
        .map(|(k, z)| {
            let doubled = k != 0 && !(n.is_multiple_of(2) && k == half);
            z.norm_sqr() * if doubled { 2.0 } else { 1.0 }
        })
        .collect()
}

/// Largest |x − x̄| of a signal (0 for a constant one).
fn centered_peak(signal: &[f64]) -> f64 {
    let mean = signal.iter().sum::<f64>() / signal.len() as f64;
    signal.iter().fold(0.0, |peak, x| peak.max((x - mean).abs()))
}

/// One-sided periodogram Γ of `signal` sampled every `sample_interval` Δt (s).
pub fn periodogram(signal: &[f64], sample_interval: f64) -> Result<Periodogram, SpectrumError> {
    check_finite(signal)?;
    if !(sample_interval.is_finite() && sample_interval > 0.0) {
        return Err(SpectrumError::InvalidSampleInterval(sample_interval));
    }
    let n = signal.len();
    // Normalizing by the peak keeps |DFT|² far from overflow for any finite input.
    let peak = centered_peak(signal);
    let scale = if peak > 0.0 { peak } else { 1.0 };
    let factor = sample_interval / n as f64 * scale * scale;
    let power_density = one_sided_power(signal, scale)
        .into_iter()
        .map(|p| p * factor)
        .collect();
    let frequencies = (0..=n / 2)
        .map(|k| k as f64 / (n as f64 * sample_interval))
        .collect();
    Ok(Periodogram {
        frequencies,
        power_density,
    })
}

/// f_err(a, b) = max_f |Γ_a − Γ_b| / max(max_f Γ_a, max_f Γ_b) for two signals on the
/// same uniform grid (dimensionless, in [0, 1]; the paper calls signals identical below
/// 0.2). The sample interval cancels out of the ratio. Two signals without any
/// fluctuation (constant or zero) give 0; one flat and one fluctuating signal give 1.
pub fn spectral_error(a: &[f64], b: &[f64]) -> Result<f64, SpectrumError> {
    if a.len() != b.len() {
        return Err(SpectrumError::LengthMismatch(a.len(), b.len()));
    }
    check_finite(a)?;
    check_finite(b)?;
    // A common scale preserves the ratio and avoids overflow of |DFT|².
    let scale = centered_peak(a).max(centered_peak(b));
    if scale == 0.0 {
        return Ok(0.0);
    }
    let (power_a, power_b) = (one_sided_power(a, scale), one_sided_power(b, scale));
    let peak = |power: &[f64]| power.iter().fold(0.0_f64, |m, &p| m.max(p));
    let denominator = peak(&power_a).max(peak(&power_b));
    if denominator <= 0.0 {
        return Ok(0.0);
    }
    let largest_difference = power_a
        .iter()
        .zip(&power_b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    Ok(largest_difference / denominator)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn sine(frequency: f64, amplitude: f64, count: usize, interval: f64) -> Vec<f64> {
        (0..count)
            .map(|k| amplitude * (2.0 * PI * frequency * k as f64 * interval).sin())
            .collect()
    }

    // Parseval: the one-sided PSD integrates to the variance of the signal; for a
    // sine of amplitude A on whole periods the variance is A²/2 and all the power sits
    // in the bin of its frequency.
    #[test]
    fn periodogram_satisfies_parseval_and_finds_the_tone() {
        let (count, interval, frequency, amplitude) = (1000, 1e-3, 50.0, 3.0);
        let signal: Vec<f64> = sine(frequency, amplitude, count, interval)
            .iter()
            .map(|x| x + 7.0)
            .collect();
        let spectrum = periodogram(&signal, interval).unwrap_or_else(|e| panic!("{e}"));
        let resolution = 1.0 / (count as f64 * interval);
        let integrated: f64 = spectrum.power_density.iter().sum::<f64>() * resolution;
        let expected = amplitude * amplitude / 2.0;
        assert!(
            (integrated - expected).abs() < 1e-9 * expected,
            "∫Γ df = {integrated}, expected variance {expected}"
        );
        let peak_bin = spectrum
            .power_density
            .iter()
            .enumerate()
            .max_by(|x, y| x.1.total_cmp(y.1))
            .map_or(0, |(k, _)| k);
        let measured = spectrum.frequencies[peak_bin];
        assert!(
            (measured - frequency).abs() < 1e-9,
            "peak at {measured} Hz, expected {frequency} Hz"
        );
    }

    // f_err is a distance between spectra: zero for identical signals, symmetric, and
    // ~1 for tones at different frequencies (their spectra do not overlap).
    #[test]
    fn spectral_error_is_a_symmetric_distance() {
        let a = sine(50.0, 1.0, 2000, 1e-3);
        let b = sine(120.0, 1.0, 2000, 1e-3);
        let same = spectral_error(&a, &a).unwrap_or(f64::NAN);
        assert!(same == 0.0, "f_err(a, a) = {same}, expected 0");
        let ab = spectral_error(&a, &b).unwrap_or(f64::NAN);
        let ba = spectral_error(&b, &a).unwrap_or(f64::NAN);
        assert!(
            (ab - 1.0).abs() < 1e-9,
            "f_err(sine 50 Hz, sine 120 Hz) = {ab}, expected 1"
        );
        assert!(ab == ba, "f_err not symmetric: {ab} vs {ba}");
    }

    // A small amplitude change of the same tone gives a proportional error:
    // Γ ∝ A², so (1 − 0.99²) for a 1 % smaller amplitude.
    #[test]
    fn spectral_error_scales_with_power_difference() {
        let a = sine(50.0, 1.0, 2000, 1e-3);
        let b = sine(50.0, 0.99, 2000, 1e-3);
        let measured = spectral_error(&a, &b).unwrap_or(f64::NAN);
        let expected = 1.0 - 0.99 * 0.99;
        assert!(
            (measured - expected).abs() < 1e-9,
            "measured {measured}, expected {expected}"
        );
    }

    // Flat signals carry no power: f_err must stay finite (0 between two flat
    // signals, 1 between a flat and a fluctuating one), never NaN.
    #[test]
    fn zero_signals_do_not_produce_nan() {
        let zero = vec![0.0; 64];
        let constant = vec![2.5; 64];
        let tone = sine(5.0, 1.0, 64, 1.0 / 64.0);
        assert_eq!(spectral_error(&zero, &constant), Ok(0.0));
        assert_eq!(spectral_error(&zero, &tone), Ok(1.0));
        let flat = periodogram(&zero, 0.1).unwrap_or_else(|e| panic!("{e}"));
        assert!(flat.power_density.iter().all(|p| *p == 0.0));
    }

    // Bad inputs are typed errors, not panics or NaN.
    #[test]
    fn bad_inputs_are_rejected() {
        assert_eq!(
            spectral_error(&[1.0, 2.0], &[1.0]),
            Err(SpectrumError::LengthMismatch(2, 1))
        );
        assert_eq!(spectral_error(&[1.0], &[1.0]), Err(SpectrumError::TooShort(1)));
        assert!(matches!(
            spectral_error(&[1.0, f64::NAN], &[1.0, 2.0]),
            Err(SpectrumError::NonFinite { index: 1, .. })
        ));
        assert_eq!(
            periodogram(&[1.0, 2.0], 0.0),
            Err(SpectrumError::InvalidSampleInterval(0.0))
        );
        let huge = [1e300, -1e300, 1e300, -1e300];
        let measured = spectral_error(&huge, &huge.map(|x| x * 0.5)).unwrap_or(f64::NAN);
        assert!(
            (measured - 0.75).abs() < 1e-12,
            "huge signals: f_err = {measured}, expected 0.75"
        );
    }
}
