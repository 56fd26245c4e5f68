//! Bracketed scalar root finding (Brent's method), shared by the frequency
//! equations and the contact switching instants.
//!
//! Brent combines inverse quadratic interpolation, secant steps and bisection: it
//! never leaves the bracket, converges superlinearly on smooth functions and falls
//! back to bisection on hard ones, so it reaches machine precision in a few tens of
//! evaluations at worst.

/// Root of `function` in [a, b] given f(a) = `value_a` and f(b) = `value_b` of opposite
/// signs (or one of them zero). Returns the abscissa to about 2ε|x|; `None` if the
/// bracket is invalid (same strict signs or non-finite values).
pub(super) fn find_root(
    mut function: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    value_a: f64,
    value_b: f64,
) -> Option<f64> {
    if !(value_a.is_finite() && value_b.is_finite() && a.is_finite() && b.is_finite()) {
        return None;
    }
    if value_a == 0.0 {
        return Some(a);
    }
    if value_b == 0.0 {
        return Some(b);
    }
    if value_a.signum() == value_b.signum() {
        return None;
    }
    // Notation of Brent (1973): b is the best estimate, a the previous one, c the
    // contrapoint with f(c) of opposite sign to f(b).
    let (mut a, mut b, mut fa, mut fb) = (a, b, value_a, value_b);
    let (mut c, mut fc) = (a, fa);
    let mut step = b - a;
    let mut previous_step = step;
    for _ in 0..200 {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            step = b - a;
            previous_step = step;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tolerance = 2.0 * f64::EPSILON * b.abs() + 1e-300;
        let half_interval = 0.5 * (c - b);
        if half_interval.abs() <= tolerance || fb == 0.0 {
            return Some(b);
        }
        if previous_step.abs() >= tolerance && fa.abs() > fb.abs() {
            // Interpolation: secant if a == c, inverse quadratic otherwise.
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * half_interval * s;
                q = 1.0 - s;
            } else {
                let q_ac = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * half_interval * q_ac * (q_ac - r) - (b - a) * (r - 1.0));
                q = (q_ac - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * half_interval * q - (tolerance * q).abs()).min((previous_step * q).abs()) {
                previous_step = step;
                step = p / q;
            } else {
                step = half_interval;
                previous_step = step;
            }
        } else {
            step = half_interval;
            previous_step = step;
        }
        a = b;
        fa = fb;
        if step.abs() > tolerance {
            b += step;
        } else {
            b += tolerance.copysign(half_interval);
        }
        fb = function(b);
        if !fb.is_finite() {
            return None;
        }
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    // cos x = x has the single root 0.7390851332151607 (the Dottie number); Brent must
    // reach it to machine precision from a wide bracket.
    #[test]
    fn finds_dottie_number_to_machine_precision() {
        let f = |x: f64| x.cos() - x;
        let root = find_root(f, 0.0, 2.0, f(0.0), f(2.0));
        let expected = 0.739_085_133_215_160_6;
        let measured = root.unwrap_or(f64::NAN);
        assert!(
            (measured - expected).abs() < 4e-16,
            "measured {measured}, expected {expected}"
        );
    }

    // A bracket without a sign change has no guaranteed root: it must be refused.
    #[test]
    fn refuses_bracket_without_sign_change() {
        let f = |x: f64| x * x + 1.0;
        assert_eq!(find_root(f, -1.0, 1.0, f(-1.0), f(1.0)), None);
    }
}
