//! Response spectra against textbook results: the steady-state resonance of a sine, the
//! dynamic amplification 2 of a step, and the closed-form shock response spectrum of a
//! half-sine pulse (primary and residual, undamped).

use super::*;
use std::f64::consts::PI;

fn relative_error(measured: f64, expected: f64) -> f64 {
    (measured - expected).abs() / expected.abs()
}

// A sine a(t) = A sin(2π f₀ t) held long enough for the transient to die out (≫ 1/(ξω))
// drives an oscillator tuned to f₀ to the steady amplitude A/(2ξω²): PSA(f₀) = A/(2ξ).
// Over frequency, PSA(f)/A = 1/√((1 − f₀²/f²)² + 4ξ²f₀²/f²), largest at
// f = f₀/√(1 − 2ξ²) (within ξ² of f₀), where it is 1/(2ξ√(1 − ξ²)).
#[test]
fn a_long_sine_peaks_at_its_frequency_with_amplification_one_over_two_xi() {
    let (amplitude, f0) = (3.0, 5.0);
    for damping in [0.02, 0.05, 0.1] {
        let duration = 12.0 / (damping * 2.0 * PI * f0) + 2.0;
        let signal = Table::sample(|t| amplitude * (2.0 * PI * f0 * t).sin(), 0.002, duration);
        let at_f0 = pseudo_acceleration(&signal, &[f0], damping).unwrap_or_else(|e| panic!("{e}"));
        let measured = at_f0.pseudo_acceleration[0] / amplitude;
        let expected = 1.0 / (2.0 * damping);
        assert!(
            relative_error(measured, expected) < 0.005,
            "ξ = {damping}: PSA(f₀)/A = {measured}, expected 1/(2ξ) = {expected}"
        );

        let grid = log_spaced(1.0, 25.0, 281);
        let spectrum = pseudo_acceleration(&signal, &grid, damping).unwrap_or_else(|e| panic!("{e}"));
        let (peak_index, peak) = spectrum
            .pseudo_acceleration
            .iter()
            .enumerate()
            .fold((0, 0.0), |best, (k, &p)| if p > best.1 { (k, p) } else { best });
        let ratio = grid[1] / grid[0];
        let peak_frequency = grid[peak_index];
        assert!(
            (peak_frequency / f0).ln().abs() <= ratio.ln() / 2.0 + damping * damping,
            "ξ = {damping}: peak at {peak_frequency} Hz, expected {f0} Hz (grid ratio {ratio})"
        );
        let steady = 1.0 / (2.0 * damping * (1.0 - damping * damping).sqrt());
        assert!(
            relative_error(peak / amplitude, steady) < 0.01,
            "ξ = {damping}: peak PSA/A = {}, expected {steady}",
            peak / amplitude
        );
    }
}

// A suddenly applied constant acceleration A moves an undamped oscillator between 0 and
// −2A/ω²: PSA = 2A at every frequency (the dynamic amplification factor of a step).
#[test]
fn a_step_is_amplified_twice_without_damping() {
    let signal = Table {
        time: vec![0.0, 10.0],
        values: vec![4.0, 4.0],
    };
    let spectrum = pseudo_acceleration(&signal, &[0.7, 3.0, 50.0], 0.0).unwrap_or_else(|e| panic!("{e}"));
    for (f, psa) in spectrum.frequencies.iter().zip(&spectrum.pseudo_acceleration) {
        assert!(
            relative_error(*psa, 8.0) < 2e-3,
            "f = {f} Hz: PSA = {psa}, expected 2A = 8"
        );
    }
}

/// The undamped shock response spectrum of a half-sine pulse A sin(πt/T) over [0, T],
/// as a multiple of A, at oscillator frequency f (Chopra, Dynamics of Structures §4.8;
/// Harris' Shock and Vibration Handbook ch. 8). With β = Ω/ω = 1/(2fT) (Ω = π/T), the
/// forced response is u ∝ (sin Ωt − β sin ωt)/(1 − β²):
/// - primary (during the pulse), extrema where cos Ωt = cos ωt: at t = 2πl/(ω + Ω),
///   l = 1, 2, … while t ≤ T, the value sin(2πlβ/(1 + β))/(1 − β); at t = 2πl/(ω − Ω)
///   (β < 1) the value sin(2πl/(1 − β)·β)/(1 + β);
/// - residual (free vibration after T): 2β|cos(π/(2β))|/|1 − β²|.
///
/// The spectrum is the larger of the two.
fn half_sine_shock_response(f: f64, duration: f64) -> f64 {
    let beta = 1.0 / (2.0 * f * duration);
    let residual = 2.0 * beta * (PI / (2.0 * beta)).cos().abs() / (1.0 - beta * beta).abs();
    let mut primary: f64 = 0.0;
    if beta < 1.0 {
        let mut l = 1.0;
        while l <= (1.0 + beta) / (2.0 * beta) {
            primary = primary.max((2.0 * PI * l * beta / (1.0 + beta)).sin().abs() / (1.0 - beta));
            l += 1.0;
        }
        let mut l = 1.0;
        while l <= (1.0 - beta) / (2.0 * beta) {
            primary = primary.max((2.0 * PI * l * beta / (1.0 - beta)).sin().abs() / (1.0 + beta));
            l += 1.0;
        }
    }
    primary.max(residual)
}

#[test]
fn a_half_sine_pulse_has_the_textbook_shock_response_spectrum() {
    let (amplitude, duration) = (50.0, 0.011);
    let signal = Table::sample(
        |t| amplitude * (PI * t / duration).sin(),
        duration / 2000.0,
        duration,
    );
    // fT from 0.05 to 20: deep in the residual régime (β ≫ 1, PSA ≈ 4fT A) through the
    // peak near fT ≈ 0.8 (PSA ≈ 1.77 A) to the quasi-static end (PSA → A).
    let grid = log_spaced(0.05 / duration, 20.0 / duration, 120);
    let spectrum = pseudo_acceleration(&signal, &grid, 0.0).unwrap_or_else(|e| panic!("{e}"));
    let mut worst: f64 = 0.0;
    for (f, psa) in grid.iter().zip(&spectrum.pseudo_acceleration) {
        let expected = half_sine_shock_response(*f, duration);
        let error = relative_error(psa / amplitude, expected);
        worst = worst.max(error);
        assert!(
            error < 3e-3,
            "f T = {:.4}: PSA/A = {}, expected {expected}",
            f * duration,
            psa / amplitude
        );
    }
    // The known landmarks of the curve: the maximum ≈ 1.77 near fT ≈ 0.8.
    let peak = spectrum
        .pseudo_acceleration
        .iter()
        .fold(0.0_f64, |m, p| m.max(*p))
        / amplitude;
    assert!(
        (1.75..1.78).contains(&peak),
        "peak PSA/A = {peak}, expected ≈ 1.77 (worst relative error {worst})"
    );
}

// The uniform-record entry is the table entry on the grid k·Δt.
#[test]
fn a_uniform_record_gives_the_spectrum_of_its_table() {
    let samples: Vec<f64> = (0..500)
        .map(|k| (k as f64 * 0.37).sin() * (k as f64 * 0.011).cos())
        .collect();
    let table = Table {
        time: (0..500).map(|k| k as f64 * 0.01).collect(),
        values: samples.clone(),
    };
    let grid = log_spaced(0.5, 40.0, 30);
    let from_table = pseudo_acceleration(&table, &grid, 0.05).unwrap_or_else(|e| panic!("{e}"));
    let uniform = pseudo_acceleration_uniform(&samples, 0.01, &grid, 0.05).unwrap_or_else(|e| panic!("{e}"));
    for (a, b) in from_table
        .pseudo_acceleration
        .iter()
        .zip(&uniform.pseudo_acceleration)
    {
        assert!(relative_error(*a, *b) < 1e-9, "table {a} vs uniform {b}");
    }
}

#[test]
fn log_spaced_frequencies_keep_a_constant_ratio_and_exact_ends() {
    let grid = log_spaced(0.1, 100.0, 31);
    assert_eq!(grid[0], 0.1);
    assert_eq!(grid[30], 100.0);
    assert!((grid[10] - 1.0).abs() < 1e-14, "grid[10] = {}", grid[10]);
    assert!((grid[20] - 10.0).abs() < 1e-13, "grid[20] = {}", grid[20]);
}

#[test]
fn bad_inputs_are_typed_errors() {
    let good = Table {
        time: vec![0.0, 0.1],
        values: vec![0.0, 1.0],
    };
    assert_eq!(
        pseudo_acceleration(&good, &[1.0], 1.0),
        Err(ResponseSpectrumError::InvalidDamping(1.0))
    );
    assert!(matches!(
        pseudo_acceleration(&good, &[1.0, -2.0], 0.05),
        Err(ResponseSpectrumError::InvalidFrequency { index: 1, .. })
    ));
    let backwards = Table {
        time: vec![0.0, 0.1, 0.1],
        values: vec![0.0, 1.0, 2.0],
    };
    assert!(matches!(
        pseudo_acceleration(&backwards, &[1.0], 0.05),
        Err(ResponseSpectrumError::NotIncreasing { index: 2, .. })
    ));
    let nan = Table {
        time: vec![0.0, 0.1],
        values: vec![0.0, f64::NAN],
    };
    assert!(matches!(
        pseudo_acceleration(&nan, &[1.0], 0.05),
        Err(ResponseSpectrumError::NonFinite { index: 1, .. })
    ));
    assert_eq!(
        pseudo_acceleration_uniform(&[0.0, 1.0], 0.0, &[1.0], 0.05),
        Err(ResponseSpectrumError::InvalidSampleInterval(0.0))
    );
}
