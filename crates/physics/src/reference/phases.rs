//! The phase solver: bases and projections, the flight/contact loop, switching
//! instants, and the continuous-time extremes.
//!
//! - Projection at a switch (mass inner product, composite Gauss rule):
//!   P = Φ_freeᵀ M Φ_spring; flight → contact: q_r = Pᵀ q_f − s_r, q̇_r = Pᵀ q̇_f;
//!   contact → flight: q_f = P q_r + s_f, q̇_f = P q̇_r, with s = Φᵀ M w_s the projections
//!   of the static contact solution w_s(x) = w_s(L) (x/L)²(3 − x/L)/2,
//!   w_s(L) = −Rk g/(1 + Rk) (tip-load shape: a cubic with w'' = 0 at the tip, loaded by
//!   the spring force −Kc(w_s(L) + g) = 3EI/L³ w_s(L)).
//! - Damping on the contact basis (paper eq. 9–10): ξ_r,j = Σᵢ P_ij² 2ξᵢω_f,i / (2ω_r,j).
//! - Switching: w(L) + g is sampled every 1/16 of the shortest retained period of the
//!   phase basis, so no excursion across the contact plane can hide between samples;
//!   the first sign change is refined with Brent to machine precision. A phase that
//!   starts slightly on the wrong side (truncation of the projected tip value) waits
//!   until it is on the right side; if its tip moves the wrong way from the start
//!   (grazing), the phase ends at once.
//! - Extremes: the lowest sampled local minima of w(L) in each phase are refined by a
//!   Brent root of ∂w(L)/∂t, so the peak force is exact, not grid-limited.

use super::brent::find_root;
use super::modes::{CantileverModes, clamped_free_roots, clamped_spring_roots};
use super::oscillator::ModalMotion;
use super::phase::{Phase, PhaseKind};
use super::quadrature::CompositeRule;
use super::solution::{ContactEvent, ContactEventKind, Extreme, ReferenceSolution};
use super::{CantileverReference, MAX_SCAN_SAMPLES, ReferenceError};
use std::f64::consts::PI;
use std::ops::ControlFlow;

/// Scan samples per shortest retained period.
const SAMPLES_PER_PERIOD: f64 = 16.0;
/// Sampled local minima refined per phase.
const REFINED_MINIMA: usize = 3;
/// Consecutive zero-length phases tolerated before declaring a stalled switch loop.
const MAX_ZERO_LENGTH_PHASES: usize = 8;

/// Everything fixed during a run: bases, damping, projections.
#[derive(Debug)]
pub(super) struct Setup {
    pub free: CantileverModes,
    pub spring: Option<CantileverModes>,
    pub free_damping: Vec<f64>,
    pub spring_damping: Vec<f64>,
    /// P_ij = ∫ m φ_free,i φ_spring,j dx, row-major (i: free mode, j: spring mode).
    pub projection: Vec<f64>,
    pub free_tip: Vec<f64>,
    pub spring_tip: Vec<f64>,
    /// ∫ m φ_free w₀ dx: release state on the free basis.
    pub release_free: Vec<f64>,
    /// ∫ m φ_spring (w₀ − w_s) dx: release state on the spring basis.
    pub release_spring: Vec<f64>,
    /// ∫ m φ_free ẇ₀ dx and ∫ m φ_spring ẇ₀ dx: the initial velocity on each basis.
    pub throw_free: Vec<f64>,
    pub throw_spring: Vec<f64>,
    /// ∫ m φ_free w_s dx and ∫ m φ_spring w_s dx.
    pub static_free: Vec<f64>,
    pub static_spring: Vec<f64>,
    /// w_s(L) (m).
    pub static_tip: f64,
}

impl Setup {
    pub fn new(input: &CantileverReference) -> Self {
        let n = input.modes;
        let (length, ei, mass) = (input.length, input.bending_stiffness(), input.mass_per_length());
        let free = CantileverModes::new(&clamped_free_roots(n), length, ei, mass);
        let rk = input.stiffness_ratio();
        let spring = (input.contact_stiffness > 0.0)
            .then(|| CantileverModes::new(&clamped_spring_roots(n, 3.0 * rk), length, ei, mass));
        let static_tip = -rk * input.gap / (1.0 + rk);

        let rule = CompositeRule::for_modes(n);
        let weights: Vec<f64> = rule.weights.iter().map(|w| w * mass * length).collect();
        let tip_load_shape = |s: f64| 0.5 * s * s * (3.0 - s);
        let release: Vec<f64> = rule
            .nodes
            .iter()
            .map(|&s| input.tip_displacement * tip_load_shape(s))
            .collect();
        let throw: Vec<f64> = rule
            .nodes
            .iter()
            .map(|&s| input.tip_velocity * tip_load_shape(s))
            .collect();
        let static_shape: Vec<f64> = rule
            .nodes
            .iter()
            .map(|&s| static_tip * tip_load_shape(s))
            .collect();
        let inner = |a: &[f64], b: &[f64]| -> f64 {
            a.iter().zip(b).zip(&weights).map(|((x, y), w)| w * x * y).sum()
        };

        let free_table = free.tabulate(&rule);
        let free_damping: Vec<f64> = (0..n).map(|i| input.damping_ratio(i)).collect();
        let release_free = free_table.iter().map(|phi| inner(phi, &release)).collect();
        let throw_free = free_table.iter().map(|phi| inner(phi, &throw)).collect();
        let static_free = free_table.iter().map(|phi| inner(phi, &static_shape)).collect();
        let free_tip = free.shapes_at_reduced(1.0);

        let (mut projection, mut spring_damping, mut spring_tip) = (Vec::new(), Vec::new(), Vec::new());
        let (mut release_spring, mut static_spring, mut throw_spring) = (Vec::new(), Vec::new(), Vec::new());
        if let Some(spring) = &spring {
            let spring_table = spring.tabulate(&rule);
            projection = free_table
                .iter()
                .flat_map(|phi_f| {
                    spring_table
                        .iter()
                        .map(|phi_r| inner(phi_f, phi_r))
                        .collect::<Vec<_>>()
                })
                .collect();
            spring_damping = (0..n)
                .map(|j| {
                    let modal_damping: f64 = (0..n)
                        .map(|i| {
                            projection[i * n + j].powi(2)
                                * 2.0
                                * free_damping[i]
                                * free.angular_frequencies()[i]
                        })
                        .sum();
                    modal_damping / (2.0 * spring.angular_frequencies()[j])
                })
                .collect();
            let offset_release: Vec<f64> = release.iter().zip(&static_shape).map(|(w, s)| w - s).collect();
            release_spring = spring_table
                .iter()
                .map(|phi| inner(phi, &offset_release))
                .collect();
            static_spring = spring_table.iter().map(|phi| inner(phi, &static_shape)).collect();
            throw_spring = spring_table.iter().map(|phi| inner(phi, &throw)).collect();
            spring_tip = spring.shapes_at_reduced(1.0);
        }
        Self {
            free,
            spring,
            free_damping,
            spring_damping,
            projection,
            free_tip,
            spring_tip,
            release_free,
            release_spring,
            throw_free,
            throw_spring,
            static_free,
            static_spring,
            static_tip,
        }
    }

    /// Phase of `kind` starting at `start` from modal state (q, q̇) of its basis.
    fn phase(&self, kind: PhaseKind, start: f64, displacement: &[f64], velocity: &[f64]) -> Phase {
        let (basis, damping, tip_shapes, tip_offset) = match (kind, &self.spring) {
            (PhaseKind::Contact, Some(spring)) => {
                (spring, &self.spring_damping, &self.spring_tip, self.static_tip)
            }
            _ => (&self.free, &self.free_damping, &self.free_tip, 0.0),
        };
        let motions = basis
            .angular_frequencies()
            .iter()
            .enumerate()
            .map(|(i, &omega)| ModalMotion::new(omega, damping[i], displacement[i], velocity[i]))
            .collect();
        Phase {
            kind,
            start,
            end: start,
            tip_offset,
            motions,
            tip_shapes: tip_shapes.clone(),
        }
    }

    /// Modal state carried across a switch out of a phase of `from` kind.
    fn switch(&self, from: PhaseKind, displacement: &[f64], velocity: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let n = self.free.len();
        let p = &self.projection;
        match from {
            PhaseKind::Flight => (
                (0..n)
                    .map(|j| {
                        (0..n).map(|i| p[i * n + j] * displacement[i]).sum::<f64>() - self.static_spring[j]
                    })
                    .collect(),
                (0..n)
                    .map(|j| (0..n).map(|i| p[i * n + j] * velocity[i]).sum())
                    .collect(),
            ),
            PhaseKind::Contact => (
                (0..n)
                    .map(|i| {
                        (0..n).map(|j| p[i * n + j] * displacement[j]).sum::<f64>() + self.static_free[i]
                    })
                    .collect(),
                (0..n)
                    .map(|i| (0..n).map(|j| p[i * n + j] * velocity[j]).sum())
                    .collect(),
            ),
        }
    }

    /// Scan step base: 1/16 of the shortest period of the basis of `kind` (s).
    fn scan_step(&self, kind: PhaseKind) -> f64 {
        let basis = match (kind, &self.spring) {
            (PhaseKind::Contact, Some(spring)) => spring,
            _ => &self.free,
        };
        let omega_max = basis.angular_frequencies().iter().fold(0.0_f64, |a, &b| a.max(b));
        2.0 * PI / omega_max / SAMPLES_PER_PERIOD
    }
}

/// What scanning one phase found.
struct ScanOutcome {
    /// τ of the switching instant, if one happens before τ_max.
    event: Option<f64>,
    /// Smallest w(L) (m) over the phase and its τ.
    minimum: (f64, f64),
}

/// Scans `phase` over [0, τ_max] for the first exit from its contact state
/// (flight: w(L) + g ≤ 0; contact: w(L) + g ≥ 0) and for its minimum tip deflection.
fn scan(phase: &Phase, tau_max: f64, base_step: f64, gap: f64, can_switch: bool) -> ScanOutcome {
    // e > 0 while the phase's contact state holds.
    let inside_sign = match phase.kind {
        PhaseKind::Flight => 1.0,
        PhaseKind::Contact => -1.0,
    };
    let state_margin = |tip: f64| inside_sign * (tip + gap);
    let step_count = (tau_max / base_step).ceil().max(1.0) as usize;
    let step = tau_max / step_count as f64;
    let mut walker = phase.walker(0.0, step);
    let first_tip = walker.next_tip();
    let mut armed = state_margin(first_tip) > 0.0;
    if can_switch && !armed && inside_sign * phase.tip_rate(0.0) < 0.0 {
        return ScanOutcome {
            event: Some(0.0),
            minimum: (first_tip, 0.0),
        };
    }
    let mut minima = LowestMinima::default();
    let (mut before_previous, mut previous) = (f64::INFINITY, first_tip);
    let mut event = None;
    let mut last_index = step_count;
    for k in 1..=step_count {
        let tip = walker.next_tip();
        if before_previous > previous && previous <= tip {
            minima.offer(previous, k - 1);
        }
        let margin = state_margin(tip);
        if can_switch && armed && margin <= 0.0 {
            let (a, b) = ((k - 1) as f64 * step, k as f64 * step);
            let f = |tau: f64| state_margin(phase.tip(tau));
            event = Some(find_root(f, a, b, f(a), f(b)).unwrap_or(b));
            last_index = k;
            break;
        }
        if !armed {
            if margin > 0.0 {
                armed = true;
            } else if margin < state_margin(previous) && can_switch {
                event = Some(0.0);
                last_index = 0;
                break;
            }
        }
        before_previous = previous;
        previous = tip;
    }
    let end = event.unwrap_or(tau_max);
    let mut minimum = (first_tip, 0.0);
    let end_tip = phase.tip(end);
    if end_tip < minimum.0 {
        minimum = (end_tip, end);
    }
    for &(sampled, index) in minima.entries() {
        if index >= last_index {
            continue;
        }
        let candidate = refine_minimum(phase, index, step, end).unwrap_or((sampled, index as f64 * step));
        if candidate.0 < minimum.0 {
            minimum = candidate;
        }
    }
    ScanOutcome { event, minimum }
}

/// Local minimum of w(L) near sample `index`: Brent root of ∂w(L)/∂t between the
/// neighbouring samples when it changes sign there.
fn refine_minimum(phase: &Phase, index: usize, step: f64, end: f64) -> Option<(f64, f64)> {
    let a = (index.saturating_sub(1)) as f64 * step;
    let b = ((index + 1) as f64 * step).min(end);
    let (rate_a, rate_b) = (phase.tip_rate(a), phase.tip_rate(b));
    if !(rate_a <= 0.0 && rate_b >= 0.0) {
        return None;
    }
    let tau = find_root(|tau| phase.tip_rate(tau), a, b, rate_a, rate_b)?;
    Some((phase.tip(tau), tau))
}

/// The few lowest sampled local minima of a phase: (w(L), sample index).
#[derive(Default)]
struct LowestMinima {
    entries: Vec<(f64, usize)>,
}

impl LowestMinima {
    fn offer(&mut self, value: f64, index: usize) {
        if self.entries.len() < REFINED_MINIMA {
            self.entries.push((value, index));
        } else if let Some(worst) = self.entries.iter_mut().max_by(|x, y| x.0.total_cmp(&y.0))
            && value < worst.0
        {
            *worst = (value, index);
        }
    }

    fn entries(&self) -> &[(f64, usize)] {
        &self.entries
    }
}

/// Runs the flight/contact loop; see the module doc.
pub(super) fn solve(
    input: &CantileverReference,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<ReferenceSolution, ReferenceError> {
    let setup = Setup::new(input);
    let (gap, duration) = (input.gap, input.duration);
    let can_switch = setup.spring.is_some();
    let finest_step = setup.scan_step(PhaseKind::Flight).min(if can_switch {
        setup.scan_step(PhaseKind::Contact)
    } else {
        f64::INFINITY
    });
    let samples = duration / finest_step;
    if !samples.is_finite() || samples > MAX_SCAN_SAMPLES {
        return Err(ReferenceError::TooExpensive { samples });
    }

    let mut events = Vec::new();
    let (mut kind, (mut displacement, mut velocity)) = if can_switch && input.tip_displacement + gap < 0.0 {
        events.push(ContactEvent {
            time: 0.0,
            kind: ContactEventKind::Impact,
        });
        (
            PhaseKind::Contact,
            (setup.release_spring.clone(), setup.throw_spring.clone()),
        )
    } else {
        (
            PhaseKind::Flight,
            (setup.release_free.clone(), setup.throw_free.clone()),
        )
    };
    let mut phases: Vec<Phase> = Vec::new();
    let mut max_contact_force = Extreme {
        value: 0.0,
        time: 0.0,
    };
    let mut min_tip_deflection = Extreme {
        value: f64::INFINITY,
        time: 0.0,
    };
    let mut stopped_by_event_limit = false;
    let mut zero_length_phases = 0;
    let mut start = 0.0;
    loop {
        let mut phase = setup.phase(kind, start, &displacement, &velocity);
        let outcome = scan(&phase, duration - start, setup.scan_step(kind), gap, can_switch);
        let (lowest_tip, lowest_tau) = outcome.minimum;
        if !lowest_tip.is_finite() {
            return Err(ReferenceError::NumericalFailure("non-finite tip deflection"));
        }
        if lowest_tip < min_tip_deflection.value {
            min_tip_deflection = Extreme {
                value: lowest_tip,
                time: start + lowest_tau,
            };
        }
        if kind == PhaseKind::Contact {
            let force = input.contact_stiffness * (-lowest_tip - gap);
            if force > max_contact_force.value {
                max_contact_force = Extreme {
                    value: force,
                    time: start + lowest_tau,
                };
            }
        }
        let Some(tau) = outcome.event else {
            phase.end = duration;
            phases.push(phase);
            break;
        };
        phase.end = start + tau;
        if events.len() >= input.max_events {
            stopped_by_event_limit = true;
            phases.push(phase);
            break;
        }
        zero_length_phases = if tau == 0.0 { zero_length_phases + 1 } else { 0 };
        if zero_length_phases > MAX_ZERO_LENGTH_PHASES {
            return Err(ReferenceError::NumericalFailure(
                "contact switching does not progress",
            ));
        }
        let (end_displacement, end_velocity) = phase.modal_state(tau);
        (displacement, velocity) = setup.switch(kind, &end_displacement, &end_velocity);
        kind = match kind {
            PhaseKind::Flight => PhaseKind::Contact,
            PhaseKind::Contact => PhaseKind::Flight,
        };
        let event_kind = match kind {
            PhaseKind::Contact => ContactEventKind::Impact,
            PhaseKind::Flight => ContactEventKind::Release,
        };
        events.push(ContactEvent {
            time: phase.end,
            kind: event_kind,
        });
        start = phase.end;
        phases.push(phase);
        if progress(start / duration).is_break() {
            return Err(ReferenceError::Cancelled { time: start });
        }
    }
    if progress(1.0).is_break() {
        return Err(ReferenceError::Cancelled { time: duration });
    }
    let to_hz = |basis: &CantileverModes| {
        basis
            .angular_frequencies()
            .iter()
            .map(|w| w / (2.0 * PI))
            .collect()
    };
    Ok(ReferenceSolution {
        events,
        contact_stiffness: input.contact_stiffness,
        gap,
        free_frequencies_hz: to_hz(&setup.free),
        contact_frequencies_hz: setup.spring.as_ref().map(to_hz).unwrap_or_default(),
        contact_damping_ratios: setup.spring_damping.clone(),
        max_contact_force,
        min_tip_deflection,
        stopped_by_event_limit,
        phases,
    })
}
