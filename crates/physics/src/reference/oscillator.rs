//! Closed-form free response of one damped modal oscillator (paper eq. 5–7),
//! valid for under-, critically and over-damped modes.
//!
//! q̈ + 2ξω q̇ + ω² q = 0 with q(0) = q₀, q̇(0) = v₀ has, with a = ξω, κ = ω²(1 − ξ²),
//! b = v₀ + a q₀:
//!   q(τ) = e^{−aτ} (q₀ C(τ) + b S(τ)),
//!   q̇(τ) = e^{−aτ} (−κ q₀ S(τ) + b C(τ)) − a q(τ),
//! where C = cos ω_d τ, S = sin(ω_d τ)/ω_d (κ > 0, ω_d = √κ); C = 1, S = τ (κ = 0);
//! C = cosh μτ, S = sinh(μτ)/μ (κ < 0, μ = √−κ). This single form avoids the 1/ω_d
//! blow-up of the textbook B = (v₀ + ξωq₀)/ω_d near critical damping.

/// One damped modal oscillator with its initial state at the start of a phase.
#[derive(Debug, Clone, Copy)]
pub(super) struct ModalMotion {
    /// Decay rate a = ξω (1/s).
    pub decay_rate: f64,
    /// κ = ω²(1 − ξ²) (rad²/s²); its sign selects the regime.
    pub kappa: f64,
    /// √|κ| (rad/s): damped angular frequency ω_d, or μ when over-damped.
    pub root_kappa: f64,
    /// ω² (rad²/s²), kept to form the slow over-damped rate μ − a = −ω²/(a + μ)
    /// without cancellation.
    omega_squared: f64,
    /// Modal displacement at the phase start, q₀ (m·√kg).
    pub initial_displacement: f64,
    /// b = q̇₀ + a q₀ (m·√kg/s).
    pub velocity_term: f64,
}

impl ModalMotion {
    /// Oscillator of angular frequency ω (rad/s) and damping ratio ξ ≥ 0 released
    /// from modal displacement q₀ and velocity q̇₀.
    pub fn new(
        angular_frequency: f64,
        damping_ratio: f64,
        initial_displacement: f64,
        initial_velocity: f64,
    ) -> Self {
        let decay_rate = damping_ratio * angular_frequency;
        let kappa = angular_frequency * angular_frequency * (1.0 - damping_ratio) * (1.0 + damping_ratio);
        Self {
            decay_rate,
            kappa,
            root_kappa: kappa.abs().sqrt(),
            omega_squared: angular_frequency * angular_frequency,
            initial_displacement,
            velocity_term: initial_velocity + decay_rate * initial_displacement,
        }
    }

    /// True for the oscillating (under-damped) regime.
    pub fn is_underdamped(&self) -> bool {
        self.kappa > 0.0
    }

    /// (q(τ), q̇(τ)) at time τ ≥ 0 after the phase start.
    pub fn state(&self, tau: f64) -> (f64, f64) {
        let (c, s, envelope) = self.kernels(tau);
        let q0 = self.initial_displacement;
        let b = self.velocity_term;
        let displacement = envelope * (q0 * c + b * s);
        let velocity = envelope * (-self.kappa * q0 * s + b * c) - self.decay_rate * displacement;
        (displacement, velocity)
    }

    /// (C, S, e^{−aτ}) with the over-damped products formed from exponentials that
    /// cannot overflow (e^{(μ−a)τ} with μ < a).
    fn kernels(&self, tau: f64) -> (f64, f64, f64) {
        if self.kappa > 0.0 {
            let (sin, cos) = (self.root_kappa * tau).sin_cos();
            (cos, sin / self.root_kappa, (-self.decay_rate * tau).exp())
        } else if self.kappa == 0.0 {
            (1.0, tau, (-self.decay_rate * tau).exp())
        } else {
            let mu = self.root_kappa;
            let slow = (-self.omega_squared / (self.decay_rate + mu) * tau).exp();
            let fast = ((-mu - self.decay_rate) * tau).exp();
            // envelope folded into C and S.
            (0.5 * (slow + fast), 0.5 * (slow - fast) / mu, 1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Every regime must satisfy the ODE q̈ + 2ξωq̇ + ω²q = 0 and the initial
    // conditions; check the residual with a central difference of q̇.
    #[test]
    fn closed_form_satisfies_the_modal_equation_in_every_regime() {
        let omega = 50.0;
        for xi in [0.0, 0.01, 0.7, 1.0, 1.5, 30.0] {
            let motion = ModalMotion::new(omega, xi, 1e-3, -0.2);
            let (q0, v0) = motion.state(0.0);
            assert!((q0 - 1e-3).abs() < 1e-18, "ξ = {xi}: q(0) = {q0}, expected 1e-3");
            assert!((v0 + 0.2).abs() < 1e-15, "ξ = {xi}: q̇(0) = {v0}, expected −0.2");
            for tau in [1e-3, 0.02, 0.3] {
                // Step well below the fastest time scale 1/(ω(1 + 2ξ)).
                let h = 1e-4 / (omega * (1.0 + 2.0 * xi));
                let (q, v) = motion.state(tau);
                let acceleration = (motion.state(tau + h).1 - motion.state(tau - h).1) / (2.0 * h);
                let residual = acceleration + 2.0 * xi * omega * v + omega * omega * q;
                let scale = acceleration.abs() + (2.0 * xi * omega * v).abs() + (omega * omega * q).abs();
                assert!(
                    residual.abs() < 1e-6 * scale,
                    "ξ = {xi}, τ = {tau}: ODE residual {residual} vs scale {scale}"
                );
            }
        }
    }
}
