//! A reproducible random stream for the bundle generator's gaps and the sweeps' random
//! axes: a seeded stream and the samplers of the gap laws, defined bit for bit so that
//! the same seed gives the same draws on every machine and Rust version.
//!
//! # Exact algorithm
//! Only IEEE-754 `+ − × ÷ √` (correctly rounded everywhere, and Rust never fuses them)
//! and integer operations are used; the logarithm is this module's own [`ln`], so no
//! platform `libm` can change a bit.
//! 1. Seeding: SplitMix64 (Steele, Lea & Flood 2014) with state `seed`: each call adds
//!    `0x9E3779B97F4A7C15` to the state `z`, then `z ^= z >> 30; z *= 0xBF58476D1CE4E5B9;
//!    z ^= z >> 27; z *= 0x94D049BB133111EB; z ^= z >> 31` (wrapping). Its first four
//!    outputs are the state `s0..s3` of xoshiro256** (Blackman & Vigna 2018).
//! 2. xoshiro256** step: output `rotl(s1 × 5, 7) × 9`; then `t = s1 << 17; s2 ^= s0;
//!    s3 ^= s1; s1 ^= s2; s0 ^= s3; s2 ^= t; s3 = rotl(s3, 45)`.
//! 3. Uniform on [0, 1): `(x >> 11) × 2⁻⁵³`; on (0, 1]: `((x >> 11) + 1) × 2⁻⁵³`.
//! 4. Standard normal, Marsaglia polar method, one variate per pair (the partner is
//!    discarded): repeat `a = 2u₁ − 1, b = 2u₂ − 1, s = a² + b²` (u on [0, 1)) until
//!    `0 < s < 1`; return `a · √(−2 ln s / s)`.
//! 5. Normal truncated at 0 (a true truncated law, by rejection, never clamping): with
//!    α = −μ/σ, if α ≤ 0 draw z from step 4 until z ≥ α (acceptance ≥ 1/2); otherwise
//!    Robert (1995): λ = (α + √(α² + 4))/2, repeat `z = α − ln(u₁)/λ` and accept when
//!    `ln(u₂) ≤ −(z − λ)²/2` (u on (0, 1], acceptance ≥ 0.76). Gap = max(μ + σz, 0), the
//!    max only absorbing a rounding below 0. σ = 0 gives μ and consumes nothing.
//! 6. Uniform law: `low + (high − low)·u`, u on [0, 1).
//!
//! One stream per layout: contacts draw in expansion order.

use super::bundle::GapDistribution;

/// Natural logarithm from `+ − × ÷` only (bit-identical everywhere, within ~2 ulp of the
/// true value): x = m·2ᵉ with m in [√½, √2), ln x = e·ln 2 + 2 atanh(t), t = (m−1)/(m+1),
/// |t| ≤ 0.1716, atanh by its odd series to t²³. Returns NaN for x ≤ 0 or non-finite x
/// (never reached by the samplers).
pub fn ln(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return f64::NAN;
    }
    let (x, mut exponent) = if x < f64::MIN_POSITIVE {
        (x * 18014398509481984.0, -54_i64) // 2⁵⁴ lifts subnormals to normal range
    } else {
        (x, 0)
    };
    let bits = x.to_bits();
    exponent += ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | (1023 << 52));
    if m > std::f64::consts::SQRT_2 {
        m *= 0.5;
        exponent += 1;
    }
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let mut series = 0.0;
    for k in (0..12).rev() {
        series = series * t2 + 1.0 / (2 * k + 1) as f64;
    }
    exponent as f64 * std::f64::consts::LN_2 + 2.0 * t * series
}

/// SplitMix64-seeded xoshiro256** and the gap samplers (module doc, steps 1–6).
#[derive(Debug, Clone)]
pub struct GapRng {
    state: [u64; 4],
}

/// One SplitMix64 step on `state`.
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl GapRng {
    pub fn new(seed: u64) -> Self {
        let mut sm = seed;
        Self {
            state: [
                splitmix64(&mut sm),
                splitmix64(&mut sm),
                splitmix64(&mut sm),
                splitmix64(&mut sm),
            ],
        }
    }

    /// Next raw xoshiro256** output.
    pub fn next_u64(&mut self) -> u64 {
        let s = &mut self.state;
        let result = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform on [0, 1), multiples of 2⁻⁵³.
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / 9007199254740992.0)
    }

    /// Uniform on (0, 1], safe for a logarithm.
    fn uniform_open_zero(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 * (1.0 / 9007199254740992.0)
    }

    /// Standard normal, Marsaglia polar method (first variate of each accepted pair).
    pub fn standard_normal(&mut self) -> f64 {
        loop {
            let a = 2.0 * self.uniform() - 1.0;
            let b = 2.0 * self.uniform() - 1.0;
            let s = a * a + b * b;
            if s > 0.0 && s < 1.0 {
                return a * (-2.0 * ln(s) / s).sqrt();
            }
        }
    }

    /// Standard normal conditioned on z ≥ alpha (step 5 of the module doc).
    pub fn standard_normal_above(&mut self, alpha: f64) -> f64 {
        if alpha <= 0.0 {
            loop {
                let z = self.standard_normal();
                if z >= alpha {
                    return z;
                }
            }
        }
        let rate = 0.5 * (alpha + (alpha * alpha + 4.0).sqrt());
        loop {
            let z = alpha - ln(self.uniform_open_zero()) / rate;
            let excess = z - rate;
            if ln(self.uniform_open_zero()) <= -0.5 * excess * excess {
                return z;
            }
        }
    }

    /// One draw of `distribution` (validated parameters assumed; never negative).
    pub fn sample(&mut self, distribution: &GapDistribution) -> f64 {
        match *distribution {
            GapDistribution::Uniform { low, high } => low + (high - low) * self.uniform(),
            GapDistribution::Normal { mean, std } => {
                if std > 0.0 {
                    (mean + std * self.standard_normal_above(-mean / std)).max(0.0)
                } else {
                    mean.max(0.0)
                }
            }
        }
    }
}
