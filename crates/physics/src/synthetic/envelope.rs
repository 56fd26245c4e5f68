//! The time envelope of a synthetic earthquake (Jennings, Housner & Tsai 1968): a
//! quadratic build-up, a plateau of strong motion, an exponential decay, here shifted so
//! that it reaches exactly 0 at the end of the record (the signal ends at rest, with no
//! jump to the table's 0 after its last sample).
//!
//!   e(t) = (t/t₁)²                                   0 ≤ t < t₁
//!   e(t) = 1                                         t₁ ≤ t ≤ t₂ = t₁ + S
//!   e(t) = (e^{−c(t−t₂)} − e^{−c(D−t₂)}) / (1 − e^{−c(D−t₂)})   t₂ < t ≤ D
//!
//! with D the duration, S the strong-motion duration, c = ln 20/(D − t₂) (the plain
//! exponential would have fallen to 5 % at D).

use crate::portable;

/// A Jennings-type envelope over [0, D].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// Build-up time t₁ (s).
    pub rise: f64,
    /// Plateau length S (s).
    pub strong_motion: f64,
    /// Record length D (s).
    pub duration: f64,
}

impl Envelope {
    /// e(t), dimensionless in [0, 1].
    pub fn at(&self, t: f64) -> f64 {
        let plateau_end = self.rise + self.strong_motion;
        if t <= 0.0 || t >= self.duration {
            0.0
        } else if t < self.rise {
            let s = t / self.rise;
            s * s
        } else if t <= plateau_end {
            1.0
        } else {
            let tail = self.duration - plateau_end;
            let rate = portable::ln(20.0) / tail;
            let floor = portable::exp(-rate * tail);
            ((portable::exp(-rate * (t - plateau_end)) - floor) / (1.0 - floor)).max(0.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builds_up_holds_and_decays_to_zero_at_the_end() {
        let envelope = Envelope {
            rise: 2.0,
            strong_motion: 8.0,
            duration: 20.0,
        };
        assert_eq!(envelope.at(0.0), 0.0);
        assert!((envelope.at(1.0) - 0.25).abs() < 1e-15);
        assert_eq!(envelope.at(2.0), 1.0);
        assert_eq!(envelope.at(10.0), 1.0);
        assert_eq!(envelope.at(20.0), 0.0);
        // Halfway down the tail the plain exponential is at 1/√20; shifted and rescaled:
        let expected = (1.0 / 20f64.sqrt() - 0.05) / 0.95;
        assert!(
            (envelope.at(15.0) - expected).abs() < 1e-14,
            "e(15) = {}",
            envelope.at(15.0)
        );
        let mut previous = 1.0;
        for k in 0..=100 {
            let value = envelope.at(10.0 + 0.1 * k as f64);
            assert!(value <= previous, "not decaying at {}", 10.0 + 0.1 * k as f64);
            previous = value;
        }
    }
}
