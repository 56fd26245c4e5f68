//! Elementary functions computed from IEEE-754 `+ − × ÷` only, so that a result that
//! must be the same bit for bit on every machine (a synthetic accelerogram drawn from a
//! seed) does not depend on the platform's `libm`, whose `exp`, `sin` and `cos` may differ
//! in the last bit between systems. Rust never fuses a multiply and an add, so each of
//! these is one fixed sequence of correctly rounded operations. Accuracy: a few ulp for
//! the arguments the physics uses (|x| ≤ 10⁵ for `sin_cos`).
//!
//! The natural logarithm lives with the random stream that needed it first
//! ([`crate::random::ln`]) and is re-exported here.

pub use crate::random::ln;

/// ln 2 split as in fdlibm: `LN2_HI` has its low 32 bits zero, so k·`LN2_HI` is exact
/// for |k| < 2²⁰.
const LN2_HI: f64 = 0.693_147_180_369_123_8;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// π/2 in three parts (fdlibm's `pio2_1`, `pio2_2`, `pio2_3`), each with 33 significant
/// bits, so that x − k·π/2 is accurate for |k| < 2²⁰.
const PIO2_1: f64 = 1.570_796_326_734_125_6;
const PIO2_2: f64 = 6.077_100_506_303_966e-11;
const PIO2_3: f64 = 2.022_266_248_711_166_5e-21;

/// eˣ: x = k ln 2 + r with |r| ≤ ln 2 / 2, eʳ by its Taylor series to r¹⁴ (truncation
/// below 10⁻¹⁷), then scaled by 2ᵏ. Overflows to ∞ above 709.78, underflows to 0 below
/// −745.2; NaN stays NaN.
pub fn exp(x: f64) -> f64 {
    if x.is_nan() {
        return x;
    }
    if x > 709.782_712_893_384 {
        return f64::INFINITY;
    }
    if x < -745.2 {
        return 0.0;
    }
    let k = (x * std::f64::consts::LOG2_E).round();
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut series = 1.0;
    for n in (1..=14).rev() {
        series = 1.0 + series * r / n as f64;
    }
    scale_by_power_of_two(series, k as i32)
}

/// y·2ᵏ for y in [0.7, 1.5] and k in [−1075, 1024], in at most two exact scalings (the
/// second only near the ends of the exponent range).
fn scale_by_power_of_two(y: f64, k: i32) -> f64 {
    let power = |e: i32| f64::from_bits(((e + 1023) as u64) << 52);
    if k > 1000 {
        y * power(1000) * power(k - 1000)
    } else if k < -1000 {
        y * power(-1000) * power(k + 1000)
    } else {
        y * power(k)
    }
}

/// (sin x, cos x): x = k π/2 + r with |r| ≤ π/4 (three-part Cody–Waite reduction), the
/// Taylor series of sin r to r¹⁹ and cos r to r²⁰ (truncation below 10⁻¹⁹), then the
/// quadrant k mod 4. Non-finite x gives NaN.
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !x.is_finite() {
        return (f64::NAN, f64::NAN);
    }
    let k = (x * std::f64::consts::FRAC_2_PI).round();
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let r2 = r * r;
    // sin r = r (1 − r²/(2·3) (1 − r²/(4·5) (1 − ...))), cos r = 1 − r²/(1·2) (1 − ...).
    let mut sine = 1.0;
    let mut cosine = 1.0;
    for n in (1..=10).rev() {
        let n = n as f64;
        sine = 1.0 - sine * r2 / ((2.0 * n) * (2.0 * n + 1.0));
        cosine = 1.0 - cosine * r2 / ((2.0 * n - 1.0) * (2.0 * n));
    }
    let (s, c) = (r * sine, cosine);
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// xʸ for x > 0: exp(y ln x). NaN for x ≤ 0.
pub fn powf(x: f64, y: f64) -> f64 {
    exp(y * ln(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative distance in units of the last place of `expected`.
    fn ulps(measured: f64, expected: f64) -> f64 {
        if measured == expected {
            return 0.0;
        }
        let spacing = f64::EPSILON * expected.abs().max(f64::MIN_POSITIVE);
        (measured - expected).abs() / spacing
    }

    // The platform functions are accurate to ~1 ulp: ours must agree with them to a few
    // ulp over the range the physics uses.
    #[test]
    fn exp_agrees_with_the_platform_to_a_few_ulp() {
        let mut worst: f64 = 0.0;
        for i in -20_000..=20_000 {
            let x = i as f64 * 0.035_3;
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        assert!(worst <= 4.0, "exp: worst {worst} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(710.0), f64::INFINITY);
        assert!(exp(f64::NAN).is_nan());
        let tiny = exp(-740.0);
        assert!(
            (tiny / (-740.0f64).exp() - 1.0).abs() < 1e-3,
            "subnormal exp(-740) = {tiny:e}"
        );
    }

    #[test]
    fn sin_cos_agree_with_the_platform_to_a_few_ulp_of_one() {
        let mut worst: f64 = 0.0;
        for i in -100_000..=100_000 {
            let x = i as f64 * 0.013_7;
            let (s, c) = sin_cos(x);
            // Near a zero the relative error is meaningless: measure against 1.
            worst = worst.max((s - x.sin()).abs().max((c - x.cos()).abs()) / f64::EPSILON);
        }
        assert!(worst <= 4.0, "sin_cos: worst {worst} ε");
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_6);
        assert!((s - 0.5).abs() < 2e-16 && (c - 0.75f64.sqrt()).abs() < 2e-16);
        assert!(sin_cos(f64::INFINITY).0.is_nan());
    }

    #[test]
    fn powf_is_exp_of_y_ln_x() {
        assert!((powf(10.0, 0.5) - 10f64.sqrt()).abs() < 1e-14);
        assert!((powf(2.0, 10.0) - 1024.0).abs() < 1e-11);
        assert!(powf(-1.0, 2.0).is_nan());
    }
}
