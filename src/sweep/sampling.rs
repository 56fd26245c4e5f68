//! Reproducible sampling of the random axes: uniform numbers from the seeded stream of
//! [`GapRng`] (SplitMix64-seeded xoshiro256**), turned into draws of a law by inversion.
//!
//! # Exact algorithm (the same values on every machine)
//! Only IEEE-754 `+ − × ÷ √`, `floor`, `round` and integer operations are used; the
//! logarithm is [`ln`] from the bundle generator and the exponential is [`exp`] below,
//! so no platform `libm` can change a bit.
//! 1. Open uniform on (0, 1): `((x >> 11) + ½) × 2⁻⁵³` for a raw output x.
//! 2. Monte Carlo: the stream seeded with `seed` gives, sample after sample, one open
//!    uniform per random axis (axes in request order).
//! 3. Latin hypercube: for each random axis in request order, a permutation π of
//!    0..N by Fisher–Yates (for i from N−1 down to 1, j = ⌊x·(i+1)/2⁶⁴⌋ with x the next
//!    raw output, swap π[i] and π[j]), then for each sample s in order one open uniform
//!    v: u = (π[s] + v)/N. Each axis hits each of its N equal-probability strata once.
//! 4. Laws by inversion of u: uniform `low + (high − low)·u`; normal `mean + std·Φ⁻¹(u)`
//!    with Φ⁻¹ by Acklam's rational approximation (relative error below 1.2·10⁻⁹);
//!    lognormal `exp(mean + std·Φ⁻¹(u))`, `mean` and `std` being those of the logarithm.

use crate::physics::random::GapRng;
pub use crate::physics::random::ln;

/// A probability law of a random axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Law {
    /// Uniform on [low, high).
    Uniform { low: f64, high: f64 },
    /// Normal with this mean and standard deviation.
    Normal { mean: f64, std: f64 },
    /// exp of a normal: `mean` and `std` are those of the natural logarithm of the value.
    LogNormal { mean: f64, std: f64 },
}

impl Law {
    /// The value whose cumulative probability is `u` (0 < u < 1).
    pub fn quantile(&self, u: f64) -> f64 {
        match *self {
            Law::Uniform { low, high } => low + (high - low) * u,
            Law::Normal { mean, std } => mean + std * standard_normal_quantile(u),
            Law::LogNormal { mean, std } => exp(mean + std * standard_normal_quantile(u)),
        }
    }
}

/// Open uniform on (0, 1) from a raw output (step 1).
fn open_uniform(rng: &mut GapRng) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 0.5) * (1.0 / 9007199254740992.0)
}

/// Monte Carlo uniforms: `samples` rows of `axes` open uniforms (step 2).
pub fn monte_carlo(seed: u64, samples: usize, axes: usize) -> Vec<Vec<f64>> {
    let mut rng = GapRng::new(seed);
    (0..samples)
        .map(|_| (0..axes).map(|_| open_uniform(&mut rng)).collect())
        .collect()
}

/// Latin hypercube uniforms: `samples` rows of `axes` values, each column stratified (step 3).
pub fn latin_hypercube(seed: u64, samples: usize, axes: usize) -> Vec<Vec<f64>> {
    let mut rng = GapRng::new(seed);
    let mut rows = vec![vec![0.0; axes]; samples];
    for axis in 0..axes {
        let mut permutation: Vec<usize> = (0..samples).collect();
        for i in (1..samples).rev() {
            let j = ((u128::from(rng.next_u64()) * (i as u128 + 1)) >> 64) as usize;
            permutation.swap(i, j);
        }
        for (sample, row) in rows.iter_mut().enumerate() {
            let v = open_uniform(&mut rng);
            row[axis] = (permutation[sample] as f64 + v) / samples as f64;
        }
    }
    rows
}

/// Φ⁻¹(p), the standard normal quantile, by Acklam's algorithm (0 < p < 1).
// The coefficients as published, digit for digit.
#[allow(clippy::excessive_precision)]
pub fn standard_normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e+01,
        2.209460984245205e+02,
        -2.759285104469687e+02,
        1.383577518672690e+02,
        -3.066479806614716e+01,
        2.506628277459239e+00,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e+01,
        1.615858368580409e+02,
        -1.556989798598866e+02,
        6.680131188771972e+01,
        -1.328068155288572e+01,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-03,
        -3.223964580411365e-01,
        -2.400758277161838e+00,
        -2.549732539343734e+00,
        4.374664141464968e+00,
        2.938163982698783e+00,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-03,
        3.224671290700398e-01,
        2.445134137142996e+00,
        3.754408661907416e+00,
    ];
    const LOW: f64 = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < LOW {
        tail((-2.0 * ln(p)).sqrt())
    } else if p > 1.0 - LOW {
        -tail((-2.0 * ln(1.0 - p)).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// eˣ from `+ − × ÷` and `floor` only (bit-identical everywhere, within a few ulp):
/// x = k·ln 2 + r with |r| ≤ ½ ln 2 (ln 2 split in two parts for an exact reduction),
/// eʳ by its Taylor series to r²⁰, then scaled by 2ᵏ.
pub fn exp(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x > 709.782712893384 {
        return f64::INFINITY;
    }
    if x < -745.1332191019412 {
        return 0.0;
    }
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let k = (x * std::f64::consts::LOG2_E + 0.5).floor();
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut series = 1.0;
    for n in (1..=20).rev() {
        series = 1.0 + series * r / n as f64;
    }
    let k = k as i64;
    // 2ᵏ in at most two normal factors, so subnormal results round only once at the end.
    let power = |e: i64| f64::from_bits(((e + 1023) as u64) << 52);
    if k < -1000 {
        series * power(k + 600) * power(-600)
    } else if k > 1000 {
        series * power(k - 100) * power(100)
    } else {
        series * power(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exponential_matches_the_platform_within_a_few_ulp() {
        for &x in &[
            -700.0,
            -20.5,
            -1.0,
            -1e-9,
            0.0,
            1e-9,
            0.5,
            1.0,
            std::f64::consts::LN_10,
            10.0,
            300.0,
            709.0,
        ] {
            let (ours, platform) = (exp(x), x.exp());
            assert!(
                ((ours - platform) / platform).abs() < 1e-14,
                "exp({x}) = {ours}, platform {platform}"
            );
        }
        assert_eq!(exp(0.0), 1.0);
    }

    #[test]
    fn the_normal_quantile_matches_known_values() {
        for (p, z) in [
            (0.5, 0.0),
            (0.975, 1.959963984540054),
            (0.05, -1.6448536269514722),
            (1e-6, -4.753424308822899),
        ] {
            let ours = standard_normal_quantile(p);
            assert!(
                (ours - z).abs() < 1e-8 * z.abs().max(1.0),
                "Φ⁻¹({p}) = {ours}, expected {z}"
            );
        }
    }

    #[test]
    fn latin_hypercube_columns_hit_every_stratum_once() {
        let rows = latin_hypercube(7, 50, 3);
        for axis in 0..3 {
            let mut strata: Vec<usize> = rows.iter().map(|r| (r[axis] * 50.0).floor() as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..50).collect::<Vec<_>>(), "axis {axis}");
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_numbers() {
        assert_eq!(monte_carlo(42, 5, 2), monte_carlo(42, 5, 2));
        assert_ne!(monte_carlo(42, 5, 2), monte_carlo(43, 5, 2));
        assert!(monte_carlo(1, 1000, 1).iter().all(|r| r[0] > 0.0 && r[0] < 1.0));
    }
}
