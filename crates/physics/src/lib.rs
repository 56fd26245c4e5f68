//! Pure numerics. Nothing in here performs IO, spawns threads or knows about the
//! service: functions take inputs (SI units) and a progress/cancel callback and return
//! results or a typed error.
//!
//! Validation errors name the offending field by a slash path relative to the struct
//! being checked (`section/outer_diameter`); callers prefix it with where that struct
//! sits in their own input document (`/inputs/beam/`).

/// Summary figures of an accelerogram: sampling, PGA, Arias intensity.
pub mod accelerogram;
pub mod beam;
pub mod bundle;
pub mod contact;
/// Wire-wrapped hexagonal bundle geometry: lattice, wrapper, wire-helix contacts, gap states.
pub mod hex;
/// Impact counting, per-impact tables and statistics (code_aster `POST_DYNA_MODA_T`).
pub mod impacts;
pub mod integrate;
pub mod loads;
pub mod modal;
/// Elementary functions from `+ − × ÷` only: the same bits on every machine.
pub mod portable;
/// A seeded, bit-reproducible random stream and its samplers (gaps, sweep sampling).
pub mod random;
/// Exact (up to modal truncation) cantilever / tip-spring impact solution (paper §2).
pub mod reference;
/// Pseudo-acceleration response spectra (and shock response spectra) of signals.
pub mod response_spectrum;
/// One-sided periodogram and the spectral error function f_err (paper eq. 11).
pub mod spectrum;
pub mod stability;
pub mod static_correction;
pub mod statistics;
/// Spectrum-compatible synthetic accelerograms (seeded, bit-reproducible).
pub mod synthetic;

/// One problem with a physics input: which field (slash path relative to the checked
/// struct) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct InputIssue {
    pub field: String,
    pub reason: String,
}

impl InputIssue {
    pub fn new(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// The same issue, seen from a containing struct (`prefix/field`).
    pub fn within(self, prefix: &str) -> Self {
        let field = if self.field.is_empty() {
            prefix.to_owned()
        } else {
            format!("{prefix}/{}", self.field)
        };
        Self {
            field,
            reason: self.reason,
        }
    }
}

/// `value` rounded to 12 significant digits: a height computed as `first + k·spacing` or
/// `node · element length` printed as the decimal it stands for (0.6, not
/// 0.6000000000000001), 1e-12 relative being far below any geometric meaning.
pub fn decimal(value: f64) -> f64 {
    if value == 0.0 || !value.is_finite() {
        return value;
    }
    format!("{value:.11e}").parse().unwrap_or(value)
}

/// Checks that `value` is finite and strictly positive; records an issue otherwise.
pub fn require_positive(issues: &mut Vec<InputIssue>, field: &str, value: f64) {
    if !value.is_finite() {
        issues.push(InputIssue::new(field, "must be a finite number"));
    } else if value <= 0.0 {
        issues.push(InputIssue::new(field, format!("must be positive (got {value})")));
    }
}

/// Checks that `value` is finite and non-negative; records an issue otherwise.
pub fn require_non_negative(issues: &mut Vec<InputIssue>, field: &str, value: f64) {
    if !value.is_finite() {
        issues.push(InputIssue::new(field, "must be a finite number"));
    } else if value < 0.0 {
        issues.push(InputIssue::new(
            field,
            format!("must not be negative (got {value})"),
        ));
    }
}
