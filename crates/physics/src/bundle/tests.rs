//! Tests of the bundle generator.

use super::*;

/// A bundle with nominal gaps 1e-4 (walls) and 2e-4 (pins).
fn layout(pins: usize, levels: Levels) -> BundleLayout {
    BundleLayout {
        pins,
        levels,
        stiffness: 2e6,
        damping: 20.0,
        wall_gap: 1e-4,
        pin_gap: 2e-4,
        gaps: GapState::Uniform,
        closures: Vec::new(),
    }
}

fn row17() -> BundleLayout {
    let regular = Levels::Regular {
        first: 0.18,
        spacing: 0.18,
        count: 10,
    };
    BundleLayout {
        pin_gap: 1e-4,
        ..layout(17, regular)
    }
}

fn random(seed: u64, distribution: GapDistribution, relative: bool) -> BundleLayout {
    BundleLayout {
        gaps: GapState::Random {
            distribution,
            seed,
            relative,
        },
        ..row17()
    }
}

fn gaps(contacts: &[Contact]) -> Vec<f64> {
    contacts.iter().map(|c| c.gap).collect()
}

fn fields(issues: &[InputIssue]) -> Vec<&str> {
    issues.iter().map(|i| i.field.as_str()).collect()
}

#[test]
fn expansion_goes_level_by_level_from_the_left_wall() {
    // 3 pins, 2 levels: per level wall–0, 0–1, 1–2, 2–wall, lowest level first, with the
    // wall gap on wall contacts and the pin gap between pins.
    let contacts = layout(3, Levels::Explicit(vec![0.5, 1.0])).expand(1.0).unwrap();
    let expected = [
        (Body::Wall, Body::Pin(0)),
        (Body::Pin(0), Body::Pin(1)),
        (Body::Pin(1), Body::Pin(2)),
        (Body::Pin(2), Body::Wall),
    ];
    assert_eq!(contacts.len(), 8, "2 levels × (3 + 1) contacts");
    for (index, contact) in contacts.iter().enumerate() {
        let (left, right) = expected[index % 4];
        let height = if index < 4 { 0.5 } else { 1.0 };
        let gap = if index % 4 == 0 || index % 4 == 3 {
            1e-4
        } else {
            2e-4
        };
        assert_eq!(
            (contact.left, contact.right),
            (left, right),
            "bodies of contact {index}"
        );
        assert_eq!(contact.height, height, "height of contact {index}");
        assert_eq!(contact.gap, gap, "gap of contact {index}");
        assert_eq!(
            (contact.stiffness, contact.damping),
            (2e6, 20.0),
            "law of contact {index}"
        );
        assert!(
            contact.validate(3, 1.0).is_empty(),
            "contact {index} must be valid"
        );
    }
}

#[test]
fn row17_benchmark_has_180_contacts_with_the_top_level_on_the_pin() {
    // Levels 0.18 k (k = 1..10) on a 1.8 m pin: 0.18 + 9 × 0.18 rounds off 1.8 and is
    // snapped exactly onto the pin top; a level rounding above the top (0.1 + 2 × 0.1 =
    // 0.30000000000000004 on a 0.3 m pin) is snapped too, not rejected.
    let step = std::hint::black_box(0.18);
    assert_ne!(
        step + 9.0 * step,
        1.8,
        "premise: the raw top level rounds off 1.8"
    );
    let step = std::hint::black_box(0.1);
    assert!(
        step + 2.0 * step > 0.3,
        "premise: this top level rounds above 0.3"
    );
    let short = layout(
        1,
        Levels::Regular {
            first: 0.1,
            spacing: 0.1,
            count: 3,
        },
    );
    let tops: Vec<f64> = short.expand(0.3).unwrap().iter().map(|c| c.height).collect();
    assert_eq!(
        tops[4..],
        [0.3, 0.3],
        "overshooting top level snapped onto the pin"
    );
    // Row17's levels are the decimals 0.18, 0.36, …, 1.8, not their float sums
    // (3 × 0.18 = 0.54 + 1e-16 once accumulated).
    let heights: Vec<f64> = row17().expand(1.8).unwrap().iter().map(|c| c.height).collect();
    for (k, decimal) in [0.18, 0.36, 0.54, 0.72, 0.9, 1.08, 1.26, 1.44, 1.62, 1.8]
        .iter()
        .enumerate()
    {
        assert_eq!(heights[k * 18], *decimal, "level {k}");
    }
    let layout = row17();
    assert_eq!(layout.contact_count(), 180);
    let contacts = layout.expand(1.8).expect("row17 must expand");
    assert_eq!(contacts.len(), 180, "10 levels × 18 contacts");
    for (level, chunk) in contacts.chunks(18).enumerate() {
        let expected = 0.18 * (level + 1) as f64;
        for contact in chunk {
            assert!(
                (contact.height - expected).abs() < 1e-12,
                "level {level}: {}",
                contact.height
            );
        }
    }
    let last = &contacts[179];
    assert_eq!(last.height, 1.8, "top level snapped exactly onto the pin top");
    assert_eq!((last.left, last.right), (Body::Pin(16), Body::Wall));
    assert!(contacts.iter().all(|c| c.gap == 1e-4));
}

#[test]
fn same_seed_gives_same_gaps_and_another_seed_other_gaps() {
    // Reproducibility is the user's contract: a seed names one gap state.
    let law = GapDistribution::Normal {
        mean: 1e-4,
        std: 3e-5,
    };
    let first = gaps(&random(7, law.clone(), false).expand(1.8).unwrap());
    let again = gaps(&random(7, law.clone(), false).expand(1.8).unwrap());
    let other = gaps(&random(8, law, false).expand(1.8).unwrap());
    assert_eq!(first, again, "same seed must give bit-identical gaps");
    let differing = first.iter().zip(&other).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 180, "another seed must change every gap");
}

#[test]
fn uniform_law_has_the_textbook_mean_and_variance() {
    // 100 000 draws on [low, high): mean (low+high)/2 and variance (high−low)²/12 within
    // 5 standard errors (SE of the variance from the 4th central moment (high−low)⁴/80).
    let (low, high, n) = (2e-5, 1.4e-4, 100_000);
    let mut rng = GapRng::new(2024);
    let draws: Vec<f64> = (0..n)
        .map(|_| rng.sample(&GapDistribution::Uniform { low, high }))
        .collect();
    assert!(
        draws.iter().all(|&x| (low..high).contains(&x)),
        "draws within [low, high)"
    );
    let mean = draws.iter().sum::<f64>() / n as f64;
    let variance = draws.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let width = high - low;
    let (mean_expected, variance_expected) = ((low + high) / 2.0, width * width / 12.0);
    let mean_se = (variance_expected / n as f64).sqrt();
    let variance_se = width * width * (1.0 / 180.0 / n as f64).sqrt();
    assert!(
        (mean - mean_expected).abs() < 5.0 * mean_se,
        "mean {mean} vs {mean_expected} (SE {mean_se})"
    );
    assert!(
        (variance - variance_expected).abs() < 5.0 * variance_se,
        "variance {variance} vs {variance_expected} (SE {variance_se})"
    );
}

/// 1 − Φ(α) by composite Simpson on [α, α + 12] (the tail beyond is < 1e-32): an
/// evaluation independent of the sampler.
fn normal_upper_tail(alpha: f64) -> f64 {
    let density = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let (intervals, width) = (20_000, 12.0);
    let h = width / intervals as f64;
    let inner: f64 = (1..intervals)
        .map(|k| (if k % 2 == 1 { 4.0 } else { 2.0 }) * density(alpha + k as f64 * h))
        .sum();
    h / 3.0 * (density(alpha) + inner + density(alpha + width))
}

#[test]
fn truncated_normal_mean_matches_the_analytic_formula() {
    // E[X | X ≥ 0] = μ + σ φ(α)/(1 − Φ(α)), α = −μ/σ. Cases: truncation negligible
    // (α = −10), half-normal (α = 0), strong on both sampler branches (α = 1, 3).
    // 100 000 draws, tolerance 5 σ/√n (the truncated law's std is below σ).
    let sigma = 1e-5;
    for alpha in [-10.0, 0.0, 1.0, 3.0] {
        let mu = -alpha * sigma;
        let tail = normal_upper_tail(alpha);
        let density = (-0.5 * alpha * alpha).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let expected = mu + sigma * density / tail;
        let n = 100_000;
        let mut rng = GapRng::new(99);
        let law = GapDistribution::Normal { mean: mu, std: sigma };
        let mean = (0..n).map(|_| rng.sample(&law)).sum::<f64>() / n as f64;
        let tolerance = 5.0 * sigma / (n as f64).sqrt();
        assert!(
            (mean - expected).abs() < tolerance,
            "α = {alpha}: sample mean {mean} vs analytic {expected} (tolerance {tolerance})"
        );
    }
    assert!(
        (normal_upper_tail(0.0) - 0.5).abs() < 1e-14,
        "Simpson check: 1 − Φ(0) = 1/2"
    );
}

#[test]
fn no_gap_is_ever_negative() {
    // Strong truncation, relative and absolute forms, many seeds: every gap is finite ≥ 0.
    let laws = [
        GapDistribution::Normal { mean: 0.0, std: 1e-4 },
        GapDistribution::Normal {
            mean: -2e-4,
            std: 1e-4,
        },
        GapDistribution::Normal { mean: 1.0, std: 2.0 },
        GapDistribution::Uniform { low: 0.0, high: 3e-4 },
    ];
    for seed in 0..200 {
        for (k, law) in laws.iter().enumerate() {
            for relative in [false, true] {
                let contacts = random(seed, law.clone(), relative).expand(1.8).unwrap();
                assert!(
                    contacts.iter().all(|c| c.gap.is_finite() && c.gap >= 0.0),
                    "seed {seed}, law {k}, relative {relative}: a gap is negative or not finite"
                );
            }
        }
    }
}

#[test]
fn closure_with_factor_zero_zeroes_exactly_its_zone() {
    // Levels 3..=5, pins 4..=6 of row17: the contacts 3–4, 4–5, 5–6, 6–7 at those levels
    // close; every other contact keeps its gap. A second closure then halves a wall zone.
    let mut layout = row17();
    layout.closures = vec![
        LocalClosure {
            first_level: 3,
            last_level: 5,
            first_pin: 4,
            last_pin: 6,
            factor: 0.0,
        },
        LocalClosure {
            first_level: 9,
            last_level: 9,
            first_pin: 0,
            last_pin: 0,
            factor: 0.5,
        },
    ];
    let contacts = layout.expand(1.8).unwrap();
    for (index, contact) in contacts.iter().enumerate() {
        let (level, slot) = (index / 18, index % 18);
        let expected = if (3..=5).contains(&level) && (4..=7).contains(&slot) {
            0.0
        } else if level == 9 && slot <= 1 {
            0.5e-4
        } else {
            1e-4
        };
        assert_eq!(
            contact.gap, expected,
            "contact {index} (level {level}, slot {slot})"
        );
    }
}

#[test]
fn validation_names_every_bad_field() {
    // A layout wrong everywhere: each problem is reported on its own field path.
    let mut bad = layout(
        0,
        Levels::Regular {
            first: -0.1,
            spacing: 0.0,
            count: 0,
        },
    );
    bad.stiffness = f64::NAN;
    bad.wall_gap = -1.0;
    bad.gaps = GapState::Random {
        distribution: GapDistribution::Uniform {
            low: 2e-4,
            high: 1e-4,
        },
        seed: 1,
        relative: false,
    };
    bad.closures = vec![LocalClosure {
        first_level: 2,
        last_level: 1,
        first_pin: 0,
        last_pin: 3,
        factor: -1.0,
    }];
    let issues = bad.validate(1.8);
    let expected = [
        "pins",
        "levels/first",
        "levels/spacing",
        "levels/count",
        "stiffness",
        "wall_gap",
        "gaps/distribution/high",
        "closures/0/first_level",
        "closures/0/last_level",
        "closures/0/last_level",
        "closures/0/first_pin",
        "closures/0/last_pin",
        "closures/0/factor",
    ];
    assert_eq!(fields(&issues), expected, "issues: {issues:#?}");
    assert!(issues.iter().all(|i| !i.reason.is_empty()));
    assert_eq!(bad.expand(1.8), Err(issues), "expand reports the same issues");

    // Wrong per-contact list length: the reason states the expected count.
    let mut short = row17();
    short.gaps = GapState::PerContact(vec![1e-4, -1.0, f64::INFINITY]);
    let issues = short.validate(1.8);
    assert_eq!(fields(&issues), ["gaps/values", "gaps/values/1", "gaps/values/2"]);
    assert!(issues[0].reason.contains("expected 180"), "{}", issues[0].reason);

    // Explicit levels outside the pin or not increasing; normal law truncated too deep.
    let mut levels = layout(2, Levels::Explicit(vec![0.5, 0.5, 0.0, f64::NAN, 2.0]));
    levels.gaps = GapState::Random {
        distribution: GapDistribution::Normal {
            mean: -1.0,
            std: 0.01,
        },
        seed: 0,
        relative: true,
    };
    let issues = levels.validate(1.8);
    let expected = [
        "levels/1",
        "levels/2",
        "levels/3",
        "levels/4",
        "gaps/distribution/mean",
    ];
    assert_eq!(fields(&issues), expected, "issues: {issues:#?}");

    // Regular levels running off the top name the count.
    let high = layout(
        2,
        Levels::Regular {
            first: 0.5,
            spacing: 0.5,
            count: 5,
        },
    );
    assert_eq!(fields(&high.validate(1.8)), ["levels/count"]);
}

#[test]
fn absurd_sizes_are_rejected_without_panicking_or_allocating() {
    // contact_count saturates; oversized layouts are refused before any expansion.
    let huge = layout(
        usize::MAX,
        Levels::Regular {
            first: 0.1,
            spacing: 0.1,
            count: usize::MAX,
        },
    );
    assert_eq!(huge.contact_count(), usize::MAX);
    let issues = huge.validate(1.8);
    assert_eq!(fields(&issues), ["levels/count", ""], "issues: {issues:#?}");
    let over = layout(100_000, Levels::Explicit(vec![1.0]));
    assert_eq!(fields(&over.expand(1.8).unwrap_err()), [""]);
    let at_limit = layout(99_999, Levels::Explicit(vec![1.0]));
    assert_eq!(at_limit.expand(1.8).map(|c| c.len()), Ok(MAX_CONTACTS));
    assert_eq!(fields(&row17().validate(f64::NAN)), ["levels"], "bad pin length");
    let overflow = random(
        1,
        GapDistribution::Normal {
            mean: 1e308,
            std: 1e308,
        },
        false,
    );
    assert_eq!(fields(&overflow.expand(1.8).unwrap_err()), ["gaps"]);
}

#[test]
fn generator_matches_the_independent_reference_bit_for_bit() {
    // Golden values from tools/bundle_rng_golden.py, a Python transcription of the published
    // SplitMix64 and xoshiro256** definitions (Python floats are IEEE doubles with
    // correctly rounded + − × ÷ √). Also the published SplitMix64 vector for seed 0.
    let mut state = 0;
    assert_eq!(splitmix64(&mut state), 0xE220_A839_7B1D_CDAF, "SplitMix64(0)");
    let mut rng = GapRng::new(42);
    let raw: Vec<u64> = (0..4).map(|_| rng.next_u64()).collect();
    let expected = [
        0x15780b2e0c2ec716,
        0x6104d9866d113a7e,
        0xae17533239e499a1,
        0xecb8ad4703b360a1,
    ];
    assert_eq!(raw, expected, "xoshiro256** seeded by SplitMix64(42)");
    let mut rng = GapRng::new(42);
    let uniform: Vec<f64> = (0..3).map(|_| rng.uniform()).collect();
    assert_eq!(
        uniform,
        [0.08386297105988216, 0.3789802506626686, 0.6800434110281394]
    );
    let mut rng = GapRng::new(42);
    let normal: Vec<f64> = (0..4).map(|_| rng.standard_normal()).collect();
    let expected = [
        -0.7262191382447857,
        0.22162270150359337,
        0.46417731016247366,
        1.476249461018415,
    ];
    assert_eq!(normal, expected, "polar-method normals");
    let mut rng = GapRng::new(42);
    let tail: Vec<f64> = (0..3).map(|_| rng.standard_normal_above(1.5)).collect();
    assert_eq!(tail, [2.7392855545292942, 1.6927993215511954, 1.5041149291451514]);
}

#[test]
fn own_logarithm_is_accurate() {
    // The deterministic ln stays within 4e-16 (relative) of the platform's over normal
    // and subnormal inputs, and is exact at powers of two.
    let mut x = 3e-320;
    while x < 1e300 {
        let (mine, platform) = (ln(x), x.ln());
        assert!(
            (mine - platform).abs() <= 4e-16 * platform.abs().max(1.0),
            "ln({x}) = {mine} vs {platform}"
        );
        x *= 1.37;
    }
    assert_eq!(ln(0.5), -std::f64::consts::LN_2);
    assert_eq!(ln(1.0), 0.0);
    assert!(ln(0.0).is_nan() && ln(-1.0).is_nan() && ln(f64::INFINITY).is_nan());
}
