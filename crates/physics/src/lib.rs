//! Pure numerics. Nothing in here performs IO, spawns threads or knows about the
//! service: functions take inputs (SI units) and a progress/cancel callback and return
//! results or a typed error.
//!
//! Validation errors name the offending field by a slash path relative to the struct
//! being checked (`section/outer_diameter`); callers prefix it with where that struct
//! sits in their own input document (`/inputs/beam/`).

/// The acceleration of a sampled displacement history (second divided differences).
pub mod acceleration;
/// Summary figures of an accelerogram: sampling, PGA, Arias intensity.
pub mod accelerogram;
pub mod beam;
pub mod bundle;
pub mod contact;
pub mod discretisation;
/// Wire-wrapped hexagonal bundle geometry: lattice, wrapper, wire-helix contacts, gap states.
pub mod hex;
/// Impact counting, per-impact tables and statistics (code_aster `POST_DYNA_MODA_T`).
pub mod impacts;
pub mod integrate;
pub mod loads;
pub mod modal;
pub mod portable;
/// Elementary functions from `+ − × ÷` only: the same bits on every machine.
/// PWR fuel assemblies: the square lattice of rods, guide tubes and the instrumentation tube.
pub mod pwr;
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
pub mod wear;

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

/// `value` when finite (a critical step is infinite for a scheme without a stability
/// limit: reported as null).
pub fn finite(value: f64) -> Option<f64> {
    value.is_finite().then_some(value)
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

/// `value` as text for a message: six significant digits at most (1.4, not
/// 1.4000000000000001), plain between 1e-3 and 1e6 (0.0097, 1800), in scientific
/// notation outside (2.1e11, 1e-300, 1e308), never hundreds of digits.
pub fn number(value: f64) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let rounded: f64 = format!("{value:.5e}").parse().unwrap_or(value);
    if (1e-3..1e6).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// `value` as [`number`] prints it, unless it would read like `bound` (a value just
/// beyond a bound, 1.0000001e9 beside 1e9): then every digit, so that the message shows
/// why it is refused.
pub fn number_beside(value: f64, bound: f64) -> String {
    let short = number(value);
    if value != bound && short == number(bound) {
        format!("{value:e}")
    } else {
        short
    }
}

/// Checks that `value` is finite and strictly positive; records an issue otherwise.
pub fn require_positive(issues: &mut Vec<InputIssue>, field: &str, value: f64) {
    if !value.is_finite() {
        issues.push(InputIssue::new(field, "must be a finite number"));
    } else if value <= 0.0 {
        issues.push(InputIssue::new(
            field,
            format!("must be positive (got {})", number(value)),
        ));
    }
}

/// Checks that `value` is finite and non-negative; records an issue otherwise.
pub fn require_non_negative(issues: &mut Vec<InputIssue>, field: &str, value: f64) {
    if !value.is_finite() {
        issues.push(InputIssue::new(field, "must be a finite number"));
    } else if value < 0.0 {
        issues.push(InputIssue::new(
            field,
            format!("must not be negative (got {})", number(value)),
        ));
    }
}

#[cfg(test)]
mod number_tests {
    use super::{number, number_beside};

    /// A value just beyond a bound is printed with every digit, not as the bound.
    #[test]
    fn a_value_beside_its_bound_shows_why_it_is_refused() {
        assert_eq!(number_beside(1.0000001e9, 1e9), "1.0000001e9");
        assert_eq!(number_beside(2e9, 1e9), "2e9");
        assert_eq!(number_beside(1e9, 1e9), "1e9");
    }

    /// Messages print what a person would type: the shortest decimal of the value at six
    /// significant digits, with an exponent only far from 1.
    #[test]
    fn numbers_print_at_sensible_precision() {
        let cases = [
            (0.1 + 0.2, "0.3"),
            (1.4000000000000001, "1.4"),
            (0.0097, "0.0097"),
            (1800.0, "1800"),
            (2.1e11, "2.1e11"),
            (1e308, "1e308"),
            (1e-300, "1e-300"),
            (-0.5, "-0.5"),
            (9.765914, "9.76591"),
            (0.0, "0"),
            (123456.7, "123457"),
            (1234567.0, "1.23457e6"),
        ];
        for (value, expected) in cases {
            assert_eq!(number(value), expected, "number({value:e})");
        }
    }
}
