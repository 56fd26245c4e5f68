//! The solved reference motion: phases, contact events and extremes, with fast
//! evaluation of the tip deflection and contact force at any time or on a grid.

use super::ReferenceError;
use super::phase::{Phase, PhaseKind};

/// What happens at a switching instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactEventKind {
    /// The tip closes the gap (w(L) + g crosses 0 downwards); contact starts.
    Impact,
    /// The tip leaves the spring (w(L) + g crosses 0 upwards); flight starts.
    Release,
}

/// One switching instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactEvent {
    /// Time (s).
    pub time: f64,
    /// Impact or release.
    pub kind: ContactEventKind,
}

/// Tip deflection and contact force sampled on a time grid.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TipHistory {
    /// Tip deflection w(L, t) (m), positive upwards (away from the spring).
    pub tip_deflection: Vec<f64>,
    /// Contact force F = Kc max(0, −w(L) − g) (N), zero in flight.
    pub contact_force: Vec<f64>,
}

/// An extreme value and when it happens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extreme {
    /// Value (unit of the quantity).
    pub value: f64,
    /// Time (s).
    pub time: f64,
}

/// Result of [`super::CantileverReference::solve`].
#[derive(Debug, Clone)]
pub struct ReferenceSolution {
    pub(super) phases: Vec<Phase>,
    pub(super) events: Vec<ContactEvent>,
    pub(super) contact_stiffness: f64,
    pub(super) gap: f64,
    pub(super) free_frequencies_hz: Vec<f64>,
    pub(super) contact_frequencies_hz: Vec<f64>,
    pub(super) contact_damping_ratios: Vec<f64>,
    pub(super) max_contact_force: Extreme,
    pub(super) min_tip_deflection: Extreme,
    pub(super) stopped_by_event_limit: bool,
}

impl ReferenceSolution {
    /// Switching instants in time order.
    pub fn events(&self) -> &[ContactEvent] {
        &self.events
    }

    /// Time of the first impact (s), if any.
    pub fn first_impact_time(&self) -> Option<f64> {
        self.events
            .iter()
            .find(|e| e.kind == ContactEventKind::Impact)
            .map(|e| e.time)
    }

    /// Number of impacts (a release shape that starts inside the spring counts one at t = 0).
    pub fn impact_count(&self) -> usize {
        self.events
            .iter()
            .filter(|e| e.kind == ContactEventKind::Impact)
            .count()
    }

    /// Largest contact force over continuous time (N) and its time (s); 0 at t = 0
    /// without contact.
    pub fn max_contact_force(&self) -> Extreme {
        self.max_contact_force
    }

    /// Smallest tip deflection over continuous time (m) and its time (s).
    pub fn min_tip_deflection(&self) -> Extreme {
        self.min_tip_deflection
    }

    /// Clamped-free natural frequencies (Hz).
    pub fn free_frequencies_hz(&self) -> &[f64] {
        &self.free_frequencies_hz
    }

    /// Clamped-spring natural frequencies (Hz); empty without spring (Kc = 0).
    pub fn contact_frequencies_hz(&self) -> &[f64] {
        &self.contact_frequencies_hz
    }

    /// Damping ratios of the clamped-spring modes (paper eq. 9–10).
    pub fn contact_damping_ratios(&self) -> &[f64] {
        &self.contact_damping_ratios
    }

    /// End of the solved interval (s): the duration, or the instant of the first
    /// event beyond `max_events`.
    pub fn end_time(&self) -> f64 {
        self.phases.last().map_or(0.0, |p| p.end)
    }

    /// True when the run stopped on `max_events` before the duration.
    pub fn stopped_by_event_limit(&self) -> bool {
        self.stopped_by_event_limit
    }

    /// Time slack accepted past the ends of the solved interval (s).
    fn time_tolerance(&self) -> f64 {
        1e-9 * self.end_time().max(f64::MIN_POSITIVE)
    }

    fn check_time(&self, time: f64) -> Result<(), ReferenceError> {
        let tolerance = self.time_tolerance();
        if time.is_finite() && time >= -tolerance && time <= self.end_time() + tolerance {
            Ok(())
        } else {
            Err(ReferenceError::TimeOutOfRange {
                time,
                end: self.end_time(),
            })
        }
    }

    /// Index of the phase holding `time` (phases cover [start, end), the last one
    /// [start, end]).
    fn phase_index(&self, time: f64) -> usize {
        let index = self.phases.partition_point(|p| p.end <= time);
        index.min(self.phases.len().saturating_sub(1))
    }

    fn force_from_tip(&self, kind: PhaseKind, tip: f64) -> f64 {
        match kind {
            PhaseKind::Flight => 0.0,
            PhaseKind::Contact => (-self.contact_stiffness * (tip + self.gap)).max(0.0),
        }
    }

    /// Tip deflection w(L, t) (m) at `time` (s).
    pub fn tip_deflection(&self, time: f64) -> Result<f64, ReferenceError> {
        self.check_time(time)?;
        let phase = &self.phases[self.phase_index(time)];
        Ok(phase.tip(time - phase.start))
    }

    /// Contact force F(t) = Kc max(0, −w(L, t) − g) (N) at `time` (s), zero in flight.
    pub fn contact_force(&self, time: f64) -> Result<f64, ReferenceError> {
        self.check_time(time)?;
        let phase = &self.phases[self.phase_index(time)];
        Ok(self.force_from_tip(phase.kind, phase.tip(time - phase.start)))
    }

    /// Tip deflection and contact force at arbitrary `times` (s), in any order.
    pub fn sample(&self, times: &[f64]) -> Result<TipHistory, ReferenceError> {
        let mut history = TipHistory {
            tip_deflection: Vec::with_capacity(times.len()),
            contact_force: Vec::with_capacity(times.len()),
        };
        for &time in times {
            self.check_time(time)?;
            let phase = &self.phases[self.phase_index(time)];
            let tip = phase.tip(time - phase.start);
            history.tip_deflection.push(tip);
            history.contact_force.push(self.force_from_tip(phase.kind, tip));
        }
        Ok(history)
    }

    /// Tip deflection and contact force at tₖ = `start` + k `step`, k < `count`
    /// (s). Phase by phase, with rotating modal phasors: a few flops per mode and sample.
    pub fn sample_uniform(&self, start: f64, step: f64, count: usize) -> Result<TipHistory, ReferenceError> {
        let mut history = TipHistory {
            tip_deflection: Vec::with_capacity(count),
            contact_force: Vec::with_capacity(count),
        };
        if count == 0 {
            return Ok(history);
        }
        if !(step.is_finite() && step > 0.0) && count > 1 {
            return Err(ReferenceError::InvalidInput {
                field: "step",
                requirement: "finite and > 0",
                value: step,
            });
        }
        self.check_time(start)?;
        self.check_time(start + (count - 1) as f64 * step)?;
        let mut k = 0;
        while k < count {
            let time = start + k as f64 * step;
            let index = self.phase_index(time);
            let phase = &self.phases[index];
            let is_last = index + 1 == self.phases.len();
            let mut walker = phase.walker(time - phase.start, step);
            while k < count {
                let time = start + k as f64 * step;
                if !is_last && time >= phase.end {
                    break;
                }
                let tip = walker.next_tip();
                history.tip_deflection.push(tip);
                history.contact_force.push(self.force_from_tip(phase.kind, tip));
                k += 1;
            }
        }
        Ok(history)
    }
}
