//! The acceleration of a sampled displacement history, for the response spectrum of a
//! point of the model (an in-structure or floor response spectrum: what an oscillator
//! mounted there would feel).
//!
//! A history gives the displacement x at times t₀ < t₁ < … ; the acceleration at each
//! interior sample is the second divided difference
//!   aₖ = 2 [ (xₖ₊₁ − xₖ)/h₊ − (xₖ − xₖ₋₁)/h₋ ] / (h₊ + h₋),  h₋ = tₖ − tₖ₋₁, h₊ = tₖ₊₁ − tₖ,
//! the second derivative of the parabola through the three samples: exact for a
//! quadratic x(t), and for a uniform step h it is (xₖ₊₁ − 2xₖ + xₖ₋₁)/h², which reads a
//! sine of angular frequency ω with the relative error (ωh)²/12 + O((ωh)⁴). The first and
//! last samples have no acceleration: the table holds t₁ … tₙ₋₂.

use crate::loads::Table;

/// Why a displacement history has no acceleration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AccelerationError {
    /// Fewer than four samples (an acceleration table needs two).
    #[error("a displacement history needs at least 4 samples for an acceleration, got {0}")]
    TooShort(usize),
    /// Times and displacements differ in length.
    #[error("{times} times but {values} displacements")]
    LengthMismatch { times: usize, values: usize },
    /// A time is not finite or not above the previous one.
    #[error("time {index} ({value} s) is not finite or not above the previous time")]
    NotIncreasing { index: usize, value: f64 },
    /// A displacement is NaN or infinite.
    #[error("displacement {index} is not finite ({value})")]
    NonFinite { index: usize, value: f64 },
}

/// The acceleration (m/s² for displacements in m, times in s) at the interior samples of
/// a displacement history, by second divided differences (module doc).
pub fn acceleration_of_displacement(time: &[f64], displacement: &[f64]) -> Result<Table, AccelerationError> {
    if time.len() != displacement.len() {
        return Err(AccelerationError::LengthMismatch {
            times: time.len(),
            values: displacement.len(),
        });
    }
    if time.len() < 4 {
        return Err(AccelerationError::TooShort(time.len()));
    }
    if let Some(index) = displacement.iter().position(|v| !v.is_finite()) {
        return Err(AccelerationError::NonFinite {
            index,
            value: displacement[index],
        });
    }
    for (index, pair) in time.windows(2).enumerate() {
        if !(pair[0].is_finite() && pair[1].is_finite() && pair[1] > pair[0]) {
            return Err(AccelerationError::NotIncreasing {
                index: index + 1,
                value: pair[1],
            });
        }
    }
    let values = (1..time.len() - 1)
        .map(|k| {
            let (before, after) = (time[k] - time[k - 1], time[k + 1] - time[k]);
            let slope_before = (displacement[k] - displacement[k - 1]) / before;
            let slope_after = (displacement[k + 1] - displacement[k]) / after;
            2.0 * (slope_after - slope_before) / (before + after)
        })
        .collect();
    Ok(Table {
        time: time[1..time.len() - 1].to_vec(),
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    // x = c₀ + c₁t + c₂t²/2 has the acceleration c₂ everywhere, and the parabola through
    // three samples is x itself: every value is c₂ up to rounding, on any grid.
    #[test]
    fn a_quadratic_has_its_constant_acceleration_on_an_uneven_grid() {
        let time = [0.0, 0.001, 0.0025, 0.003, 0.0052, 0.006];
        let x = |t: f64| 0.002 - 0.3 * t + 0.5 * 9.81 * t * t;
        let displacement: Vec<f64> = time.iter().map(|&t| x(t)).collect();
        let table = acceleration_of_displacement(&time, &displacement).unwrap();
        assert_eq!(table.time, time[1..5]);
        for (k, a) in table.values.iter().enumerate() {
            assert!(
                (a - 9.81).abs() < 1e-7,
                "sample {k}: measured {a} m/s², expected 9.81"
            );
        }
    }

    // x = X sin ωt sampled every h: the second difference is −(4/h²) sin²(ωh/2) x, that
    // is −ω²x (1 − (ωh)²/12 + …): the relative error of the textbook formula.
    #[test]
    fn a_sine_is_read_with_the_error_of_the_second_difference() {
        let (amplitude, frequency, h) = (1e-3, 50.0, 1e-4);
        let omega = 2.0 * PI * frequency;
        let time: Vec<f64> = (0..400).map(|k| k as f64 * h).collect();
        let displacement: Vec<f64> = time.iter().map(|t| amplitude * (omega * t).sin()).collect();
        let table = acceleration_of_displacement(&time, &displacement).unwrap();
        let factor = 4.0 / (h * h) * (omega * h / 2.0).sin().powi(2);
        let relative = 1.0 - factor / (omega * omega);
        let expected_relative = (omega * h).powi(2) / 12.0;
        assert!(
            (relative - expected_relative).abs() < 1e-3 * expected_relative,
            "measured relative error {relative}, expected (ωh)²/12 = {expected_relative}"
        );
        for (t, a) in table.time.iter().zip(&table.values) {
            let exact = -factor * amplitude * (omega * t).sin();
            assert!(
                (a - exact).abs() < 1e-6 * factor * amplitude,
                "t = {t}: measured {a}, expected {exact}"
            );
        }
    }

    #[test]
    fn bad_histories_are_refused_at_their_sample() {
        assert_eq!(
            acceleration_of_displacement(&[0.0, 1.0, 2.0], &[0.0, 1.0, 2.0]),
            Err(AccelerationError::TooShort(3))
        );
        assert_eq!(
            acceleration_of_displacement(&[0.0, 1.0, 1.0, 2.0], &[0.0; 4]),
            Err(AccelerationError::NotIncreasing { index: 2, value: 1.0 })
        );
        assert!(matches!(
            acceleration_of_displacement(&[0.0, 1.0, 2.0, 3.0], &[0.0, f64::NAN, 0.0, 0.0]),
            Err(AccelerationError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            acceleration_of_displacement(&[0.0, 1.0, 2.0, 3.0], &[0.0; 3]),
            Err(AccelerationError::LengthMismatch { .. })
        ));
    }
}
