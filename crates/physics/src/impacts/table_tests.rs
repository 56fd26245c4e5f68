//! The table's rule against its plain statement (sort each contact, take its fair share,
//! then the largest of the rest), on random impacts fed in random orders; and the
//! guarantees an engineer reads the table by, each checked on its own.

use super::*;
use crate::random::GapRng;

fn impact(contact: usize, start: f64, peak_force: f64) -> Impact {
    Impact {
        contact,
        start,
        peak_time: start + 1e-4,
        peak_force,
        impulse: peak_force * 1e-4,
        duration: 2e-4,
        approach_velocity: 0.1,
        rebounds: 0,
        dissipated: 0.0,
        energy: 0.0,
    }
}

/// `count` impacts over `contacts` contacts, one every 1 ms per contact; contact c's
/// forces are uniform on [0, 10 (c + 1)²) N, rounded to 0.5 N so that ties happen.
fn random_impacts(rng: &mut GapRng, contacts: usize, count: usize) -> Vec<Impact> {
    let mut next_start = vec![0.0; contacts];
    (0..count)
        .map(|_| {
            let c = (rng.next_u64() % contacts as u64) as usize;
            let top = 10.0 * ((c + 1) * (c + 1)) as f64;
            let force = (rng.uniform() * top * 2.0).floor() / 2.0;
            next_start[c] += 1e-3;
            impact(c, next_start[c], force)
        })
        .collect()
}

/// The rule as the module doc states it, on the whole list at once.
pub(crate) fn plain_rule(impacts: &[Impact], contacts: usize, max_rows: usize) -> Vec<Impact> {
    let share = fair_share(max_rows, contacts);
    let larger_first = |a: &Impact, b: &Impact| ByForce(*b).cmp(&ByForce(*a));
    let mut kept = Vec::new();
    let mut rest = Vec::new();
    for c in 0..contacts {
        let mut own: Vec<Impact> = impacts.iter().filter(|i| i.contact == c).copied().collect();
        own.sort_by(larger_first);
        let split = own.len().min(share);
        kept.extend_from_slice(&own[..split]);
        rest.extend_from_slice(&own[split..]);
    }
    rest.sort_by(larger_first);
    let room = max_rows - kept.len();
    kept.extend(rest.into_iter().take(room));
    kept.sort_by(|a, b| a.start.total_cmp(&b.start).then(a.contact.cmp(&b.contact)));
    kept
}

fn keep(impacts: &[Impact], contacts: usize, max_rows: usize) -> ImpactTable {
    let mut keeper = TableKeeper::new(contacts, max_rows);
    for &i in impacts {
        keeper.push(i);
        let held = keeper.share_rows + keeper.others.len();
        assert!(
            held <= max_rows,
            "the keeper holds {held} impacts for {max_rows} rows"
        );
    }
    keeper.finish()
}

fn shuffle(rng: &mut GapRng, impacts: &mut [Impact]) {
    for k in (1..impacts.len()).rev() {
        let j = (rng.next_u64() % (k as u64 + 1)) as usize;
        impacts.swap(k, j);
    }
}

#[test]
fn the_kept_rows_are_the_rule_whatever_order_the_impacts_end_in() {
    let mut rng = GapRng::new(33);
    for (contacts, count, max_rows) in [
        (4, 500, 40),
        (4, 500, 3),
        (7, 2000, 100),
        (30, 300, 20),
        (3, 50, 50),
        (3, 50, 49),
    ] {
        let mut impacts = random_impacts(&mut rng, contacts, count);
        let expected = plain_rule(&impacts, contacts, max_rows);
        assert_eq!(expected.len(), max_rows.min(count));
        for _ in 0..3 {
            let table = keep(&impacts, contacts, max_rows);
            assert_eq!(
                table.rows, expected,
                "{contacts} contacts, {count} impacts, {max_rows} rows: the kept rows differ from the rule"
            );
            shuffle(&mut rng, &mut impacts);
        }
    }
}

#[test]
fn a_table_under_the_cap_is_every_impact_by_start() {
    let mut rng = GapRng::new(7);
    let impacts = random_impacts(&mut rng, 5, 300);
    for max_rows in [300, 301, 100_000] {
        let table = keep(&impacts, 5, max_rows);
        let mut every = impacts.clone();
        every.sort_by(|a, b| a.start.total_cmp(&b.start).then(a.contact.cmp(&b.contact)));
        assert_eq!(table.rows, every);
        assert!(!table.truncated());
        assert_eq!((table.impacts, table.untabulated), (300, 0));
        assert_eq!(table.untabulated_max_peak, None);
        assert_eq!(table.contact_tabulated, table.contact_impacts);
    }
}

#[test]
fn the_counts_add_up_and_name_what_was_left_out() {
    let mut rng = GapRng::new(11);
    let (contacts, max_rows) = (6, 60);
    let impacts = random_impacts(&mut rng, contacts, 1000);
    let table = keep(&impacts, contacts, max_rows);
    assert!(table.truncated());
    assert_eq!(table.impacts, 1000);
    assert_eq!(table.rows.len() as u64 + table.untabulated, table.impacts);
    assert_eq!(table.contact_impacts.iter().sum::<u64>(), table.impacts);
    assert_eq!(
        table.contact_tabulated.iter().sum::<u64>(),
        table.rows.len() as u64
    );
    for c in 0..contacts {
        let counted = impacts.iter().filter(|i| i.contact == c).count() as u64;
        let rows = table.rows.iter().filter(|r| r.contact == c).count() as u64;
        assert_eq!(table.contact_impacts[c], counted, "contact {c}'s impacts");
        assert_eq!(table.contact_tabulated[c], rows, "contact {c}'s rows");
    }
    assert_eq!((table.max_rows, table.fair_share), (60, 10));
    // The largest dropped peak, and every impact above it kept.
    let kept = |i: &Impact| table.rows.contains(i);
    let dropped_max = impacts
        .iter()
        .filter(|i| !kept(i))
        .map(|i| i.peak_force)
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(table.untabulated_max_peak, Some(dropped_max));
    assert!(impacts.iter().filter(|i| i.peak_force > dropped_max).all(kept));
}

/// Each contact's rows are its largest impacts; the run's largest, and every contact's
/// largest (N ≥ C), are in the table.
#[test]
fn each_contact_keeps_its_largest_and_the_run_peak_is_kept() {
    let mut rng = GapRng::new(5);
    for (contacts, max_rows) in [(8, 16), (8, 8), (8, 3), (8, 1)] {
        let impacts = random_impacts(&mut rng, contacts, 800);
        let table = keep(&impacts, contacts, max_rows);
        assert_eq!(table.rows.len(), max_rows);
        let run_peak = impacts.iter().map(|i| i.peak_force).fold(0.0, f64::max);
        let table_peak = table.rows.iter().map(|r| r.peak_force).fold(0.0, f64::max);
        assert_eq!(
            table_peak, run_peak,
            "{max_rows} rows: the run's peak {run_peak} N is not in the table"
        );
        for c in 0..contacts {
            let kept: Vec<&Impact> = table.rows.iter().filter(|r| r.contact == c).collect();
            let smallest_kept = kept.iter().map(|r| r.peak_force).fold(f64::INFINITY, f64::min);
            let largest_dropped = impacts
                .iter()
                .filter(|i| i.contact == c && !table.rows.contains(i))
                .map(|i| i.peak_force)
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                largest_dropped <= smallest_kept,
                "contact {c}: dropped {largest_dropped} N, kept {smallest_kept} N"
            );
            if max_rows >= contacts {
                let largest = impacts
                    .iter()
                    .filter(|i| i.contact == c)
                    .map(|i| i.peak_force)
                    .fold(0.0, f64::max);
                assert!(
                    kept.iter().any(|r| r.peak_force == largest),
                    "contact {c}'s largest"
                );
            }
        }
    }
}

/// A contact hammered at 1000 N and one tapping at 1 N, 20 rows: the quiet contact keeps
/// its fair share (10), the loud one the rest, however many more of its impacts there are.
#[test]
fn a_loud_contact_takes_no_more_than_its_share_from_a_quiet_one() {
    let mut impacts = Vec::new();
    for k in 0..500 {
        impacts.push(impact(0, k as f64 * 1e-3, 1000.0 + k as f64));
    }
    for k in 0..30 {
        impacts.push(impact(1, k as f64 * 1e-2, 1.0 + k as f64 * 1e-3));
    }
    let table = keep(&impacts, 2, 20);
    assert_eq!(table.contact_tabulated, vec![10, 10]);
    // The quiet contact's ten largest: its last ten.
    let quiet: Vec<f64> = table
        .rows
        .iter()
        .filter(|r| r.contact == 1)
        .map(|r| r.peak_force)
        .collect();
    let expected: Vec<f64> = (20..30).map(|k| 1.0 + k as f64 * 1e-3).collect();
    assert_eq!(quiet, expected);
    // With one quiet impact only, the loud contact takes the nine rows it leaves.
    impacts.truncate(501);
    let table = keep(&impacts, 2, 20);
    assert_eq!(table.contact_tabulated, vec![19, 1]);
}

/// More contacts than rows: no share, the largest impacts of the run.
#[test]
fn with_more_contacts_than_rows_the_largest_impacts_are_kept() {
    let mut rng = GapRng::new(3);
    let impacts = random_impacts(&mut rng, 12, 400);
    let table = keep(&impacts, 12, 5);
    assert_eq!(table.fair_share, 0);
    let mut forces: Vec<f64> = impacts.iter().map(|i| i.peak_force).collect();
    forces.sort_by(|a, b| b.total_cmp(a));
    let mut kept: Vec<f64> = table.rows.iter().map(|r| r.peak_force).collect();
    kept.sort_by(|a, b| b.total_cmp(a));
    assert_eq!(kept, forces[..5]);
}

#[test]
fn the_fair_share_is_the_rows_over_the_contacts() {
    assert_eq!(fair_share(100_000, 61 * 3), 546);
    assert_eq!(fair_share(10, 3), 3);
    assert_eq!(fair_share(2, 3), 0);
    assert_eq!(fair_share(7, 0), 7);
}
