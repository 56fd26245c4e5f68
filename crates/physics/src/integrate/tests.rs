//! Physics checks of the explicit integrator: energy conservation and dissipation,
//! analytic contact duration, convergence orders, the critical step against brute
//! force, and the energy balance of a damped, excited multi-contact row.

use std::ops::ControlFlow;

use super::*;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Law};
use crate::loads::{BaseAcceleration, PointForce, Table};
use crate::modal::ModalBasis;
use crate::stability::Scheme;

pub(super) fn basis(elements: usize, modes: usize) -> ModalBasis {
    ModalBasis::compute(&default_tube(elements), modes).expect("valid beam")
}

pub(super) fn free_model(basis: &ModalBasis, xi: f64, tip: f64) -> Model<'_> {
    Model {
        basis,
        pins: 1,
        damping_ratios: vec![xi; basis.modes()],
        contacts: vec![],
        initial_tip_displacements: vec![tip],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    }
}

pub(super) fn settings(scheme: Scheme, dt: f64, duration: f64) -> Settings {
    Settings {
        scheme,
        time_step: TimeStep::Fixed(dt),
        tolerance: DEFAULT_TOLERANCE,
        check: Check::None,
        duration,
        output_interval: None,
        recorded_contacts: None,
        impacts: Default::default(),
        threads: 1,
        output_heights: vec![1.0],
    }
}

/// A step loop of the integrator.
#[derive(Debug, Clone, Copy)]
pub(super) enum Loop {
    /// Pins bending along x, walls moving with the feet.
    Row,
    /// Pins in the transverse plane, on one thread or on two.
    Plane { threads: usize },
    /// The row, with walls of their own motion (standing still in space here).
    Walls,
}

pub(super) const LOOPS: [Loop; 4] = [
    Loop::Row,
    Loop::Plane { threads: 1 },
    Loop::Plane { threads: 2 },
    Loop::Walls,
];

/// The threads `kind` runs on.
pub(super) fn threads(kind: Loop) -> usize {
    match kind {
        Loop::Plane { threads } => threads,
        _ => 1,
    }
}

/// A row `model` run on `kind`: in the plane every contact normal +x and the releases
/// along x (the y lines at rest), or with walls of their own motion.
pub(super) fn on_loop(mut model: Model<'_>, kind: Loop) -> Model<'_> {
    match kind {
        Loop::Row => {}
        Loop::Plane { .. } => {
            model.plane = Some(Plane {
                normals: vec![[1.0, 0.0]; model.contacts.len()],
                base_acceleration_y: None,
            });
            if !model.initial_tip_displacements.is_empty() {
                let pins = model.pins;
                model.initial_tip_displacements.resize(2 * pins, 0.0);
            }
        }
        Loop::Walls => model.walls = Some(WallMotion::rigid(None, None)),
    }
    model
}

pub(super) fn run(model: &Model<'_>, settings: &Settings) -> Simulation {
    simulate(model, settings, &mut |_| ControlFlow::Continue(())).expect("run succeeds")
}

pub(super) fn tip_wall(stiffness: f64, gap: f64, damping: f64) -> Contact {
    Contact {
        left: Body::Wall,
        right: Body::Pin(0),
        height: 1.0,
        gap,
        stiffness,
        damping,
        law: Law::LINEAR,
    }
}

/// Undamped free vibration: central difference conserves a modified energy, so the
/// mechanical energy only oscillates by O((ωΔt)²) around its initial value and never
/// drifts. Tchamwa–Wielgosz (φ > 1) removes energy at every step: the energy decreases
/// monotonically.
#[test]
fn central_difference_conserves_energy_and_tchamwa_dissipates_it() {
    let basis = basis(40, 6);
    let model = free_model(&basis, 0.0, 1e-3);
    let dt = 1e-5;
    let cd = run(&model, &settings(Scheme::CentralDifference, dt, 0.3));
    let initial = cd.mechanical_energy[0];
    let worst = cd
        .mechanical_energy
        .iter()
        .map(|e| (e - initial).abs() / initial)
        .fold(0.0, f64::max);
    let omega_max = basis.angular_frequencies()[5];
    let bound = (omega_max * dt).powi(2);
    assert!(
        worst < bound,
        "CD energy deviation {worst:e} above (ω_max Δt)² = {bound:e}"
    );
    assert!(
        cd.energy.relative_residual() < bound,
        "CD balance residual {:e}",
        cd.energy.relative_residual()
    );

    // A first-order scheme's plain energy wobbles by O(ωΔt) within a period; its
    // envelope (the maximum over each period of the fundamental) must decrease.
    let tw = run(&model, &settings(Scheme::Tchamwa { phi: 1.1 }, dt, 0.3));
    let period_steps = (std::f64::consts::TAU / basis.angular_frequencies()[0] / dt) as usize;
    let envelope: Vec<f64> = tw
        .mechanical_energy
        .chunks(period_steps)
        .map(|c| c.iter().copied().fold(0.0, f64::max))
        .collect();
    assert!(envelope.len() >= 2);
    for pair in envelope.windows(2) {
        assert!(
            pair[1] < pair[0],
            "Tchamwa energy envelope must decrease: {envelope:?}"
        );
    }
    let last = *tw.mechanical_energy.last().unwrap();
    assert!(
        last < 0.999 * initial,
        "Tchamwa should dissipate: {last:e} vs {initial:e}"
    );
}

/// One mode hitting a wall spring with zero gap and no damping: while in contact the
/// modal oscillator has ω_c² = ω₁² + Kc ψ(L)², and with zero gap its equilibrium stays
/// at w = 0, so each contact lasts exactly half a period, π/ω_c.
#[test]
fn single_mode_contact_lasts_half_a_contact_period() {
    let basis = basis(20, 1);
    let stiffness = 50.0;
    let mut model = free_model(&basis, 0.0, 1e-3);
    model.contacts = vec![tip_wall(stiffness, 0.0, 0.0)];
    let psi = basis.deflection_at(1.0)[0];
    let omega_c = (basis.angular_frequencies()[0].powi(2) + stiffness * psi * psi).sqrt();
    let dt = 2e-6;
    // Released at the top of its swing: impact after a quarter free period, then cycles
    // of one contact (π/ω_c) and one flight (π/ω₁). Stop in the middle of the 4th flight.
    let omega = basis.angular_frequencies()[0];
    let pi = std::f64::consts::PI;
    let duration = pi / (2.0 * omega) + 3.0 * (pi / omega + pi / omega_c) + pi / omega_c + pi / (2.0 * omega);
    let result = run(&model, &settings(Scheme::CentralDifference, dt, duration));
    let stats = &result.contact_statistics[0];
    assert_eq!(stats.impacts, 4, "impacts");
    let per_impact = stats.contact_time / stats.impacts as f64;
    let expected = std::f64::consts::PI / omega_c;
    assert!(
        (per_impact - expected).abs() < 2.0 * dt,
        "contact duration {per_impact} s vs π/ω_c = {expected} s"
    );
    // Energy is exchanged with the spring and comes back: no loss without damping.
    assert!(
        result.energy.relative_residual() < 1e-5,
        "balance residual {:e}",
        result.energy.relative_residual()
    );
}

/// Damped free vibration of 3 modes has the closed form
/// qᵢ(t) = e^{−ξωt}(qᵢ₀ cos ω_d t + ξω qᵢ₀/ω_d sin ω_d t): the tip error at a fixed time
/// falls as Δt² for central difference and as Δt for Tchamwa–Wielgosz.
#[test]
fn observed_convergence_orders_are_two_and_one() {
    let basis = basis(20, 3);
    let xi = 0.02;
    let model = free_model(&basis, xi, 1e-3);
    let duration = 0.05;
    let psi = basis.deflection_at(1.0);
    let q0 = basis
        .unit_tip_release()
        .unwrap()
        .iter()
        .map(|u| u * 1e-3)
        .collect::<Vec<_>>();
    let exact_tip = |t: f64| -> f64 {
        (0..3)
            .map(|i| {
                let w = basis.angular_frequencies()[i];
                let wd = w * (1.0 - xi * xi).sqrt();
                psi[i] * (-xi * w * t).exp() * q0[i] * ((wd * t).cos() + xi * w / wd * (wd * t).sin())
            })
            .sum()
    };
    for (scheme, expected_order) in [
        (Scheme::CentralDifference, 2.0),
        (Scheme::Tchamwa { phi: 1.05 }, 1.0),
    ] {
        let error = |dt: f64| {
            let result = run(&model, &settings(scheme, dt, duration));
            let t = *result.time.last().unwrap();
            (result.deflections[0][0].last().unwrap() - exact_tip(t)).abs()
        };
        let (coarse, fine) = (error(4e-5), error(2e-5));
        let order = (coarse / fine).log2();
        assert!(
            (order - expected_order).abs() < 0.25,
            "{scheme:?}: observed order {order} ({coarse:e} → {fine:e})"
        );
    }
}

/// The critical step from the eigenvalues of diag(ω²) + Kc ψψᵀ is the true stability
/// limit: a pin held against a stiff wall spring by a constant tip force stays in
/// contact; 1 % below the critical step the run is bounded, 1 % above it diverges.
#[test]
fn critical_step_matches_brute_force_divergence() {
    let basis = basis(20, 4);
    let mut model = free_model(&basis, 0.0, 0.0);
    model.contacts = vec![tip_wall(1e6, 0.0, 0.0)];
    // Push toward the wall (negative deflection) so the contact stays closed.
    model.point_forces = vec![PointForce {
        line: 0,
        height: 1.0,
        force: Table {
            time: vec![0.0, 10.0],
            values: vec![-1.0, -1.0],
        },
    }];
    let critical = critical_time_step(&model, Scheme::CentralDifference);
    let without_contact = 2.0 / basis.angular_frequencies()[3];
    assert!(
        critical < 0.5 * without_contact,
        "contact must shorten the step: {critical:e} vs {without_contact:e}"
    );
    let mut below = settings(Scheme::CentralDifference, 0.99 * critical, 2000.0 * critical);
    let stable = simulate(&model, &below, &mut |_| ControlFlow::Continue(()));
    assert!(stable.is_ok(), "stable below critical: {:?}", stable.err());
    let above = Plan::unchecked(&model, &below, 1.01 * critical)
        .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
        .map(|assessed| assessed.simulation);
    let Err(diverged @ SimulationError::Diverged { .. }) = above else {
        panic!("diverges above critical: {:?}", above.map(|s| s.energy));
    };
    // The failure names the step, the critical step, and the way out.
    let message = diverged.to_string();
    for expected in [
        format!("{:e}", 1.01 * critical),
        format!("{critical:e}"),
        "\"auto\"".into(),
    ] {
        assert!(message.contains(&expected), "{message} lacks {expected}");
    }
    below.time_step = TimeStep::Fixed(1.01 * critical);
    let refused = simulate(&model, &below, &mut |_| ControlFlow::Continue(()));
    assert!(
        matches!(refused, Err(SimulationError::TimeStepAboveCritical { .. })),
        "{:?}",
        refused.err()
    );
}

/// A damped two-pin row shaken by a half-sine base shock, with wall and pin–pin
/// contacts carrying dashpots at two levels.
pub(super) fn shaken_two_pin_row(basis: &ModalBasis) -> Model<'_> {
    let contact = |left, right, height| Contact {
        left,
        right,
        height,
        gap: 5e-5,
        stiffness: 2e4,
        damping: 2.0,
        law: Law::LINEAR,
    };
    Model {
        basis,
        pins: 2,
        damping_ratios: vec![0.02; basis.modes()],
        contacts: vec![
            contact(Body::Wall, Body::Pin(0), 0.5),
            contact(Body::Pin(0), Body::Pin(1), 0.5),
            contact(Body::Pin(1), Body::Wall, 0.5),
            contact(Body::Wall, Body::Pin(0), 1.0),
            contact(Body::Pin(0), Body::Pin(1), 1.0),
            contact(Body::Pin(1), Body::Wall, 1.0),
        ],
        initial_tip_displacements: vec![2e-4, -1e-4],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 20.0,
            duration: 0.01,
        }),
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    }
}

/// Energy balance on the shaken two-pin row: kinetic + strain + contact + dissipated
/// − base work stays equal to the initial energy to within a small fraction.
#[test]
fn energy_balance_closes_on_a_damped_excited_multi_contact_row() {
    let basis = basis(20, 8);
    let model = shaken_two_pin_row(&basis);
    let result = run(
        &model,
        &Settings {
            output_interval: Some(1e-4),
            ..settings(Scheme::CentralDifference, 2e-6, 0.1)
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

/// The step lays contacts out by SIMD lanes (one lane per level on the scalar fallback,
/// four levels per vector with AVX2) and unrolls rows of up to 8 vectors: the same run
/// on this CPU's SIMD level and on the scalar fallback agrees to rounding, with both
/// schemes, a point force, contacts in no regular order, and rows short enough to be
/// unrolled (7 modes) or not (37 modes).
#[test]
fn this_cpus_simd_level_and_the_scalar_fallback_agree() {
    for (elements, modes, duration) in [(20, 7, 0.02), (24, 37, 0.005)] {
        let basis = basis(elements, modes);
        let mut model = shaken_two_pin_row(&basis);
        // Six levels: two blocks of levels with AVX2, every lane used.
        model.contacts.reverse();
        for (left, right, height, damping) in [
            (Body::Pin(1), Body::Wall, 0.8, 0.0),
            (Body::Wall, Body::Pin(0), 0.3, 1.0),
            (Body::Pin(0), Body::Pin(1), 0.65, 2.0),
            (Body::Pin(1), Body::Wall, 0.2, 0.5),
        ] {
            model.contacts.push(Contact {
                left,
                right,
                height,
                gap: 2e-5,
                stiffness: 3e4,
                damping,
                law: Law::LINEAR,
            });
        }
        model.point_forces.push(PointForce {
            line: 1,
            height: 0.9,
            force: Table {
                time: vec![0.0, 0.005, 1.0],
                values: vec![0.0, 2.0, 2.0],
            },
        });
        for scheme in [Scheme::CentralDifference, Scheme::Tchamwa { phi: 1.1 }] {
            let settings = Settings {
                time_step: TimeStep::Auto,
                output_interval: Some(1e-4),
                ..settings(scheme, 0.0, duration)
            };
            let plan = Plan::new(&model, &settings).expect("a valid model");
            let on = |arch| plan.run_on(arch, &mut |_| ControlFlow::Continue(()));
            let scalar = on(pulp::Arch::Scalar).expect("scalar run").simulation;
            let simd = on(pulp::Arch::new()).expect("SIMD run").simulation;
            let impacts: u64 = scalar.contact_statistics.iter().map(|s| s.impacts).sum();
            assert!(impacts > 2, "the case must exercise contacts: {impacts} impacts");
            let agree = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale;
            for (s, v) in scalar.contact_statistics.iter().zip(&simd.contact_statistics) {
                assert_eq!(s.impacts, v.impacts, "{modes} modes, {scheme:?}");
                assert!(
                    agree(s.max_force, v.max_force, 1.0 + s.max_force),
                    "{s:?} vs {v:?}"
                );
                assert!(agree(s.impulse, v.impulse, 1e-3 + s.impulse), "{s:?} vs {v:?}");
                assert!(
                    agree(s.max_penetration, v.max_penetration, 1e-4),
                    "{s:?} vs {v:?}"
                );
            }
            for (s, v) in scalar.contact_forces.iter().zip(&simd.contact_forces) {
                let peak = s.iter().fold(1.0f64, |m, f| m.max(f.abs()));
                assert!(
                    s.iter().zip(v).all(|(a, b)| agree(*a, *b, peak)),
                    "{modes} modes, {scheme:?}"
                );
            }
            for (s, v) in scalar.pin_extremes.iter().zip(&simd.pin_extremes) {
                assert!(agree(s.max_abs_deflection, v.max_abs_deflection, 1e-4) && s.height == v.height);
            }
            let scale = scalar.energy.initial + scalar.energy.external_work.abs();
            assert!(agree(
                scalar.energy.dissipated_contact,
                simd.energy.dissipated_contact,
                scale
            ));
            assert!(agree(scalar.energy.kinetic, simd.energy.kinetic, scale));
        }
    }
}

/// Cancellation stops the run promptly with a typed error.
#[test]
fn progress_callback_can_cancel() {
    let basis = basis(10, 3);
    let model = free_model(&basis, 0.01, 1e-3);
    let mut calls = 0;
    let result = simulate(
        &model,
        &settings(Scheme::CentralDifference, 1e-5, 10.0),
        &mut |_| {
            calls += 1;
            if calls == 2 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    assert_eq!(result, Err(SimulationError::Cancelled));
}

/// A pin thrown from straight in its tip-load shape with tip velocity V (no contact, no
/// damping) moves in each mode as qᵢ(t) = uᵢ V sin(ωᵢ t) / ωᵢ (unit modal masses, uᵢ the
/// unit tip release's coordinates): its initial energy is all kinetic, ½ V² Σ uᵢ², and
/// the deflection history at 1 m converges to Σ φᵢ(1) uᵢ V sin(ωᵢ t) / ωᵢ at second order
/// in Δt (central difference).
#[test]
fn a_pin_thrown_in_its_tip_load_shape_moves_in_every_mode_as_a_sine() {
    let basis = basis(40, 6);
    let speed = 0.05;
    let mut model = free_model(&basis, 0.0, 0.0);
    model.initial_tip_displacements = vec![];
    model.initial_tip_velocities = vec![speed];
    let unit = basis.unit_tip_release().expect("a free top");
    let omega = basis.angular_frequencies();
    let phi = basis.deflection_at(1.0);
    let exact = |t: f64| -> f64 {
        (0..basis.modes())
            .map(|i| phi[i] * unit[i] * speed * (omega[i] * t).sin() / omega[i])
            .sum()
    };
    let kinetic = 0.5 * speed * speed * unit.iter().map(|u| u * u).sum::<f64>();
    let worst_error = |dt: f64| {
        let run = run(&model, &settings(Scheme::CentralDifference, dt, 0.02));
        assert_close_rel("initial energy", run.energy.initial, kinetic, 1e-12);
        let deflections = &run.deflections[0][0];
        assert_eq!(deflections[0], 0.0, "thrown from straight");
        let scale = deflections.iter().fold(0.0_f64, |m, w| m.max(w.abs()));
        assert!(scale > 0.0);
        (run.time.iter().zip(deflections))
            .map(|(t, w)| (w - exact(*t)).abs())
            .fold(0.0, f64::max)
            / scale
    };
    let (coarse, fine) = (worst_error(4e-6), worst_error(2e-6));
    assert!(coarse < 1e-3, "error {coarse:e} of the peak at Δt = 4 µs");
    let order = (coarse / fine).log2();
    assert!(
        (1.8..2.2).contains(&order),
        "order {order} ({coarse:e} → {fine:e})"
    );
}

#[track_caller]
fn assert_close_rel(what: &str, measured: f64, expected: f64, tolerance: f64) {
    assert!(
        (measured - expected).abs() <= tolerance * expected.abs(),
        "{what}: {measured:e} against {expected:e}"
    );
}
