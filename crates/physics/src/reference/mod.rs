//! Semi-analytic reference of a cantilever whose tip hits a linear spring (paper
//! section 2, BRIEF §5): the public input, its validation, and the typed errors.
//!
//! The beam (clamped at x = 0, uniform, Euler–Bernoulli) is released from the static
//! tip-load shape w(x) = u₀ ψ(x), ψ(x) = (x/L)²(3 − x/L)/2, moving in that shape with
//! the velocity ẇ(x) = v₀ ψ(x) (v₀ = 0: at rest). While w(L) + g ≥ 0 it
//! flies on its clamped-free modes; while w(L) < −g the spring Kc pushes back with
//! F = Kc(−w(L) − g) and the beam moves on its clamped-spring modes around the static
//! solution of that phase. Each phase is solved in closed form; the switching instants
//! are located to machine precision and the fields projected from one basis onto the
//! other (submodules `modes`, `phases`, `solution`).

mod brent;
mod modes;
mod oscillator;
mod phase;
mod phases;
mod quadrature;
mod solution;

pub use modes::{CantileverModes, MAX_MODES, clamped_free_roots, clamped_pinned_roots, clamped_spring_roots};
pub use phase::PhaseKind;
pub use solution::{ContactEvent, ContactEventKind, Extreme, ReferenceSolution, TipHistory};

use std::ops::ControlFlow;

/// Largest number of scan samples a solve may need (duration over the scan step):
/// a guard against inputs that would run for hours.
pub const MAX_SCAN_SAMPLES: f64 = 2e8;

/// Input of the reference: geometry, material, contact, release and run control.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverReference {
    /// Beam length L (m), > 0.
    pub length: f64,
    /// Young's modulus E (Pa), > 0.
    pub young_modulus: f64,
    /// Density ρ (kg/m³), > 0.
    pub density: f64,
    /// Cross-section area A (m²), > 0.
    pub area: f64,
    /// Second moment of area I (m⁴), > 0.
    pub inertia: f64,
    /// Added mass per unit length (kg/m), ≥ 0; the modal mass is m = ρA + this.
    pub added_mass_per_length: f64,
    /// Tip spring stiffness Kc (N/m), ≥ 0; 0 means no contact (free vibration).
    /// Rk = Kc L³/(3EI).
    pub contact_stiffness: f64,
    /// Gap g (m), ≥ 0: contact while w(L) < −g.
    pub gap: f64,
    /// Modal damping ratios ξᵢ of the clamped-free modes (dimensionless, ≥ 0): one per
    /// mode; a shorter list repeats its last value; empty means undamped.
    pub damping_ratios: Vec<f64>,
    /// Tip deflection u₀ of the release shape (m), any sign.
    pub tip_displacement: f64,
    /// Tip velocity v₀ (m/s) of the release shape at t = 0, any sign (0: at rest).
    pub tip_velocity: f64,
    /// Simulated duration (s), > 0.
    pub duration: f64,
    /// Modes per basis (clamped-free and clamped-spring), 1..=[`MAX_MODES`].
    pub modes: usize,
    /// Largest number of impacts + releases; the run ends at the next one.
    pub max_events: usize,
}

/// Why a reference solve or evaluation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    /// A scalar input is outside its domain.
    #[error("{field} must be {requirement}, got {value}")]
    InvalidInput {
        field: &'static str,
        requirement: &'static str,
        value: f64,
    },
    /// The number of modes is outside 1..=MAX_MODES.
    #[error("modes must be between 1 and {MAX_MODES}, got {0}")]
    InvalidModeCount(usize),
    /// The run would need too many scan samples (duration × highest frequency).
    #[error("the run needs about {samples:.3e} scan samples, more than the limit {MAX_SCAN_SAMPLES:.0e}")]
    TooExpensive { samples: f64 },
    /// The progress callback asked to stop.
    #[error("cancelled at t = {time} s")]
    Cancelled { time: f64 },
    /// A requested time lies outside the solved interval.
    #[error("time {time} s is outside the solved interval [0, {end}] s")]
    TimeOutOfRange { time: f64, end: f64 },
    /// Non-finite numbers appeared (inputs too extreme for double precision).
    #[error("numerical failure: {0}")]
    NumericalFailure(&'static str),
}

impl CantileverReference {
    /// Mass per unit length m = ρA + added mass (kg/m).
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.area + self.added_mass_per_length
    }

    /// Bending stiffness EI (N·m²).
    pub fn bending_stiffness(&self) -> f64 {
        self.young_modulus * self.inertia
    }

    /// Static tip stiffness of the cantilever 3EI/L³ (N/m).
    pub fn tip_stiffness(&self) -> f64 {
        3.0 * self.bending_stiffness() / self.length.powi(3)
    }

    /// Rk = Kc L³/(3EI) (dimensionless).
    pub fn stiffness_ratio(&self) -> f64 {
        self.contact_stiffness / self.tip_stiffness()
    }

    /// ξ of clamped-free mode `index` (0-based): the list value, its last value past
    /// its end, 0 for an empty list.
    pub fn damping_ratio(&self, index: usize) -> f64 {
        self.damping_ratios
            .get(index)
            .or(self.damping_ratios.last())
            .copied()
            .unwrap_or(0.0)
    }

    /// Checks every field; see the field docs for the domains.
    pub fn validate(&self) -> Result<(), ReferenceError> {
        let positive = [
            ("length", self.length),
            ("young_modulus", self.young_modulus),
            ("density", self.density),
            ("area", self.area),
            ("inertia", self.inertia),
            ("duration", self.duration),
        ];
        for (field, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(ReferenceError::InvalidInput {
                    field,
                    requirement: "finite and > 0",
                    value,
                });
            }
        }
        let non_negative = [
            ("added_mass_per_length", self.added_mass_per_length),
            ("contact_stiffness", self.contact_stiffness),
            ("gap", self.gap),
        ];
        for (field, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ReferenceError::InvalidInput {
                    field,
                    requirement: "finite and >= 0",
                    value,
                });
            }
        }
        if let Some(&bad) = self
            .damping_ratios
            .iter()
            .find(|v| !(v.is_finite() && **v >= 0.0))
        {
            return Err(ReferenceError::InvalidInput {
                field: "damping_ratios",
                requirement: "finite and >= 0",
                value: bad,
            });
        }
        for (field, value) in [
            ("tip_displacement", self.tip_displacement),
            ("tip_velocity", self.tip_velocity),
        ] {
            if !value.is_finite() {
                return Err(ReferenceError::InvalidInput {
                    field,
                    requirement: "finite",
                    value,
                });
            }
        }
        if self.modes == 0 || self.modes > MAX_MODES {
            return Err(ReferenceError::InvalidModeCount(self.modes));
        }
        let derived = [
            self.mass_per_length(),
            self.bending_stiffness(),
            self.tip_stiffness(),
            self.stiffness_ratio(),
        ];
        if derived.iter().any(|v| !v.is_finite() || *v < 0.0) || self.tip_stiffness() == 0.0 {
            return Err(ReferenceError::NumericalFailure(
                "EI, m or 3EI/L³ is not a finite positive number",
            ));
        }
        Ok(())
    }

    /// Solves the impact history over [0, `duration`].
    ///
    /// `progress` receives the solved fraction of the duration (0..=1) after each
    /// phase; returning `ControlFlow::Break(())` stops with [`ReferenceError::Cancelled`].
    pub fn solve(
        &self,
        progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
    ) -> Result<ReferenceSolution, ReferenceError> {
        self.validate()?;
        phases::solve(self, progress)
    }
}

#[cfg(test)]
mod tests;
