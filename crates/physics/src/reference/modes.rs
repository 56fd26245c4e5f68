//! Analytic bending modes of a uniform Euler–Bernoulli cantilever (clamped at x = 0):
//! frequency equations, robust root bracketing, stable shape evaluation and mass
//! normalization.
//!
//! With s = x/L and φ(s) = A(cosh λs − cos λs) + B(sinh λs − sin λs) (clamped at 0):
//! - the moment condition φ''(1) = 0 gives B = −σA with σ = (cosh λ + cos λ)/(sinh λ + sin λ),
//!   for the free tip *and* for the spring tip (the spring only enters the shear
//!   condition), so both bases share φ(s) = cosh λs − cos λs − σ(sinh λs − sin λs);
//! - the shear condition EI w'''(L) = Kc w(L), i.e. φ'''(1) = R φ(1) with R = Kc L³/EI,
//!   then gives λ³(1 + cos λ cosh λ) + R(sin λ cosh λ − cos λ sinh λ) = 0
//!   (R = 0: clamped-free 1 + cos λ cosh λ = 0; R → ∞: clamped-pinned tan λ = tanh λ).
//!
//! The i-th clamped-spring eigenvalue grows monotonically with R (Rayleigh) from the
//! i-th clamped-free root to the i-th clamped-pinned root, and the latter lies below the
//! (i+1)-th clamped-free root: [free_i, pinned_i] brackets exactly one root, so roots
//! are never skipped nor duplicated. The equation is evaluated divided by cosh λ.

use super::brent::find_root;
use super::quadrature::CompositeRule;
use std::f64::consts::PI;

/// Largest number of modes per basis the reference supports.
pub const MAX_MODES: usize = 60;

/// i-th root (1-based) of 1 + cos λ cosh λ = 0, bracketed in [(i−1)π, iπ].
fn clamped_free_root(index: usize) -> f64 {
    let f = |lambda: f64| lambda.cos() + 1.0 / lambda.cosh();
    let (a, b) = ((index as f64 - 1.0) * PI, index as f64 * PI);
    // The bracket always changes sign (|sech| < 1); the fallback is the asymptote.
    find_root(f, a, b, f(a), f(b)).unwrap_or((index as f64 - 0.5) * PI)
}

/// i-th root (1-based) of tan λ = tanh λ (λ > 0), bracketed in [iπ, iπ + π/2].
fn clamped_pinned_root(index: usize) -> f64 {
    let f = |lambda: f64| lambda.sin() - lambda.cos() * lambda.tanh();
    let (a, b) = (index as f64 * PI, (index as f64 + 0.5) * PI);
    find_root(f, a, b, f(a), f(b)).unwrap_or((index as f64 + 0.25) * PI)
}

/// First `count` roots of 1 + cos λ cosh λ = 0 (clamped-free cantilever).
pub fn clamped_free_roots(count: usize) -> Vec<f64> {
    (1..=count).map(clamped_free_root).collect()
}

/// First `count` roots of tan λ = tanh λ (clamped-pinned beam).
pub fn clamped_pinned_roots(count: usize) -> Vec<f64> {
    (1..=count).map(clamped_pinned_root).collect()
}

/// First `count` roots of λ³(1 + cos λ cosh λ) + R(sin λ cosh λ − cos λ sinh λ) = 0
/// (cantilever with a tip spring, R = Kc L³/EI ≥ 0, dimensionless).
///
/// Solved as [λ³(sech λ + cos λ) + R(sin λ − cos λ tanh λ)]/(λ³ + R) = 0 in
/// [free_i, pinned_i]. When rounding hides the sign change (R below ~1e-14 λ³ or above
/// ~1e14 λ³) the root is the bracket end whose residual is smaller.
pub fn clamped_spring_roots(count: usize, stiffness_ratio: f64) -> Vec<f64> {
    let r = stiffness_ratio;
    if r <= 0.0 || !r.is_finite() {
        return clamped_free_roots(count);
    }
    let residual = |lambda: f64| {
        let cube = lambda * lambda * lambda;
        (cube * (1.0 / lambda.cosh() + lambda.cos()) + r * (lambda.sin() - lambda.cos() * lambda.tanh()))
            / (cube + r)
    };
    (1..=count)
        .map(|index| {
            let (a, b) = (clamped_free_root(index), clamped_pinned_root(index));
            let (fa, fb) = (residual(a), residual(b));
            find_root(residual, a, b, fa, fb).unwrap_or(if fa.abs() <= fb.abs() { a } else { b })
        })
        .collect()
}

/// Coefficients of one analytic mode shape, evaluated without overflow:
/// φ(s) = c_grow e^{λ(s−1)} + c_decay e^{−λs} − cos λs + σ sin λs, where
/// c_grow e^{λ(s−1)} = (1−σ)e^{λs}/2 and c_decay = (1+σ)/2. With E = e^{−λ},
/// D = 1 − E² + 2E sin λ: σ = (1 + E² + 2E cos λ)/D and (1 − σ)/2 = E(sin λ − cos λ − E)/D,
/// so c_grow = (sin λ − cos λ − E)/D has no cancellation for any λ.
#[derive(Debug, Clone, Copy)]
struct ShapeCoefficients {
    lambda: f64,
    sigma: f64,
    grow: f64,
    decay: f64,
}

impl ShapeCoefficients {
    fn new(lambda: f64) -> Self {
        let e = (-lambda).exp();
        let (sin, cos) = lambda.sin_cos();
        let denominator = 1.0 - e * e + 2.0 * e * sin;
        let sigma = (1.0 + e * e + 2.0 * e * cos) / denominator;
        Self {
            lambda,
            sigma,
            grow: (sin - cos - e) / denominator,
            decay: 0.5 * (1.0 + sigma),
        }
    }

    /// Unnormalized φ(s), s ∈ [0, 1].
    fn value(&self, s: f64) -> f64 {
        let y = self.lambda * s;
        let (sin, cos) = y.sin_cos();
        self.grow * (y - self.lambda).exp() + self.decay * (-y).exp() - cos + self.sigma * sin
    }
}

/// Mass-normalized analytic modes of one cantilever configuration.
#[derive(Debug, Clone)]
pub struct CantileverModes {
    length: f64,
    shapes: Vec<ShapeCoefficients>,
    /// Factor turning φ(s) into the mass-normalized shape (1/√kg).
    normalization: Vec<f64>,
    /// ωᵢ = λᵢ² √(EI/m) / L² (rad/s).
    angular_frequencies: Vec<f64>,
}

impl CantileverModes {
    /// Modes for the eigenvalues `roots` (λᵢ) of a beam of `length` (m), bending
    /// stiffness `bending_stiffness` EI (N·m²) and mass per length `mass_per_length`
    /// m (kg/m), normalized so that ∫₀ᴸ m φᵢ² dx = 1 by composite Gauss–Legendre
    /// quadrature.
    pub fn new(roots: &[f64], length: f64, bending_stiffness: f64, mass_per_length: f64) -> Self {
        let shapes: Vec<ShapeCoefficients> = roots.iter().map(|&l| ShapeCoefficients::new(l)).collect();
        let rule = CompositeRule::for_modes(roots.len());
        let normalization = shapes
            .iter()
            .map(|shape| {
                let integral: f64 = rule
                    .nodes
                    .iter()
                    .zip(&rule.weights)
                    .map(|(&s, &w)| w * shape.value(s).powi(2))
                    .sum();
                1.0 / (mass_per_length * length * integral).sqrt()
            })
            .collect();
        let wave_speed = (bending_stiffness / mass_per_length).sqrt() / (length * length);
        let angular_frequencies = roots.iter().map(|l| l * l * wave_speed).collect();
        Self {
            length,
            shapes,
            normalization,
            angular_frequencies,
        }
    }

    /// Number of modes.
    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// True when the basis holds no mode.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// Angular frequencies ωᵢ (rad/s).
    pub fn angular_frequencies(&self) -> &[f64] {
        &self.angular_frequencies
    }

    /// Eigenvalues λᵢ (dimensionless).
    pub fn roots(&self) -> Vec<f64> {
        self.shapes.iter().map(|s| s.lambda).collect()
    }

    /// Mass-normalized shape of mode `index` (0-based) at abscissa `x` (m), in 1/√kg;
    /// 0 for an index out of range.
    pub fn shape(&self, index: usize, x: f64) -> f64 {
        match (self.shapes.get(index), self.normalization.get(index)) {
            (Some(shape), Some(scale)) => scale * shape.value(x / self.length),
            _ => 0.0,
        }
    }

    /// Mass-normalized shapes of every mode at the reduced abscissa s = x/L.
    pub(super) fn shapes_at_reduced(&self, s: f64) -> Vec<f64> {
        self.shapes
            .iter()
            .zip(&self.normalization)
            .map(|(shape, scale)| scale * shape.value(s))
            .collect()
    }

    /// Shape values at every node of `rule`: result[i][k] = φᵢ(sₖ L).
    pub(super) fn tabulate(&self, rule: &CompositeRule) -> Vec<Vec<f64>> {
        self.shapes
            .iter()
            .zip(&self.normalization)
            .map(|(shape, scale)| rule.nodes.iter().map(|&s| scale * shape.value(s)).collect())
            .collect()
    }
}

#[cfg(test)]
#[path = "modes_tests.rs"]
mod tests;
