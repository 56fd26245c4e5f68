//! Distribution-free bounds on quantiles from order statistics (Wilks 1941): what a
//! sweep of n independent runs can say about a quantile of the result whatever its
//! distribution.
//!
//! The number of runs above the p-quantile x_p is binomial (n, 1 − p), so the r-th largest
//! of n values is at or above x_p with probability
//! γ(n, r, p) = P(B ≥ r) = 1 − Σ_{j<r} C(n, j) (1 − p)^j p^(n−j).
//! A one-sided p/γ upper bound is the r-th largest value for the largest r with
//! γ(n, r, p) ≥ γ (the largest r is the tightest bound); it exists from
//! n = ⌈ln(1 − γ) / ln p⌉ runs (59 for 95 %/95 %), and uses the second largest from 93.

/// The confidence that the `rank`-th largest of `runs` values (1: the largest) bounds the
/// `coverage`-quantile from above.
pub fn confidence(runs: usize, rank: usize, coverage: f64) -> f64 {
    if rank == 0 || rank > runs {
        return 0.0;
    }
    // Σ_{j<rank} C(n, j) q^j p^(n−j), q = 1 − p, term by term from j = 0 (p^n) by the
    // ratio (n − j)/(j + 1) · q/p, in logs so that no factorial overflows.
    let (p, q) = (coverage, 1.0 - coverage);
    let mut log_term = runs as f64 * p.ln();
    let mut below = 0.0;
    for j in 0..rank {
        below += log_term.exp();
        log_term += ((runs - j) as f64 / (j + 1) as f64).ln() + q.ln() - p.ln();
    }
    (1.0 - below).clamp(0.0, 1.0)
}

/// The rank from the top (1: the largest) of the tightest one-sided `coverage`/`level`
/// upper bound from `runs` values; `None` when even the largest is not one.
pub fn upper_rank(runs: usize, coverage: f64, level: f64) -> Option<usize> {
    (1..=runs)
        .take_while(|&r| confidence(runs, r, coverage) >= level)
        .last()
}

/// The most runs [`runs_needed`] looks at: a bound that needs more is out of any
/// campaign's reach (a coverage or a confidence a hair below 1).
pub const MAX_RUNS_NEEDED: usize = 1_000_000_000_000;

/// The fewest runs whose `rank`-th largest is a one-sided `coverage`/`level` upper bound;
/// `None` above [`MAX_RUNS_NEEDED`]. γ(n, r, p) grows with n, so the first n is found by
/// doubling then bisection: O(r · log n).
pub fn runs_needed(rank: usize, coverage: f64, level: f64) -> Option<usize> {
    let rank = rank.max(1);
    let enough = |runs: usize| confidence(runs, rank, coverage) >= level;
    let mut high = rank;
    while !enough(high) {
        if high > MAX_RUNS_NEEDED {
            return None;
        }
        high *= 2;
    }
    if high == rank {
        return Some(rank);
    }
    // high / 2 ≥ rank was not enough.
    let mut low = high / 2;
    while high - low > 1 {
        let middle = low + (high - low) / 2;
        if enough(middle) {
            high = middle;
        } else {
            low = middle;
        }
    }
    (high <= MAX_RUNS_NEEDED).then_some(high)
}

/// The empirical `coverage`-quantile and the `coverage`/`level` upper bound of the first
/// n values, for n = 1, 2, ..., in the order given (the order the runs were drawn).
pub fn convergence(values: &[f64], coverage: f64, level: f64) -> Vec<Step> {
    let mut sorted: Vec<f64> = Vec::with_capacity(values.len());
    // The tightest rank never falls as runs are added (γ grows with n): it is carried
    // from one n to the next, each step testing only the next rank.
    let mut rank = 0;
    values
        .iter()
        .enumerate()
        .map(|(index, &value)| {
            let at = sorted.partition_point(|&x| x.total_cmp(&value).is_le());
            sorted.insert(at, value);
            let runs = index + 1;
            while rank < runs && confidence(runs, rank + 1, coverage) >= level {
                rank += 1;
            }
            Step {
                runs,
                value,
                quantile: super::aggregate::quantile(&sorted, coverage),
                bound: (rank > 0).then(|| sorted[runs - rank]),
                bound_rank: (rank > 0).then_some(rank),
            }
        })
        .collect()
}

/// One step of [`convergence`]: what the first `runs` values say.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// How many values so far.
    pub runs: usize,
    /// The `runs`-th value itself.
    pub value: f64,
    /// The empirical quantile of the first `runs` values.
    pub quantile: f64,
    /// The upper bound, `None` until enough runs.
    pub bound: Option<f64>,
    /// Its rank from the top.
    pub bound_rank: Option<usize>,
}

/// Coverage and confidence of the bound the aggregates give.
pub const COVERAGE: f64 = 0.95;
pub const LEVEL: f64 = 0.95;

/// The 95 %/95 % upper bound of `sorted` (increasing) values and its rank from the top;
/// `None` below 59 values.
pub fn upper_bound(sorted: &[f64]) -> Option<(f64, usize)> {
    let n = sorted.len();
    upper_rank(n, COVERAGE, LEVEL).map(|rank| (sorted[n - rank], rank))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Wilks' classical numbers: 59 runs for a first-order 95 %/95 % bound, 93 for the
    /// second order, 124 for the third; 45 runs for 95 %/90 %, 92 for 99 %/60 %.
    #[test]
    fn the_classical_run_counts() {
        assert_eq!(runs_needed(1, 0.95, 0.95), Some(59));
        assert_eq!(runs_needed(2, 0.95, 0.95), Some(93));
        assert_eq!(runs_needed(3, 0.95, 0.95), Some(124));
        assert_eq!(runs_needed(1, 0.95, 0.90), Some(45));
        assert_eq!(runs_needed(1, 0.99, 0.60), Some(92));
        // From 59 runs the largest is the bound, from 93 the second largest.
        assert_eq!(upper_rank(58, 0.95, 0.95), None);
        assert_eq!(upper_rank(59, 0.95, 0.95), Some(1));
        assert_eq!(upper_rank(92, 0.95, 0.95), Some(1));
        assert_eq!(upper_rank(93, 0.95, 0.95), Some(2));
        let values: Vec<f64> = (0..93).map(f64::from).collect();
        assert_eq!(upper_bound(&values), Some((91.0, 2)));
        assert_eq!(upper_bound(&values[..59]), Some((58.0, 1)));
        assert_eq!(upper_bound(&values[..58]), None);
        // γ of the largest: 1 − p^n.
        assert!((confidence(59, 1, 0.95) - (1.0 - 0.95f64.powi(59))).abs() < 1e-12);
    }

    /// γ(n, r, p) summed the plain way: binomial coefficients as products, no logs.
    fn plain_confidence(runs: usize, rank: usize, coverage: f64) -> f64 {
        let below: f64 = (0..rank)
            .map(|j| {
                let choose: f64 = (0..j).map(|i| (runs - i) as f64 / (i + 1) as f64).product();
                choose * (1.0 - coverage).powi(j as i32) * coverage.powi((runs - j) as i32)
            })
            .sum();
        1.0 - below
    }

    /// The first n at which the plain sum reaches the confidence, counting up.
    fn plain_runs_needed(rank: usize, coverage: f64, level: f64) -> usize {
        (rank..)
            .find(|&n| plain_confidence(n, rank, coverage) >= level)
            .unwrap()
    }

    /// Other coverages and confidences, each count checked against the binomial sum
    /// counted up from n = rank and, for the largest value, against the closed form
    /// n = ⌈ln(1 − γ) / ln p⌉: 99 %/95 % needs 299 runs, 95 %/99 % 90, 99 %/99 % 459.
    #[test]
    fn run_counts_at_other_coverages_follow_the_binomial_sum() {
        for (coverage, level) in [
            (0.95f64, 0.95f64),
            (0.99, 0.95),
            (0.95, 0.99),
            (0.99, 0.99),
            (0.9, 0.9),
        ] {
            let closed = ((1.0f64 - level).ln() / coverage.ln()).ceil() as usize;
            assert_eq!(
                runs_needed(1, coverage, level),
                Some(closed),
                "{coverage}/{level}"
            );
            for rank in 1..=4 {
                assert_eq!(
                    runs_needed(rank, coverage, level),
                    Some(plain_runs_needed(rank, coverage, level)),
                    "rank {rank} at {coverage}/{level}"
                );
            }
        }
        assert_eq!(runs_needed(1, 0.99, 0.95), Some(299));
        assert_eq!(runs_needed(1, 0.95, 0.99), Some(90));
        assert_eq!(runs_needed(1, 0.99, 0.99), Some(459));
        // A coverage a hair below 1 is out of reach, not a hang.
        assert_eq!(runs_needed(1, 1.0 - 1e-15, 0.95), None);
    }

    /// At every n, the convergence track's quantile and bound are those of the first n
    /// values sorted afresh.
    #[test]
    fn the_convergence_track_is_the_order_statistics_of_each_prefix() {
        let values: Vec<f64> = (0..130)
            .map(|i| ((i * 37) % 101) as f64 + 0.5 * (i % 3) as f64)
            .collect();
        let track = convergence(&values, 0.95, 0.95);
        assert_eq!(track.len(), values.len());
        for step in &track {
            let mut prefix = values[..step.runs].to_vec();
            prefix.sort_by(f64::total_cmp);
            assert_eq!(step.value, values[step.runs - 1]);
            assert_eq!(
                step.quantile,
                crate::sweep::aggregate::quantile(&prefix, 0.95),
                "n = {}",
                step.runs
            );
            let expected = upper_rank(step.runs, 0.95, 0.95);
            assert_eq!(step.bound_rank, expected, "n = {}", step.runs);
            assert_eq!(
                step.bound,
                expected.map(|r| prefix[step.runs - r]),
                "n = {}",
                step.runs
            );
        }
        assert_eq!(track[57].bound, None);
        assert_eq!(track[58].bound_rank, Some(1));
        assert_eq!(track[92].bound_rank, Some(2));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 16, failure_persistence: None, ..ProptestConfig::default() })]

        /// On a known distribution (uniform on [0, 1): x_0.95 = 0.95), the bound from 59 or
        /// 93 runs is at or above 0.95 in at least 95 % of 4000 seeded sweeps (the miss
        /// rate is binomial: its 99.9 % upper limit at p = 5 % and 4000 trials is 6.2 %,
        /// so a correct rule fails this with probability ≪ 1e-3).
        #[test]
        fn the_bound_covers_the_quantile_at_its_confidence(seed in any::<u64>(), runs in prop::sample::select(vec![59usize, 93, 150])) {
            let mut state = seed | 1;
            let mut uniform = || {
                // xorshift64*: a reproducible uniform stream for the test.
                state ^= state >> 12;
                state ^= state << 25;
                state ^= state >> 27;
                (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
            };
            let trials = 4000;
            let mut misses = 0;
            for _ in 0..trials {
                let mut values: Vec<f64> = (0..runs).map(|_| uniform()).collect();
                values.sort_by(f64::total_cmp);
                if upper_bound(&values).expect("enough runs").0 < 0.95 {
                    misses += 1;
                }
            }
            let rate = misses as f64 / trials as f64;
            prop_assert!(rate <= 0.062, "{runs} runs: the bound missed x_0.95 in {rate} of the sweeps");
            // And it is not absurdly loose: it misses sometimes (γ < 1).
            prop_assert!(misses > 0, "{runs} runs: never missed");
        }
    }
}
