//! Coefficients of restitution of the contact laws, exactly (docs/contact-laws.md).
//!
//! Both laws are judged on the impact of two free bodies of reduced mass m (one of them
//! a wall: m is the other's mass) meeting at the approach speed v₀: the penetration
//! obeys m δ̈ = −F(δ, δ̇), δ(0) = 0, δ̇(0) = v₀, and the bodies part when the force,
//! which never pulls, falls to zero; e = −δ̇(end)/v₀.
//!
//! **Linear spring–dashpot** F = max(0, K δ + c δ̇), β = c/2m, ω₀² = K/m,
//! ζ = β/ω₀. Underdamped, δ = (v₀/ω) e^{−βt} sin ωt with ω² = ω₀² − β²; the force
//! m v₀ e^{−βt} [((ω² − β²)/ω) sin ωt + 2β cos ωt] vanishes at ωt = π − 2 atan r,
//! r = β/ω (before δ returns to 0: the dashpot would pull there), where
//! δ̇ = −v₀ e^{−βt}. So e = exp(−r (π − 2 atan r)), r = ζ/√(1 − ζ²), for every ζ < 1
//! (the textbook e = exp(−π r), which lets the dashpot pull, is 2–45 % off for
//! ζ = 0.01–0.5). Overdamped (ζ > 1) the same steps with hyperbolic functions give
//! e = exp(−(2/s) artanh s), s = √(ζ² − 1)/ζ; ζ = 1 gives e⁻². e depends on ζ only:
//! given e, [`linear_damping_ratio`] inverts it and c = 2 ζ √(K m).
//!
//! **Power law with Hunt–Crossley damping** F = max(0, K δⁿ (1 + α δ̇)). With
//! δ = L y, t = T τ, L/T = v₀ and m L/T² = K Lⁿ the motion is
//! y″ = −yⁿ (1 + a y′), y(0) = 0, y′(0) = 1, with a = α v₀ alone: e depends on
//! (n, α v₀) and not on K or m. [`hunt_crossley_factor`] integrates that equation
//! (fourth-order Runge–Kutta, the end found by interpolation) and inverts it, so
//! α = a(n, e)/v₀ rebounds with e at v₀ exactly (up to 1e-9), less at higher speeds and
//! more at lower ones, as measured impacts do.

/// e of the linear spring–dashpot that never pulls, at damping ratio ζ = c/(2√(K m)).
pub fn linear_restitution(zeta: f64) -> f64 {
    if zeta <= 0.0 {
        return 1.0;
    }
    if zeta < 1.0 {
        let r = zeta / (1.0 - zeta * zeta).sqrt();
        (-r * (std::f64::consts::PI - 2.0 * r.atan())).exp()
    } else if zeta == 1.0 {
        (-2.0f64).exp()
    } else {
        let s = (zeta * zeta - 1.0).sqrt() / zeta;
        (-(2.0 / s) * s.atanh()).exp()
    }
}

/// The damping ratio ζ whose linear spring–dashpot rebounds with `e` in (0, 1].
pub fn linear_damping_ratio(e: f64) -> f64 {
    invert_decreasing(e, linear_restitution)
}

/// e of F = K δⁿ (1 + α δ̇) for a = α v₀ (dimensionless), exponent n ≥ 1.
pub fn hunt_crossley_restitution(exponent: f64, a: f64) -> f64 {
    if a <= 0.0 {
        return 1.0;
    }
    // y″ = −yⁿ (1 + a y′) while the force is positive, from (0, 1).
    let acceleration = |y: f64, v: f64| -(y.max(0.0).powf(exponent)) * (1.0 + a * v).max(0.0);
    // About 4 000 steps over the contact (its dimensionless duration is about 3).
    let h = 1e-3;
    let (mut y, mut v) = (0.0f64, 1.0f64);
    for _ in 0..10_000_000u64 {
        let (k1y, k1v) = (v, acceleration(y, v));
        let (k2y, k2v) = (
            v + 0.5 * h * k1v,
            acceleration(y + 0.5 * h * k1y, v + 0.5 * h * k1v),
        );
        let (k3y, k3v) = (
            v + 0.5 * h * k2v,
            acceleration(y + 0.5 * h * k2y, v + 0.5 * h * k2v),
        );
        let (k4y, k4v) = (v + h * k3v, acceleration(y + h * k3y, v + h * k3v));
        let next_y = y + h / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
        let next_v = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        // The force yⁿ (1 + a y′) vanishes where the bodies part: at y′ = −1/a while
        // they still overlap (the damping term cancels the spring), or at y = 0.
        if 1.0 + a * next_v <= 0.0 {
            return 1.0 / a;
        }
        if next_y <= 0.0 {
            let fraction = y / (y - next_y);
            return -(v + fraction * (next_v - v));
        }
        (y, v) = (next_y, next_v);
    }
    0.0
}

/// The Hunt–Crossley a = α v₀ whose power law of exponent n rebounds with `e`.
pub fn hunt_crossley_factor(exponent: f64, e: f64) -> f64 {
    invert_decreasing(e, |a| hunt_crossley_restitution(exponent, a))
}

/// x ≥ 0 with f(x) = target for f decreasing from f(0) = 1 toward 0: bracketed by
/// doubling, then bisected to a relative 1e-12.
fn invert_decreasing(target: f64, f: impl Fn(f64) -> f64) -> f64 {
    if target >= 1.0 {
        return 0.0;
    }
    let mut high = 1.0;
    while f(high) > target && high < 1e12 {
        high *= 2.0;
    }
    let mut low = 0.0;
    for _ in 0..200 {
        let middle = 0.5 * (low + high);
        if f(middle) > target {
            low = middle;
        } else {
            high = middle;
        }
        if high - low <= 1e-12 * high {
            break;
        }
    }
    0.5 * (low + high)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integrates m δ̈ = −F(δ, δ̇) for two free bodies from their approach speed, with
    /// steps of 1e-4 of the contact period (velocity Verlet, the force evaluated at the
    /// half-step velocity estimate), and returns the rebound over approach speed.
    fn free_impact(mass: f64, approach: f64, force: impl Fn(f64, f64) -> f64, period: f64) -> f64 {
        let h = period * 1e-5;
        let (mut x, mut v) = (0.0f64, approach);
        loop {
            // Midpoint (RK2) step of the relative motion.
            let a1 = -force(x, v) / mass;
            let (xm, vm) = (x + 0.5 * h * v, v + 0.5 * h * a1);
            let a2 = -force(xm, vm) / mass;
            x += h * vm;
            v += h * a2;
            if force(x, v) <= 0.0 && v < 0.0 {
                return -v / approach;
            }
        }
    }

    #[test]
    fn a_linear_dashpot_that_never_pulls_rebounds_with_the_exact_e() {
        let (stiffness, mass): (f64, f64) = (2e6, 0.3);
        for e in [1.0, 0.95, 0.8, 0.5, 0.2, 0.05] {
            let zeta = linear_damping_ratio(e);
            let damping = 2.0 * zeta * (stiffness * mass).sqrt();
            let law = |d: f64, rate: f64| {
                if d > 0.0 {
                    (stiffness * d + damping * rate).max(0.0)
                } else {
                    0.0
                }
            };
            let period = 2.0 * std::f64::consts::PI * (mass / stiffness).sqrt();
            for approach in [0.01, 1.0] {
                let rebound = free_impact(mass, approach, law, period);
                assert!((rebound - e).abs() < 1e-3, "e {e}: ζ {zeta}, rebound {rebound}");
            }
        }
    }

    #[test]
    fn the_textbook_relation_is_off_because_it_lets_the_dashpot_pull() {
        // e = exp(−πζ/√(1−ζ²)) holds for a dashpot that pulls; ours does not.
        for (zeta, at_least) in [(0.01, 0.0001), (0.1, 0.02), (0.5, 0.4)] {
            let textbook = (-std::f64::consts::PI * zeta / (1.0f64 - zeta * zeta).sqrt()).exp();
            let ours = linear_restitution(zeta);
            assert!(
                ours > textbook * (1.0 + at_least),
                "ζ {zeta}: {ours} vs {textbook}"
            );
        }
        // Continuous through critical damping, and e ~ 1/(4ζ²) far above it.
        assert!((linear_restitution(1.0 - 1e-9) - linear_restitution(1.0 + 1e-9)).abs() < 1e-6);
        assert!((linear_restitution(1e3) * 4e6 - 1.0).abs() < 1e-3);
    }

    #[test]
    fn a_hunt_crossley_power_law_rebounds_with_e_at_its_speed_and_less_when_faster() {
        let (stiffness, mass, exponent) = (5e9, 0.2, 1.5);
        for e in [0.9, 0.6, 0.3] {
            let speed = 0.5;
            let alpha = hunt_crossley_factor(exponent, e) / speed;
            let law = |d: f64, rate: f64| {
                if d > 0.0 {
                    (stiffness * d.powf(exponent) * (1.0 + alpha * rate)).max(0.0)
                } else {
                    0.0
                }
            };
            // The contact time scale of the power law at a speed.
            let period =
                |speed: f64| 10.0 * (mass * speed * speed / stiffness).powf(1.0 / (exponent + 1.0)) / speed;
            let rebound = free_impact(mass, speed, law, period(speed));
            assert!((rebound - e).abs() < 1e-3, "e {e}: rebound {rebound}");
            let faster = free_impact(mass, 4.0 * speed, law, period(4.0 * speed));
            assert!(faster < rebound - 0.01, "e {e}: {faster} at 4 v₀ vs {rebound}");
        }
    }

    #[test]
    fn small_hunt_crossley_damping_follows_its_first_order_expansion() {
        // For a → 0 the energy lost is ∫ K δⁿ α δ̇ δ̇ dt ≈ a × (the work integral of the
        // elastic impact), so 1 − e is linear in a: halving a halves 1 − e.
        let (one, half) = (
            1.0 - hunt_crossley_restitution(1.5, 1e-3),
            1.0 - hunt_crossley_restitution(1.5, 5e-4),
        );
        assert!((one / half - 2.0).abs() < 1e-2, "{one} vs {half}");
        // Linear (n = 1) Hunt–Crossley of vanishing a: the undamped impact, e → 1.
        assert!((hunt_crossley_restitution(1.0, 1e-9) - 1.0).abs() < 1e-6);
    }
}
