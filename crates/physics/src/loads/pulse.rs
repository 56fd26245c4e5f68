//! The classical transport and handling shock pulses besides the half-sine (MIL-STD-810
//! method 516, IEC 60068-2-27): haversine, terminal-peak sawtooth and trapezoid, each a
//! closed form of time that starts at t = 0 and is 0 after its end.
//!
//! | pulse | a(t) on its support | velocity change Δv = ∫a dt |
//! |---|---|---|
//! | haversine, duration T | A sin²(π t/T) = A (1 − cos 2πt/T)/2 | A T / 2 |
//! | terminal-peak sawtooth, duration T | A t/T (then drops to 0) | A T / 2 |
//! | trapezoid, rise r, plateau p, fall f | A t/r, then A, then A (r+p+f−t)/f | A (r/2 + p + f/2) |

use crate::{InputIssue, require_non_negative, require_positive};

/// A shock pulse a(t) (m/s²), zero before t = 0 and after its end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pulse {
    /// a(t) = amplitude · sin²(π t / duration) for 0 ≤ t ≤ duration: starts and ends with
    /// zero slope.
    Haversine { amplitude: f64, duration: f64 },
    /// a(t) = amplitude · t / duration for 0 ≤ t ≤ duration, then 0 at once.
    TerminalPeakSawtooth { amplitude: f64, duration: f64 },
    /// Linear rise to `amplitude` in `rise` (s), `plateau` (s) at it, linear fall to 0 in
    /// `fall` (s).
    Trapezoid {
        amplitude: f64,
        rise: f64,
        plateau: f64,
        fall: f64,
    },
}

impl Pulse {
    /// a(t) (m/s²).
    pub fn at(&self, t: f64) -> f64 {
        if !(t >= 0.0 && t <= self.duration()) {
            return 0.0;
        }
        match *self {
            Pulse::Haversine { amplitude, duration } => {
                let s = (std::f64::consts::PI * t / duration).sin();
                amplitude * s * s
            }
            Pulse::TerminalPeakSawtooth { amplitude, duration } => amplitude * t / duration,
            Pulse::Trapezoid {
                amplitude,
                rise,
                plateau,
                fall,
            } => {
                if t < rise {
                    amplitude * t / rise
                } else if t <= rise + plateau {
                    amplitude
                } else {
                    amplitude * (rise + plateau + fall - t) / fall
                }
            }
        }
    }

    /// Time from the start to the end of the pulse (s).
    pub fn duration(&self) -> f64 {
        match *self {
            Pulse::Haversine { duration, .. } | Pulse::TerminalPeakSawtooth { duration, .. } => duration,
            Pulse::Trapezoid {
                rise, plateau, fall, ..
            } => rise + plateau + fall,
        }
    }

    /// Δv = ∫ a dt over the pulse (m/s), the closed forms of the module table.
    pub fn velocity_change(&self) -> f64 {
        match *self {
            Pulse::Haversine { amplitude, duration }
            | Pulse::TerminalPeakSawtooth { amplitude, duration } => 0.5 * amplitude * duration,
            Pulse::Trapezoid {
                amplitude,
                rise,
                plateau,
                fall,
            } => amplitude * (0.5 * rise + plateau + 0.5 * fall),
        }
    }

    /// The period (s) a time step must resolve with its steps per period to follow the
    /// shape: the haversine's cosine period T; for the sawtooth the half-sine convention
    /// (a ramp of T is half a period 2T); for the trapezoid twice its shortest ramp (or
    /// twice its plateau when both ramps are steps).
    pub fn resolution_period(&self) -> f64 {
        match *self {
            Pulse::Haversine { duration, .. } => duration,
            Pulse::TerminalPeakSawtooth { duration, .. } => 2.0 * duration,
            Pulse::Trapezoid {
                rise, plateau, fall, ..
            } => {
                let shortest = [rise, fall, plateau]
                    .into_iter()
                    .filter(|d| *d > 0.0)
                    .fold(f64::INFINITY, f64::min);
                2.0 * shortest
            }
        }
    }

    /// Every problem (fields relative to the excitation object): a finite amplitude,
    /// positive durations; a trapezoid's ramps and plateau may be 0 (a step, a triangle)
    /// but not all three.
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        let amplitude = match *self {
            Pulse::Haversine { amplitude, duration }
            | Pulse::TerminalPeakSawtooth { amplitude, duration } => {
                require_positive(&mut issues, "duration", duration);
                amplitude
            }
            Pulse::Trapezoid {
                amplitude,
                rise,
                plateau,
                fall,
            } => {
                require_non_negative(&mut issues, "rise", rise);
                require_non_negative(&mut issues, "plateau", plateau);
                require_non_negative(&mut issues, "fall", fall);
                if issues.is_empty() && rise + plateau + fall <= 0.0 {
                    issues.push(InputIssue::new(
                        "plateau",
                        "rise + plateau + fall must be positive (got 0 s): the pulse has no duration",
                    ));
                }
                amplitude
            }
        };
        if !amplitude.is_finite() {
            issues.push(InputIssue::new("amplitude", "must be a finite number"));
        }
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ a dt by the trapezoidal rule on `intervals` equal intervals over [0, end]
    /// (exact for the piecewise-linear pulses when their corners fall on the grid).
    fn integral(pulse: &Pulse, end: f64, intervals: usize) -> f64 {
        let h = end / intervals as f64;
        let sum: f64 = (1..intervals).map(|k| pulse.at(k as f64 * h)).sum();
        h * (sum + 0.5 * (pulse.at(0.0) + pulse.at(end)))
    }

    // sin²(πt/T) is 1/2 at T/4 and 3T/4, 1 at T/2, 0 at the ends; its mean over the
    // pulse is 1/2, so Δv = A T / 2.
    #[test]
    fn haversine_takes_its_closed_form_values_and_velocity_change() {
        let pulse = Pulse::Haversine {
            amplitude: 150.0,
            duration: 0.006,
        };
        for (t, expected) in [
            (0.0, 0.0),
            (0.0015, 75.0),
            (0.003, 150.0),
            (0.0045, 75.0),
            (0.006, 0.0),
        ] {
            let measured = pulse.at(t);
            assert!(
                (measured - expected).abs() < 1e-12,
                "a({t}) = {measured}, expected {expected}"
            );
        }
        assert_eq!(pulse.at(-1e-9), 0.0);
        assert_eq!(pulse.at(0.0061), 0.0);
        // The trapezoidal rule is spectrally accurate for a smooth periodic integrand.
        let measured = integral(&pulse, 0.006, 64);
        let expected = 150.0 * 0.006 / 2.0;
        assert!(
            (measured - expected).abs() < 1e-12 * expected,
            "∫a dt = {measured}, expected A T/2 = {expected}"
        );
        assert_eq!(pulse.velocity_change(), expected);
    }

    #[test]
    fn terminal_peak_sawtooth_ramps_then_drops_and_gives_half_a_t() {
        let pulse = Pulse::TerminalPeakSawtooth {
            amplitude: 200.0,
            duration: 0.011,
        };
        assert!((pulse.at(0.0055) - 100.0).abs() < 1e-12);
        assert!((pulse.at(0.011) - 200.0).abs() < 1e-12);
        assert_eq!(pulse.at(0.011 * (1.0 + 1e-12)), 0.0);
        // The ramp's integral over [0, T] by the trapezoidal rule is exact.
        let measured = integral(&pulse, 0.011, 100);
        let expected = 200.0 * 0.011 / 2.0;
        assert!(
            (measured - expected).abs() < 1e-12 * expected,
            "∫a dt = {measured}, expected {expected}"
        );
        assert!((pulse.velocity_change() - expected).abs() < 1e-15);
    }

    // A trapezoid (2 ms rise, 6 ms plateau, 4 ms fall) of 300 m/s²: Δv = A(r/2 + p + f/2)
    // = 300 · (0.001 + 0.006 + 0.002) = 2.7 m/s.
    #[test]
    fn trapezoid_rises_holds_falls_and_gives_its_area() {
        let pulse = Pulse::Trapezoid {
            amplitude: 300.0,
            rise: 0.002,
            plateau: 0.006,
            fall: 0.004,
        };
        for (t, expected) in [
            (0.001, 150.0),
            (0.002, 300.0),
            (0.005, 300.0),
            (0.008, 300.0),
            (0.010, 150.0),
            (0.012, 0.0),
        ] {
            let measured = pulse.at(t);
            assert!(
                (measured - expected).abs() < 1e-9,
                "a({t}) = {measured}, expected {expected}"
            );
        }
        assert_eq!(pulse.at(0.0121), 0.0);
        assert!((pulse.duration() - 0.012).abs() < 1e-15);
        let measured = integral(&pulse, 0.012, 1200);
        assert!(
            (measured - 2.7).abs() < 1e-9,
            "∫a dt = {measured}, expected 2.7 m/s"
        );
        assert!((pulse.velocity_change() - 2.7).abs() < 1e-12);
        // A rectangle (no ramps) is allowed and resolved by its plateau.
        let rectangle = Pulse::Trapezoid {
            amplitude: 1.0,
            rise: 0.0,
            plateau: 0.01,
            fall: 0.0,
        };
        assert!(rectangle.validate().is_empty());
        assert_eq!(rectangle.at(0.0), 1.0);
        assert_eq!(rectangle.at(0.01), 1.0);
        assert!((rectangle.resolution_period() - 0.02).abs() < 1e-15);
    }

    #[test]
    fn bad_parameters_name_their_field_and_bound() {
        let issues = Pulse::Haversine {
            amplitude: f64::NAN,
            duration: 0.0,
        }
        .validate();
        let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
        assert_eq!(fields, ["duration", "amplitude"]);
        assert!(issues[0].reason.contains("positive"), "{}", issues[0].reason);
        let issues = Pulse::Trapezoid {
            amplitude: 1.0,
            rise: -0.001,
            plateau: 0.0,
            fall: 0.001,
        }
        .validate();
        assert_eq!(issues.len(), 1);
        assert_eq!(issues[0].field, "rise");
        assert!(issues[0].reason.contains("negative"), "{}", issues[0].reason);
        let issues = Pulse::Trapezoid {
            amplitude: 1.0,
            rise: 0.0,
            plateau: 0.0,
            fall: 0.0,
        }
        .validate();
        assert_eq!(issues.len(), 1, "{issues:?}");
        assert_eq!(issues[0].field, "plateau");
    }
}
