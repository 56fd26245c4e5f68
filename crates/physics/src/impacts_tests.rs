//! Impact counting fed synthetic force pulses directly: counts, rebounds, exact
//! impulses, durations and fractions, block spreads, histograms, validation.

use super::*;

const DT: f64 = 1e-4;
const STIFFNESS: f64 = 1e6;

/// Feeds `forces` (step n = 1, 2, … has force `forces[n − 1]`; a closed contact where
/// the force is positive) to one contact and returns its statistics, the table and the
/// histograms.
fn feed(counting: &ImpactCounting, forces: &[f64]) -> (ImpactStatistics, ImpactTable, ImpactHistogram) {
    let clock = ImpactClock::new(counting, DT, forces.len() as u64);
    let mut log = ImpactLog::new(1, counting);
    let mut contact = ContactImpacts::new(0, 4.0, counting.blocks);
    let (mut previous, mut block) = (0.0, 0);
    for (k, &force) in forces.iter().enumerate() {
        let penetration = force / STIFFNESS;
        let n = k as u64 + 1;
        if clock.block(n) != block {
            block = clock.block(n);
            contact.enter_block(block, &clock);
        }
        if clock.loads(force) && force > 0.0 {
            contact.record(&clock, &mut log, (n, block), force, (penetration, previous), 0.0);
        }
        previous = penetration;
    }
    let statistics = contact.finish(&clock, &mut log);
    let (table, histogram) = log.finish();
    (statistics, table, histogram)
}

/// `steps` steps of `force` then `gap` steps of none, `times` times, then `tail` steps of none.
fn pulses(force: f64, steps: usize, gap: usize, times: usize, tail: usize) -> Vec<f64> {
    let mut forces = Vec::new();
    for _ in 0..times {
        forces.extend(std::iter::repeat_n(force, steps));
        forces.extend(std::iter::repeat_n(0.0, gap));
    }
    forces.extend(std::iter::repeat_n(0.0, tail));
    forces
}

#[test]
fn pulses_closer_than_the_rest_time_are_one_impact_with_a_rebound() {
    // Two 5-step pulses 3 steps apart: with a rest time of 4 steps they merge.
    let forces = pulses(100.0, 5, 3, 2, 10);
    let counting = ImpactCounting {
        rest_time: 4.0 * DT,
        ..ImpactCounting::default()
    };
    let (statistics, table, _) = feed(&counting, &forces);
    assert_eq!(statistics.summary.impacts, 1);
    assert_eq!(table.rows.len(), 1);
    assert_eq!(table.rows[0].rebounds, 1);
    assert_eq!(statistics.rebounds_per_impact, 1.0);
    // From the start of the first pulse to the end of the second, the gap included.
    assert!((table.rows[0].duration - 13.0 * DT).abs() < 1e-15);
    // Only the loaded steps carry force: 10 of them.
    assert!((statistics.loaded_time - 10.0 * DT).abs() < 1e-15);
}

#[test]
fn pulses_farther_than_the_rest_time_are_two_impacts() {
    let forces = pulses(100.0, 5, 3, 2, 10);
    for rest_steps in [0.0, 1.0, 2.5, 3.0] {
        let counting = ImpactCounting {
            rest_time: rest_steps * DT,
            ..ImpactCounting::default()
        };
        let (statistics, table, _) = feed(&counting, &forces);
        assert_eq!(statistics.summary.impacts, 2, "rest time {rest_steps} steps");
        assert!(table.rows.iter().all(|r| r.rebounds == 0));
        assert!(table.rows.iter().all(|r| (r.duration - 5.0 * DT).abs() < 1e-15));
        assert!((table.rows[1].start - 8.0 * DT).abs() < 1e-15);
    }
}

#[test]
fn a_rectangular_pulse_has_the_impulse_f_tau_and_its_duration_exactly() {
    let (force, steps) = (250.0, 37);
    let forces = pulses(force, steps, 0, 1, 63);
    let (statistics, table, _) = feed(&ImpactCounting::default(), &forces);
    let tau = steps as f64 * DT;
    let total = forces.len() as f64 * DT;
    let row = table.rows[0];
    assert!((row.impulse - force * tau).abs() <= 1e-12 * force * tau);
    assert!((statistics.summary.impulse - force * tau).abs() <= 1e-12 * force * tau);
    assert!((row.duration - tau).abs() < 1e-15);
    assert_eq!(row.start, 0.0);
    assert_eq!((row.peak_force, row.rebounds), (force, 0));
    assert!((statistics.summary.contact_fraction - tau / total).abs() < 1e-12);
    assert!((statistics.summary.mean_force - force * tau / total).abs() < 1e-9);
    assert!((statistics.summary.rms_force - force * (tau / total).sqrt()).abs() < 1e-9);
    assert!((statistics.mean_contact_force - force).abs() < 1e-9);
    assert!((statistics.rms_contact_force - force).abs() < 1e-9);
    assert_eq!(statistics.summary.max_force, force);
    assert_eq!(
        (statistics.min_duration, statistics.max_duration),
        (row.duration, row.duration)
    );
}

#[test]
fn the_approach_velocity_and_impact_energy_follow_the_first_step() {
    // Penetration rises by 2 µm in the first step: δ̇ = 0.02 m/s; m = 1/4 kg.
    let forces = [2.0, 4.0, 0.0];
    let (statistics, table, _) = feed(&ImpactCounting::default(), &forces);
    let v = 2.0 / STIFFNESS / DT;
    assert!((table.rows[0].approach_velocity - v).abs() < 1e-15);
    let energy = 0.5 * 0.25 * v * v;
    assert!((table.rows[0].energy - energy).abs() < 1e-18);
    assert!((statistics.max_impact_energy - energy).abs() < 1e-18);
    assert_eq!(table.rows[0].peak_time, 2.0 * DT);
}

#[test]
fn the_threshold_counts_only_the_loaded_steps() {
    // A triangle 0 → 100 → 0 N over 21 steps, twice: with a 50 N threshold, each
    // impact holds the steps at 50 N or more.
    let triangle: Vec<f64> = (0..=20).map(|k| 100.0 - 10.0 * (k as f64 - 10.0).abs()).collect();
    let mut forces = triangle.clone();
    forces.extend(std::iter::repeat_n(0.0, 5));
    forces.extend(&triangle);
    let counting = ImpactCounting {
        force_threshold: 50.0,
        ..ImpactCounting::default()
    };
    let (statistics, table, _) = feed(&counting, &forces);
    let loaded: Vec<f64> = triangle.iter().copied().filter(|&f| f >= 50.0).collect();
    assert_eq!(statistics.summary.impacts, 2);
    assert!((statistics.loaded_time - 2.0 * loaded.len() as f64 * DT).abs() < 1e-15);
    let impulse: f64 = loaded.iter().sum::<f64>() * DT;
    for row in &table.rows {
        assert!((row.impulse - impulse).abs() < 1e-12);
        assert!((row.duration - loaded.len() as f64 * DT).abs() < 1e-15);
    }
    // Below the threshold the two triangles' gap is 5 + 2 × 5 = 15 steps: a rest time of
    // up to 15 steps ends the first impact there, a longer one merges them.
    for (rest, impacts) in [(14.9, 2), (15.0, 2), (15.1, 1), (16.0, 1)] {
        let counting = ImpactCounting {
            force_threshold: 50.0,
            rest_time: rest * DT,
            ..ImpactCounting::default()
        };
        assert_eq!(feed(&counting, &forces).0.summary.impacts, impacts, "rest {rest}");
    }
}

#[test]
fn block_statistics_of_a_stationary_pulse_train_have_no_spread() {
    // 40 pulses of 3 steps every 10 steps, 4 blocks of 10 pulses.
    let forces = pulses(80.0, 3, 7, 40, 0);
    let counting = ImpactCounting {
        blocks: 4,
        ..ImpactCounting::default()
    };
    let (statistics, _, _) = feed(&counting, &forces);
    let blocks = statistics.blocks.expect("four blocks");
    assert_eq!(blocks.blocks, 4);
    assert_eq!(blocks.impacts.mean, 10.0);
    for spread in [
        blocks.impacts,
        blocks.impacts_per_second,
        blocks.contact_fraction,
        blocks.mean_force,
        blocks.rms_force,
        blocks.max_force,
        blocks.impulse,
    ] {
        assert!(
            spread.standard_deviation <= 1e-12 * spread.mean.abs(),
            "{spread:?}"
        );
    }
    assert!((blocks.contact_fraction.mean - 0.3).abs() < 1e-12);
    assert!((statistics.summary.impacts_per_second - 40.0 / (400.0 * DT)).abs() < 1e-9);
    // Uneven halves do spread: 10 pulses, then nothing.
    let mut uneven = pulses(80.0, 3, 7, 10, 100);
    uneven.truncate(200);
    let counting = ImpactCounting {
        blocks: 2,
        ..ImpactCounting::default()
    };
    let blocks = feed(&counting, &uneven).0.blocks.expect("two blocks");
    assert_eq!(blocks.impacts.mean, 5.0);
    assert_eq!(blocks.impacts.standard_deviation, 5.0);
}

#[test]
fn blocks_change_after_their_last_step() {
    for (steps, blocks) in [(400, 4), (10, 3), (7, 7), (1000, 1), (5, 100)] {
        let counting = ImpactCounting {
            blocks,
            ..ImpactCounting::default()
        };
        let clock = ImpactClock::new(&counting, DT, steps);
        let mut block = clock.block(1);
        let mut last = clock.last_step(block);
        assert_eq!(block, 0);
        for n in 1..=steps + 3 {
            if n > last {
                block = clock.block(n);
                last = clock.last_step(block);
            }
            assert_eq!(block, clock.block(n), "step {n} of {steps} in {blocks} blocks");
        }
    }
}

#[test]
fn histograms_share_their_classes_and_count_every_impact() {
    // Peaks 10, 20, …, 100 N: 10 classes of 10 N, the largest in the last class.
    let mut forces = Vec::new();
    for k in 1..=10 {
        forces.extend([10.0 * k as f64, 0.0]);
    }
    let counting = ImpactCounting {
        classes: 5,
        ..ImpactCounting::default()
    };
    let (statistics, _, histogram) = feed(&counting, &forces);
    assert_eq!(statistics.summary.impacts, 10);
    assert_eq!(histogram.edges, vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0]);
    assert_eq!(histogram.counts, vec![1, 2, 2, 2, 3]);
    assert_eq!(histogram.per_contact, vec![histogram.counts.clone()]);
    assert_eq!(histogram.impacts, 10);
}

/// Seven pulses of rising force on one contact and three rows: the three largest are
/// kept (the last three, sorted by start), the four others counted as left out.
#[test]
fn rows_beyond_the_limit_keep_the_largest_and_count_the_rest() {
    let mut forces = Vec::new();
    for k in 1..=7 {
        forces.extend([k as f64, k as f64, 0.0, 0.0]);
    }
    let counting = ImpactCounting {
        max_rows: 3,
        ..ImpactCounting::default()
    };
    let (statistics, table, histogram) = feed(&counting, &forces);
    assert_eq!(statistics.summary.impacts, 7);
    assert_eq!((table.rows.len(), table.untabulated, table.impacts), (3, 4, 7));
    let kept: Vec<f64> = table.rows.iter().map(|r| r.peak_force).collect();
    assert_eq!(kept, [5.0, 6.0, 7.0]);
    assert_eq!(table.untabulated_max_peak, Some(4.0));
    assert_eq!(
        (table.contact_impacts.clone(), table.contact_tabulated.clone()),
        (vec![7], vec![3])
    );
    assert_eq!(histogram.impacts, 7);
}

#[test]
fn a_contact_closed_at_the_start_counts_one_impact_from_zero() {
    let counting = ImpactCounting::default();
    let clock = ImpactClock::new(&counting, DT, 10);
    let mut log = ImpactLog::new(1, &counting);
    let mut contact = ContactImpacts::new(0, 1.0, 1);
    contact.record_initial(&clock, 7.0);
    for n in 1..=3 {
        contact.record(&clock, &mut log, (n, 0), 7.0, (1e-6, 1e-6), 0.5);
    }
    let statistics = contact.finish(&clock, &mut log);
    let (table, _) = log.finish();
    assert_eq!(statistics.summary.impacts, 1);
    let row = table.rows[0];
    assert_eq!((row.start, row.approach_velocity, row.energy), (0.0, 0.0, 0.0));
    // Step 0 weighs nothing: three steps of force and dissipation.
    assert!((row.impulse - 21.0 * DT).abs() < 1e-15);
    assert!((row.dissipated - 1.5 * DT).abs() < 1e-15);
    assert!((row.duration - 3.0 * DT).abs() < 1e-15);
}

#[test]
fn bad_settings_are_named() {
    let counting = ImpactCounting {
        force_threshold: -1.0,
        rest_time: f64::NAN,
        blocks: MAX_BLOCKS + 1,
        classes: 0,
        max_rows: 0,
    };
    let fields: Vec<String> = counting.validate().into_iter().map(|i| i.field).collect();
    assert_eq!(
        fields,
        ["force_threshold", "rest_time", "blocks", "classes", "max_rows"]
    );
    let too_many = ImpactCounting {
        classes: MAX_CLASSES + 1,
        ..ImpactCounting::default()
    };
    assert_eq!(too_many.validate().len(), 1);
    assert!(ImpactCounting::default().validate().is_empty());
}
