//! Time-dependent loads: base acceleration of the wrapper (applied in the wrapper frame
//! as the inertial load −M r a(t), i.e. −Γᵢ a(t) on mode i) and point forces at a height.

mod pulse;

pub use pulse::Pulse;

use super::{InputIssue, require_non_negative, require_positive};

/// Imposed acceleration of the wrapper (walls and pin feet), m/s², in the direction of
/// positive deflection.
#[derive(Debug, Clone, PartialEq)]
pub enum BaseAcceleration {
    /// a(t) = amplitude · sin(π t / duration) for 0 ≤ t ≤ duration, 0 after.
    HalfSine { amplitude: f64, duration: f64 },
    /// a(t) = amplitude · sin(2π frequency t) for `cycles` periods, 0 after.
    Sine {
        amplitude: f64,
        frequency: f64,
        cycles: f64,
    },
    /// Samples (s, m/s²), linear between them, 0 before the first and after the last.
    Table(Table),
    /// A transport or handling shock pulse: haversine, terminal-peak sawtooth, trapezoid.
    Pulse(Pulse),
}

impl BaseAcceleration {
    /// a(t) (m/s²).
    pub fn at(&self, t: f64) -> f64 {
        match self {
            BaseAcceleration::HalfSine { amplitude, duration } => {
                if (0.0..=*duration).contains(&t) {
                    amplitude * (std::f64::consts::PI * t / duration).sin()
                } else {
                    0.0
                }
            }
            BaseAcceleration::Sine {
                amplitude,
                frequency,
                cycles,
            } => {
                if t >= 0.0 && t * frequency <= *cycles {
                    amplitude * (std::f64::consts::TAU * frequency * t).sin()
                } else {
                    0.0
                }
            }
            BaseAcceleration::Table(table) => table.at(t),
            BaseAcceleration::Pulse(pulse) => pulse.at(t),
        }
    }

    /// The time (s) after which the signal is 0 for good: the pulse's duration, the
    /// sine's last cycle, the table's last sample.
    pub fn end(&self) -> f64 {
        match self {
            BaseAcceleration::HalfSine { duration, .. } => *duration,
            BaseAcceleration::Sine {
                frequency, cycles, ..
            } => cycles / frequency,
            BaseAcceleration::Table(table) => table.time.last().copied().unwrap_or(0.0),
            BaseAcceleration::Pulse(pulse) => pulse.duration(),
        }
    }

    /// The same signal multiplied by `factor` (a component of a signal along a
    /// direction: `factor` = cos θ or sin θ).
    pub fn scaled(&self, factor: f64) -> BaseAcceleration {
        match self {
            BaseAcceleration::HalfSine { amplitude, duration } => BaseAcceleration::HalfSine {
                amplitude: factor * amplitude,
                duration: *duration,
            },
            BaseAcceleration::Sine {
                amplitude,
                frequency,
                cycles,
            } => BaseAcceleration::Sine {
                amplitude: factor * amplitude,
                frequency: *frequency,
                cycles: *cycles,
            },
            BaseAcceleration::Table(table) => BaseAcceleration::Table(Table {
                time: table.time.clone(),
                values: table.values.iter().map(|v| factor * v).collect(),
            }),
            BaseAcceleration::Pulse(pulse) => BaseAcceleration::Pulse(match pulse {
                Pulse::Haversine { amplitude, duration } => Pulse::Haversine {
                    amplitude: factor * amplitude,
                    duration: *duration,
                },
                Pulse::TerminalPeakSawtooth { amplitude, duration } => Pulse::TerminalPeakSawtooth {
                    amplitude: factor * amplitude,
                    duration: *duration,
                },
                Pulse::Trapezoid {
                    amplitude,
                    rise,
                    plateau,
                    fall,
                } => Pulse::Trapezoid {
                    amplitude: factor * amplitude,
                    rise: *rise,
                    plateau: *plateau,
                    fall: *fall,
                },
            }),
        }
    }

    /// Every problem (fields relative to the excitation object).
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        match self {
            BaseAcceleration::HalfSine { amplitude, duration } => {
                require_finite(&mut issues, "amplitude", *amplitude);
                require_positive(&mut issues, "duration", *duration);
            }
            BaseAcceleration::Sine {
                amplitude,
                frequency,
                cycles,
            } => {
                require_finite(&mut issues, "amplitude", *amplitude);
                require_positive(&mut issues, "frequency", *frequency);
                require_positive(&mut issues, "cycles", *cycles);
            }
            BaseAcceleration::Table(table) => issues.extend(table.validate("acceleration")),
            BaseAcceleration::Pulse(pulse) => issues.extend(pulse.validate()),
        }
        issues
    }
}

/// A sampled function of time, linear between samples, 0 outside them.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Sample times (s), non-negative and strictly increasing.
    pub time: Vec<f64>,
    /// Values at those times.
    pub values: Vec<f64>,
}

impl Table {
    /// A ramp from 0 at t = 0 to `value` at `rise` (s), then held (to a time far past
    /// any run).
    pub fn ramp_and_hold(rise: f64, value: f64) -> Self {
        Self {
            time: vec![0.0, rise, 1e3 + rise],
            values: vec![0.0, value, value],
        }
    }

    /// `signal` sampled every `interval` (s) from 0 to `end` (s) included (the last
    /// interval shorter when `end` is not a multiple).
    pub fn sample(signal: impl Fn(f64) -> f64, interval: f64, end: f64) -> Self {
        let whole = (end / interval).floor() as usize;
        let mut time: Vec<f64> = (0..=whole as u64)
            .map(|k| crate::integrate::sample_time(k, interval))
            .collect();
        if end - whole as f64 * interval > 1e-9 * interval {
            time.push(end);
        }
        let values = time.iter().map(|&t| signal(t)).collect();
        Self { time, values }
    }

    pub fn at(&self, t: f64) -> f64 {
        let (times, values) = (&self.time, &self.values);
        if times.is_empty() || t < times[0] || t > times[times.len() - 1] {
            return 0.0;
        }
        let upper = times.partition_point(|&s| s <= t);
        if upper == 0 {
            return values[0];
        }
        if upper >= times.len() {
            return values[times.len() - 1];
        }
        let (t0, t1) = (times[upper - 1], times[upper]);
        let weight = (t - t0) / (t1 - t0);
        values[upper - 1] + weight * (values[upper] - values[upper - 1])
    }

    /// The shortest interval between two samples (s); ∞ with fewer than two.
    pub fn shortest_interval(&self) -> f64 {
        self.time
            .windows(2)
            .map(|pair| pair[1] - pair[0])
            .fold(f64::INFINITY, f64::min)
    }

    /// Checks the table; `values_field` names the value column (`acceleration`, `force`).
    pub fn validate(&self, values_field: &str) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if self.time.len() < 2 {
            issues.push(InputIssue::new("time", "needs at least two samples"));
        }
        if self.time.len() != self.values.len() {
            issues.push(InputIssue::new(
                values_field,
                format!(
                    "must have as many samples as `time` ({} vs {})",
                    self.values.len(),
                    self.time.len()
                ),
            ));
        }
        for (k, t) in self.time.iter().enumerate() {
            require_non_negative(&mut issues, &format!("time/{k}"), *t);
            if k > 0 && *t <= self.time[k - 1] {
                issues.push(InputIssue::new(
                    format!("time/{k}"),
                    "times must be strictly increasing",
                ));
                break;
            }
        }
        for (k, v) in self.values.iter().enumerate() {
            require_finite(&mut issues, &format!("{values_field}/{k}"), *v);
        }
        issues
    }
}

/// A force history applied at a height of one pin along one of its deflection lines, in
/// the direction of positive deflection (N).
#[derive(Debug, Clone, PartialEq)]
pub struct PointForce {
    /// The deflection line loaded (`Model::lines`): pin p is line p in a row; in the
    /// plane, pin p along x is line p and along y line pins + p.
    pub line: usize,
    /// Height from the foot (m).
    pub height: f64,
    pub force: Table,
}

fn require_finite(issues: &mut Vec<InputIssue>, field: &str, value: f64) {
    if !value.is_finite() {
        issues.push(InputIssue::new(field, "must be a finite number"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_sine_peaks_at_mid_duration_and_stops() {
        let shock = BaseAcceleration::HalfSine {
            amplitude: 50.0,
            duration: 0.01,
        };
        assert!((shock.at(0.005) - 50.0).abs() < 1e-12);
        assert_eq!(shock.at(0.0101), 0.0);
        assert_eq!(shock.at(-1.0), 0.0);
    }

    #[test]
    fn table_interpolates_linearly_and_is_zero_outside() {
        let table = Table {
            time: vec![0.0, 1.0, 3.0],
            values: vec![0.0, 2.0, -2.0],
        };
        assert!((table.at(0.5) - 1.0).abs() < 1e-15);
        assert!((table.at(2.0) - 0.0).abs() < 1e-15);
        assert_eq!(table.at(3.0), -2.0);
        assert_eq!(table.at(3.5), 0.0);
        let bad = Table {
            time: vec![0.0, 0.0],
            values: vec![1.0, f64::NAN],
        };
        let fields: Vec<String> = bad
            .validate("acceleration")
            .into_iter()
            .map(|i| i.field)
            .collect();
        assert_eq!(fields, ["time/1", "acceleration/1"]);
    }

    // The end is where each signal is 0 for good: just after it, every kind is 0, and
    // (but for a sine ending on a zero crossing) not just before.
    #[test]
    fn every_signal_is_zero_after_its_end() {
        let signals = [
            BaseAcceleration::HalfSine {
                amplitude: 5.0,
                duration: 0.01,
            },
            BaseAcceleration::Sine {
                amplitude: 2.0,
                frequency: 10.0,
                cycles: 2.25,
            },
            BaseAcceleration::Table(Table {
                time: vec![0.0, 0.5, 1.5],
                values: vec![0.0, 1.0, 3.0],
            }),
            BaseAcceleration::Pulse(Pulse::Trapezoid {
                amplitude: 1.0,
                rise: 0.1,
                plateau: 0.2,
                fall: 0.1,
            }),
        ];
        let ends = [0.01, 0.225, 1.5, 0.4];
        for (signal, want) in signals.iter().zip(ends) {
            let end = signal.end();
            assert!((end - want).abs() < 1e-15, "{signal:?}: end {end}, want {want}");
            assert_eq!(signal.at(end * (1.0 + 1e-9)), 0.0, "{signal:?}");
            assert!(signal.at(end * (1.0 - 1e-3)) != 0.0, "{signal:?}");
        }
    }

    #[test]
    fn sine_lasts_its_cycles() {
        let sine = BaseAcceleration::Sine {
            amplitude: 2.0,
            frequency: 10.0,
            cycles: 2.0,
        };
        assert!((sine.at(0.025) - 2.0).abs() < 1e-12);
        assert_eq!(sine.at(0.21), 0.0);
    }
}
