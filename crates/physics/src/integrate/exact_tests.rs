//! Physics checks of the exact modal scheme: the propagator against the closed form,
//! free vibration exact at steps far above the explicit critical step, contact
//! durations, second order, the energy balance, and the same impacts as central
//! difference converged (with the static correction's stiff pseudo-modes at steps they
//! do not bound).

use super::exact::Propagator;
use super::tests::{basis, free_model, run, settings, shaken_two_pin_row, tip_wall};
use super::*;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Friction, Law};
use crate::loads::{BaseAcceleration, PointForce, Table};
use crate::modal::ModalBasis;
use crate::stability::Scheme;

/// The damped oscillator's step in closed form under a load linear over the step: the
/// particular solution α + βt (β = (f₁ − f₀)/(ω²h), α = (f₀ − 2ξωβ)/ω²) plus the free
/// damped motion (well conditioned for ωh not small).
fn closed_form(omega: f64, xi: f64, h: f64, (q, v, f0, f1): (f64, f64, f64, f64)) -> (f64, f64) {
    let wd = omega * (1.0 - xi * xi).sqrt();
    let beta = (f1 - f0) / (omega * omega * h);
    let alpha = (f0 - 2.0 * xi * omega * beta) / (omega * omega);
    let (u, du) = (q - alpha, v - beta);
    let decay = (-xi * omega * h).exp();
    let (s, c) = (wd * h).sin_cos();
    let position = decay * (u * (c + xi * omega / wd * s) + du * s / wd);
    let velocity = decay * (du * (c - xi * omega / wd * s) - u * omega * omega / wd * s);
    (alpha + beta * h + position, beta + velocity)
}

#[test]
fn the_propagator_is_the_exact_step_of_a_damped_mode_under_a_linear_load() {
    let state = (1.3e-3, -0.7, 2.0, -5.0);
    for &(omega, xi) in &[
        (10.0, 0.0),
        (10.0, 0.05),
        (3.0e3, 0.01),
        (2.0e5, 0.02),
        (5.0e6, 0.0),
    ] {
        for &h in &[1e-5, 1e-4, 1e-3] {
            let w = omega * h;
            if w < 0.05 {
                continue;
            }
            let p = Propagator::new(omega, xi, h);
            let apply = |c: &[f64; 4]| c[0] * state.0 + c[1] * state.1 + c[2] * state.2 + c[3] * state.3;
            let (q, v) = closed_form(omega, xi, h, state);
            // Scales: the displacement a unit of each input gives.
            let q_scale = state.0.abs() + (state.1 / omega).abs() + (state.2 / (omega * omega)).abs() * 2.0;
            let v_scale = q_scale * omega;
            assert!(
                (apply(&p.q) - q).abs() <= 1e-11 * q_scale,
                "ω = {omega}, ξ = {xi}, h = {h}: q {} vs {q}",
                apply(&p.q)
            );
            assert!(
                (apply(&p.v) - v).abs() <= 1e-11 * v_scale,
                "ω = {omega}, ξ = {xi}, h = {h}: v {} vs {v}",
                apply(&p.v)
            );
        }
    }
    // No stiffness: uniformly accelerated motion under a linear load.
    let h = 2e-3;
    let p = Propagator::new(0.0, 0.0, h);
    let expected_q = [1.0, h, h * h / 3.0, h * h / 6.0];
    let expected_v = [0.0, 1.0, h / 2.0, h / 2.0];
    for k in 0..4 {
        assert!((p.q[k] - expected_q[k]).abs() <= 1e-15 * expected_q[k].abs().max(1e-300));
        assert!((p.v[k] - expected_v[k]).abs() <= 1e-15 * expected_v[k].abs().max(1e-300));
    }
    // A slow mode (ωh = 1e-4) against its Taylor expansion: q ≈ (1 − w²/2) q + h v + …
    let (omega, h) = (0.1, 1e-3);
    let p = Propagator::new(omega, 0.0, h);
    let w2 = (omega * h).powi(2);
    assert!(
        (p.q[0] - (1.0 - w2 / 2.0 + w2 * w2 / 24.0)).abs() <= 4.0 * f64::EPSILON,
        "{}",
        p.q[0] - 1.0
    );
    assert!((p.q[1] / h - (1.0 - w2 / 6.0)).abs() <= 4.0 * f64::EPSILON);
    assert!((p.v[0] / (-omega * omega * h) - (1.0 - w2 / 6.0)).abs() <= 4.0 * f64::EPSILON);
}

/// Damped free vibration of 6 modes is exact at any step: at 20 × the critical step of
/// central difference the tip follows the closed form to rounding.
#[test]
fn free_vibration_is_exact_at_steps_far_above_the_explicit_limit() {
    let basis = basis(20, 6);
    let xi = 0.02;
    let model = free_model(&basis, xi, 1e-3);
    let critical = critical_time_step(&model, Scheme::CentralDifference);
    let dt = 20.0 * critical;
    let result = run(&model, &settings(Scheme::ExactModal, dt, 400.0 * dt));
    let psi = basis.deflection_at(1.0);
    let q0: Vec<f64> = basis
        .unit_tip_release()
        .unwrap()
        .iter()
        .map(|u| u * 1e-3)
        .collect();
    let exact_tip = |t: f64| -> f64 {
        (0..basis.modes())
            .map(|i| {
                let w = basis.angular_frequencies()[i];
                let wd = w * (1.0 - xi * xi).sqrt();
                psi[i] * (-xi * w * t).exp() * q0[i] * ((wd * t).cos() + xi * w / wd * (wd * t).sin())
            })
            .sum()
    };
    let worst = result
        .time
        .iter()
        .zip(&result.deflections[0][0])
        .map(|(t, w)| (w - exact_tip(*t)).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "worst tip error {worst:e} m (tip 1e-3 m)");
    assert_eq!(result.step.critical_time_step, f64::INFINITY);
}

/// One mode against a wall spring with no gap and no damping: each contact lasts half
/// the period of ω_c² = ω₁² + Kc ψ(L)² (as for central difference), here with 40 steps
/// per contact, and the energy comes back.
#[test]
fn a_single_mode_contact_lasts_half_a_contact_period() {
    let basis = basis(20, 1);
    let stiffness = 50.0;
    let mut model = free_model(&basis, 0.0, 1e-3);
    model.contacts = vec![tip_wall(stiffness, 0.0, 0.0)];
    let psi = basis.deflection_at(1.0)[0];
    let omega = basis.angular_frequencies()[0];
    let omega_c = (omega.powi(2) + stiffness * psi * psi).sqrt();
    let pi = std::f64::consts::PI;
    let dt = pi / omega_c / 40.0;
    let duration = pi / (2.0 * omega) + 3.0 * (pi / omega + pi / omega_c) + pi / omega_c + pi / (2.0 * omega);
    let result = run(&model, &settings(Scheme::ExactModal, dt, duration));
    let stats = &result.contact_statistics[0];
    assert_eq!(stats.impacts, 4, "impacts");
    let per_impact = stats.contact_time / stats.impacts as f64;
    let expected = pi / omega_c;
    assert!(
        (per_impact - expected).abs() < 2.0 * dt,
        "contact duration {per_impact} s vs π/ω_c = {expected} s"
    );
    assert!(
        result.energy.relative_residual() < 1e-3,
        "balance residual {:e}",
        result.energy.relative_residual()
    );
}

/// A pin held against a stiff wall spring by a constant tip force and shaken by a sine
/// stays in contact: the response is smooth, and the error of the tip deflection at a
/// fixed time falls as h² (against a run at h/16).
#[test]
fn the_scheme_is_second_order_with_a_closed_contact() {
    let basis = basis(20, 6);
    let mut model = free_model(&basis, 0.01, 0.0);
    model.contacts = vec![tip_wall(1e5, 0.0, 5.0)];
    model.point_forces = vec![PointForce {
        line: 0,
        height: 1.0,
        force: Table {
            time: vec![0.0, 10.0],
            values: vec![-20.0, -20.0],
        },
    }];
    model.base_acceleration = Some(BaseAcceleration::Sine {
        amplitude: 2.0,
        frequency: 40.0,
        cycles: 100.0,
    });
    let tip = |dt: f64| {
        let result = run(&model, &settings(Scheme::ExactModal, dt, 0.05));
        assert!(result.contact_statistics[0].impacts <= 1, "stays closed");
        *result.deflections[0][0].last().unwrap()
    };
    let h = 2e-4;
    let reference = tip(h / 16.0);
    let (coarse, fine) = ((tip(h) - reference).abs(), (tip(h / 2.0) - reference).abs());
    let order = (coarse / fine).log2();
    assert!(
        (1.8..2.3).contains(&order),
        "order {order} ({coarse:e} → {fine:e})"
    );
}

/// The energy balance closes on the damped, shaken two-pin row with dashpots (the
/// implicit solve's rate terms): the same bound as central difference, at 25 × its
/// step.
#[test]
fn the_energy_balance_closes_on_a_damped_excited_multi_contact_row() {
    let basis = basis(20, 8);
    let model = shaken_two_pin_row(&basis);
    let result = run(
        &model,
        &Settings {
            output_interval: Some(1e-4),
            ..settings(Scheme::ExactModal, 5e-5, 0.1)
        },
    );
    let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts > 5, "the case must exercise contacts: {impacts} impacts");
    assert!(result.energy.dissipated_contact > 0.0 && result.energy.dissipated_modal > 0.0);
    let residual = result.energy.relative_residual();
    assert!(
        residual < 1e-3,
        "energy balance residual {residual:e}: {:?}",
        result.energy
    );
}

/// A three-pin row shaken into its walls and each other at five heights, on 24 modes
/// and the static correction (pseudo-modes far above the modes): the exact scheme's
/// step follows the contacts, central difference's the top of the basis. Both at their
/// `auto` step give the peak contact force of the exact scheme converged (at an eighth
/// of its step) within the tolerance's scale, the exact one with over five times fewer
/// steps.
#[test]
fn impacts_match_converged_central_difference_with_far_fewer_steps() {
    let heights = [0.2, 0.4, 0.6, 0.8, 1.0];
    let basis = ModalBasis::compute_with_static_correction(&default_tube(60), 24, &heights).unwrap();
    let model = three_pin_model(&basis, &heights);
    let auto = |scheme| Settings {
        time_step: TimeStep::Auto,
        ..settings(scheme, 1.0, 0.03)
    };
    let explicit = run(&model, &auto(Scheme::CentralDifference));
    let exact = run(&model, &auto(Scheme::ExactModal));
    let converged = run(
        &model,
        &settings(Scheme::ExactModal, exact.step.time_step / 8.0, 0.03),
    );
    let reference = peak(&converged);
    let impacts: u64 = exact.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts > 3, "the case must exercise contacts: {impacts} impacts");
    for (name, run) in [("central difference", &explicit), ("exact", &exact)] {
        assert!(
            (peak(run) - reference).abs() <= 2e-3 * reference,
            "{name}: peak {} N ({} steps) vs {reference} N converged",
            peak(run),
            run.steps
        );
    }
    assert!(
        exact.steps * 5 < explicit.steps,
        "{} steps (exact) vs {} (central difference)",
        exact.steps,
        explicit.steps
    );
}

/// Three pins in a triangle bending in the plane, each against a wall and its two
/// neighbours along the triangle's sides, on 8 modes and the static correction, shaken
/// along x and y: the exact scheme at its `auto` step agrees with central difference at
/// a quarter of its own in peak force (within the verdict's bound for peaks), in wear
/// work ∫ F |v_t| dt (the sliding velocity from the x and y lines), and closes its
/// energy balance.
#[test]
fn pins_bending_in_the_plane_match_central_difference() {
    let heights = [0.5, 1.0];
    let basis = ModalBasis::compute_with_static_correction(&default_tube(30), 8, &heights).unwrap();
    let model = triangle(&basis, &heights, Friction::NONE);
    let (exact, explicit) = exact_and_converged_explicit(&model, 0.04);
    let wear = |s: &Simulation| s.wear_work.iter().sum::<f64>();
    let impacts: u64 = exact.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts > 5, "the case must exercise contacts: {impacts} impacts");
    assert!(
        (peak(&exact) - peak(&explicit)).abs() <= 10.0 * DEFAULT_TOLERANCE * peak(&explicit),
        "peak {} N (exact, {} steps) vs {} N (central difference, {} steps)",
        peak(&exact),
        exact.steps,
        peak(&explicit),
        explicit.steps
    );
    assert!(wear(&explicit) > 0.0);
    assert!(
        (wear(&exact) - wear(&explicit)).abs() <= 0.05 * wear(&explicit),
        "wear work {} J (exact) vs {} J (central difference)",
        wear(&exact),
        wear(&explicit)
    );
    assert!(
        exact.energy.relative_residual() < 1e-3,
        "energy balance residual {:e}",
        exact.energy.relative_residual()
    );
    assert!(exact.steps * 4 < explicit.steps);
}

/// Friction is not in the exact scheme's solve: refused at `scheme` with the reason.
#[test]
fn friction_is_refused_at_the_scheme() {
    let basis = basis(20, 4);
    let model = triangle(
        &basis,
        &[1.0],
        Friction {
            coefficient: 0.3,
            tangential_stiffness: 1e5,
        },
    );
    let refused = Plan::new(&model, &settings(Scheme::ExactModal, 1e-4, 0.01)).map(|_| ());
    let Err(SimulationError::InvalidSettings(issues)) = refused else {
        panic!("refused: {refused:?}");
    };
    assert!(
        issues
            .iter()
            .any(|i| i.field == "scheme" && i.reason.contains("friction"))
    );
}

/// The exact scheme at its `auto` step, and central difference at a quarter of its own
/// (converged for the comparisons), over `duration`.
fn exact_and_converged_explicit(model: &Model<'_>, duration: f64) -> (Simulation, Simulation) {
    let auto = |scheme| Settings {
        time_step: TimeStep::Auto,
        ..settings(scheme, 1.0, duration)
    };
    let exact = run(model, &auto(Scheme::ExactModal));
    let explicit_step = step_size::resolve(model, &auto(Scheme::CentralDifference)).unwrap();
    let explicit = run(
        model,
        &settings(Scheme::CentralDifference, explicit_step.time_step / 4.0, duration),
    );
    (exact, explicit)
}

/// The largest contact force of a run (N).
fn peak(simulation: &Simulation) -> f64 {
    simulation
        .contact_statistics
        .iter()
        .map(|c| c.max_force)
        .fold(0.0, f64::max)
}

/// Three pins at the corners of a triangle (0 at the lower left, 1 at the lower right,
/// 2 on top) at `heights`: 0.1 mm gaps, 1e6 N/m, a dashpot of 5 N·s/m, `friction` on
/// every contact; a wall left of pin 0, right of pin 1 and above pin 2; shaken by
/// half-sines of 60 m/s² along x and 40 m/s² along y.
fn triangle<'a>(basis: &'a ModalBasis, heights: &[f64], friction: Friction) -> Model<'a> {
    let (half, high) = (0.5, 3.0_f64.sqrt() / 2.0);
    let sides = [
        (Body::Wall, Body::Pin(0), [1.0, 0.0]),
        (Body::Pin(1), Body::Wall, [1.0, 0.0]),
        (Body::Pin(2), Body::Wall, [0.0, 1.0]),
        (Body::Pin(0), Body::Pin(1), [1.0, 0.0]),
        (Body::Pin(1), Body::Pin(2), [-half, high]),
        (Body::Pin(0), Body::Pin(2), [half, high]),
    ];
    let (mut contacts, mut normals) = (Vec::new(), Vec::new());
    for &height in heights {
        for (left, right, normal) in sides {
            contacts.push(Contact {
                left,
                right,
                height,
                gap: 1e-4,
                stiffness: 1e6,
                damping: 5.0,
                law: Law {
                    friction,
                    ..Law::LINEAR
                },
            });
            normals.push(normal);
        }
    }
    Model {
        basis,
        pins: 3,
        damping_ratios: vec![0.01; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 60.0,
            duration: 0.004,
        }),
        walls: None,
        plane: Some(Plane {
            normals,
            base_acceleration_y: Some(BaseAcceleration::HalfSine {
                amplitude: 40.0,
                duration: 0.006,
            }),
        }),
        point_forces: vec![],
        kinds: Vec::new(),
    }
}

/// The steps and CPU of both schemes at their `auto` step on the three-pin row of
/// [`impacts_match_converged_central_difference_with_far_fewer_steps`] as the basis
/// grows (docs/static-correction.md): `cargo test --release -p chocmodal-physics --lib
/// exact_modal_cost_by_modes -- --ignored --nocapture`.
#[test]
#[ignore]
fn exact_modal_cost_by_modes() {
    let heights = [0.2, 0.4, 0.6, 0.8, 1.0];
    println!("| modes | central difference: peak, steps, s | exact modal: peak, steps, s | exact at h/8 |");
    for modes in [6, 12, 24, 40] {
        let basis = ModalBasis::compute_with_static_correction(&default_tube(60), modes, &heights).unwrap();
        let model = three_pin_model(&basis, &heights);
        let timed = |scheme| {
            let start = std::time::Instant::now();
            let result = run(
                &model,
                &Settings {
                    time_step: TimeStep::Auto,
                    ..settings(scheme, 1.0, 0.03)
                },
            );
            (result, start.elapsed().as_secs_f64())
        };
        let (explicit, t_explicit) = timed(Scheme::CentralDifference);
        let (exact, t_exact) = timed(Scheme::ExactModal);
        let fine = run(
            &model,
            &settings(Scheme::ExactModal, exact.step.time_step / 8.0, 0.03),
        );
        println!(
            "| {modes} + 5 | {:.4} N, {}, {t_explicit:.3} | {:.4} N, {}, {t_exact:.3} | {:.4} N |",
            peak(&explicit),
            explicit.steps,
            peak(&exact),
            exact.steps,
            peak(&fine)
        );
    }
}

/// Three pins between two walls at `heights` (gaps 0.1 mm, 1e6 N/m), shaken by a
/// 60 m/s², 4 ms half-sine.
fn three_pin_model<'a>(basis: &'a ModalBasis, heights: &[f64]) -> Model<'a> {
    let contact = |left, right, height| Contact {
        left,
        right,
        height,
        gap: 1e-4,
        stiffness: 1e6,
        damping: 0.0,
        law: Law::LINEAR,
    };
    let mut contacts = Vec::new();
    for &height in heights {
        contacts.push(contact(Body::Wall, Body::Pin(0), height));
        contacts.push(contact(Body::Pin(0), Body::Pin(1), height));
        contacts.push(contact(Body::Pin(1), Body::Pin(2), height));
        contacts.push(contact(Body::Pin(2), Body::Wall, height));
    }
    Model {
        basis,
        pins: 3,
        damping_ratios: vec![0.01; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 60.0,
            duration: 0.004,
        }),
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    }
}

/// Stiff contacts with dashpots (2e6 N/m, 20 N·s/m, as the shipped 17-pin row): a
/// dashpot makes the law jump by c δ̇ at touch, where a step can end with no solution
/// but a contact held at touch (the solve's touching side). Five pins at three heights
/// rattle through a 50 m/s² shock: the run completes, its energy balance closes, and
/// its peak force is central difference's at a quarter of its `auto` step within the
/// verdict's bound for peaks (10 × the tolerance; measured 0.5 %: the touch makes the
/// error locally first order, and the step check sees it).
#[test]
fn stiff_contacts_with_dashpots_rattle_to_central_differences_peak() {
    let heights = [0.4, 0.7, 1.0];
    let basis = ModalBasis::compute_with_static_correction(&default_tube(30), 8, &heights).unwrap();
    let mut contacts = Vec::new();
    for &height in &heights {
        for pin in 0..=5 {
            let side = |p: usize| {
                if p == 0 || p == 6 {
                    Body::Wall
                } else {
                    Body::Pin(p - 1)
                }
            };
            contacts.push(Contact {
                left: side(pin),
                right: side(pin + 1),
                height,
                gap: 1e-4,
                stiffness: 2e6,
                damping: 20.0,
                law: Law::LINEAR,
            });
        }
    }
    let model = Model {
        basis: &basis,
        pins: 5,
        damping_ratios: vec![0.01; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 50.0,
            duration: 0.005,
        }),
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    };
    let (exact, explicit) = exact_and_converged_explicit(&model, 0.04);
    assert_dissipative_rattling_matches(&exact, &explicit, 10);
}

/// A nonlinear law (Hertz, n = 3/2, with Hunt–Crossley damping, α = 0.5 s/m): the solve
/// finds each contact's force by Newton within its bracket (no closed form). On the
/// three-pin row with the static correction the exact scheme at its `auto` step agrees
/// with central difference converged within the verdict's bound for peaks and closes
/// its energy balance.
#[test]
fn a_hertz_law_with_hunt_crossley_damping_matches_central_difference() {
    let heights = [0.5, 0.8, 1.0];
    let basis = ModalBasis::compute_with_static_correction(&default_tube(30), 8, &heights).unwrap();
    let mut model = three_pin_model(&basis, &heights);
    for contact in &mut model.contacts {
        contact.stiffness = 1e8;
        contact.law = Law {
            exponent: 1.5,
            hunt_crossley: 0.5,
            force_scale: 50.0,
            ..Law::LINEAR
        };
    }
    let (exact, explicit) = exact_and_converged_explicit(&model, 0.03);
    assert_dissipative_rattling_matches(&exact, &explicit, 5);
}

/// The exact run rattles (more than `impacts` impacts), its contacts dissipate, its
/// energy balance closes (residual below 1e-3), and its peak contact force is central
/// difference's within the verdict's bound for peaks (10 × the tolerance).
fn assert_dissipative_rattling_matches(exact: &Simulation, explicit: &Simulation, impacts: u64) {
    let count: u64 = exact.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(count > impacts, "the case must rattle: {count} impacts");
    assert!(exact.energy.dissipated_contact > 0.0);
    assert!(
        exact.energy.relative_residual() < 1e-3,
        "energy balance residual {:e}",
        exact.energy.relative_residual()
    );
    assert!(
        (peak(exact) - peak(explicit)).abs() <= 10.0 * DEFAULT_TOLERANCE * peak(explicit),
        "peak {} N (exact, {} steps) vs {} N (central difference, {} steps)",
        peak(exact),
        exact.steps,
        peak(explicit),
        explicit.steps
    );
}
