//! The excitations the processes share: a base acceleration along a line, and one in the
//! transverse plane (one signal along a direction, or two components).

use serde::Deserialize;
use utoipa::ToSchema;

use crate::physics::loads::{BaseAcceleration, Pulse, Table};
use crate::processes::FieldError;
use crate::processes::common_inputs::at;
use crate::processes::input_schema::NonNegativeNumber;

/// The standard gravity (m/s²): 1 g.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// The unit of a record's accelerations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, Deserialize, ToSchema)]
pub enum AccelerationUnit {
    /// m/s² (the default).
    #[default]
    #[serde(rename = "m/s2")]
    MetresPerSecondSquared,
    /// The standard gravity, 9.80665 m/s².
    #[serde(rename = "g")]
    G,
}

impl AccelerationUnit {
    /// From its name in a query: `m/s2` (also `m/s^2`, `m/s²`) or `g`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "m/s2" | "m/s^2" | "m/s²" => Some(Self::MetresPerSecondSquared),
            "g" => Some(Self::G),
            _ => None,
        }
    }

    /// m/s² per unit.
    pub fn factor(self) -> f64 {
        match self {
            Self::MetresPerSecondSquared => 1.0,
            Self::G => STANDARD_GRAVITY,
        }
    }
}

/// Base acceleration a(t) (m/s²), positive toward the right wall (the +x axis of a
/// hexagonal bundle's direction), starting at t = 0.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum BaseAccelerationInput {
    /// amplitude · sin(π t / duration) during `duration`, then 0.
    HalfSine {
        /// Peak acceleration (m/s²), signed.
        amplitude: f64,
        /// Length of the pulse (s).
        #[schema(exclusive_minimum = 0.0)]
        duration: f64,
    },
    /// amplitude · sin(2π frequency t) for `cycles` periods, then 0.
    Sine {
        /// Peak acceleration (m/s²), signed.
        amplitude: f64,
        /// Frequency (Hz).
        #[schema(exclusive_minimum = 0.0)]
        frequency: f64,
        /// Number of periods (dimensionless; a fraction ends mid-period).
        #[schema(exclusive_minimum = 0.0)]
        cycles: f64,
    },
    /// Samples, linear between them, 0 after the last.
    Table {
        /// Sample times (s), at least two, ≥ 0 and strictly increasing.
        #[schema(value_type = Vec<NonNegativeNumber>)]
        time: Vec<f64>,
        /// Acceleration at each time (m/s², or g when `unit` is `g`).
        acceleration: Vec<f64>,
        /// The unit of `acceleration`: `m/s2` (the default) or `g` (9.80665 m/s²).
        #[serde(default)]
        unit: AccelerationUnit,
    },
    /// amplitude · sin²(π t / duration) during `duration`, then 0 (velocity change
    /// amplitude · duration / 2).
    Haversine {
        /// Peak acceleration (m/s²), signed.
        amplitude: f64,
        /// Length of the pulse (s).
        #[schema(exclusive_minimum = 0.0)]
        duration: f64,
    },
    /// amplitude · t / duration during `duration`, then 0 at once (velocity change
    /// amplitude · duration / 2).
    TerminalPeakSawtooth {
        /// Peak acceleration (m/s²), signed.
        amplitude: f64,
        /// Length of the pulse (s).
        #[schema(exclusive_minimum = 0.0)]
        duration: f64,
    },
    /// Linear rise to `amplitude` in `rise`, `plateau` at it, linear fall to 0 in `fall`;
    /// a ramp or the plateau may be 0, not all three (velocity change amplitude ·
    /// (rise/2 + plateau + fall/2)).
    Trapezoid {
        /// Plateau acceleration (m/s²), signed.
        amplitude: f64,
        /// Duration of the rise (s).
        #[schema(minimum = 0.0)]
        rise: f64,
        /// Duration of the plateau (s).
        #[schema(minimum = 0.0)]
        plateau: f64,
        /// Duration of the fall (s).
        #[schema(minimum = 0.0)]
        fall: f64,
    },
    /// A synthetic earthquake matching a target response spectrum, drawn from a seed.
    SpectrumCompatible(crate::processes::synthetic_input::SpectrumCompatibleInput),
    /// A stored accelerogram (`POST /signals`) by its `id`, times `scale` (default 1).
    Signal(crate::processes::signal_input::SignalInput),
}

impl BaseAccelerationInput {
    /// Every problem (fields relative to the excitation object).
    pub fn validate(&self) -> Vec<crate::physics::InputIssue> {
        match self {
            Self::SpectrumCompatible(synthetic) => synthetic.validate(),
            Self::Signal(signal) => signal.validate(),
            other => other.physics().validate(),
        }
    }

    /// Whether this signal is checked as its own inputs ([`Self::validate`]) rather than
    /// through the table the integrator sees: a synthetic record (generated from them)
    /// and a stored signal (checked when it was uploaded). Problems the model check
    /// finds in their tables would only restate those, at members the request lacks.
    pub fn is_checked_apart(&self) -> bool {
        matches!(self, Self::SpectrumCompatible(_) | Self::Signal(_))
    }

    /// The stored signal this refers to, if it is one.
    pub fn signal_mut(&mut self) -> Option<&mut crate::processes::signal_input::SignalInput> {
        match self {
            Self::Signal(signal) => Some(signal),
            _ => None,
        }
    }

    /// The excitation the integrator sees (a synthetic record or a stored signal as its
    /// table).
    pub fn physics(&self) -> BaseAcceleration {
        match self {
            Self::SpectrumCompatible(synthetic) => BaseAcceleration::Table(synthetic.table()),
            Self::Signal(signal) => BaseAcceleration::Table(signal.table()),
            Self::HalfSine { amplitude, duration } => BaseAcceleration::HalfSine {
                amplitude: *amplitude,
                duration: *duration,
            },
            Self::Sine {
                amplitude,
                frequency,
                cycles,
            } => BaseAcceleration::Sine {
                amplitude: *amplitude,
                frequency: *frequency,
                cycles: *cycles,
            },
            Self::Table {
                time,
                acceleration,
                unit,
            } => BaseAcceleration::Table(Table {
                time: time.clone(),
                values: acceleration.iter().map(|a| a * unit.factor()).collect(),
            }),
            Self::Haversine { amplitude, duration } => BaseAcceleration::Pulse(Pulse::Haversine {
                amplitude: *amplitude,
                duration: *duration,
            }),
            Self::TerminalPeakSawtooth { amplitude, duration } => {
                BaseAcceleration::Pulse(Pulse::TerminalPeakSawtooth {
                    amplitude: *amplitude,
                    duration: *duration,
                })
            }
            Self::Trapezoid {
                amplitude,
                rise,
                plateau,
                fall,
            } => BaseAcceleration::Pulse(Pulse::Trapezoid {
                amplitude: *amplitude,
                rise: *rise,
                plateau: *plateau,
                fall: *fall,
            }),
        }
    }
}

/// A signal in the plane as the request gives it: one signal along a direction, or two
/// components (member names and values).
#[derive(Debug)]
pub struct PlaneSignal<'a> {
    pub single: (&'static str, &'a Option<BaseAccelerationInput>),
    /// The direction member, its value (given or defaulted), and whether it was given.
    pub direction: (&'static str, Option<f64>, bool),
    pub x: (&'static str, &'a Option<BaseAccelerationInput>),
    pub y: (&'static str, &'a Option<BaseAccelerationInput>),
}

/// The (x, y) components of a [`PlaneSignal`], or the errors: one signal with an
/// optional direction, or two components, not both.
pub fn plane_signal(
    signal: PlaneSignal<'_>,
    errors: &mut Vec<FieldError>,
) -> (Option<BaseAcceleration>, Option<BaseAcceleration>) {
    let pointer = "/inputs/excitation";
    let component = |(member, signal): (&str, &Option<BaseAccelerationInput>),
                     errors: &mut Vec<FieldError>| {
        signal.as_ref().map(|s| {
            errors.extend(at(&format!("{pointer}/{member}"), s.validate()));
            s.physics()
        })
    };
    let single = component(signal.single, errors);
    let x = component(signal.x, errors);
    let y = component(signal.y, errors);
    let (direction_member, direction, direction_given) = signal.direction;
    if let Some(direction) = direction
        && !direction.is_finite()
    {
        errors.push(FieldError::new(
            format!("{pointer}/{direction_member}"),
            "must be a finite angle in degrees",
        ));
    }
    let (single_member, x_member, y_member) = (signal.single.0, signal.x.0, signal.y.0);
    match single {
        Some(one) => {
            if x.is_some() || y.is_some() {
                let field = if x.is_some() { x_member } else { y_member };
                errors.push(FieldError::new(
                    format!("{pointer}/{field}"),
                    format!(
                        "give either {single_member} (with {direction_member}) or the components \
                         {x_member} and {y_member}, not both"
                    ),
                ));
            }
            let angle = direction.unwrap_or(0.0).to_radians();
            (Some(one.scaled(angle.cos())), Some(one.scaled(angle.sin())))
        }
        None => {
            if direction_given {
                errors.push(FieldError::new(
                    format!("{pointer}/{direction_member}"),
                    format!(
                        "is the direction of {single_member}, which is not given (the components \
                         {x_member} and {y_member} need none)"
                    ),
                ));
            }
            (x, y)
        }
    }
}

/// The stored signals among the excitation members `members` (name in
/// `/inputs/excitation`, value), with their pointers.
pub fn signal_slots<'a>(
    members: impl IntoIterator<Item = (&'static str, &'a mut Option<BaseAccelerationInput>)>,
) -> Vec<crate::processes::signal_input::SignalSlot<'a>> {
    members
        .into_iter()
        .filter_map(|(member, signal)| {
            let signal = signal.as_mut()?.signal_mut()?;
            Some((format!("/inputs/excitation/{member}"), signal))
        })
        .collect()
}
