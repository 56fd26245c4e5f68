//! The time step of a run: the critical (stability) step, and the `auto` rule that picks
//! a step for accuracy within stability.
//!
//! **Stability.** ω_max is the highest angular frequency of the modal system with every
//! contact closed ([`crate::stability`]; in the plane with each contact along its
//! normal, never above the row with the same contacts); a scheme is stable for
//! ω_max Δt ≤ its limit (2 for central difference).
//!
//! **Accuracy (`auto`).** A stable step is not an accurate one: at 0.8 × the critical
//! step a contact lasts about two steps, and the energy balance and the peak forces are
//! off by tens of per cent. `auto` resolves the fastest motion the run can excite with a
//! number of steps per period that depends on the tolerance:
//!
//! - the fastest motion of the structure, period 2π/ω_max (every contact that can close
//!   closed): at most `T/N` with N = [`STEPS_PER_PERIOD`] × (10⁻³ / tolerance)^(1/p), p
//!   the order of the scheme (2 for central difference, 1 for Tchamwa–Wielgosz), because
//!   the error of a p-th order scheme scales as (ωΔt)^p;
//! - the excitation: the same N steps per period of a half-sine (period twice its
//!   duration) or a sine, and at least one step per interval between two samples of an
//!   acceleration or force table (so that no sample is stepped over);
//! - never above [`STABILITY_FRACTION`] of the critical step;
//! - and a whole number of steps per output interval, so that samples fall on exactly
//!   k × interval: Δt = interval / ⌈interval / Δt⌉.
//!
//! N = 50 at the default tolerance 10⁻³ was measured on rows of 5 to 20 pins (E from
//! 2e9 to 2.1e11 Pa, Kc from 1e5 to 1e7 N/m, gaps 0 to 1 mm, sine, half-sine and table
//! excitation) and on the cantilever: the energy residual stays below the tolerance (the
//! worst of 48 nearby steps was 5.9e-4; 1.2e-3 at N = 40) and peak contact forces of
//! shocks within 10 × tolerance of the Δt → 0 limit (tests and the calibration tables
//! in `accuracy_tests.rs`: `cargo test --lib calibration_table energy_spread --
//! --ignored --nocapture`).

use super::{Model, Settings, SimulationError, TimeStep};
use crate::loads::BaseAcceleration;
use crate::stability::{PinModes, Scheme, max_angular_frequency, max_angular_frequency_in_plane};

/// Steps per period of the fastest motion at the default tolerance (10⁻³).
pub const STEPS_PER_PERIOD: f64 = 50.0;
/// Tolerance at which [`STEPS_PER_PERIOD`] holds.
pub const REFERENCE_TOLERANCE: f64 = 1e-3;
/// Default relative tolerance of `auto` and of the quality verdict.
pub const DEFAULT_TOLERANCE: f64 = 1e-3;
/// `auto` never uses more than this fraction of the critical step.
pub const STABILITY_FRACTION: f64 = 0.8;
/// Fewest steps per period `auto` ever uses, whatever the tolerance.
const MIN_STEPS_PER_PERIOD: f64 = 8.0;
/// Fewest steps per period of the fastest motion (and of the excitation) at 2Δt for the
/// check to compare the run with a run at 2Δt ([`StepSize::doubled`]): 2.5 times the
/// 8 below which a peak's error is no longer O(Δt²) (`quality`), so that the doubled run
/// is still in the range where Richardson's estimate holds.
pub const DOUBLED_STEPS_PER_PERIOD: f64 = 20.0;

/// The step of a run and what it was measured against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSize {
    /// Δt (s).
    pub time_step: f64,
    /// Critical step of the scheme with every contact closed (s).
    pub critical_time_step: f64,
    /// The fastest motion the step resolves (rad/s): ω_max, the highest angular
    /// frequency with every contact closed, for the explicit schemes; the quickest
    /// contact for the exact modal scheme ([`resolved_frequency`]).
    pub max_angular_frequency: f64,
    /// What bounded an `auto` step; `Given` for a fixed one.
    pub limited_by: StepLimit,
    /// The time scales of the excitation the step must resolve.
    pub excitation: ExcitationScales,
}

/// The time scales of a model's excitation: the shortest period to resolve with many
/// steps (twice a half-sine's duration, a sine's period, a pulse's resolution period)
/// and the shortest interval between two samples of a table (never stepped over).
/// Infinite when the model has none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExcitationScales {
    /// Shortest period of the excitation (s).
    pub period: f64,
    /// Shortest sampling interval of an acceleration or force table (s).
    pub interval: f64,
}

impl ExcitationScales {
    /// No excitation with a time scale (free vibration, constant loads).
    pub const NONE: Self = Self {
        period: f64::INFINITY,
        interval: f64::INFINITY,
    };

    /// The longest step that resolves each period with `steps_per_period` steps and
    /// steps over no sample; `None` when nothing bounds it.
    fn bound(&self, steps_per_period: f64) -> Option<f64> {
        let bound = (self.period / steps_per_period).min(self.interval);
        (bound.is_finite() && bound > 0.0).then_some(bound)
    }
}

/// The constraint that set an `auto` step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepLimit {
    /// The user gave the step.
    Given,
    /// The period of the fastest motion with the contacts closed.
    FastestMotion,
    /// The time scale of the excitation (pulse, sine period, table sampling).
    Excitation,
    /// The stability limit.
    Stability,
}

impl StepLimit {
    /// A short phrase for documents and messages.
    pub fn describe(&self) -> &'static str {
        match self {
            StepLimit::Given => "given",
            StepLimit::FastestMotion => "fastest_motion",
            StepLimit::Excitation => "excitation",
            StepLimit::Stability => "stability",
        }
    }
}

/// The time of sample (or step) k (s) on a grid of `interval`: the double nearest to
/// k × the decimal `interval` stands for (m / 10^e, the fewest decimals that read back
/// as it), so that it prints as that decimal (`0.009`, not the `0.009000000000000001` of
/// `9.0 * 0.001`) and two grids of the same interval share their times exactly.
///
/// k·m and 10^e are exact doubles (k·m ≤ 2^53, e ≤ 22), so one quotient rounds the exact
/// value once: the nearest double. An interval with no such decimal (a step chosen by
/// `auto`: interval / n) falls back to the plain product k × interval. No allocation:
/// cheap enough for an event's time inside the stepping loop.
pub fn sample_time(k: u64, interval: f64) -> f64 {
    let plain = k as f64 * interval;
    let Some((m, e)) = short_decimal(interval) else {
        return plain;
    };
    match k.checked_mul(m).filter(|&km| km <= 1 << 53) {
        Some(km) => km as f64 / EXACT_POWERS_OF_TEN[e],
        None => plain,
    }
}

/// Powers of ten that are exact doubles.
const EXACT_POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18,
    1e19, 1e20, 1e21, 1e22,
];

/// `x` (finite, positive) as m / 10^e with the fewest decimals e that read back as `x`
/// (m / 10^e rounds to `x`), m ≤ 2^53; `None` when no e ≤ 22 does.
fn short_decimal(x: f64) -> Option<(u64, usize)> {
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    EXACT_POWERS_OF_TEN.iter().enumerate().find_map(|(e, &power)| {
        let m = (x * power).round();
        (m >= 1.0 && m <= (1u64 << 53) as f64 && m / power == x).then_some((m as u64, e))
    })
}

impl StepSize {
    /// Time steps of a run of `duration` (never past it).
    pub fn steps(&self, duration: f64) -> u64 {
        ((duration / self.time_step) * (1.0 + 1e-12)).floor().max(1.0) as u64
    }

    /// Steps between two samples: round(interval / Δt) (at least 1), or 1 without an
    /// interval (every step).
    pub fn output_every(&self, interval: Option<f64>) -> u64 {
        interval.map_or(1, |interval| ((interval / self.time_step).round() as u64).max(1))
    }

    /// The interval between samples actually used (s): the requested one when the step
    /// divides it (always under `auto`), else the whole number of steps nearest to it.
    pub fn output_interval(&self, interval: Option<f64>) -> f64 {
        let every = self.output_every(interval);
        match interval {
            Some(requested) if ((every as f64 * self.time_step) - requested).abs() <= 1e-9 * requested => {
                requested
            }
            _ => every as f64 * self.time_step,
        }
    }

    /// Δt / critical step.
    pub fn over_critical(&self) -> f64 {
        self.time_step / self.critical_time_step
    }

    /// Steps per period of the fastest motion with the contacts closed, 2π / (ω_max Δt).
    pub fn steps_per_fastest_period(&self) -> f64 {
        std::f64::consts::TAU / (self.max_angular_frequency * self.time_step)
    }

    /// The same step halved (the step-halving check).
    pub fn halved(&self) -> Self {
        Self {
            time_step: 0.5 * self.time_step,
            ..*self
        }
    }

    /// The step doubled, for a check that compares the run with a run at 2Δt: only
    /// where 2Δt still resolves the fastest motion and the excitation with
    /// [`DOUBLED_STEPS_PER_PERIOD`] steps per period, steps over no table sample and is
    /// stable with margin ([`STABILITY_FRACTION`]); else why not, as a phrase.
    pub fn doubled(&self) -> Result<Self, String> {
        let doubled = Self {
            time_step: 2.0 * self.time_step,
            ..*self
        };
        let per_period = doubled.steps_per_fastest_period();
        if per_period < DOUBLED_STEPS_PER_PERIOD {
            return Err(format!(
                "at 2Δt the fastest motion would get {per_period:.1} steps per period \
                 (at least {DOUBLED_STEPS_PER_PERIOD} wanted)"
            ));
        }
        if doubled.time_step > STABILITY_FRACTION * self.critical_time_step {
            return Err(format!(
                "2Δt would be {:.2} of the critical step (at most {STABILITY_FRACTION} wanted)",
                doubled.over_critical()
            ));
        }
        let per_excitation = self.excitation.period / doubled.time_step;
        if per_excitation < DOUBLED_STEPS_PER_PERIOD {
            return Err(format!(
                "at 2Δt the excitation would get {per_excitation:.1} steps per period \
                 (at least {DOUBLED_STEPS_PER_PERIOD} wanted)"
            ));
        }
        if doubled.time_step > self.excitation.interval * (1.0 + 1e-9) {
            return Err(format!(
                "2Δt would step over samples of a table {} s apart",
                crate::number(self.excitation.interval)
            ));
        }
        Ok(doubled)
    }
}

/// Steps per period of the fastest motion that `auto` uses for `tolerance`.
pub fn steps_per_period(scheme: Scheme, tolerance: f64) -> f64 {
    let order = scheme_order(scheme);
    (STEPS_PER_PERIOD * (REFERENCE_TOLERANCE / tolerance).powf(1.0 / order)).max(MIN_STEPS_PER_PERIOD)
}

/// Order of accuracy of the scheme: 2 for central difference, 1 for Tchamwa–Wielgosz
/// with φ > 1 (φ = 1 is central difference in another form).
pub fn scheme_order(scheme: Scheme) -> f64 {
    match scheme {
        Scheme::CentralDifference => 2.0,
        Scheme::Tchamwa { phi } if phi <= 1.0 => 2.0,
        Scheme::Tchamwa { .. } => 1.0,
        Scheme::ExactModal => 2.0,
    }
}

/// ω_max (rad/s) of the model with every contact closed.
pub fn max_frequency(model: &Model<'_>) -> f64 {
    let shapes: Vec<Vec<f64>> = model
        .contacts
        .iter()
        .map(|c| model.basis.deflection_at(c.height))
        .collect();
    let (scales, kinds) = (model.kind_scales(), model.pin_kinds());
    let pins = PinModes {
        frequencies: kinds.iter().map(|k| scales[*k].frequencies).collect(),
        shape_scales: kinds.iter().map(|k| 1.0 / scales[*k].mass.sqrt()).collect(),
    };
    match &model.plane {
        None => max_angular_frequency(&pins, &model.contacts, &shapes),
        Some(plane) => max_angular_frequency_in_plane(&pins, &model.contacts, &shapes, &plane.normals),
    }
}

/// How far above the contact frequency ω_c the exact modal scheme's step resolves
/// ([`contact_frequency`]).
pub const CONTACT_HARMONICS: f64 = 4.0;

/// The fastest motion the exact modal scheme's step must resolve (rad/s): the quickest
/// contact. Its modes are exact whatever ω Δt, so what a step must follow is how fast a
/// contact force rises and falls. A spring k against a slender beam of bending stiffness
/// EI and mass m per length answers at the frequency where k |H(ω)| = 1, H the
/// driving-point receptance of an infinite Euler–Bernoulli beam,
/// |H(ω)| = 1/(4√2 EI^¼ m^¾ ω^{3/2}): ω_c = (k/(4√2 EI^¼ m^¾))^{2/3}, with k doubled
/// between two pins (each pin's receptance adds); never below the first mode's
/// frequency, which a soft contact follows. Bodies of several kinds: each contact with
/// the lighter impedance of its two pins, the first frequency of the quickest kind. What the step resolves is
/// [`CONTACT_HARMONICS`] × that, the range that carries the peak force: measured on a
/// three-pin row with the static correction, the peak at 50 steps per period of ω_c
/// alone was 2.2 % low, at 50 per period of 4 ω_c 0.1 % (the scheme's error falls as
/// h²). The step check proves the step it gives.
pub fn contact_frequency(model: &Model<'_>) -> f64 {
    // Per kind of body (the basis's first): its beam's impedance and first frequency.
    let bases: Vec<&crate::modal::ModalBasis> = std::iter::once(model.basis)
        .chain(model.kinds.iter().map(|k| k.basis))
        .collect();
    let impedances: Vec<f64> = bases
        .iter()
        .map(|basis| {
            let spec = basis.spec();
            4.0 * std::f64::consts::SQRT_2
                * spec.bending_stiffness().powf(0.25)
                * spec.mass_per_length().powf(0.75)
        })
        .collect();
    let first = bases
        .iter()
        .map(|b| CONTACT_HARMONICS * b.angular_frequencies().first().copied().unwrap_or(0.0))
        .fold(0.0, f64::max);
    let pin_kinds = model.pin_kinds();
    model
        .contacts
        .iter()
        .filter(|c| c.normal_law().is_active())
        .map(|c| {
            // Between two pins, the more mobile one's impedance (the quicker contact).
            let sides: Vec<f64> = [c.left, c.right]
                .iter()
                .filter_map(|b| match b {
                    crate::contact::Body::Pin(p) => pin_kinds.get(*p).map(|k| impedances[*k]),
                    crate::contact::Body::Wall => None,
                })
                .collect();
            let impedance = sides.iter().copied().fold(f64::INFINITY, f64::min);
            let impedance = if impedance.is_finite() {
                impedance
            } else {
                impedances[0]
            };
            let stiffness = c.stability_stiffness() * sides.len().max(1) as f64;
            CONTACT_HARMONICS * (stiffness / impedance).powf(2.0 / 3.0)
        })
        .fold(first, f64::max)
}

/// The angular frequency a step of `scheme` must resolve: ω_max with every contact
/// closed for the explicit schemes (their stability and accuracy follow it), the
/// quickest contact for the exact modal scheme ([`contact_frequency`]).
pub fn resolved_frequency(model: &Model<'_>, scheme: Scheme) -> f64 {
    match scheme {
        Scheme::ExactModal => contact_frequency(model),
        _ => max_frequency(model),
    }
}

/// Critical time step (s) of `scheme` for this model, all contacts closed.
pub fn critical_time_step(model: &Model<'_>, scheme: Scheme) -> f64 {
    scheme.stability_limit() / max_frequency(model)
}

/// The time scales of the model's excitation.
pub fn excitation_scales(model: &Model<'_>) -> ExcitationScales {
    let mut scales = ExcitationScales::NONE;
    let base_y = model.plane.as_ref().and_then(|p| p.base_acceleration_y.as_ref());
    let walls = model
        .walls
        .iter()
        .flat_map(|w| [&w.left_x, &w.right_x, &w.y])
        .flatten();
    for base in model.base_acceleration.iter().chain(base_y).chain(walls) {
        match base {
            BaseAcceleration::HalfSine { duration, .. } => scales.period = scales.period.min(2.0 * duration),
            BaseAcceleration::Sine { frequency, .. } => scales.period = scales.period.min(1.0 / frequency),
            BaseAcceleration::Table(table) => {
                scales.interval = scales.interval.min(table.shortest_interval())
            }
            BaseAcceleration::Pulse(pulse) => scales.period = scales.period.min(pulse.resolution_period()),
        }
    }
    for force in &model.point_forces {
        scales.interval = scales.interval.min(force.force.shortest_interval());
    }
    scales
}

/// The step a run will use, or why it cannot run (a given step above the critical one).
pub fn resolve(model: &Model<'_>, settings: &Settings) -> Result<StepSize, SimulationError> {
    let omega = resolved_frequency(model, settings.scheme);
    let critical = settings.scheme.stability_limit() / omega;
    let excitation = excitation_scales(model);
    match settings.time_step {
        TimeStep::Fixed(dt) if dt > critical * (1.0 + 1e-12) => Err(SimulationError::TimeStepAboveCritical {
            time_step: dt,
            critical_time_step: critical,
        }),
        TimeStep::Fixed(dt) => Ok(StepSize {
            time_step: dt,
            critical_time_step: critical,
            max_angular_frequency: omega,
            limited_by: StepLimit::Given,
            excitation,
        }),
        TimeStep::Auto => {
            let per_period = steps_per_period(settings.scheme, settings.tolerance);
            let mut candidates = vec![
                (
                    std::f64::consts::TAU / (omega * per_period),
                    StepLimit::FastestMotion,
                ),
                (STABILITY_FRACTION * critical, StepLimit::Stability),
            ];
            if let Some(bound) = excitation.bound(per_period) {
                candidates.push((bound, StepLimit::Excitation));
            }
            let (mut dt, limited_by) = candidates
                .into_iter()
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap_or((STABILITY_FRACTION * critical, StepLimit::Stability));
            // Never longer than the run, and a whole number of steps per sample (a run far
            // shorter than the interval, with a step too short to count them, has only
            // its first sample).
            dt = dt.min(settings.duration);
            if let Some(interval) = settings.output_interval
                && interval > 0.0
                && (interval / dt).is_finite()
            {
                dt = interval / (interval / dt).ceil();
            }
            Ok(StepSize {
                time_step: dt,
                critical_time_step: critical,
                max_angular_frequency: omega,
                limited_by,
                excitation,
            })
        }
    }
}

#[cfg(test)]
mod sample_time_tests {
    use super::*;

    #[test]
    fn sample_times_are_the_decimals_k_times_the_interval() {
        // (interval, m, e): interval = m / 10^e.
        for (interval, m, e) in [
            (1e-3, 1, 3),
            (1e-4, 1, 4),
            (2.5e-4, 25, 5),
            (0.1, 1, 1),
            (5.0, 5, 0),
            (20.0, 20, 0),
            (1e-6, 1, 6),
        ] {
            assert_eq!(short_decimal(interval), Some((m, e)), "{interval}");
            for k in 0..20_000u64 {
                let expected: f64 = format!("{}e-{e}", k * m).parse().unwrap();
                let t = sample_time(k, interval);
                assert_eq!(t, expected, "sample {k} of {interval}: {t} instead of {expected}");
            }
        }
        // The plain product prints badly, the sample time does not.
        assert_eq!(format!("{}", 9.0 * 1e-3), "0.009000000000000001");
        assert_eq!(format!("{}", sample_time(9, 1e-3)), "0.009");
        assert_eq!(format!("{}", sample_time(3, 0.1)), "0.3");
        // An interval with no short decimal: the plain product.
        let odd = 1.0 / 3.0e4;
        assert_eq!(sample_time(7, odd), 7.0 * odd);
    }
}
