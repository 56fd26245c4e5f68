//! Time-domain corrections with wavelets (Lilhanand & Tseng 1988; the tapered cosine
//! wavelet of Al Atik & Abrahamson 2010, as in RspMatch) for what the Fourier rounds of
//! [`super`] leave: a spectrum of a record a few periods long is jagged at its low
//! frequencies (neighbouring oscillators 2 % apart peak at different times, 5–10 % apart
//! in value), finer than a Fourier ratio on a record of that length can shape. A wavelet
//! placed at an oscillator's peak moves that peak.
//!
//! # A round
//! 1. Which frequencies: those of the given grid (the caller's verification grid) whose
//!    deviation |Sa/Sa_target − 1| is the largest within a ratio [`NEIGHBOURHOOD`] on
//!    each side (the local extremes of the deviation: one wavelet per bump) and above
//!    a threshold (the caller's: 0.8 × the tolerance). A bump well within the
//!    tolerance is left alone: its wavelet, broad in frequency, would move its
//!    neighbours, those that matter, as much as itself (measured on the design spectra
//!    of the synthetic tests, seeds 1–10, 60 cases: every local extreme corrected left
//!    3 refused; those above 0.3, 0.5, 0.7, 0.8 and 1.0 × the tolerance left 5, 2, 2,
//!    1 and 1; `cargo test -p chocmodal-physics --release --lib design_spectra_ --
//!    --include-ignored --nocapture` with the threshold changed).
//! 2. For each, fᵢ: the oscillator's relative displacement uᵢ(t) over the record and one
//!    period of the lowest grid frequency after it, stepped exactly as
//!    [`crate::response_spectrum`] does (linear between samples, sub-steps of at most a
//!    1/64 period); its peak, signed, at tᵢ; the change it needs
//!    Δᵢ = sign(uᵢ(tᵢ)) (Sa_target(fᵢ)/ωᵢ² − |uᵢ(tᵢ)|).
//! 3. One wavelet per frequency, placed for its oscillator's peak at tⱼ (the lag Δtⱼ
//!    puts its response at tⱼ in phase; it keeps building for about a period after):
//!    wⱼ(t) = cos(ω'ⱼ τ) e^{−(τ/γⱼ)²}, τ = t − tⱼ + Δtⱼ, ω'ⱼ = ωⱼ √(1 − ξ²),
//!    Δtⱼ = atan(√(1 − ξ²)/ξ)/ω'ⱼ, γⱼ = 1.178 fⱼ^−0.93 s, cut at |τ| > 4γⱼ and where the
//!    envelope is 0 (the record's ends).
//! 4. Its weight as if it were alone: bⱼ = Δⱼ / Cⱼⱼ, Cⱼⱼ the response of oscillator j at
//!    tⱼ to wⱼ alone, from rest; add r × Σ bⱼ wⱼ, r the caller's relaxation (at most
//!    [`RELAXATION`]; the caller then corrects the baseline).
//!
//! The wavelets are a few periods long, hence broad in frequency: neighbours 7 % apart
//! respond to each other's wavelets almost as much as to their own. Solving the coupled
//! system C b = Δ (Lilhanand & Tseng) then gives large weights of opposite signs that
//! meet the selected peaks and throw the spectrum between them far off (measured on the
//! 1000-per-decade grid: 25–57 % after a round from 12 %); the uncoupled weights, a
//! fraction at a time, move every selected peak toward the target and leave the
//! coupling to the next round, which sees it. Every operation is IEEE `+ − × ÷ √` or
//! [`crate::portable`]'s.

use crate::portable;
use crate::response_spectrum::{STEPS_PER_PERIOD, Step};

/// Largest fraction of the uncoupled wavelet weights added in a round (1 would meet
/// every selected peak exactly if the other wavelets moved nothing there; the caller
/// lowers it after a round that overshot). Measured at a fixed fraction on the design
/// spectra of the synthetic tests (30 cases with seeds 1–5, 30 with seeds 6–10), every
/// local extreme corrected: 0.3 left 2 + 2 of the 60 refused, 0.5 left 5 + 3 (the rounds
/// overshoot), 0.2 left 2 + 1 at a larger cost; with the caller's threshold (0.8 × the
/// tolerance), 0.3 leaves 0 + 1, 0.2 leaves 1 + 1.
pub const RELAXATION: f64 = 0.3;

/// A selected frequency has the largest deviation among the grid's frequencies within
/// this ratio of it on either side (±7 %: 30 frequencies at 1000 per decade).
pub const NEIGHBOURHOOD: f64 = 1.072;

/// The wavelets are cut where their taper is below e^(−TAPER_CUT²) ≈ 1e-7.
const TAPER_CUT: f64 = 4.0;

/// One oscillator on the record's grid: its exact sub-step.
struct Oscillator {
    omega: f64,
    substeps: usize,
    step: Step,
}

/// A point of an oscillator's history: sample interval `interval` (from sample
/// `interval` to `interval` + 1), sub-step `substep` (1-based) within it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Instant {
    interval: usize,
    substep: usize,
}

impl Oscillator {
    fn new(frequency: f64, damping: f64, h: f64) -> Self {
        let omega = std::f64::consts::TAU * frequency;
        let substeps = (h * STEPS_PER_PERIOD * frequency).ceil().max(1.0) as usize;
        Self {
            omega,
            substeps,
            step: Step::new(omega, damping, h / substeps as f64),
        }
    }

    /// Steps over `samples` (linear between them) from rest at sample `from`, calling
    /// `visit` with the instant (intervals counted from sample 0) and u after every
    /// sub-step, until it returns false.
    fn run(&self, samples: &[f64], from: usize, mut visit: impl FnMut(Instant, f64) -> bool) {
        let (mut u, mut v) = (0.0, 0.0);
        for (k, pair) in samples.windows(2).enumerate().skip(from) {
            let (a0, a1) = (pair[0], pair[1]);
            let mut f0 = -a0;
            for substep in 1..=self.substeps {
                let f1 = if substep == self.substeps {
                    -a1
                } else {
                    -(a0 + (a1 - a0) * substep as f64 / self.substeps as f64)
                };
                (u, v) = self.step.advance(u, v, f0, f1);
                if !visit(Instant { interval: k, substep }, u) {
                    return;
                }
                f0 = f1;
            }
        }
    }

    /// The largest |u| over `samples`, signed, and when.
    fn peak(&self, samples: &[f64]) -> (Instant, f64) {
        let mut peak = (
            Instant {
                interval: 0,
                substep: 1,
            },
            0.0_f64,
        );
        self.run(samples, 0, |at, u| {
            if u.abs() > peak.1.abs() {
                peak = (at, u);
            }
            true
        });
        peak
    }

    /// u at `at` under `samples` alone, at rest before sample `from` (where they are 0).
    fn response_at(&self, samples: &[f64], from: usize, at: Instant) -> f64 {
        if at.interval < from {
            return 0.0;
        }
        let mut value = 0.0;
        self.run(samples, from, |now, u| {
            if now == at {
                value = u;
                return false;
            }
            true
        });
        value
    }
}

/// atan(y) for y ≥ 0 from `+ − × ÷ √` only: the argument halved three times
/// (atan y = 2 atan(y / (1 + √(1 + y²)))), then the alternating series.
fn atan(y: f64) -> f64 {
    let mut x = y;
    for _ in 0..3 {
        x /= 1.0 + (1.0 + x * x).sqrt();
    }
    // |x| ≤ tan(π/16) < 0.2: 30 terms leave < 0.2⁶¹.
    let (mut sum, mut power) = (0.0, x);
    for k in 0..30 {
        let term = power / (2 * k + 1) as f64;
        sum += if k % 2 == 0 { term } else { -term };
        power *= x * x;
    }
    8.0 * sum
}

/// Wavelet j of the module doc on `count` samples every `h`, for a peak of its oscillator
/// at `peak_time`, 0 where `envelope` is 0 or beyond it: (first non-zero index, values
/// from there).
fn wavelet(
    frequency: f64,
    damping: f64,
    peak_time: f64,
    h: f64,
    envelope: &[f64],
    count: usize,
) -> (usize, Vec<f64>) {
    let root = (1.0 - damping * damping).sqrt();
    let omega_d = std::f64::consts::TAU * frequency * root;
    let lag = atan(root / damping) / omega_d;
    let width = 1.178 * portable::powf(frequency, -0.93);
    let centre = peak_time - lag;
    let first = ((centre - TAPER_CUT * width) / h).ceil().max(0.0) as usize;
    let last = (((centre + TAPER_CUT * width) / h).floor().max(0.0) as usize).min(count - 1);
    let values = (first..=last.max(first))
        .map(|k| {
            let tau = k as f64 * h - centre;
            if envelope.get(k).is_none_or(|e| *e <= 0.0) || tau.abs() > TAPER_CUT * width {
                return 0.0;
            }
            let (_, cos) = portable::sin_cos(omega_d * tau);
            cos * portable::exp(-(tau / width) * (tau / width))
        })
        .collect();
    (first, values)
}

/// Step 1 of the module doc: indices of the local extremes of |`deviation`| at the
/// increasing `frequencies`, each the largest within a ratio [`NEIGHBOURHOOD`] and
/// above `threshold` (≥ 0).
fn select(frequencies: &[f64], deviation: &[f64], threshold: f64) -> Vec<usize> {
    (0..deviation.len())
        .filter(|&i| {
            let here = deviation[i].abs();
            let (low, high) = (frequencies[i] / NEIGHBOURHOOD, frequencies[i] * NEIGHBOURHOOD);
            let from = frequencies.partition_point(|&f| f < low);
            let to = frequencies.partition_point(|&f| f <= high);
            here > threshold && here > 0.0 && deviation[from..to].iter().all(|d| d.abs() <= here)
        })
        .collect()
}

/// What a round works on.
pub struct Matching<'a> {
    /// The frequencies where the record's spectrum is known (Hz), increasing.
    pub frequencies: &'a [f64],
    /// Sa_target at each (m/s²).
    pub wanted: &'a [f64],
    /// The record's Sa at each (m/s²).
    pub spectrum: &'a [f64],
    pub damping: f64,
    /// Sampling interval (s).
    pub step: f64,
    /// The record's envelope: the wavelets are 0 where it is 0.
    pub envelope: &'a [f64],
    /// Fraction r of the uncoupled weights added.
    pub relaxation: f64,
    /// Only local extremes of |Sa/Sa_target − 1| above this are corrected.
    pub threshold: f64,
}

impl Matching<'_> {
    /// `samples` after one round of the module doc (before the baseline correction), or
    /// `None` when no frequency is selected (none above the threshold).
    pub fn round(&self, samples: &[f64]) -> Option<Vec<f64>> {
        let h = self.step;
        let deviation: Vec<f64> = self
            .spectrum
            .iter()
            .zip(self.wanted)
            .map(|(s, w)| s / w - 1.0)
            .collect();
        let selected = select(self.frequencies, &deviation, self.threshold);
        if selected.is_empty() {
            return None;
        }
        let tail = (1.0 / (self.frequencies[0] * h)).ceil() as usize;
        let mut record = samples.to_vec();
        record.resize(samples.len() + tail, 0.0);
        let oscillators: Vec<Oscillator> = selected
            .iter()
            .map(|&i| Oscillator::new(self.frequencies[i], self.damping, h))
            .collect();
        let mut peaks = Vec::with_capacity(selected.len());
        let mut change = Vec::with_capacity(selected.len());
        for (&i, oscillator) in selected.iter().zip(&oscillators) {
            let (at, value) = oscillator.peak(&record);
            let wanted = self.wanted[i] / (oscillator.omega * oscillator.omega);
            peaks.push(at);
            change.push(value.signum() * (wanted - value.abs()));
        }
        let wavelets: Vec<(usize, Vec<f64>)> = selected
            .iter()
            .zip(&oscillators)
            .zip(&peaks)
            .map(|((&i, oscillator), at)| {
                let time = (at.interval as f64 + at.substep as f64 / oscillator.substeps as f64) * h;
                wavelet(
                    self.frequencies[i],
                    self.damping,
                    time,
                    h,
                    self.envelope,
                    record.len(),
                )
            })
            .collect();
        let mut out = samples.to_vec();
        let mut alone = vec![0.0; record.len()];
        for (((first, values), oscillator), (at, change)) in
            wavelets.iter().zip(&oscillators).zip(peaks.iter().zip(&change))
        {
            alone.fill(0.0);
            alone[*first..*first + values.len()].copy_from_slice(values);
            // At rest one sample before the wavelet's first (0 there: the step from it is
            // the wavelet's linear rise).
            let response = oscillator.response_at(&alone, first.saturating_sub(1), *at);
            if response == 0.0 || !response.is_finite() {
                continue;
            }
            let weight = self.relaxation * change / response;
            for (x, w) in out.iter_mut().skip(*first).zip(values) {
                *x += weight * w;
            }
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan_from_square_roots_matches_the_library() {
        for y in [0.0, 1e-3, 0.2, 1.0, 3.0, 19.97, 1e3] {
            assert!((atan(y) - y.atan()).abs() < 1e-14, "atan({y}) = {}", atan(y));
        }
    }

    // The local extremes of |deviation|, one per bump.
    #[test]
    fn one_frequency_per_bump_of_the_deviation() {
        let deviation = [
            0.0, 0.05, 0.12, 0.06, 0.0, 0.0, 0.0, 0.0, -0.03, -0.2, -0.1, 0.01, 0.08,
        ];
        // 100 per decade: three on each side are within the neighbourhood, four are not.
        let frequencies: Vec<f64> = (0..deviation.len())
            .map(|k| 10f64.powf(k as f64 / 100.0))
            .collect();
        assert_eq!(select(&frequencies, &deviation, 0.0), [2, 9]);
        assert!(select(&frequencies[..5], &[0.0; 5], 0.0).is_empty());
        // Above a threshold only: the bump at 0.12 is left alone.
        assert_eq!(select(&frequencies, &deviation, 0.15), [9]);
    }

    // A wavelet alone drives its own oscillator hard at the time it was placed for (the
    // response keeps building for about a period after it: 0.79 of its peak there).
    #[test]
    fn a_wavelet_drives_its_oscillator_where_it_was_placed() {
        let (h, xi) = (0.005, 0.05);
        let count = 4001;
        let envelope = vec![1.0; count];
        for f in [0.5, 2.0, 10.0, 33.0] {
            let (first, values) = wavelet(f, xi, 10.0, h, &envelope, count);
            let mut samples = vec![0.0; count];
            samples[first..first + values.len()].copy_from_slice(&values);
            let oscillator = Oscillator::new(f, xi, h);
            let (_, peak) = oscillator.peak(&samples);
            let at = Instant {
                interval: 2000 - 1,
                substep: oscillator.substeps,
            };
            let there = oscillator.response_at(&samples, first.saturating_sub(1), at);
            assert!(
                there.abs() > 0.75 * peak.abs(),
                "{f} Hz: u(10 s) = {there:e}, peak {peak:e}"
            );
        }
    }
}
