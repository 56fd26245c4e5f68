//! Spectrum-compatible synthetic accelerograms (the SIMQKE method, Gasparini & Vanmarcke
//! 1976; code_aster `GENE_ACCE_SEISME`): a stationary random signal with seeded phases,
//! shaped in time by an envelope, its Fourier amplitudes corrected again and again until
//! its response spectrum matches a target, with its peak acceleration held to the
//! target's top value and, late in the iteration, wavelets added in time where the
//! Fourier corrections stall (RspMatch-style); baseline-corrected after every change.
//!
//! # Algorithm
//! 1. Grid: n = round(D/h) + 1 samples every h (s); the stationary signal lives on
//!    N = the power of two ≥ n, bins f_j = j/(N h).
//! 2. Phases φ_j = 2π u_j, u_j drawn in bin order j = 1, …, N/2 − 1 from
//!    [`crate::random::GapRng`] seeded with `seed`.
//! 3. Amplitudes A_j = Sa(f_j)/√f_j · taper(f_j) (a PSD ∝ Sa²/f, the shape of the
//!    usual spectrum-to-PSD relations; the iteration fixes the level), Sa the target held
//!    constant outside its band; taper 1 over the band, (f/f_lo)² below it down to 0 at
//!    f_lo/2, (f_hi/f)² above it, 0 beyond 0.8 × Nyquist.
//! 4. First record: x(t_k) = Σ_j 2A_j cos(2π f_j t_k + φ_j) (an inverse FFT), times the
//!    envelope e(t_k) ([`Envelope`]), baseline-corrected ([`baseline`]).
//! 5. Check: its pseudo-acceleration spectrum at the target damping
//!    ([`crate::response_spectrum`]) on the check grid (the target's frequencies and
//!    [`CHECK_POINTS_PER_DECADE`] log-spaced frequencies per decade across its band);
//!    deviation = max |Sa_record/Sa_target − 1|.
//! 6. Fourier round: the record's own Fourier transform (zero-padded to twice its length
//!    so that the filter does not wrap around) is multiplied by R(f) = Sa_target/Sa_record,
//!    R interpolated linearly in ln f between check frequencies and held outside the band;
//!    transformed back, cut to [0, D], 0 where the envelope is 0 (both ends),
//!    baseline-corrected. Correcting the record itself rather than the stationary
//!    amplitudes converges where few cycles of a low frequency fit in the strong motion.
//!    Then (6b) the peak acceleration: if the record's PGA exceeds the target's value at
//!    its highest frequency by more than 0.4 × the tolerance, every excursion
//!    (a run of samples of one sign between zero crossings) that peaks above that value
//!    is scaled down to peak at it, and the baseline corrected again. Near the top of a
//!    design spectrum an oscillator is nearly rigid and peaks with the record's PGA, which
//!    the whole band sets: a Fourier ratio near 33 Hz barely moves it (RG 1.60 ended
//!    13–26 % off at 33 Hz after 40 Fourier rounds, seeds 1–5), the peak limit does. The
//!    target is read as flat above its band (as RG 1.60 is above 33 Hz), so its top value
//!    is taken for the zero-period acceleration; the limit only lowers, so a target whose
//!    top is above the PGA it implies (Eurocode 8 at 33 Hz: 1.23 a_g S) gets a PGA at or
//!    below its top value (0.77–0.92 of it measured), not its a_g S.
//!    Rounds 2 … ⌊max_iterations/2⌋ + 1 are Fourier rounds, each checked as in 5; they
//!    stop early once the deviation is below 0.8 × the tolerance.
//! 7. Verification: the closest record of the Fourier rounds, its spectrum on the
//!    verification grid (the target's frequencies and [`VERIFY_POINTS_PER_DECADE`]
//!    log-spaced frequencies per decade, the grid of the independent check in the tests).
//!    The spectrum of a record a few periods long is jagged at its low end between check
//!    frequencies (10–15 % off where the check grid saw 8 %): this is the deviation
//!    reported, and the one the tolerance is held to.
//! 8. Wavelet rounds ([`wavelets`]), while the verified deviation exceeds the tolerance
//!    and is within twice it (further off, wavelets cannot close the gap and each round
//!    costs a spectrum on the dense grid): a tapered cosine wavelet (Al Atik &
//!    Abrahamson 2010) at the peak of each oscillator where the deviation on the
//!    verification grid has a local extreme (±7 % in frequency) above 0.8 × the
//!    tolerance (the Fourier rounds' goal: the bumps near or beyond the limit; a
//!    wavelet is broad in frequency, and one on a bump well within the tolerance moves
//!    its neighbours as much), each weighted as if alone, a fraction of that added
//!    (0.3; halved after a round that left the deviation larger, raised 1.5 times up
//!    to 0.3 after one that lowered it), baseline-corrected, the peak held as in 6b;
//!    each round verified as in 7. They move an oscillator's peak where it is, which a
//!    Fourier ratio cannot do finely enough at the low end of the band. They stop once
//!    the deviation is within the tolerance or after `max_iterations` rounds in all;
//!    the record with the smallest verified deviation is kept, and refused if it
//!    exceeds the tolerance.
//!
//! # What it reaches, what it costs
//! Measured on 5 %-damped design spectra to 33 Hz (RG 1.60 at 0.3 g, Eurocode 8 type 1
//! ground C at a_g = 0.3 g, a 0.5–33 Hz shape with 3.9 m/s² at 33 Hz), seeds 1–5,
//! 20 s / 10 s of strong motion and 12 s / 6 s, defaults (tolerance 10 %, 40 rounds,
//! h = 5 ms): all 30 generated within the tolerance at 1000 frequencies per decade
//! (recomputed independently: the same figures, 7.9–10.0 %) in 10–39 rounds; seeds
//! 6–10: 29 of 30 (the 0.5–33 Hz shape at 12 s, seed 9, refused at 10.9 % at 1.04 Hz).
//! Before the wavelets were limited to the bumps above 0.8 × the tolerance (every local
//! extreme had one): 28 of 30 and 29 of 30, those of seeds 1–5 refused at 10.3 % and
//! 10.7 % below 0.75 Hz after 40 rounds (20 s records). None of the records it returns
//! is further off at 1000 per decade than it says (before the verification grid, 8 of
//! the 28 it then returned were 10.0–13.0 % off there). The 33 Hz end is met: RG
//! 1.60's spectrum from 9 to 33 Hz is within 10 % for every seed, its PGA 1.00–1.03 ×
//! 0.3 g; Eurocode 8's PGA is 0.77–0.92 of its 33 Hz value. The wavelet rounds do not
//! converge steadily: from 10–15 % they wander by a few per cent from round to round
//! (the relaxation rule damps the swings; the failing case above cycles between 11 and
//! 15 %), and a record within the tolerance is found in most cases, not all (a coupled
//! solve of the wavelet weights, longer or more wavelets, line searches on the
//! relaxation, going back to the best record after a worse round, Fourier rounds on
//! a grid dense at the low end, wavelets that raise a lower peak at a dip instead of
//! the highest, and a start whose low frequencies come in a short burst did no
//! better). Measured with `cargo test -p chocmodal-physics --release --lib
//! design_spectra_ -- --include-ignored --nocapture` (seeds 1–5: the acceptance test,
//! each case's figures; seeds 6–10: `design_spectra_with_other_seeds`).
//!
//! Cost: each Fourier round is a spectrum on the check grid (about samples ×
//! Σ⌈64 f h⌉ exact steps); each wavelet round a spectrum on the verification grid (ten
//! times that) and one oscillator run per wavelet (a few tens). 0.2–3.4 s per design
//! case above. The longest request ([`MAX_SAMPLES`]: 64 001 samples of RG 1.60) took
//! 7.7 s at a 1 % tolerance (21 Fourier rounds, verified at 7.7 %, refused without
//! wavelet rounds) and 55 s at 4 % (verified within twice it: wavelet rounds through
//! round 40, refused at 4.9 %; 54 s and 4.7 % when every local extreme had a wavelet),
//! against 21 s for all 40 rounds before the verification grid (`cargo test -p
//! chocmodal-physics --release --lib the_longest_request -- --ignored --nocapture`, on
//! 2 cores shared with other work).
//!
//! Every operation is IEEE `+ − × ÷ √` or [`crate::portable`]'s functions and our own FFT
//! ([`fft`]): the same seed gives the same samples, bit for bit, on every machine.

mod baseline;
mod envelope;
mod fft;
mod target;
mod wavelets;

pub use baseline::end_motion;
pub use envelope::Envelope;
pub use target::TargetSpectrum;

use crate::loads::Table;
use crate::random::GapRng;
use crate::response_spectrum::{log_spaced, pseudo_acceleration_uniform};
use crate::{InputIssue, portable};

/// Most samples of a generated record (2¹⁶: 5.5 minutes at 200 samples per second).
/// Generation costs about samples × grid frequencies × rounds oscillator steps (the
/// wavelet rounds on the verification grid, ten times denser): this keeps the worst
/// request to about a minute (measured: 64 001 samples, 40 rounds, 55 s), checked
/// before any work.
pub const MAX_SAMPLES: usize = 1 << 16;
/// Default largest deviation of the spectrum from the target over its band (10 %).
pub const DEFAULT_TOLERANCE: f64 = 0.1;
/// Default most correction rounds.
pub const DEFAULT_MAX_ITERATIONS: usize = 40;
/// Check frequencies per decade of the target's band: the Fourier rounds' grid.
pub const CHECK_POINTS_PER_DECADE: f64 = 100.0;
/// Verification frequencies per decade of the target's band: the grid on which the
/// reported deviation is measured and the wavelet rounds work (the spectrum of a short
/// record is jagged between check frequencies at its low end).
pub const VERIFY_POINTS_PER_DECADE: f64 = 1000.0;

/// The Fourier rounds stop once the deviation on the check grid is below this fraction
/// of the tolerance (or after ⌊max_iterations/2⌋ + 1 rounds): a margin for the spectrum
/// between check frequencies. The wavelet rounds correct only the bumps of the
/// deviation above it.
const GOAL: f64 = 0.8;

/// The wavelet rounds fine-tune a record verified within this multiple of the tolerance;
/// one further off is returned as it is (and refused): they correct a few per cent, and
/// each costs a spectrum on the dense grid.
const REACH: f64 = 2.0;

/// The Fourier rounds lower the record's largest excursions (step 6b) once its peak
/// acceleration is more than this fraction of the tolerance above the target's value at
/// its highest frequency.
const PEAK_GATE: f64 = 0.4;

/// What to generate.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumCompatible {
    pub target: TargetSpectrum,
    /// Record length D (s).
    pub duration: f64,
    /// Plateau of the envelope S (s), 0 < S < D.
    pub strong_motion: f64,
    /// Build-up time of the envelope (s); `None`: a quarter of D − S.
    pub rise: Option<f64>,
    /// Sampling interval h (s); `None`: min(0.005, 1/(5 f_max)), f_max the target's
    /// highest frequency.
    pub time_step: Option<f64>,
    /// Largest relative deviation of the spectrum from the target over its band.
    pub tolerance: f64,
    /// Most correction rounds before giving up.
    pub max_iterations: usize,
    /// Seed of the random phases.
    pub seed: u64,
}

/// A generated record.
#[derive(Debug, Clone, PartialEq)]
pub struct Accelerogram {
    /// Sampling interval (s); sample k is at t = k·h.
    pub time_step: f64,
    /// Acceleration (m/s²).
    pub samples: Vec<f64>,
    /// Correction rounds taken (the first spectrum check counts as round 1).
    pub iterations: usize,
    /// Largest |Sa/Sa_target − 1| on the verification grid
    /// ([`VERIFY_POINTS_PER_DECADE`] log-spaced frequencies per decade of the band and
    /// the target's frequencies).
    pub max_deviation: f64,
    /// Where it occurs (Hz).
    pub deviation_frequency: f64,
}

impl Accelerogram {
    /// The record as a table: times k·h (s), acceleration (m/s²).
    pub fn table(&self) -> Table {
        Table {
            time: (0..self.samples.len())
                .map(|k| k as f64 * self.time_step)
                .collect(),
            values: self.samples.clone(),
        }
    }
}

impl SpectrumCompatible {
    /// The sampling interval used (s).
    pub fn sampling_interval(&self) -> f64 {
        self.time_step.unwrap_or_else(|| {
            let (_, highest) = self.target.band();
            (1.0 / (5.0 * highest)).min(0.005)
        })
    }

    fn envelope(&self) -> Envelope {
        Envelope {
            rise: self.rise.unwrap_or(0.25 * (self.duration - self.strong_motion)),
            strong_motion: self.strong_motion,
            duration: self.duration,
        }
    }

    /// Every problem (fields relative to the request object: `target/frequencies/2`,
    /// `strong_motion`, …).
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues: Vec<InputIssue> = self
            .target
            .validate()
            .into_iter()
            .map(|i| i.within("target"))
            .collect();
        crate::require_positive(&mut issues, "duration", self.duration);
        crate::require_positive(&mut issues, "strong_motion", self.strong_motion);
        if self.duration.is_finite() && self.strong_motion.is_finite() && self.strong_motion >= self.duration
        {
            issues.push(InputIssue::new(
                "strong_motion",
                format!(
                    "must be shorter than the duration ({} s): the envelope needs a build-up and a decay",
                    self.duration
                ),
            ));
        }
        if let Some(rise) = self.rise {
            crate::require_positive(&mut issues, "rise", rise);
            if rise.is_finite() && rise >= self.duration - self.strong_motion {
                issues.push(InputIssue::new(
                    "rise",
                    format!(
                        "must be shorter than duration − strong_motion ({} s), leaving time to decay",
                        self.duration - self.strong_motion
                    ),
                ));
            }
        }
        if let Some(step) = self.time_step {
            crate::require_positive(&mut issues, "time_step", step);
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            issues.push(InputIssue::new(
                "tolerance",
                format!(
                    "must be a relative deviation between 0 and 1, both excluded (got {})",
                    self.tolerance
                ),
            ));
        }
        if !(1..=100).contains(&self.max_iterations) {
            issues.push(InputIssue::new(
                "max_iterations",
                format!("must be between 1 and 100 (got {})", self.max_iterations),
            ));
        }
        if !issues.is_empty() {
            return issues;
        }
        // The record must hold the band: its lowest frequency twice over the strong
        // motion, its highest frequency well below the Nyquist frequency.
        let (lowest, highest) = self.target.band();
        if lowest * self.strong_motion < 2.0 {
            issues.push(InputIssue::new(
                "target/frequencies/0",
                format!(
                    "must be at least 2/strong_motion = {} Hz: the strong motion must last two periods \
                     of the lowest frequency (got {lowest} Hz)",
                    2.0 / self.strong_motion
                ),
            ));
        }
        let step = self.sampling_interval();
        if highest > 0.2 / step {
            issues.push(InputIssue::new(
                "time_step",
                format!(
                    "must be at most 1/(5 × {highest} Hz) = {} s to resolve the target's highest frequency",
                    0.2 / highest
                ),
            ));
        }
        let samples = (self.duration / step).round() + 1.0;
        if samples > MAX_SAMPLES as f64 {
            issues.push(InputIssue::new(
                "duration",
                format!(
                    "makes {samples} samples at {step} s, over the limit of {MAX_SAMPLES}: shorten it or \
                     sample more coarsely"
                ),
            ));
        }
        issues
    }

    /// The accelerogram (module doc), or every problem with the request; a request whose
    /// spectrum does not come within the tolerance in `max_iterations` rounds is refused
    /// with the deviation reached, at `tolerance`.
    pub fn generate(&self) -> Result<Accelerogram, Vec<InputIssue>> {
        let issues = self.validate();
        if !issues.is_empty() {
            return Err(issues);
        }
        let (best, rounds) = self.iterate().map_err(|issue| vec![issue])?;
        if best.max_deviation > self.tolerance {
            return Err(vec![InputIssue::new(
                "tolerance",
                format!(
                    "not reached: after {} rounds the closest spectrum still deviates from the target by \
                     {:.1} % at {:.3} Hz (tolerance {:.1} %); a longer strong motion, a narrower band or a \
                     looser tolerance helps",
                    rounds,
                    100.0 * best.max_deviation,
                    best.deviation_frequency,
                    100.0 * self.tolerance
                ),
            )]);
        }
        Ok(best)
    }

    /// Steps 1–8 of the module doc on a validated request: the best iterate and the
    /// rounds taken.
    fn iterate(&self) -> Result<(Accelerogram, usize), InputIssue> {
        let step = self.sampling_interval();
        let count = (self.duration / step).round() as usize + 1;
        let size = count.next_power_of_two().max(4);
        let bin = |j: usize| j as f64 / (size as f64 * step);
        let (lowest, highest) = self.target.band();
        let nyquist = 0.5 / step;

        let mut rng = GapRng::new(self.seed);
        let phases: Vec<(f64, f64)> = (1..size / 2)
            .map(|_| portable::sin_cos(std::f64::consts::TAU * rng.uniform()))
            .collect();
        let amplitudes: Vec<f64> = (1..size / 2)
            .map(|j| {
                let f = bin(j);
                let taper = if f < 0.5 * lowest || f > 0.8 * nyquist {
                    0.0
                } else if f < lowest {
                    (f / lowest) * (f / lowest)
                } else if f > highest {
                    (highest / f) * (highest / f)
                } else {
                    1.0
                };
                self.target.at(f) / f.sqrt() * taper
            })
            .collect();

        let envelope = self.envelope();
        let shape: Vec<f64> = (0..count).map(|k| envelope.at(k as f64 * step)).collect();
        let check = Grid::new(&self.target, CHECK_POINTS_PER_DECADE);
        let verify = Grid::new(&self.target, VERIFY_POINTS_PER_DECADE);
        let zero_period = check.wanted[check.wanted.len() - 1];

        let evaluate = |samples: Vec<f64>, round: usize, grid: &Grid| {
            let spectrum =
                pseudo_acceleration_uniform(&samples, step, &grid.frequencies, self.target.damping)
                    .map_err(|e| InputIssue::new("", format!("the generated record has no spectrum: {e}")))?
                    .pseudo_acceleration;
            let (max_deviation, deviation_frequency) = spectrum
                .iter()
                .zip(&grid.wanted)
                .zip(&grid.frequencies)
                .map(|((s, w), f)| ((s / w - 1.0).abs(), *f))
                .fold((0.0_f64, lowest), |m, x| if x.0 > m.0 { x } else { m });
            let record = Accelerogram {
                time_step: step,
                samples,
                iterations: round,
                max_deviation,
                deviation_frequency,
            };
            Ok::<_, InputIssue>((record, spectrum))
        };

        // Steps 4–6: Fourier rounds on the check grid.
        let (mut best, mut spectrum) =
            evaluate(synthesize(&amplitudes, &phases, size, &shape, step), 1, &check)?;
        let mut current = best.samples.clone();
        let last_fourier_round = (self.max_iterations / 2 + 1).min(self.max_iterations);
        let mut round = 1;
        while round < last_fourier_round && best.max_deviation > GOAL * self.tolerance {
            round += 1;
            let next = self.fourier_round(&current, step, &shape, &check, &spectrum, zero_period);
            current.clone_from(&next);
            let (record, next_spectrum) = evaluate(next, round, &check)?;
            spectrum = next_spectrum;
            if record.max_deviation < best.max_deviation {
                best = record;
            }
        }

        // Step 7: the closest record verified on the dense grid; step 8: wavelet rounds
        // on it while it is off by more than the tolerance but within reach.
        let (mut best, mut spectrum) = evaluate(best.samples, best.iterations, &verify)?;
        if best.max_deviation > REACH * self.tolerance {
            return Ok((best, round));
        }
        let mut current = best.samples.clone();
        let mut relaxation = wavelets::RELAXATION;
        let mut previous = best.max_deviation;
        while round < self.max_iterations && best.max_deviation > self.tolerance {
            round += 1;
            let matching = wavelets::Matching {
                frequencies: &verify.frequencies,
                wanted: &verify.wanted,
                spectrum: &spectrum,
                damping: self.target.damping,
                step,
                envelope: &shape,
                relaxation,
                threshold: GOAL * self.tolerance,
            };
            let Some(mut next) = matching.round(&current) else {
                break;
            };
            baseline::correct(&mut next, step, &shape);
            hold_peak(&mut next, zero_period, self.tolerance, step, &shape);
            current.clone_from(&next);
            let (record, next_spectrum) = evaluate(next, round, &verify)?;
            spectrum = next_spectrum;
            // A round that made it worse overshot (the rounds then swing between two
            // states): smaller steps until one helps, then back up.
            if record.max_deviation > previous {
                relaxation *= 0.5;
            } else {
                relaxation = (1.5 * relaxation).min(wavelets::RELAXATION);
            }
            previous = record.max_deviation;
            if record.max_deviation < best.max_deviation {
                best = record;
            }
        }
        Ok((best, round))
    }

    /// Step 6 of the module doc: `current`, whose spectrum on `grid` is `spectrum`, with
    /// its Fourier amplitudes scaled by the ratio of the target to it and its peak
    /// acceleration held to `zero_period`.
    fn fourier_round(
        &self,
        current: &[f64],
        step: f64,
        shape: &[f64],
        grid: &Grid,
        spectrum: &[f64],
        zero_period: f64,
    ) -> Vec<f64> {
        let ratios: Vec<f64> = grid
            .wanted
            .iter()
            .zip(spectrum)
            .map(|(w, s)| if *s > 0.0 { w / s } else { 1.0 })
            .collect();
        let mut next = reshape(current, step, shape, |f| {
            interpolate_log(&grid.frequencies, &ratios, f)
        });
        hold_peak(&mut next, zero_period, self.tolerance, step, shape);
        next
    }
}

/// Frequencies where a record's spectrum is computed, and the target there.
struct Grid {
    frequencies: Vec<f64>,
    wanted: Vec<f64>,
}

impl Grid {
    /// The target's frequencies and `per_decade` log-spaced frequencies per decade
    /// across its band.
    fn new(target: &TargetSpectrum, per_decade: f64) -> Self {
        let frequencies = check_grid(target, per_decade);
        let wanted = frequencies.iter().map(|&f| target.at(f)).collect();
        Self { frequencies, wanted }
    }
}

/// Step 6b of the module doc: if the peak acceleration of `samples` exceeds
/// `zero_period` by more than [`PEAK_GATE`] × `tolerance`, its excursions above it
/// scaled down to it and the baseline corrected again.
fn hold_peak(samples: &mut [f64], zero_period: f64, tolerance: f64, step: f64, shape: &[f64]) {
    let peak = samples.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if peak > zero_period * (1.0 + PEAK_GATE * tolerance) {
        limit_excursions(samples, zero_period);
        baseline::correct(samples, step, shape);
    }
}

/// The target's frequencies and `per_decade` log-spaced frequencies per decade across
/// its band, sorted, without repeats.
fn check_grid(target: &TargetSpectrum, per_decade: f64) -> Vec<f64> {
    let (lowest, highest) = target.band();
    let decades = portable::ln(highest / lowest) / std::f64::consts::LN_10;
    let count = ((decades * per_decade).ceil() as usize + 1).max(2);
    let mut grid = log_spaced(lowest, highest, count);
    grid.extend_from_slice(&target.frequencies);
    grid.sort_by(f64::total_cmp);
    grid.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    grid
}

/// `values` given at increasing `at`, linear in ln f between them, held outside.
fn interpolate_log(at: &[f64], values: &[f64], f: f64) -> f64 {
    let last = at.len() - 1;
    if f <= at[0] {
        return values[0];
    }
    if f >= at[last] {
        return values[last];
    }
    let upper = at.partition_point(|&g| g <= f);
    let weight = portable::ln(f / at[upper - 1]) / portable::ln(at[upper] / at[upper - 1]);
    values[upper - 1] + weight * (values[upper] - values[upper - 1])
}

/// Step 6b of the module doc: every excursion of `samples` (a run of samples of one
/// sign, between zero crossings) that peaks above `level` scaled down to peak at it.
fn limit_excursions(samples: &mut [f64], level: f64) {
    let mut start = 0;
    while start < samples.len() {
        let positive = samples[start] > 0.0;
        let negative = samples[start] < 0.0;
        let end = start
            + samples[start..]
                .iter()
                .position(|x| !((positive && *x > 0.0) || (negative && *x < 0.0)))
                .unwrap_or(samples.len() - start)
                .max(1);
        let peak = samples[start..end].iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        if peak > level {
            let scale = level / peak;
            for x in &mut samples[start..end] {
                *x *= scale;
            }
        }
        start = end;
    }
}

/// Step 4 of the module doc: the first `shape.len()` samples of the stationary signal
/// of these amplitudes and phases (cos φ, sin φ) on `size` points, times the envelope
/// `shape`, baseline-corrected.
fn synthesize(amplitudes: &[f64], phases: &[(f64, f64)], size: usize, shape: &[f64], step: f64) -> Vec<f64> {
    let mut re = vec![0.0; size];
    let mut im = vec![0.0; size];
    for (j, (amplitude, (sin_phase, cos_phase))) in amplitudes.iter().zip(phases).enumerate() {
        let k = j + 1;
        re[k] = amplitude * cos_phase;
        im[k] = amplitude * sin_phase;
        re[size - k] = re[k];
        im[size - k] = -im[k];
    }
    fft::transform(&mut re, &mut im, true);
    let mut samples: Vec<f64> = shape.iter().zip(&re).map(|(e, x)| e * x).collect();
    baseline::correct(&mut samples, step, shape);
    samples
}

/// `samples` with each Fourier component scaled by `ratio(f)` (f in Hz; zero-padded to
/// twice the length so that the filter does not wrap around), then baseline-corrected.
fn reshape(samples: &[f64], step: f64, shape: &[f64], ratio: impl Fn(f64) -> f64) -> Vec<f64> {
    let size = (2 * samples.len()).next_power_of_two();
    let mut re = vec![0.0; size];
    let mut im = vec![0.0; size];
    re[..samples.len()].copy_from_slice(samples);
    fft::transform(&mut re, &mut im, false);
    re[0] = 0.0;
    im[0] = 0.0;
    for j in 1..=size / 2 {
        let scale = ratio(j as f64 / (size as f64 * step));
        re[j] *= scale;
        im[j] *= scale;
        if j < size / 2 {
            re[size - j] = re[j];
            im[size - j] = -im[j];
        } else {
            im[j] = 0.0;
        }
    }
    fft::transform(&mut re, &mut im, true);
    let mut out: Vec<f64> = re[..samples.len()]
        .iter()
        .zip(shape)
        .map(|(x, e)| if *e > 0.0 { x / size as f64 } else { 0.0 })
        .collect();
    baseline::correct(&mut out, step, shape);
    out
}

#[cfg(test)]
mod tests;
