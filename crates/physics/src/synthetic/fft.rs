//! A radix-2 fast Fourier transform built from `+ − ×` and [`crate::portable`] twiddles,
//! so that a synthetic accelerogram is the same bit for bit on every machine (a library
//! FFT picks its algorithm by CPU features, and its twiddles come from the platform's
//! `sin`/`cos`).

use crate::portable;

/// In-place transform of (`re`, `im`), length a power of two:
/// X_k = Σⱼ xⱼ e^{∓2πi jk/N} (− forward, + inverse), without any 1/N factor.
/// Iterative Cooley–Tukey, decimation in time: bit-reversal permutation, then stages of
/// butterflies of span 2, 4, …, N with twiddles w_N^{j·N/span} from one table.
pub fn transform(re: &mut [f64], im: &mut [f64], inverse: bool) {
    let n = re.len();
    debug_assert!(
        n.is_power_of_two() && im.len() == n,
        "length {n} is a power of two"
    );
    if n < 2 {
        return;
    }
    let bits = n.trailing_zeros();
    for i in 0..n {
        let j = i.reverse_bits() >> (usize::BITS - bits);
        if j > i {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let sign = if inverse { 1.0 } else { -1.0 };
    let twiddles: Vec<(f64, f64)> = (0..n / 2)
        .map(|j| {
            let (s, c) = portable::sin_cos(std::f64::consts::TAU * j as f64 / n as f64);
            (c, sign * s)
        })
        .collect();
    let mut span = 2;
    while span <= n {
        let half = span / 2;
        let stride = n / span;
        for start in (0..n).step_by(span) {
            for j in 0..half {
                let (wr, wi) = twiddles[j * stride];
                let (a, b) = (start + j, start + j + half);
                let tr = wr * re[b] - wi * im[b];
                let ti = wr * im[b] + wi * re[b];
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        span *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Against the defining sum, and the inverse undoes the forward up to the factor N.
    #[test]
    fn matches_the_direct_sum_and_inverts() {
        let n = 64;
        let signal: Vec<f64> = (0..n).map(|k| ((k * k) % 17) as f64 - 8.0).collect();
        let (mut re, mut im) = (signal.clone(), vec![0.0; n]);
        transform(&mut re, &mut im, false);
        for k in 0..n {
            let (mut sr, mut si) = (0.0, 0.0);
            for (j, x) in signal.iter().enumerate() {
                let angle = -std::f64::consts::TAU * (j * k) as f64 / n as f64;
                sr += x * angle.cos();
                si += x * angle.sin();
            }
            assert!(
                (re[k] - sr).abs() < 1e-11 && (im[k] - si).abs() < 1e-11,
                "bin {k}: ({}, {}) vs direct ({sr}, {si})",
                re[k],
                im[k]
            );
        }
        transform(&mut re, &mut im, true);
        for (k, x) in signal.iter().enumerate() {
            assert!(
                (re[k] / n as f64 - x).abs() < 1e-12,
                "sample {k}: {} vs {x}",
                re[k] / n as f64
            );
        }
    }
}
