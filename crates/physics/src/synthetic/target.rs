//! The target of a spectrum-compatible accelerogram: a pseudo-acceleration response
//! spectrum given at increasing frequencies, straight between them on log–log axes (the
//! way design spectra are drawn and tabulated).

use crate::InputIssue;
use crate::portable;

/// A target pseudo-acceleration spectrum.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetSpectrum {
    /// Frequencies (Hz), positive and strictly increasing; the first and last bound the
    /// band over which a generated signal must match.
    pub frequencies: Vec<f64>,
    /// Pseudo-acceleration at each frequency (m/s²), positive.
    pub accelerations: Vec<f64>,
    /// Damping ratio ξ of the spectrum (dimensionless, in (0, 1); 0.05 in most codes).
    pub damping: f64,
}

impl TargetSpectrum {
    /// Lowest and highest frequency (Hz) of a validated target.
    pub fn band(&self) -> (f64, f64) {
        (self.frequencies[0], self.frequencies[self.frequencies.len() - 1])
    }

    /// PSA (m/s²) at `f` (Hz): log–log interpolation between the given points, the end
    /// values held outside the band.
    pub fn at(&self, f: f64) -> f64 {
        let (freqs, values) = (&self.frequencies, &self.accelerations);
        let last = freqs.len() - 1;
        if f <= freqs[0] {
            return values[0];
        }
        if f >= freqs[last] {
            return values[last];
        }
        let upper = freqs.partition_point(|&g| g <= f);
        let (f0, f1) = (freqs[upper - 1], freqs[upper]);
        let (a0, a1) = (values[upper - 1], values[upper]);
        let slope = portable::ln(a1 / a0) / portable::ln(f1 / f0);
        a0 * portable::powf(f / f0, slope)
    }

    /// Every problem, fields relative to the target object (`frequencies/3`).
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if self.frequencies.len() < 2 {
            issues.push(InputIssue::new(
                "frequencies",
                format!("needs at least 2 frequencies, got {}", self.frequencies.len()),
            ));
        }
        for (k, f) in self.frequencies.iter().enumerate() {
            let field = format!("frequencies/{k}");
            if !(f.is_finite() && *f > 0.0) {
                issues.push(InputIssue::new(
                    field,
                    format!("must be a positive number of Hz (got {f})"),
                ));
            } else if k > 0 && *f <= self.frequencies[k - 1] {
                issues.push(InputIssue::new(
                    field,
                    format!(
                        "frequencies must be strictly increasing: {f} Hz follows {} Hz",
                        self.frequencies[k - 1]
                    ),
                ));
            }
        }
        if self.accelerations.len() != self.frequencies.len() {
            issues.push(InputIssue::new(
                "accelerations",
                format!(
                    "needs one value per frequency ({}), got {}",
                    self.frequencies.len(),
                    self.accelerations.len()
                ),
            ));
        }
        for (k, a) in self.accelerations.iter().enumerate() {
            if !(a.is_finite() && *a > 0.0) {
                issues.push(InputIssue::new(
                    format!("accelerations/{k}"),
                    format!("must be a positive pseudo-acceleration in m/s² (got {a})"),
                ));
            }
        }
        if !(self.damping.is_finite() && self.damping > 0.0 && self.damping < 1.0) {
            issues.push(InputIssue::new(
                "damping",
                format!(
                    "must be a damping ratio between 0 and 1, both excluded (got {})",
                    self.damping
                ),
            ));
        }
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // A straight line on log–log axes: PSA ∝ f^s between two points, so the geometric
    // mean frequency gets the geometric mean value.
    #[test]
    fn interpolates_straight_on_log_log_axes() {
        let target = TargetSpectrum {
            frequencies: vec![1.0, 4.0, 10.0],
            accelerations: vec![2.0, 8.0, 8.0],
            damping: 0.05,
        };
        assert!(target.validate().is_empty());
        assert!(
            (target.at(2.0) - 4.0).abs() < 1e-13,
            "PSA(2 Hz) = {}",
            target.at(2.0)
        );
        assert!((target.at(6.0) - 8.0).abs() < 1e-13);
        assert_eq!(target.at(0.5), 2.0);
        assert_eq!(target.at(20.0), 8.0);
    }

    #[test]
    fn unsorted_frequencies_and_negative_values_name_their_index() {
        let target = TargetSpectrum {
            frequencies: vec![1.0, 5.0, 3.0],
            accelerations: vec![2.0, -1.0, 1.0],
            damping: 0.05,
        };
        let fields: Vec<String> = target.validate().into_iter().map(|i| i.field).collect();
        assert_eq!(fields, ["frequencies/2", "accelerations/1"]);
        let target = TargetSpectrum {
            frequencies: vec![1.0],
            accelerations: vec![2.0, 3.0],
            damping: 1.5,
        };
        let fields: Vec<String> = target.validate().into_iter().map(|i| i.field).collect();
        assert_eq!(fields, ["frequencies", "accelerations", "damping"]);
    }
}
