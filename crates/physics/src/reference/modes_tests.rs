//! Tests of the analytic cantilever modes against textbook values and structural
//! properties (interlacing, limits, orthonormality).

use super::*;

/// Clamped-pinned textbook eigenvalue λ₁ (tan λ = tanh λ).
const CLAMPED_PINNED_FIRST: f64 = 3.926_602;

/// Residual of the clamped-spring frequency equation divided by cosh λ (λ³ + R).
fn scaled_residual(lambda: f64, r: f64) -> f64 {
    let cube = lambda.powi(3);
    (cube * (1.0 / lambda.cosh() + lambda.cos()) + r * (lambda.sin() - lambda.cos() * lambda.tanh()))
        / (cube + r)
}

// The clamped-free cantilever eigenvalues are tabulated in every vibration textbook
// (Blevins): 1.875104, 4.694091, 7.854757, 10.995541, 14.137168, then
// λᵢ → (2i − 1)π/2 with an error ~2e^{−λ}.
#[test]
fn clamped_free_roots_match_textbook_and_asymptote() {
    let roots = clamped_free_roots(MAX_MODES);
    let textbook = [1.875_104, 4.694_091, 7.854_757, 10.995_541, 14.137_168];
    for (i, (measured, expected)) in roots.iter().zip(textbook).enumerate() {
        assert!(
            (measured - expected).abs() < 1e-6,
            "λ{}: measured {measured}, expected {expected}",
            i + 1
        );
    }
    for (i, measured) in roots.iter().enumerate().skip(5) {
        let asymptote = (2.0 * (i + 1) as f64 - 1.0) * PI / 2.0;
        assert!(
            (measured - asymptote).abs() < 3.0 * (-measured).exp() + 1e-13,
            "λ{}: measured {measured}, asymptote {asymptote}",
            i + 1
        );
    }
}

// A vanishing spring leaves the clamped-free beam; an infinitely stiff one pins the
// tip: the roots must tend to 1 + cos λ cosh λ = 0 and to tan λ = tanh λ (λ₁ = 3.9266).
#[test]
fn spring_roots_tend_to_free_and_pinned_limits() {
    let free = clamped_free_roots(MAX_MODES);
    let soft = clamped_spring_roots(MAX_MODES, 1e-12);
    for (i, (s, f)) in soft.iter().zip(&free).enumerate() {
        assert!(
            (s - f).abs() < 1e-10,
            "R = 1e-12, λ{}: {s} vs clamped-free {f}",
            i + 1
        );
    }
    let pinned = clamped_pinned_roots(MAX_MODES);
    assert!(
        (pinned[0] - CLAMPED_PINNED_FIRST).abs() < 1e-6,
        "clamped-pinned λ1: measured {}, expected {CLAMPED_PINNED_FIRST}",
        pinned[0]
    );
    let stiff = clamped_spring_roots(MAX_MODES, 3e12);
    for (i, (s, p)) in stiff.iter().zip(&pinned).enumerate() {
        // λ_pinned − λ ≈ C λ³/R for a stiff spring.
        let bound = 10.0 * p.powi(3) / 3e12;
        assert!(
            (s - p).abs() < bound,
            "R = 3e12, λ{}: {s} vs clamped-pinned {p}",
            i + 1
        );
    }
}

// Rayleigh monotonicity: the i-th clamped-spring eigenvalue lies between the i-th
// clamped-free and the i-th clamped-pinned ones, which lie below the next clamped-free
// root. So roots are strictly increasing, never skipped nor duplicated, and each
// satisfies the frequency equation.
#[test]
fn spring_roots_are_interlaced_without_duplicates() {
    let free = clamped_free_roots(MAX_MODES);
    let pinned = clamped_pinned_roots(MAX_MODES);
    for rk in [0.0, 1e-3, 1.0, 80.0, 1e3, 1e6] {
        let r = 3.0 * rk;
        let roots = clamped_spring_roots(MAX_MODES, r);
        assert_eq!(roots.len(), MAX_MODES, "Rk = {rk}: root count");
        for i in 0..MAX_MODES {
            assert!(
                free[i] <= roots[i] && roots[i] <= pinned[i],
                "Rk = {rk}, λ{}: {} not in [{}, {}]",
                i + 1,
                roots[i],
                free[i],
                pinned[i]
            );
            if i + 1 < MAX_MODES {
                assert!(
                    roots[i] < free[i + 1] && roots[i] < roots[i + 1] - 0.5,
                    "Rk = {rk}: λ{} = {} too close to λ{} = {}",
                    i + 1,
                    roots[i],
                    i + 2,
                    roots[i + 1]
                );
            }
            let residual = scaled_residual(roots[i], r);
            assert!(
                residual.abs() < 1e-12,
                "Rk = {rk}, λ{}: residual {residual}",
                i + 1
            );
        }
    }
}

/// Maximum |G − I| of the mass Gram matrix G_ij = ∫ m φᵢ φⱼ dx, with a quadrature
/// four times finer than the one used for normalization.
fn gram_deviation(modes: &CantileverModes, mass_per_length: f64, length: f64) -> f64 {
    let rule = CompositeRule::new(4 * MAX_MODES);
    let table = modes.tabulate(&rule);
    let mut deviation = 0.0_f64;
    for i in 0..modes.len() {
        for j in 0..=i {
            let gram: f64 = (0..rule.nodes.len())
                .map(|k| rule.weights[k] * mass_per_length * length * table[i][k] * table[j][k])
                .sum();
            let identity = if i == j { 1.0 } else { 0.0 };
            deviation = deviation.max((gram - identity).abs());
        }
    }
    deviation
}

// Eigenfunctions of a self-adjoint problem are orthogonal for the mass inner product;
// after normalization the Gram matrix is the identity. This fails if the shapes lose
// digits at high modes (cosh λ ~ e^{190}) or if σ / the spring boundary condition
// were wrong (a spring shape would then not be an eigenfunction).
#[test]
fn shapes_are_mass_orthonormal_up_to_sixty_modes() {
    let (length, mass_per_length, bending_stiffness) = (1.3, 0.12, 35.0);
    let free = CantileverModes::new(
        &clamped_free_roots(MAX_MODES),
        length,
        bending_stiffness,
        mass_per_length,
    );
    let deviation = gram_deviation(&free, mass_per_length, length);
    assert!(deviation < 1e-10, "clamped-free: max |G − I| = {deviation:e}");
    for rk in [1e-3, 1.0, 80.0, 1e3, 1e6] {
        let roots = clamped_spring_roots(MAX_MODES, 3.0 * rk);
        let spring = CantileverModes::new(&roots, length, bending_stiffness, mass_per_length);
        let deviation = gram_deviation(&spring, mass_per_length, length);
        assert!(
            deviation < 1e-10,
            "clamped-spring Rk = {rk}: max |G − I| = {deviation:e}"
        );
    }
}

// Mass-normalized clamped-free modes of a uniform beam satisfy φᵢ(L)² = 4/(mL)
// (classical result, ∫₀¹ φ² ds = 1 with φ(1) = ±2 for this σ); the clamped end has
// zero deflection.
#[test]
fn clamped_free_tip_values_are_classical() {
    let (length, mass_per_length) = (2.0, 0.5);
    let free = CantileverModes::new(&clamped_free_roots(MAX_MODES), length, 10.0, mass_per_length);
    let expected = 2.0 / (mass_per_length * length).sqrt();
    for i in 0..MAX_MODES {
        let tip = free.shape(i, length).abs();
        assert!(
            (tip - expected).abs() < 1e-11,
            "mode {}: |φ(L)| = {tip}, expected {expected}",
            i + 1
        );
        let root = free.shape(i, 0.0);
        assert!(root.abs() < 1e-13, "mode {}: φ(0) = {root}, expected 0", i + 1);
    }
}

// BRIEF §7: steel tube L = 1 m, D = 10 mm, d = 9 mm, E = 2.1e11 Pa, ρ = 7800 kg/m³:
// ω = λ² √(EI/ρA)/L² gives f₁ = 9.76591 Hz, f₂ = 61.2019 Hz, and with a tip spring
// Rk = 1 the first clamped-spring frequency is 13.6088 Hz.
#[test]
fn default_tube_frequencies_match_public_values() {
    let (outer, inner) = (0.010_f64, 0.009_f64);
    let area = PI / 4.0 * (outer.powi(2) - inner.powi(2));
    let inertia = PI / 64.0 * (outer.powi(4) - inner.powi(4));
    let (ei, mass) = (2.1e11 * inertia, 7800.0 * area);
    let free = CantileverModes::new(&clamped_free_roots(2), 1.0, ei, mass);
    let spring = CantileverModes::new(&clamped_spring_roots(1, 3.0), 1.0, ei, mass);
    let hz = |omega: f64| omega / (2.0 * PI);
    let checks = [
        (
            "clamped-free f1",
            hz(free.angular_frequencies()[0]),
            9.76591,
            5e-6,
        ),
        (
            "clamped-free f2",
            hz(free.angular_frequencies()[1]),
            61.2019,
            5e-5,
        ),
        (
            "clamped-spring f1",
            hz(spring.angular_frequencies()[0]),
            13.6088,
            5e-5,
        ),
    ];
    // Tolerance: half a unit of the last published digit.
    for (name, measured, expected, tolerance) in checks {
        assert!(
            (measured - expected).abs() <= tolerance,
            "{name}: measured {measured} Hz, expected {expected} Hz"
        );
    }
}
