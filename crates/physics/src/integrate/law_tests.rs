//! The contact laws through every step loop: one set of tests per law, each run on the
//! row, on the plane (one thread and two, which take the shared closed-contact pass),
//! and on the row with walls of their own motion ([`Loop`]). The law itself is written
//! once ([`crate::contact::NormalLaw`]); these check that every loop applies it.
//!
//! The impacts are of a one-mode pin: a single-degree-of-freedom oscillator whose mass
//! at its tip is its apparent mass 1/ψ₁(L)², the mass a restitution is
//! calibrated with ([`Model::reduced_mass`]). Its contact springs are ~300 times
//! stiffer than its own, so each impact is that of a free body (to ~(ω₁/ω_c)²).

use super::tests::{LOOPS, Loop, basis, on_loop, run, settings, shaken_two_pin_row, threads};
use super::*;
use crate::contact::{Body, Contact, Law, NormalLaw, Restitution};
use crate::loads::{PointForce, Table};
use crate::modal::ModalBasis;
use crate::stability::Scheme;

/// One pin of `basis` with `contacts` (their normals +x in the plane) and a release of
/// its tip by `tip` (m) along x, on `kind`.
fn one_pin<'a>(basis: &'a ModalBasis, contacts: Vec<Contact>, tip: f64, kind: Loop) -> Model<'a> {
    let model = Model {
        basis,
        pins: 1,
        damping_ratios: vec![0.0; basis.modes()],
        contacts,
        initial_tip_displacements: vec![tip],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    };
    on_loop(model, kind)
}

/// The wall on the pin's left at its tip: δ = −w − gap.
fn left_wall(stiffness: f64, gap: f64, law: Law) -> Contact {
    Contact {
        left: Body::Wall,
        right: Body::Pin(0),
        height: 1.0,
        gap,
        stiffness,
        damping: 0.0,
        law,
    }
}

/// ω₁ and the tip's apparent mass 1/ψ₁(L)² of a one-mode basis.
fn oscillator(basis: &ModalBasis) -> (f64, f64) {
    let psi = basis.deflection_at(1.0)[0];
    (basis.angular_frequencies()[0], 1.0 / (psi * psi))
}

/// The rebound of the first impact of a pin released from its tip deflection w₀ (it
/// swings toward the left wall, which sits at w = 0): the largest deflection between
/// the end of that impact and the next, over w₀. Undamped and with one mode, the
/// pin's amplitude after the impact is its rebound speed over ω₁.
fn first_rebound(result: &Simulation) -> f64 {
    let (w, forces) = (&result.deflection_peaks[0][0], &result.contact_force_peaks[0]);
    let released = result.deflections[0][0][0];
    let touch = forces
        .iter()
        .position(|f| *f > 0.0)
        .expect("the pin hits the wall");
    let parted = touch
        + forces[touch..]
            .iter()
            .position(|f| *f == 0.0)
            .expect("it rebounds");
    let next = parted
        + forces[parted..]
            .iter()
            .position(|f| *f > 0.0)
            .unwrap_or(forces.len() - parted);
    w[parted..next].iter().copied().fold(0.0, f64::max) / released
}

/// The settings of an impact test: `dt` a fiftieth of the contact's period (a two
/// thousandth for a dashpot: the explicit scheme evaluates it with a velocity a half
/// step behind, and its force jumps to c v₀ at touch, which make the rebound's error
/// first order in the step: 3e-3 at 50 steps and e = 0.9, 1.4e-3 at 500 and e = 0.6),
/// samples every step, long enough for the rebound's half swing.
fn impact_settings(omega: f64, omega_contact: f64, kind: Loop, dashpot: bool) -> Settings {
    let per_period = if dashpot { 2000.0 } else { 50.0 };
    let dt = std::f64::consts::TAU / omega_contact / per_period;
    Settings {
        output_interval: Some(dt),
        threads: threads(kind),
        ..settings(Scheme::CentralDifference, dt, 1.6 * std::f64::consts::PI / omega)
    }
}

/// A linear spring–dashpot given a restitution e: the pin rebounds with e on every
/// loop (the dashpot c = 2ζ(e)√(K m) with the tip's apparent mass), where the
/// textbook dashpot (which lets it pull) would rebound with more.
#[test]
fn a_linear_law_with_a_restitution_rebounds_with_it_on_every_loop() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let omega_contact = 300.0 * omega;
    let stiffness = omega_contact * omega_contact * mass;
    for kind in LOOPS {
        for e in [0.9, 0.6, 0.3] {
            let law = Law {
                restitution: Some(Restitution {
                    coefficient: e,
                    speed: f64::NAN,
                    mass: None,
                }),
                ..Law::LINEAR
            };
            let model = one_pin(&basis, vec![left_wall(stiffness, 0.0, law)], 1e-3, kind);
            assert!(model.validate().is_empty(), "{:?}", model.validate());
            let result = run(&model, &impact_settings(omega, omega_contact, kind, true));
            let rebound = first_rebound(&result);
            assert!((rebound - e).abs() < 1e-3, "{kind:?}, e {e}: rebound {rebound}");
        }
    }
}

/// A Hertz law (n = 3/2) with the Hunt–Crossley damping its restitution sets for the
/// approach speed of the impact: the pin rebounds with e at that speed, and with less
/// when released twice as far (twice the speed), on every loop.
#[test]
fn a_hertz_law_with_hunt_crossley_damping_rebounds_with_e_at_its_speed_on_every_loop() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let (exponent, stiffness, tip) = (1.5, 1e10, 1e-3);
    // The pin meets the wall at its largest speed, ω₁ × its released tip.
    let released = {
        let model = one_pin(&basis, vec![], tip, Loop::Row);
        run(&model, &settings(Scheme::CentralDifference, 1e-5, 1e-5)).deflections[0][0][0]
    };
    let speed = omega * released;
    // The undamped peak penetration ((n + 1) m v²/2K)^(1/(n+1)) at twice the speed
    // bounds the forces of both runs.
    let peak = |v: f64| {
        let depth = ((exponent + 1.0) * mass * v * v / (2.0 * stiffness)).powf(1.0 / (exponent + 1.0));
        stiffness * depth.powf(exponent)
    };
    let force_scale = 1.5 * peak(2.0 * speed);
    let tangent = NormalLaw {
        stiffness,
        damping: 0.0,
        exponent,
        hunt_crossley: 0.0,
    };
    let depth = tangent.penetration_at(force_scale);
    let omega_contact = (exponent * stiffness * depth.powf(exponent - 1.0) / mass).sqrt();
    for kind in LOOPS {
        for e in [0.8, 0.4] {
            let law = Law {
                exponent,
                force_scale,
                restitution: Some(Restitution {
                    coefficient: e,
                    speed,
                    mass: None,
                }),
                ..Law::LINEAR
            };
            let contacts = vec![left_wall(stiffness, 0.0, law)];
            let slow = one_pin(&basis, contacts.clone(), tip, kind);
            assert!(slow.validate().is_empty(), "{:?}", slow.validate());
            let settings = impact_settings(omega, omega_contact, kind, false);
            let rebound = first_rebound(&run(&slow, &settings));
            assert!((rebound - e).abs() < 1e-3, "{kind:?}, e {e}: rebound {rebound}");
            let fast = one_pin(&basis, contacts, 2.0 * tip, kind);
            let faster = first_rebound(&run(&fast, &settings));
            assert!(
                faster < rebound - 0.01,
                "{kind:?}, e {e}: {faster} at 2 v₀ vs {rebound}"
            );
        }
    }
}

/// The power law's elastic energy K δⁿ⁺¹/(n + 1) closes the energy balance of a
/// shaken, damped two-pin row on every loop as the linear law's ½ K δ² does.
#[test]
fn the_energy_balance_closes_with_a_power_law_on_every_loop() {
    let basis = basis(20, 8);
    for kind in LOOPS {
        let mut model = shaken_two_pin_row(&basis);
        for contact in &mut model.contacts {
            // About the linear law's force at its typical penetration (2e4 N/m × 1e-4 m).
            contact.stiffness = 2e4 / 1e-4f64.sqrt();
            contact.law = Law {
                exponent: 1.5,
                hunt_crossley: 0.5,
                force_scale: 50.0,
                ..Law::LINEAR
            };
        }
        if let Loop::Plane { .. } = kind {
            model.plane = Some(Plane {
                normals: vec![[1.0, 0.0]; model.contacts.len()],
                base_acceleration_y: None,
            });
            model.initial_tip_displacements = vec![2e-4, -1e-4, 0.0, 0.0];
        }
        if let Loop::Walls = kind {
            model.walls = Some(WallMotion::rigid(model.base_acceleration.clone(), None));
        }
        assert!(model.validate().is_empty(), "{:?}", model.validate());
        let result = run(
            &model,
            &Settings {
                output_interval: Some(1e-4),
                threads: threads(kind),
                ..settings(Scheme::CentralDifference, 2e-6, 0.1)
            },
        );
        let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
        assert!(
            impacts > 5,
            "{kind:?}: the case must exercise contacts ({impacts} impacts)"
        );
        let peak = result
            .contact_statistics
            .iter()
            .map(|s| s.max_force)
            .fold(0.0, f64::max);
        assert!(
            peak < 50.0,
            "{kind:?}: the force scale must bound the peak ({peak} N)"
        );
        assert!(result.energy.dissipated_contact > 0.0, "{kind:?}");
        let residual = result.energy.relative_residual();
        assert!(
            residual < 1e-3,
            "{kind:?}: residual {residual:e}: {:?}",
            result.energy
        );
    }
}

/// A pin clamped at its tip between two preloaded walls (interference g on each side,
/// preload K g) under a tip force ramped up slowly and held: below the force that
/// unloads one side, both contacts stay closed throughout and the tip settles where
/// statics puts it, P ψ²/(ω₁² + 2 K ψ²); above it, the unloaded side opens.
#[test]
fn a_preloaded_clamp_holds_below_its_preload_and_opens_above_it_on_every_loop() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let (stiffness, interference) = (1e5, 1e-4);
    let omega_contact = (omega * omega + 2.0 * stiffness / mass).sqrt();
    // The force at which the left contact's compression K (g − w) reaches zero.
    let opening = interference * (omega * omega * mass + 2.0 * stiffness);
    let contacts = vec![
        left_wall(stiffness, -interference, Law::LINEAR),
        Contact {
            left: Body::Pin(0),
            right: Body::Wall,
            ..left_wall(stiffness, -interference, Law::LINEAR)
        },
    ];
    let ramp = 200.0 / omega_contact;
    for kind in LOOPS {
        for (load, holds) in [(0.5 * opening, true), (1.5 * opening, false)] {
            let mut model = one_pin(&basis, contacts.clone(), 0.0, kind);
            model.damping_ratios = vec![0.05];
            model.point_forces = vec![PointForce {
                line: 0,
                height: 1.0,
                force: Table::ramp_and_hold(ramp, load),
            }];
            assert!(model.validate().is_empty(), "{:?}", model.validate());
            let dt = std::f64::consts::TAU / omega_contact / 40.0;
            let result = run(
                &model,
                &Settings {
                    output_interval: Some(10.0 * dt),
                    threads: threads(kind),
                    ..settings(Scheme::CentralDifference, dt, ramp + 60.0 / omega)
                },
            );
            let lowest = |c: usize| {
                result.contact_forces[c]
                    .iter()
                    .copied()
                    .fold(f64::INFINITY, f64::min)
            };
            if holds {
                assert!(lowest(0) > 0.0 && lowest(1) > 0.0, "{kind:?}: the clamp opened");
                let settled = *result.deflections[0][0].last().unwrap();
                let statics = load / (omega * omega * mass + 2.0 * stiffness);
                assert!(
                    (settled - statics).abs() < 1e-3 * statics,
                    "{kind:?}: tip {settled} vs statics {statics}"
                );
            } else {
                assert_eq!(lowest(0), 0.0, "{kind:?}: the unloaded side must open");
                assert!(lowest(1) > 0.0, "{kind:?}: the loaded side stays closed");
            }
        }
    }
}

/// A preload with nothing to balance it is refused at its gap, as is a restitution at
/// a clamped foot (no mode moves there) and friction on a row.
#[test]
fn preloads_that_do_not_balance_and_laws_a_model_cannot_carry_are_refused() {
    let basis = basis(20, 2);
    let lonely = one_pin(&basis, vec![left_wall(1e5, -1e-4, Law::LINEAR)], 0.0, Loop::Row);
    let fields: Vec<String> = lonely.validate().into_iter().map(|i| i.field).collect();
    assert_eq!(fields, ["contacts/0/gap"]);
    let at_foot = Contact {
        height: 0.0,
        law: Law {
            restitution: Some(Restitution {
                coefficient: 0.5,
                speed: f64::NAN,
                mass: None,
            }),
            ..Law::LINEAR
        },
        ..left_wall(1e5, 0.0, Law::LINEAR)
    };
    let rubbing = Contact {
        law: Law {
            friction: crate::contact::Friction {
                coefficient: 0.3,
                tangential_stiffness: 1e5,
            },
            ..Law::LINEAR
        },
        ..left_wall(1e5, 0.0, Law::LINEAR)
    };
    let model = one_pin(&basis, vec![at_foot, rubbing], 0.0, Loop::Row);
    let fields: Vec<String> = model.validate().into_iter().map(|i| i.field).collect();
    assert_eq!(
        fields,
        [
            "contacts/0/law/restitution",
            "contacts/1/law/friction/coefficient"
        ]
    );
}

/// The loops that carry friction: the plane on one thread and on two, and the plane
/// with walls of their own motion (the row's contacts have no tangent).
const FRICTION_LOOPS: [(usize, bool); 3] = [(1, false), (2, false), (1, true)];

/// One pin of a one-mode `basis` clamped at its tip between two walls along y, each
/// pressing with `preload` N (interference `preload`/K), with `friction` on both:
/// sliding along x meets 2 μ N. Released from `tip` (m) along x; the plane on
/// `threads` threads, its walls moving by `walls` (or with the feet).
fn clamped_in_the_plane(
    basis: &ModalBasis,
    (stiffness, preload, friction): (f64, f64, crate::contact::Friction),
    tip: f64,
    (threads, walls): (usize, Option<WallMotion>),
) -> (Model<'_>, Settings) {
    let gap = -preload / stiffness;
    let law = Law {
        friction,
        ..Law::LINEAR
    };
    let below = Contact {
        left: Body::Wall,
        right: Body::Pin(0),
        height: 1.0,
        gap,
        stiffness,
        damping: 0.0,
        law,
    };
    let above = Contact {
        left: Body::Pin(0),
        right: Body::Wall,
        ..below.clone()
    };
    let model = Model {
        basis,
        pins: 1,
        damping_ratios: vec![0.0; basis.modes()],
        contacts: vec![below, above],
        initial_tip_displacements: vec![tip, 0.0],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        walls,
        plane: Some(Plane {
            normals: vec![[0.0, 1.0]; 2],
            base_acceleration_y: None,
        }),
        point_forces: vec![],
        kinds: Vec::new(),
    };
    let settings = Settings {
        threads,
        ..settings(Scheme::CentralDifference, 1.0, 1.0)
    };
    (model, settings)
}

/// Settings with a step of `per_period` steps per period of the fastest motion of
/// `model` (its stiffest springs closed), samples every `every` steps, for `duration`.
fn resolved(model: &Model<'_>, base: &Settings, per_period: f64, every: f64, duration: f64) -> Settings {
    let critical = super::step_size::critical_time_step(model, Scheme::CentralDifference);
    // The central difference is stable below 2/ω: the period is π × the critical step.
    let dt = std::f64::consts::PI * critical / per_period;
    Settings {
        time_step: TimeStep::Fixed(dt),
        output_interval: Some(every * dt),
        duration,
        ..base.clone()
    }
}

/// Free decay under Coulomb friction (code_aster sdnd100's closed form): a
/// one-degree-of-freedom oscillator of stiffness k rubbing with a force F = 2 μ N
/// loses 2 F/k of amplitude every half cycle, a linear envelope, until it sticks.
#[test]
fn free_decay_under_coulomb_friction_loses_4_mu_n_over_k_per_cycle_on_every_loop() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let k = omega * omega * mass;
    let (normal, mu) = (1.0, 0.01);
    let friction = crate::contact::Friction {
        coefficient: mu,
        tangential_stiffness: 1e3 * k,
    };
    let drop = 2.0 * (2.0 * mu * normal) / k;
    let tip = 12.5 * drop;
    for (threads, moving) in FRICTION_LOOPS {
        let walls = moving.then(|| WallMotion::rigid(None, None));
        let (model, base) = clamped_in_the_plane(&basis, (1e5, normal, friction), tip, (threads, walls));
        assert!(model.validate().is_empty(), "{:?}", model.validate());
        let period = std::f64::consts::TAU / omega;
        let settings = resolved(&model, &base, 200.0, 1.0, 6.0 * period);
        let result = run(&model, &settings);
        let w = &result.deflection_peaks[0][0];
        let released = result.deflections[0][0][0];
        // The extreme of each half cycle, between two crossings of zero.
        let mut extremes = vec![];
        let mut current = 0.0f64;
        for (a, b) in w.iter().zip(&w[1..]) {
            if a.abs() > current.abs() {
                current = *a;
            }
            if a.signum() != b.signum() && *b != 0.0 {
                extremes.push(current);
                current = 0.0;
            }
        }
        assert!(
            extremes.len() >= 10,
            "{threads} threads, walls {moving}: {extremes:?}"
        );
        for (cycle, extreme) in extremes.iter().take(10).enumerate() {
            let expected = released.abs() - cycle as f64 * drop;
            assert!(
                (extreme.abs() - expected).abs() < 0.02 * drop,
                "{threads} threads, walls {moving}: half cycle {cycle}: {extreme} vs ±{expected}"
            );
        }
        assert!(result.energy.relative_residual() < 1e-3, "{:?}", result.energy);
        assert!(result.friction_statistics[0].slip_distance > 0.0);
    }
}

/// A rod clamped by two preloaded springs with friction under a tangential load
/// ramped up and held: below the friction limit 2 μ N it sticks (it never slips, and
/// settles at P/(k + 2 k_t), the beam and both stick springs in parallel); above it,
/// it slides to where the beam alone carries P − 2 μ N.
#[test]
fn a_clamp_with_friction_holds_below_its_limit_and_slips_above_on_every_loop() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let k = omega * omega * mass;
    let (normal, mu, k_t) = (1.0, 0.2, 100.0 * k);
    let friction = crate::contact::Friction {
        coefficient: mu,
        tangential_stiffness: k_t,
    };
    let limit = 2.0 * mu * normal;
    for (threads, moving) in FRICTION_LOOPS {
        for (load, holds) in [(0.5 * limit, true), (2.0 * limit, false)] {
            let walls = moving.then(|| WallMotion::rigid(None, None));
            let (mut model, base) =
                clamped_in_the_plane(&basis, (1e5, normal, friction), 0.0, (threads, walls));
            model.damping_ratios = vec![0.05];
            let period = std::f64::consts::TAU / omega;
            model.point_forces = vec![PointForce {
                line: 0,
                height: 1.0,
                force: Table {
                    time: vec![0.0, 2.0 * period, 1e3],
                    values: vec![0.0, load, load],
                },
            }];
            assert!(model.validate().is_empty(), "{:?}", model.validate());
            let settings = resolved(&model, &base, 40.0, 20.0, 30.0 * period);
            let result = run(&model, &settings);
            let settled = *result.deflections[0][0].last().unwrap();
            let slid = result.friction_statistics[0].slip_distance;
            if holds {
                assert_eq!(slid, 0.0, "{threads} threads, walls {moving}: the clamp slipped");
                let statics = load / (k + 2.0 * k_t);
                assert!(
                    (settled - statics).abs() < 1e-2 * statics,
                    "{threads} threads, walls {moving}: {settled} vs {statics}"
                );
            } else {
                assert!(slid > 0.0, "{threads} threads, walls {moving}: it must slide");
                // Sliding stops where the beam carries P less the friction it can hold
                // (within the stick band ±2 μ N/k around that rest point).
                let rest = (load - limit) / k;
                assert!(
                    (settled - rest).abs() <= limit / k * 1.01,
                    "{threads} threads, walls {moving}: {settled} vs {rest}"
                );
            }
        }
    }
}

/// A rod clamped between two preloaded walls that slide past it at a constant speed V
/// once a smooth start is over: the rod hangs on its beam at 2 μ N/k (5 mm, passed by
/// the walls within 0.3 s) and each contact
/// slides at V under N, so its friction wear power |T| |v_t| is μ N V and its normal
/// work rate F |v_t| is N V exactly (the difference of two runs removes the start).
#[test]
fn wear_power_is_mu_n_v_for_a_constant_normal_force_and_sliding_speed() {
    let basis = basis(20, 1);
    let (normal, mu, speed) = (2.0, 0.15, 2e-2);
    let friction = crate::contact::Friction {
        coefficient: mu,
        tangential_stiffness: 1e4,
    };
    for threads in [1, 2] {
        let start = 0.05;
        let walls = WallMotion::rigid(
            Some(crate::loads::BaseAcceleration::HalfSine {
                amplitude: std::f64::consts::PI * speed / (2.0 * start),
                duration: start,
            }),
            None,
        );
        let (mut model, base) =
            clamped_in_the_plane(&basis, (1e5, normal, friction), 0.0, (threads, Some(walls)));
        model.damping_ratios = vec![0.2];
        let work = |duration: f64| {
            let settings = resolved(&model, &base, 40.0, 1000.0, duration);
            let result = run(&model, &settings);
            let friction = result.friction_statistics[0];
            (
                friction.tangential_wear_work,
                result.wear_work[0],
                result.steps as f64 * settings_dt(&settings),
            )
        };
        let (early, late) = (work(2.0), work(3.0));
        let elapsed = late.2 - early.2;
        let tangential = (late.0 - early.0) / elapsed;
        let normal_rate = (late.1 - early.1) / elapsed;
        assert!(
            (tangential - mu * normal * speed).abs() < 1e-3 * mu * normal * speed,
            "{threads} threads: {tangential} W vs μNV = {}",
            mu * normal * speed
        );
        assert!(
            (normal_rate - normal * speed).abs() < 1e-3 * normal * speed,
            "{threads} threads: {normal_rate} W vs NV = {}",
            normal * speed
        );
    }
}

fn settings_dt(settings: &Settings) -> f64 {
    match settings.time_step {
        TimeStep::Fixed(dt) => dt,
        TimeStep::Auto => unreachable!("the tests fix their step"),
    }
}

/// A power law whose peak passes the force its step was sized for: the verdict says so
/// (`doubtful`, naming the scale), and `poor` when the step is above the critical step
/// at the peak's stiffness (or the run stops as diverged).
#[test]
fn a_power_law_past_its_force_scale_is_doubtful_and_poor_when_unstable_there() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let (exponent, stiffness, tip) = (1.5, 1e10, 1e-3);
    // The undamped peak of the release's impact (see the Hertz restitution test).
    let speed = omega * tip;
    let depth = ((exponent + 1.0) * mass * speed * speed / (2.0 * stiffness)).powf(1.0 / (exponent + 1.0));
    let peak = stiffness * depth.powf(exponent);
    let run_with = |force_scale: f64, of_critical: f64| {
        let law = Law {
            exponent,
            force_scale,
            ..Law::LINEAR
        };
        let model = one_pin(&basis, vec![left_wall(stiffness, 0.0, law)], tip, Loop::Row);
        let critical = super::step_size::critical_time_step(&model, Scheme::CentralDifference);
        let settings = settings(
            Scheme::CentralDifference,
            of_critical * critical,
            std::f64::consts::PI / omega,
        );
        Plan::new(&model, &settings).and_then(|plan| plan.run(&mut |_| std::ops::ControlFlow::Continue(())))
    };
    // (A one-mode basis is far from converged: the verdict judges that too, so the
    // force scale's part is read from its reason.)
    let about_the_scale = |quality: &Quality| quality.reasons.iter().any(|r| r.contains("force_scale"));
    let sized = run_with(2.0 * peak, 0.05).expect("runs");
    assert!(!about_the_scale(&sized.quality), "{:?}", sized.quality.reasons);
    let under = run_with(peak / 3.0, 0.05).expect("runs");
    assert!(about_the_scale(&under.quality), "{:?}", under.quality.reasons);
    assert_ne!(under.quality.verdict, Verdict::Good);
    assert_ne!(under.quality.verdict, Verdict::Unchecked);
    // 3^(1/3) ≈ 1.44 times the scale's tangent stiffness at the peak: ω 1.2 × higher,
    // above the limit at 0.9 of the scale's critical step.
    match run_with(peak / 3.0, 0.9) {
        Ok(unstable) => {
            assert_eq!(
                unstable.quality.verdict,
                Verdict::Poor,
                "{:?}",
                unstable.quality.reasons
            );
            assert!(
                unstable
                    .quality
                    .reasons
                    .iter()
                    .any(|r| r.contains("above the critical step")),
                "{:?}",
                unstable.quality.reasons
            );
        }
        Err(error) => assert!(matches!(error, SimulationError::Diverged { .. }), "{error}"),
    }
}

/// The step-halving check measures the change of the largest wear work rate (pins in
/// the plane; none for the row), and the verdict judges it with the peaks: a change
/// past the tolerance is a reason.
#[test]
fn the_step_halving_check_judges_the_wear_work_rate() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let friction = crate::contact::Friction {
        coefficient: 0.01,
        tangential_stiffness: 1e3 * omega * omega * mass,
    };
    let (model, base) = clamped_in_the_plane(&basis, (1e5, 1.0, friction), 5e-3, (1, None));
    for per_period in [12.0, 200.0] {
        let settings = Settings {
            check: Check::StepHalving,
            tolerance: 1e-3,
            ..resolved(
                &model,
                &base,
                per_period,
                10.0,
                3.0 * std::f64::consts::TAU / omega,
            )
        };
        let assessed = Plan::new(&model, &settings)
            .and_then(|plan| plan.run(&mut |_| std::ops::ControlFlow::Continue(())))
            .expect("runs");
        let check = assessed.quality.step_halving.expect("checked");
        let error = check
            .estimated_wear_work_rate_error
            .expect("the plane has a wear work rate");
        assert!(error.is_finite(), "{check:?}");
        let judged = assessed
            .quality
            .reasons
            .iter()
            .any(|r| r.contains("wear work rate"));
        assert_eq!(
            judged,
            error > 10.0 * 1e-3,
            "{per_period} steps per period: {error} {:?}",
            assessed.quality.reasons
        );
    }
    // The row has none.
    let row = one_pin(&basis, vec![left_wall(1e5, 0.0, Law::LINEAR)], 1e-3, Loop::Row);
    let settings = Settings {
        check: Check::StepHalving,
        ..resolved(&row, &base, 50.0, 10.0, 0.05)
    };
    let assessed = Plan::new(&row, &settings)
        .and_then(|plan| plan.run(&mut |_| std::ops::ControlFlow::Continue(())))
        .expect("runs");
    assert_eq!(
        assessed
            .quality
            .step_halving
            .expect("checked")
            .wear_work_rate_change,
        None
    );
}

/// The stick spring of friction stiffens the fastest motion like a normal spring: a
/// given step that the frictionless clamp allows is refused with friction's critical
/// step, which the stability analysis finds with k_t along the tangent.
#[test]
fn a_step_friction_makes_unstable_is_refused_with_the_step_it_needs() {
    let basis = basis(20, 1);
    let (omega, mass) = oscillator(&basis);
    let stiff = crate::contact::Friction {
        coefficient: 0.3,
        tangential_stiffness: 1e4 * omega * omega * mass,
    };
    let (frictionless, base) =
        clamped_in_the_plane(&basis, (1e3, 1.0, crate::contact::Friction::NONE), 0.0, (1, None));
    let (rubbing, _) = clamped_in_the_plane(&basis, (1e3, 1.0, stiff), 0.0, (1, None));
    let allowed = super::step_size::critical_time_step(&frictionless, Scheme::CentralDifference);
    let needed = super::step_size::critical_time_step(&rubbing, Scheme::CentralDifference);
    // Two stick springs k_t on the tip's apparent mass: ω² = ω₁² + 2 k_t/m along x.
    let omega_x = (omega * omega + 2.0 * stiff.tangential_stiffness / mass).sqrt();
    assert!(
        (needed - 2.0 / omega_x).abs() < 1e-9 * needed,
        "{needed} vs {}",
        2.0 / omega_x
    );
    let settings = Settings {
        time_step: TimeStep::Fixed(0.9 * allowed),
        duration: 0.01,
        ..base
    };
    assert!(Plan::new(&frictionless, &settings).is_ok());
    match Plan::new(&rubbing, &settings) {
        Err(SimulationError::TimeStepAboveCritical {
            critical_time_step, ..
        }) => {
            assert!((critical_time_step - needed).abs() < 1e-12 * needed)
        }
        other => panic!("the step must be refused: {other:?}"),
    }
}

/// code_aster sdnd104a (analytic reference): a 1 kg block on a plane with Coulomb
/// friction (μ = 0.1, N = 10 N, RIGI_TAN = 9e6) whose base moves with A sin(2πt); the
/// wear power PUIS_USURE = mean of N |v| over [4, 12] s is 15.2671 W for A = 15 m/s²,
/// 0.409062 for 1.5, 2.26164e-4 for 1.01 and 0 for 0.99 (the block never slides).
///
/// The block is the tip of a one-mode pin so soft that its frequency is the block's
/// (ω² = 3e-5 s⁻²), clamped between two preloaded walls with friction: its tip moves as
/// x'' = −ψΓ a(t) − ψ² (friction) with the tip's apparent mass 1/ψ². So the base
/// acceleration is A/(ψΓ), the walls press with N = 10/ψ² in all (two contacts),
/// k_t = 4.5e6/ψ² each; the wear power of the block is the two contacts' normal work
/// rate over 1/ψ² (their normal force is 1/ψ² times the block's), over [4, 12] s from
/// two runs.
#[test]
fn a_block_rubbing_on_a_shaken_plane_wears_as_code_aster_sdnd104a() {
    // The test tube, its Young's modulus scaled down until ω₁² = 3e-5 s⁻² (ω² ∝ E).
    let spec = |young_modulus: f64| crate::beam::BeamSpec {
        young_modulus,
        ..crate::beam::tests::default_tube(8)
    };
    let stiff = ModalBasis::compute(&spec(2.1e11), 1).expect("valid beam");
    let young_modulus = 2.1e11 * 3e-5 / stiff.angular_frequencies()[0].powi(2);
    let basis = ModalBasis::compute(&spec(young_modulus), 1).expect("valid beam");
    assert!((basis.angular_frequencies()[0].powi(2) - 3e-5).abs() < 1e-9);
    let psi = basis.deflection_at(1.0)[0];
    let gamma = basis.participation()[0];
    let mass = 1.0 / (psi * psi);
    for (amplitude, reference, precision) in [
        (15.0, 15.2671, 5e-4),
        (1.5, 0.409062, 5e-4),
        (1.01, 2.26164e-4, 5e-3),
        (0.99, 0.0, 0.0),
    ] {
        let friction = crate::contact::Friction {
            coefficient: 0.1,
            tangential_stiffness: 4.5e6 * mass,
        };
        let (mut model, base) =
            clamped_in_the_plane(&basis, (9e6 * mass, 5.0 * mass, friction), 0.0, (1, None));
        model.base_acceleration = Some(crate::loads::BaseAcceleration::Sine {
            amplitude: amplitude / (psi * gamma),
            frequency: 1.0,
            cycles: 12.0,
        });
        let work = |duration: f64| {
            let settings = Settings {
                time_step: TimeStep::Fixed(2e-5),
                output_interval: Some(0.1),
                duration,
                ..base.clone()
            };
            let result = run(&model, &settings);
            result.wear_work.iter().sum::<f64>() / mass
        };
        let power = (work(12.0) - work(4.0)) / 8.0;
        assert!(
            (power - reference).abs() <= precision * reference,
            "A = {amplitude}: PUIS_USURE {power} W vs {reference}"
        );
    }
}
