//! Gauss–Legendre quadrature on the reduced beam abscissa s = x/L ∈ [0, 1].
//!
//! Owns the node/weight computation (Newton iterations on the Legendre polynomial,
//! no tables) and the composite rule used for every mass inner product of the
//! reference: mode normalization, basis-to-basis projection, initial conditions.

/// Points per panel of the composite rule: exact for polynomials of degree 31 on each
/// panel, i.e. far beyond one oscillation of a product of two retained modes.
pub(super) const POINTS_PER_PANEL: usize = 16;

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1].
///
/// Newton's method on Pₙ(x) from the Tricomi-like guess xᵢ ≈ cos(π(i − ¼)/(n + ½)),
/// with Pₙ and Pₙ' from the three-term recurrence
/// (k+1)P_{k+1} = (2k+1) x P_k − k P_{k−1}, P'ₙ = n (x Pₙ − P_{n−1})/(x² − 1);
/// weights wᵢ = 2 / ((1 − xᵢ²) P'ₙ(xᵢ)²).
pub(super) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut derivative = 1.0;
        for _ in 0..100 {
            let (p_n, p_n_minus_1) = legendre_pair(n, x);
            derivative = nf * (x * p_n - p_n_minus_1) / (x * x - 1.0);
            let step = p_n / derivative;
            x -= step;
            if step.abs() <= 1e-16 {
                break;
            }
        }
        let (p_n, p_n_minus_1) = legendre_pair(n, x);
        if p_n.is_finite() && p_n_minus_1.is_finite() {
            derivative = nf * (x * p_n - p_n_minus_1) / (x * x - 1.0);
        }
        let weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = weight;
        weights[n - 1 - i] = weight;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    (nodes, weights)
}

/// (Pₙ(x), Pₙ₋₁(x)) by the three-term recurrence.
fn legendre_pair(n: usize, x: f64) -> (f64, f64) {
    let mut previous = 1.0;
    let mut current = x;
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 1..n {
        let kf = k as f64;
        let next = ((2.0 * kf + 1.0) * x * current - kf * previous) / (kf + 1.0);
        previous = current;
        current = next;
    }
    (current, previous)
}

/// Composite Gauss–Legendre rule on [0, 1]: `panels` equal panels of
/// [`POINTS_PER_PANEL`] points each. ∫₀¹ f(s) ds ≈ Σ wₖ f(sₖ).
#[derive(Debug, Clone)]
pub(super) struct CompositeRule {
    /// Abscissae sₖ ∈ (0, 1), increasing.
    pub nodes: Vec<f64>,
    /// Weights wₖ (sum to 1).
    pub weights: Vec<f64>,
}

impl CompositeRule {
    /// Rule with `panels.max(1)` panels.
    pub fn new(panels: usize) -> Self {
        let panels = panels.max(1);
        let (reference_nodes, reference_weights) = gauss_legendre(POINTS_PER_PANEL);
        let width = 1.0 / panels as f64;
        let mut nodes = Vec::with_capacity(panels * POINTS_PER_PANEL);
        let mut weights = Vec::with_capacity(panels * POINTS_PER_PANEL);
        for panel in 0..panels {
            let left = panel as f64 * width;
            for (node, weight) in reference_nodes.iter().zip(&reference_weights) {
                nodes.push(left + 0.5 * width * (node + 1.0));
                weights.push(0.5 * width * weight);
            }
        }
        Self { nodes, weights }
    }

    /// Panels needed to integrate products of two of the first `modes` beam modes:
    /// a product of modes i, j oscillates with wavenumber ≲ (i + j)π, so one panel
    /// per retained mode keeps about one oscillation per 16-point panel.
    pub fn for_modes(modes: usize) -> Self {
        Self::new(modes.max(4) + 4)
    }

    /// ∫₀¹ f(s) ds.
    #[cfg(test)]
    pub fn integrate(&self, mut integrand: impl FnMut(f64) -> f64) -> f64 {
        self.nodes
            .iter()
            .zip(&self.weights)
            .map(|(&s, &w)| w * integrand(s))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // An n-point Gauss–Legendre rule integrates every polynomial of degree ≤ 2n − 1
    // exactly: check ∫₋₁¹ x^k dx = 2/(k+1) (k even), 0 (k odd) for the 16-point rule.
    #[test]
    fn gauss_legendre_is_exact_for_degree_2n_minus_1() {
        let (nodes, weights) = gauss_legendre(POINTS_PER_PANEL);
        for degree in 0..(2 * POINTS_PER_PANEL) {
            let measured: f64 = nodes
                .iter()
                .zip(&weights)
                .map(|(x, w)| w * x.powi(degree as i32))
                .sum();
            let expected = if degree % 2 == 0 {
                2.0 / (degree as f64 + 1.0)
            } else {
                0.0
            };
            assert!(
                (measured - expected).abs() < 1e-14,
                "degree {degree}: measured {measured}, expected {expected}"
            );
        }
    }

    // The composite rule must integrate the fast oscillations met by products of the
    // highest retained modes: ∫₀¹ cos(k s) ds = sin(k)/k with k ≈ 2 × λ₆₀ ≈ 380.
    #[test]
    fn composite_rule_integrates_fast_oscillations() {
        let rule = CompositeRule::for_modes(60);
        for wavenumber in [1.0_f64, 37.3, 190.0, 379.9] {
            let measured = rule.integrate(|s| (wavenumber * s).cos());
            let expected = wavenumber.sin() / wavenumber;
            assert!(
                (measured - expected).abs() < 1e-14,
                "k = {wavenumber}: measured {measured}, expected {expected}"
            );
        }
    }
}
