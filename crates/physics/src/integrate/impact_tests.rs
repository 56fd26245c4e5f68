//! Impacts counted in full runs: the single-mode wall impact against its closed form
//! (duration, peak force, impulse, approach velocity and energy), rebounds merged by a
//! rest time, and on a damped shaken row the per-impact table against the per-contact
//! totals and the energy balance, and capped to fewer rows than impacts, the largest of
//! them by the table's rule.

use std::f64::consts::PI;

use super::tests::{basis, free_model, run, settings, shaken_two_pin_row, tip_wall};
use super::*;
use crate::stability::Scheme;

/// One mode released at the top of its swing hits a wall spring with zero gap and no
/// damping (as in `single_mode_contact_lasts_half_a_contact_period`): it arrives with
/// all its energy kinetic, δ̇ = ψ q̇ with ½ q̇² = E₀, stays π/ω_c in contact, peaks at
/// Kc δ̇/ω_c and takes the impulse 2 Kc δ̇/ω_c². Its impact energy ½ m δ̇² with
/// m = 1/ψ² is E₀. Returns the model's run with `counting`.
fn single_mode_impacts(counting: ImpactCounting) -> (Simulation, f64, f64, f64) {
    let basis = basis(20, 1);
    let stiffness = 50.0;
    let mut model = free_model(&basis, 0.0, 1e-3);
    model.contacts = vec![tip_wall(stiffness, 0.0, 0.0)];
    let psi = basis.deflection_at(1.0)[0];
    let omega = basis.angular_frequencies()[0];
    let omega_c = (omega * omega + stiffness * psi * psi).sqrt();
    let duration = PI / (2.0 * omega) + 3.0 * (PI / omega + PI / omega_c) + PI / omega_c + PI / (2.0 * omega);
    let result = run(
        &model,
        &Settings {
            impacts: counting,
            ..settings(Scheme::CentralDifference, 2e-6, duration)
        },
    );
    (result, psi, omega, omega_c)
}

#[test]
fn a_single_mode_impact_has_its_closed_form_duration_peak_impulse_and_energy() {
    let (result, psi, _, omega_c) = single_mode_impacts(ImpactCounting::default());
    let stiffness = 50.0;
    let initial = result.energy.initial;
    let approach = psi.abs() * (2.0 * initial).sqrt();
    let rows = &result.impact_table.rows;
    assert_eq!(rows.len(), 4);
    assert_eq!(result.contact_statistics[0].impacts, 4);
    let dt = 2e-6;
    for row in rows {
        assert!((row.duration - PI / omega_c).abs() < 2.0 * dt, "{row:?}");
        let close = |value: f64, expected: f64| (value - expected).abs() < 1e-3 * expected;
        assert!(close(row.approach_velocity, approach), "{row:?} vs {approach}");
        assert!(close(row.energy, initial), "{row:?} vs {initial}");
        assert!(close(row.peak_force, stiffness * approach / omega_c), "{row:?}");
        let impulse = 2.0 * stiffness * approach / (omega_c * omega_c);
        assert!(close(row.impulse, impulse), "{row:?} vs {impulse}");
        assert_eq!((row.rebounds, row.dissipated), (0, 0.0));
    }
    let statistics = &result.impact_statistics[0];
    assert!((statistics.mean_impact_energy - initial).abs() < 1e-3 * initial);
    assert!((statistics.summary.impulse - result.contact_statistics[0].impulse).abs() < 1e-15);
}

#[test]
fn a_rest_time_longer_than_the_flights_merges_the_impacts_into_rebounds() {
    let (free, _, omega, omega_c) = single_mode_impacts(ImpactCounting::default());
    // Each flight lasts π/ω₁: a rest time beyond it makes one impact of four.
    let merged = single_mode_impacts(ImpactCounting {
        rest_time: 1.1 * PI / omega,
        ..ImpactCounting::default()
    })
    .0;
    assert_eq!(merged.impact_statistics[0].summary.impacts, 1);
    assert_eq!(merged.contact_statistics[0].impacts, 1);
    let row = merged.impact_table.rows[0];
    assert_eq!(row.rebounds, 3);
    let span = 4.0 * PI / omega_c + 3.0 * PI / omega;
    assert!((row.duration - span).abs() < 1e-4 * span, "{row:?} vs {span}");
    // The same steps carry the force: impulse and loaded time are unchanged.
    let (a, b) = (&free.impact_statistics[0], &merged.impact_statistics[0]);
    assert_eq!(
        (a.summary.impulse, a.loaded_time),
        (b.summary.impulse, b.loaded_time)
    );
    // A threshold above the peaks counts nothing.
    let peak = free.contact_statistics[0].max_force;
    let none = single_mode_impacts(ImpactCounting {
        force_threshold: 1.01 * peak,
        ..ImpactCounting::default()
    })
    .0;
    assert_eq!(none.contact_statistics[0].impacts, 0);
    assert!(none.impact_table.rows.is_empty());
}

/// On a damped, shaken two-pin row with dashpots: per contact, the impulses of its
/// impacts add up to its impulse, their largest peak is its largest force, its first
/// impact starts within a step of its first closure, and the dashpot energy of every
/// impact adds up to the energy balance's contact dissipation.
#[test]
fn the_impact_table_adds_up_to_the_contact_totals_and_the_energy_balance() {
    let basis = basis(20, 8);
    let model = shaken_two_pin_row(&basis);
    let dt = 2e-6;
    let result = run(
        &model,
        &Settings {
            output_interval: Some(1e-4),
            impacts: ImpactCounting {
                blocks: 5,
                ..ImpactCounting::default()
            },
            ..settings(Scheme::CentralDifference, dt, 0.1)
        },
    );
    let rows = &result.impact_table.rows;
    assert!(rows.len() > 5, "the case must exercise contacts");
    assert_eq!(result.impact_table.untabulated, 0);
    for (c, stats) in result.contact_statistics.iter().enumerate() {
        let mine: Vec<_> = rows.iter().filter(|r| r.contact == c).collect();
        assert_eq!(mine.len() as u64, stats.impacts, "contact {c}");
        let impulse: f64 = mine.iter().map(|r| r.impulse).sum();
        assert!(
            (impulse - stats.impulse).abs() <= 1e-12 * stats.impulse.max(1e-30),
            "contact {c}"
        );
        let peak = mine.iter().map(|r| r.peak_force).fold(0.0, f64::max);
        assert_eq!(peak, stats.max_force, "contact {c}");
        if let (Some(first), Some(closure)) = (mine.first(), stats.first_impact_time) {
            assert!(first.start <= closure && closure <= first.start + dt * (1.0 + 1e-9));
        }
        let summary = &result.impact_statistics[c];
        let blocks = summary.blocks.expect("five blocks");
        assert!((blocks.impacts.mean * 5.0 - stats.impacts as f64).abs() < 1e-9);
        assert!((blocks.impulse.mean * 5.0 - stats.impulse).abs() <= 1e-9 * stats.impulse.max(1e-30));
        assert_eq!(
            result.impact_histogram.per_contact[c].iter().sum::<u64>(),
            stats.impacts
        );
    }
    assert!(rows.windows(2).all(|w| w[0].start <= w[1].start));

    // The balance integrates the dashpot power by the trapezoidal rule, the impacts by
    // steps: the two agree exactly when no contact is closed at the end (the powers
    // before and after each impact are zero). So end the run at a sample where every
    // contact is open.
    let open = (1..result.time.len())
        .rev()
        .find(|&k| {
            result
                .contact_forces
                .iter()
                .all(|f| f[k] == 0.0 && f[k - 1] == 0.0)
        })
        .expect("a sample with every contact open");
    let ended = run(
        &model,
        &Settings {
            output_interval: Some(1e-4),
            ..settings(Scheme::CentralDifference, dt, result.time[open])
        },
    );
    let dissipated: f64 = ended.impact_table.rows.iter().map(|r| r.dissipated).sum();
    let balance = ended.energy.dissipated_contact;
    assert!(balance > 0.0);
    assert!(
        (dissipated - balance).abs() < 1e-9 * balance,
        "{dissipated:e} vs {balance:e}"
    );
}

/// With a threshold and a rest time of 0 an impact is a closure after a separation:
/// without dashpots the force is positive exactly when the contact is closed, so the
/// count is the rising edges of the force sampled at every step.
#[test]
fn with_no_threshold_or_rest_the_count_is_the_closures() {
    let basis = basis(20, 8);
    let mut model = shaken_two_pin_row(&basis);
    for contact in &mut model.contacts {
        contact.damping = 0.0;
    }
    let result = run(&model, &settings(Scheme::CentralDifference, 2e-6, 0.05));
    let mut total = 0;
    for (forces, stats) in result.contact_forces.iter().zip(&result.contact_statistics) {
        let mut closures = u64::from(forces[0] > 0.0);
        closures += forces.windows(2).filter(|w| w[0] <= 0.0 && w[1] > 0.0).count() as u64;
        assert_eq!(stats.impacts, closures);
        total += closures;
    }
    assert!(total > 5, "the case must exercise contacts: {total}");
}

/// The contact statistics (contact time, impulse, largest force and its time) follow
/// the force at every step whatever the counting: with a threshold of 0 they come from
/// the impacts' sums, with a threshold from sums of their own, and both equal the force
/// history sampled at every step (without dashpots a contact is closed exactly when its
/// force is positive).
#[test]
fn the_contact_statistics_are_the_step_forces_with_or_without_a_threshold() {
    let basis = basis(20, 8);
    let mut model = shaken_two_pin_row(&basis);
    for contact in &mut model.contacts {
        contact.damping = 0.0;
    }
    let dt = 2e-6;
    for threshold in [0.0, 5.0] {
        let result = run(
            &model,
            &Settings {
                output_interval: Some(dt),
                impacts: ImpactCounting {
                    force_threshold: threshold,
                    ..ImpactCounting::default()
                },
                ..settings(Scheme::CentralDifference, dt, 0.03)
            },
        );
        assert_eq!(result.time.len() as u64, result.steps + 1);
        let mut closed = 0;
        for (c, (forces, stats)) in result
            .contact_forces
            .iter()
            .zip(&result.contact_statistics)
            .enumerate()
        {
            let steps = forces[1..].iter().filter(|&&f| f > 0.0).count();
            closed += steps;
            let impulse: f64 = forces[1..].iter().map(|f| f * dt).sum();
            let (k, max) = forces
                .iter()
                .enumerate()
                .fold((0, 0.0), |(k, m), (i, &f)| if f > m { (i, f) } else { (k, m) });
            let what = format!("threshold {threshold}, contact {c}");
            assert!(
                (stats.contact_time - steps as f64 * dt).abs() < 1e-9 * dt,
                "{what}"
            );
            assert!(
                (stats.impulse - impulse).abs() <= 1e-12 * impulse.max(1e-30),
                "{what}"
            );
            assert_eq!(stats.max_force, max, "{what}");
            assert_eq!(stats.max_force_time, result.time[k], "{what}");
        }
        assert!(
            closed > 100,
            "the case must exercise contacts: {closed} closed steps"
        );
    }
}

/// The damped shaken row run twice, its table complete and capped at a third of its
/// impacts: the statistics are the same, the capped table holds exactly the rows the
/// rule picks from the complete one (each contact's fair share of its largest, then the
/// largest of the rest), the run's peak among them, and its counts add up to the
/// statistics' impact count.
#[test]
fn a_capped_table_keeps_the_largest_impacts_of_the_complete_one() {
    let basis = basis(20, 8);
    let model = shaken_two_pin_row(&basis);
    let with_rows = |max_rows| {
        run(
            &model,
            &Settings {
                output_interval: Some(1e-4),
                impacts: ImpactCounting {
                    max_rows,
                    ..ImpactCounting::default()
                },
                ..settings(Scheme::CentralDifference, 2e-6, 0.1)
            },
        )
    };
    let complete = with_rows(crate::impacts::DEFAULT_MAX_ROWS);
    let every = &complete.impact_table.rows;
    assert!(!complete.impact_table.truncated());
    let contacts = model.contacts.len();
    let cap = every.len() / 3;
    assert!(
        cap > contacts,
        "the case must leave rows beyond the fair shares: {cap} rows"
    );
    let capped = with_rows(cap);
    assert_eq!(capped.impact_statistics, complete.impact_statistics);
    let table = &capped.impact_table;
    assert!(table.truncated());
    assert_eq!(
        table.rows,
        crate::impacts::table::tests::plain_rule(every, contacts, cap),
        "the capped table is not the rule applied to the complete one"
    );
    let counted: u64 = capped.contact_statistics.iter().map(|s| s.impacts).sum();
    assert_eq!(table.impacts, counted);
    assert_eq!(table.rows.len() as u64 + table.untabulated, counted);
    for (c, stats) in capped.contact_statistics.iter().enumerate() {
        assert_eq!(table.contact_impacts[c], stats.impacts, "contact {c}");
        assert!(
            table
                .rows
                .iter()
                .any(|r| r.contact == c && r.peak_force == stats.max_force),
            "contact {c}: its largest force {} N is not in the table",
            stats.max_force
        );
    }
    let run_peak = capped
        .contact_statistics
        .iter()
        .map(|s| s.max_force)
        .fold(0.0, f64::max);
    let table_peak = table.rows.iter().map(|r| r.peak_force).fold(0.0, f64::max);
    assert_eq!(table_peak, run_peak);
}
