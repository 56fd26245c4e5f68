//! Impacts as engineers post-process shocks (code_aster `POST_DYNA_MODA_T`, option
//! `IMPACT`): counted with a force threshold and a rest time, tabulated one by one, and
//! summarised per contact over the whole run and over equal blocks of it.
//!
//! The integrator feeds [`ContactImpacts::record`] at every loaded step of a closed
//! contact (δ > 0); nothing is read back from thinned histories. Step n covers
//! ((n − 1)Δt, nΔt]. A step is *loaded* when the force is at least the threshold (with
//! the default threshold 0, every closed step). An impact starts at a loaded step that
//! follows at least `rest_time` of unloaded steps (or none at all); loaded steps that
//! come back sooner are rebounds of the same impact. So with a threshold and a rest
//! time of 0 an impact is a closure after a separation, the count the integrator has
//! always given.
//!
//! Two differences from code_aster's `compt` routine, both deliberate: an impact ends
//! once the force has stayed below the threshold for at least `rest_time` (code_aster
//! compares sample counts, so its rest time is one sample longer from two samples on),
//! and `rebounds` counts the returns above the threshold after the first within one
//! impact (code_aster's `NB_REBON_CHOC` counts every return below it, first included,
//! so it is our rebounds + 1 per impact).
//!
//! The per-impact table holds every impact up to `max_rows`; past that it keeps the
//! largest by peak force with a fair share per contact, and counts what it left out
//! (`table.rs`, where the rule is stated).

use crate::InputIssue;

pub(crate) mod table;
pub use table::{ImpactTable, TableKeeper, fair_share};

/// Default [`ImpactCounting::classes`].
pub const DEFAULT_CLASSES: usize = 10;
/// Largest [`ImpactCounting::classes`].
pub const MAX_CLASSES: usize = 10_000;
/// Largest [`ImpactCounting::blocks`] (every contact keeps sums per block).
pub const MAX_BLOCKS: usize = 100;
/// Default [`ImpactCounting::max_rows`].
pub const DEFAULT_MAX_ROWS: usize = 100_000;
/// Most impacts whose peak forces are kept for the histograms (80 MB); beyond that the
/// histograms count the first ones and say so ([`ImpactHistogram::impacts`]).
pub const MAX_HISTOGRAM_IMPACTS: usize = 10_000_000;
/// Values of one row of the per-impact table (contact, start, peak time, peak force,
/// impulse, duration, approach velocity, rebounds, dissipated, energy).
pub const TABLE_COLUMNS: usize = 10;

/// How impacts are counted, summarised and tabulated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactCounting {
    /// A step is loaded when the contact force is at least this (N, ≥ 0).
    pub force_threshold: f64,
    /// An impact ends once the force has stayed below the threshold this long (s, ≥ 0):
    /// loaded steps that come back sooner are its rebounds.
    pub rest_time: f64,
    /// Equal blocks of the run over which the statistics are also computed, for their
    /// spread (code_aster's `NB_BLOC`; 1…[`MAX_BLOCKS`]).
    pub blocks: usize,
    /// Classes of the peak-force histograms (1…[`MAX_CLASSES`]).
    pub classes: usize,
    /// Rows of the per-impact table (≥ 1): every impact while they number at most this,
    /// else the largest by peak force with a fair share per contact ([`TableKeeper`]);
    /// the statistics cover every impact regardless.
    pub max_rows: usize,
}

impl Default for ImpactCounting {
    fn default() -> Self {
        Self {
            force_threshold: 0.0,
            rest_time: 0.0,
            blocks: 1,
            classes: DEFAULT_CLASSES,
            max_rows: DEFAULT_MAX_ROWS,
        }
    }
}

impl ImpactCounting {
    /// Every problem with these settings (fields relative to the struct).
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        crate::require_non_negative(&mut issues, "force_threshold", self.force_threshold);
        crate::require_non_negative(&mut issues, "rest_time", self.rest_time);
        if !(1..=MAX_BLOCKS).contains(&self.blocks) {
            issues.push(InputIssue::new(
                "blocks",
                format!("must be between 1 and {MAX_BLOCKS} (got {})", self.blocks),
            ));
        }
        if !(1..=MAX_CLASSES).contains(&self.classes) {
            issues.push(InputIssue::new(
                "classes",
                format!("must be between 1 and {MAX_CLASSES} (got {})", self.classes),
            ));
        }
        if self.max_rows == 0 {
            issues.push(InputIssue::new(
                "max_rows",
                "must be at least 1: the table always holds the run's largest impact".to_owned(),
            ));
        }
        issues
    }
}

/// One impact of one contact.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Impact {
    /// Contact index.
    pub contact: usize,
    /// Start (s): the beginning of its first loaded step.
    pub start: f64,
    /// When the force peaked (s).
    pub peak_time: f64,
    /// Largest force (N).
    pub peak_force: f64,
    /// ∫ F dt over its loaded steps (N·s).
    pub impulse: f64,
    /// From its start to the end of its last loaded step, rebounds included (s).
    pub duration: f64,
    /// Relative normal velocity δ̇ over its first step (m/s; > 0 closing); 0 for a
    /// contact already closed at t = 0.
    pub approach_velocity: f64,
    /// Returns above the threshold after the first, within `rest_time`.
    pub rebounds: u64,
    /// Energy the contact dashpot dissipated during it, ∫ (F − Kc δ) δ̇ dt (J).
    pub dissipated: f64,
    /// ½ m v² of the approach (J), m the contact's effective mass
    /// ([`ContactImpacts::new`]).
    pub energy: f64,
}

/// What a run's clock says about impacts: threshold, rest steps and blocks.
#[derive(Debug, Clone, Copy)]
pub struct ImpactClock {
    threshold: f64,
    /// Unloaded steps that end an impact: ⌈rest_time / Δt⌉, at least 1.
    rest_steps: u64,
    dt: f64,
    steps: u64,
    blocks: usize,
}

impl ImpactClock {
    /// For a run of `steps` steps of `dt`.
    pub fn new(counting: &ImpactCounting, dt: f64, steps: u64) -> Self {
        // A rest time that is a whole number of steps up to rounding is that number.
        let rest = (counting.rest_time / dt * (1.0 - 1e-12)).ceil();
        Self {
            threshold: counting.force_threshold,
            rest_steps: rest.clamp(1.0, (1u64 << 62) as f64) as u64,
            dt,
            steps: steps.max(1),
            blocks: counting.blocks.max(1),
        }
    }

    /// The block of step n (step 0, the initial state, is in the first), for
    /// [`ContactImpacts::record`]; [`ImpactClock::last_step`] says when it changes.
    pub fn block(&self, n: u64) -> usize {
        let k = n.saturating_sub(1).min(self.steps - 1);
        ((k as u128 * self.blocks as u128) / self.steps as u128) as usize
    }

    /// The last step of block b (u64::MAX for the last block, which takes any step past
    /// the run's end): a step loop moves to the next block once past it.
    pub fn last_step(&self, b: usize) -> u64 {
        if b + 1 >= self.blocks {
            u64::MAX
        } else {
            self.block_start(b + 1)
        }
    }

    /// ⌈b·N / B⌉: the steps before block b (step n is in block ⌊(n − 1)·B / N⌋).
    fn block_start(&self, b: usize) -> u64 {
        (b as u128 * self.steps as u128).div_ceil(self.blocks as u128) as u64
    }

    /// Steps of block b.
    fn block_steps(&self, b: usize) -> u64 {
        self.block_start(b + 1) - self.block_start(b)
    }

    /// Whether every closed step is loaded (a threshold of 0: contact forces are never
    /// negative), so that the impacts' sums are the contact's.
    pub fn loads_every_closed_step(&self) -> bool {
        self.threshold <= 0.0
    }

    /// Whether a force loads the contact.
    #[inline(always)]
    pub fn loads(&self, force: f64) -> bool {
        force >= self.threshold
    }
}

/// Sums of one contact over one block.
#[derive(Debug, Clone, Copy)]
struct Sums {
    impacts: u64,
    rebounds: u64,
    loaded_time: f64,
    impulse: f64,
    force_squared: f64,
    max_force: f64,
    duration: f64,
    min_duration: f64,
    max_duration: f64,
    energy: f64,
    max_energy: f64,
}

impl Default for Sums {
    fn default() -> Self {
        Self {
            impacts: 0,
            rebounds: 0,
            loaded_time: 0.0,
            impulse: 0.0,
            force_squared: 0.0,
            max_force: 0.0,
            duration: 0.0,
            min_duration: f64::INFINITY,
            max_duration: 0.0,
            energy: 0.0,
            max_energy: 0.0,
        }
    }
}

/// Sums over a contact's loaded steps since the start of the run (steps n ≥ 1), in
/// forces and powers (× Δt when read).
#[derive(Debug, Clone, Copy, Default)]
struct Cumulative {
    steps: u64,
    force: f64,
    force_squared: f64,
    dissipation: f64,
}

/// What [`ContactImpacts::record`] touches at every loaded step, in one cache line.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Hot {
    /// The last loaded step ([`NEVER`] before the first).
    last_step: u64,
    sums: Cumulative,
    /// The peak of the impact under way, and its step.
    peak_force: f64,
    peak_step: u64,
}

/// [`Hot::last_step`] of a contact never loaded: n − NEVER (wrapping) is about 2⁶³ for
/// any step n, more than any rest ([`ImpactClock::new`] caps it below).
const NEVER: u64 = 1 << 63;

/// The impact under way (its peak is in [`Hot`]).
#[derive(Debug, Clone, Copy)]
struct Running {
    first_step: u64,
    block: usize,
    rebounds: u64,
    approach_velocity: f64,
    energy: f64,
    /// The cumulative sums before its first step.
    before: Cumulative,
}

/// The per-impact table and the peak forces of a run, shared by its contacts.
#[derive(Debug, Clone, Default)]
pub struct ImpactLog {
    classes: usize,
    table: TableKeeper,
    /// Per contact, the peak force of each impact (for the histograms).
    peaks: Vec<Vec<f64>>,
    kept_peaks: usize,
}

/// Where an ended impact goes: the run's [`ImpactLog`], or a list a thread keeps for it
/// (pushed to the log afterwards, in order, so the log is the same whichever thread
/// ended them).
pub trait ImpactSink {
    fn push(&mut self, impact: Impact);
}

impl ImpactSink for Vec<Impact> {
    fn push(&mut self, impact: Impact) {
        Vec::push(self, impact);
    }
}

impl ImpactSink for ImpactLog {
    fn push(&mut self, impact: Impact) {
        self.table.push(impact);
        if self.kept_peaks < MAX_HISTOGRAM_IMPACTS {
            self.peaks[impact.contact].push(impact.peak_force);
            self.kept_peaks += 1;
        }
    }
}

impl ImpactLog {
    /// For `contacts` contacts, as `counting` says (rows kept, histogram classes).
    pub fn new(contacts: usize, counting: &ImpactCounting) -> Self {
        Self {
            classes: counting.classes.max(1),
            table: TableKeeper::new(contacts, counting.max_rows),
            peaks: vec![Vec::new(); contacts],
            kept_peaks: 0,
        }
    }

    /// The table sorted by start time (then contact) with what it left out, and the
    /// peak-force histograms in `classes` equal classes from 0 to the largest peak of
    /// the run.
    pub fn finish(self) -> (ImpactTable, ImpactHistogram) {
        let classes = self.classes;
        let top = self.peaks.iter().flatten().fold(0.0_f64, |m, &f| m.max(f));
        let edges: Vec<f64> = (0..=classes)
            .map(|k| crate::decimal(top * k as f64 / classes as f64))
            .collect();
        let class_of = |f: f64| {
            if top > 0.0 {
                ((f * classes as f64 / top) as usize).min(classes - 1)
            } else {
                0
            }
        };
        let per_contact: Vec<Vec<u64>> = self
            .peaks
            .iter()
            .map(|peaks| {
                let mut counts = vec![0; classes];
                for &f in peaks {
                    counts[class_of(f)] += 1;
                }
                counts
            })
            .collect();
        let mut total = vec![0; classes];
        for counts in &per_contact {
            for (t, c) in total.iter_mut().zip(counts) {
                *t += c;
            }
        }
        (
            self.table.finish(),
            ImpactHistogram {
                edges,
                counts: total,
                per_contact,
                impacts: self.kept_peaks as u64,
            },
        )
    }
}

/// Histograms of the impacts' peak forces, with the same classes for every contact.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ImpactHistogram {
    /// Class edges (N): `classes + 1` values from 0 to the largest peak of the run; a
    /// class holds [edge k, edge k + 1), the last one its upper edge too.
    pub edges: Vec<f64>,
    /// Impacts per class over every contact.
    pub counts: Vec<u64>,
    /// Per contact, impacts per class.
    pub per_contact: Vec<Vec<u64>>,
    /// Impacts counted ([`MAX_HISTOGRAM_IMPACTS`] at most).
    pub impacts: u64,
}

/// One contact's impacts as the run goes.
#[derive(Debug, Clone)]
pub struct ContactImpacts {
    hot: Hot,
    contact: usize,
    inverse_mass: f64,
    running: Option<Running>,
    /// The current block, and the cumulative sums when it began.
    block: usize,
    block_start: Cumulative,
    blocks: Vec<Sums>,
    /// The largest peak of the impacts that ended, and its step.
    max_force: f64,
    max_force_step: u64,
}

impl ContactImpacts {
    /// Contact `contact`, whose relative normal acceleration per unit force is
    /// `inverse_mass` (1/kg: Σᵢ ψᵢ² summed over the pins it touches, for a basis of unit
    /// modal masses), with `blocks` blocks.
    pub fn new(contact: usize, inverse_mass: f64, blocks: usize) -> Self {
        Self {
            hot: Hot {
                last_step: NEVER,
                sums: Cumulative::default(),
                peak_force: 0.0,
                peak_step: 0,
            },
            contact,
            inverse_mass,
            running: None,
            block: 0,
            block_start: Cumulative::default(),
            blocks: vec![Sums::default(); blocks.max(1)],
            max_force: 0.0,
            max_force_step: 0,
        }
    }

    /// The initial state of a contact closed at t = 0, with its force then: an impact
    /// starts at t = 0 (no approach, no weight: step 1 is the first to count).
    pub fn record_initial(&mut self, clock: &ImpactClock, force: f64) {
        if !clock.loads(force) {
            return;
        }
        self.running = Some(Running {
            first_step: 0,
            block: 0,
            rebounds: 0,
            approach_velocity: 0.0,
            energy: 0.0,
            before: self.hot.sums,
        });
        (self.hot.last_step, self.hot.peak_force, self.hot.peak_step) = (0, force, 0);
    }

    /// Loaded step n ≥ 1 (in block `block`, [`ImpactClock::block`]; the caller calls
    /// [`ContactImpacts::enter_block`] as blocks change): its force, its penetration now
    /// and a step before, and the power its dashpot dissipates (W). This runs at every
    /// loaded step of every contact: four sums, a store and a comparison, and a branch
    /// taken only when an impact or a rebound starts.
    #[inline(always)]
    pub fn record(
        &mut self,
        clock: &ImpactClock,
        log: &mut impl ImpactSink,
        (n, block): (u64, usize),
        force: f64,
        (penetration, previous): (f64, f64),
        dissipation: f64,
    ) {
        if n.wrapping_sub(self.hot.last_step) != 1 {
            self.returns(clock, log, (n, block), force, penetration - previous);
        }
        let hot = &mut self.hot;
        hot.last_step = n;
        hot.sums.steps += 1;
        hot.sums.force += force;
        hot.sums.force_squared += force * force;
        hot.sums.dissipation += dissipation;
        if force > hot.peak_force {
            (hot.peak_force, hot.peak_step) = (force, n);
        }
    }

    /// Step n loads the contact after unloaded steps (or for the first time): a
    /// rebound of the impact under way if they lasted less than the rest time, else a
    /// new impact, approaching by `rise` over the step.
    #[cold]
    #[inline(never)]
    fn returns(
        &mut self,
        clock: &ImpactClock,
        log: &mut impl ImpactSink,
        (n, block): (u64, usize),
        force: f64,
        rise: f64,
    ) {
        if let Some(running) = &mut self.running
            && n.wrapping_sub(self.hot.last_step) <= clock.rest_steps
        {
            running.rebounds += 1;
            return;
        }
        self.close(log, clock.dt);
        let approach_velocity = rise / clock.dt;
        let energy = if self.inverse_mass > 0.0 {
            0.5 * approach_velocity * approach_velocity / self.inverse_mass
        } else {
            0.0
        };
        self.running = Some(Running {
            first_step: n,
            block,
            rebounds: 0,
            approach_velocity,
            energy,
            before: self.hot.sums,
        });
        (self.hot.peak_force, self.hot.peak_step) = (force, n);
    }

    /// Block `block` begins (before its first step is recorded).
    pub fn enter_block(&mut self, block: usize, clock: &ImpactClock) {
        self.flush(clock.dt);
        self.block = block.min(self.blocks.len() - 1);
    }

    /// The current block's loaded steps into its sums.
    fn flush(&mut self, dt: f64) {
        let (now, start) = (self.hot.sums, self.block_start);
        let sums = &mut self.blocks[self.block];
        sums.loaded_time += (now.steps - start.steps) as f64 * dt;
        sums.impulse += (now.force - start.force) * dt;
        sums.force_squared += (now.force_squared - start.force_squared) * dt;
        self.block_start = now;
    }

    /// The impact under way, if any, ends: into its start's block and the log.
    fn close(&mut self, log: &mut impl ImpactSink, dt: f64) {
        let Some(done) = self.running.take() else {
            return;
        };
        let (now, before) = (self.hot.sums, done.before);
        let start = done.first_step.saturating_sub(1) as f64 * dt;
        let impact = Impact {
            contact: self.contact,
            start,
            peak_time: self.hot.peak_step as f64 * dt,
            peak_force: self.hot.peak_force,
            impulse: (now.force - before.force) * dt,
            duration: self.hot.last_step as f64 * dt - start,
            approach_velocity: done.approach_velocity,
            rebounds: done.rebounds,
            dissipated: (now.dissipation - before.dissipation) * dt,
            energy: done.energy,
        };
        if impact.peak_force > self.max_force {
            (self.max_force, self.max_force_step) = (impact.peak_force, self.hot.peak_step);
        }
        let sums = &mut self.blocks[done.block];
        sums.impacts += 1;
        sums.rebounds += impact.rebounds;
        sums.max_force = sums.max_force.max(impact.peak_force);
        sums.duration += impact.duration;
        sums.min_duration = sums.min_duration.min(impact.duration);
        sums.max_duration = sums.max_duration.max(impact.duration);
        sums.energy += impact.energy;
        sums.max_energy = sums.max_energy.max(impact.energy);
        log.push(impact);
    }

    /// The impacts counted so far (the one under way included).
    pub fn count(&self) -> u64 {
        self.blocks.iter().map(|s| s.impacts).sum::<u64>() + u64::from(self.running.is_some())
    }

    /// What [`ContactStatistics`](crate::ContactStatistics) sums over the closed steps,
    /// when every closed step is loaded (a threshold of 0, [`ImpactClock::loads_every_closed_step`]):
    /// contact time, impulse, and the largest force with its time (initial state
    /// included).
    pub fn closed_steps(&self, dt: f64) -> ClosedSteps {
        let sums = self.hot.sums;
        let (mut max_force, mut step) = (self.max_force, self.max_force_step);
        if self.running.is_some() && self.hot.peak_force > max_force {
            (max_force, step) = (self.hot.peak_force, self.hot.peak_step);
        }
        ClosedSteps {
            contact_time: sums.steps as f64 * dt,
            impulse: sums.force * dt,
            max_force,
            max_force_time: crate::integrate::sample_time(step, dt),
        }
    }

    /// Ends the impact under way and summarises the contact over the run and its blocks.
    pub fn finish(mut self, clock: &ImpactClock, log: &mut ImpactLog) -> ImpactStatistics {
        self.flush(clock.dt);
        self.close(log, clock.dt);
        let duration = clock.steps as f64 * clock.dt;
        let mut total = Sums::default();
        for sums in &self.blocks {
            total.impacts += sums.impacts;
            total.rebounds += sums.rebounds;
            total.loaded_time += sums.loaded_time;
            total.impulse += sums.impulse;
            total.force_squared += sums.force_squared;
            total.max_force = total.max_force.max(sums.max_force);
            total.duration += sums.duration;
            total.min_duration = total.min_duration.min(sums.min_duration);
            total.max_duration = total.max_duration.max(sums.max_duration);
            total.energy += sums.energy;
            total.max_energy = total.max_energy.max(sums.max_energy);
        }
        let blocks = (self.blocks.len() > 1).then(|| {
            let summaries: Vec<Summary> = self
                .blocks
                .iter()
                .enumerate()
                .map(|(b, sums)| Summary::of(sums, clock.block_steps(b) as f64 * clock.dt))
                .collect();
            BlockSpread::of(&summaries)
        });
        ImpactStatistics {
            summary: Summary::of(&total, duration),
            rebounds_per_impact: ratio(total.rebounds as f64, total.impacts as f64),
            mean_duration: ratio(total.duration, total.impacts as f64),
            min_duration: if total.impacts > 0 {
                total.min_duration
            } else {
                0.0
            },
            max_duration: total.max_duration,
            loaded_time: total.loaded_time,
            mean_contact_force: ratio(total.impulse, total.loaded_time),
            rms_contact_force: ratio(total.force_squared, total.loaded_time).sqrt(),
            mean_impact_energy: ratio(total.energy, total.impacts as f64),
            max_impact_energy: total.max_energy,
            blocks,
        }
    }
}

/// A contact's closed steps over the run ([`ContactImpacts::closed_steps`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedSteps {
    /// s.
    pub contact_time: f64,
    /// ∫ F dt (N·s).
    pub impulse: f64,
    /// N, and when (s).
    pub max_force: f64,
    pub max_force_time: f64,
}

/// a / b, 0 when b is 0.
fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 { a / b } else { 0.0 }
}

/// The statistics of one contact over a stretch of time (the run or one block).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Summary {
    /// Impacts that started in it.
    pub impacts: u64,
    /// Impacts per second.
    pub impacts_per_second: f64,
    /// Fraction of the time loaded (force at least the threshold).
    pub contact_fraction: f64,
    /// Mean force over the whole time, ∫F dt / T (N).
    pub mean_force: f64,
    /// RMS force over the whole time, √(∫F² dt / T) (N).
    pub rms_force: f64,
    /// Largest force (N): over a block, the largest peak of the impacts that started in
    /// it (as they are counted there).
    pub max_force: f64,
    /// ∫ F dt over the loaded steps (N·s).
    pub impulse: f64,
}

impl Summary {
    fn of(sums: &Sums, time: f64) -> Self {
        Self {
            impacts: sums.impacts,
            impacts_per_second: ratio(sums.impacts as f64, time),
            contact_fraction: ratio(sums.loaded_time, time),
            mean_force: ratio(sums.impulse, time),
            rms_force: ratio(sums.force_squared, time).sqrt(),
            max_force: sums.max_force,
            impulse: sums.impulse,
        }
    }
}

/// Mean and standard deviation of a statistic across blocks.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Spread {
    pub mean: f64,
    /// Population standard deviation (÷ blocks).
    pub standard_deviation: f64,
}

/// The [`Summary`] statistics across the blocks of a run.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct BlockSpread {
    pub blocks: usize,
    pub impacts: Spread,
    pub impacts_per_second: Spread,
    pub contact_fraction: Spread,
    pub mean_force: Spread,
    pub rms_force: Spread,
    pub max_force: Spread,
    pub impulse: Spread,
}

impl BlockSpread {
    fn of(summaries: &[Summary]) -> Self {
        let spread = |value: fn(&Summary) -> f64| {
            let n = summaries.len() as f64;
            let mean = summaries.iter().map(value).sum::<f64>() / n;
            let variance = summaries.iter().map(|s| (value(s) - mean).powi(2)).sum::<f64>() / n;
            Spread {
                mean,
                standard_deviation: variance.sqrt(),
            }
        };
        Self {
            blocks: summaries.len(),
            impacts: spread(|s| s.impacts as f64),
            impacts_per_second: spread(|s| s.impacts_per_second),
            contact_fraction: spread(|s| s.contact_fraction),
            mean_force: spread(|s| s.mean_force),
            rms_force: spread(|s| s.rms_force),
            max_force: spread(|s| s.max_force),
            impulse: spread(|s| s.impulse),
        }
    }
}

/// One contact's impact statistics over the run.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ImpactStatistics {
    #[serde(flatten)]
    pub summary: Summary,
    /// Rebounds per impact (mean).
    pub rebounds_per_impact: f64,
    /// Impact durations, rebounds included (s); 0 without impacts.
    pub mean_duration: f64,
    pub min_duration: f64,
    pub max_duration: f64,
    /// Time loaded (s).
    pub loaded_time: f64,
    /// Mean and RMS force over the loaded time (N).
    pub mean_contact_force: f64,
    pub rms_contact_force: f64,
    /// ½ m v² of the approach (J), mean and largest over the impacts.
    pub mean_impact_energy: f64,
    pub max_impact_energy: f64,
    /// The statistics across `blocks` equal blocks; absent for one block.
    pub blocks: Option<BlockSpread>,
}

#[cfg(test)]
#[path = "impacts_tests.rs"]
mod tests;
