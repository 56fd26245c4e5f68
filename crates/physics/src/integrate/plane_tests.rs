//! Physics checks of the plane (pins bending along x and y, contact normals in the
//! transverse plane).
//!
//! The plane is the row turned: a row whose every contact normal and excitation is
//! rotated by θ moves along the rotated direction only, with the row's forces and the
//! row's deflections along it; a normal at θ = 0 is the row itself. Beyond the row, the
//! contact force acts on both pins equal and opposite along the normal (Newton's third
//! law: the sum of two pins' deflections ignores a contact between them), the energy
//! balance closes with oblique normals, dashpots and an excitation along x and y, and
//! the wear work ∫ F |v_t| dt matches the one computed from the step-by-step force and
//! deflection histories.

use std::f64::consts::PI;
use std::ops::ControlFlow;

use super::*;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Law};
use crate::loads::BaseAcceleration;
use crate::modal::ModalBasis;
use crate::stability::Scheme;

fn basis(modes: usize) -> ModalBasis {
    ModalBasis::compute(&default_tube(20), modes).expect("valid beam")
}

/// A damped two-pin row between walls shaken along x by a half-sine of `amplitude`:
/// wall–p0, p0–p1 and p1–wall contacts at three heights, with different gaps.
fn shaken_row(basis: &ModalBasis, amplitude: f64) -> Model<'_> {
    let mut contacts = Vec::new();
    for (height, gap) in [(0.5, 4e-5), (0.8, 6e-5), (1.0, 5e-5)] {
        for (k, (left, right)) in [
            (Body::Wall, Body::Pin(0)),
            (Body::Pin(0), Body::Pin(1)),
            (Body::Pin(1), Body::Wall),
        ]
        .into_iter()
        .enumerate()
        {
            contacts.push(Contact {
                left,
                right,
                height,
                gap: gap * (1.0 + 0.3 * k as f64),
                stiffness: 2e4,
                damping: 2.0,
                law: Law::LINEAR,
            });
        }
    }
    Model {
        basis,
        pins: 2,
        damping_ratios: vec![0.02; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude,
            duration: 0.01,
        }),
        point_forces: vec![],
        walls: None,
        plane: None,
        kinds: Vec::new(),
    }
}

/// The same row in the plane with every normal and the excitation turned by θ.
fn turned_row<'a>(basis: &'a ModalBasis, amplitude: f64, theta: f64) -> Model<'a> {
    let mut model = shaken_row(basis, amplitude * theta.cos());
    model.plane = Some(Plane {
        normals: vec![[theta.cos(), theta.sin()]; model.contacts.len()],
        base_acceleration_y: Some(BaseAcceleration::HalfSine {
            amplitude: amplitude * theta.sin(),
            duration: 0.01,
        }),
    });
    model
}

pub(super) fn settings(dt: f64, duration: f64) -> Settings {
    Settings {
        scheme: Scheme::CentralDifference,
        time_step: TimeStep::Fixed(dt),
        tolerance: DEFAULT_TOLERANCE,
        check: Check::None,
        duration,
        output_interval: Some(1e-4),
        output_heights: vec![1.0, 0.8],
        recorded_contacts: None,
        impacts: Default::default(),
        threads: 1,
    }
}

pub(super) fn run(model: &Model<'_>, settings: &Settings) -> Simulation {
    simulate(model, settings, &mut |_| ControlFlow::Continue(())).expect("run succeeds")
}

/// |a − b| ≤ tolerance × scale, with a message that prints both.
#[track_caller]
pub(super) fn assert_close(what: &str, measured: f64, expected: f64, tolerance: f64, scale: f64) {
    assert!(
        (measured - expected).abs() <= tolerance * scale,
        "{what}: measured {measured:e}, expected {expected:e} (tolerance {tolerance:e} × {scale:e})"
    );
}

/// The largest |value| of a set of histories.
fn peak<'a>(histories: impl IntoIterator<Item = &'a Vec<f64>>) -> f64 {
    histories.into_iter().flatten().fold(0.0, |m, x| m.max(x.abs()))
}

/// A row turned by θ is the row: the same forces, impacts, impulses and energies, the
/// row's deflections along the normal and none across it, and no wear (the contacts
/// never slide). θ = 2 turns the row past the y axis (both components change sign
/// relative to θ = 0.3).
#[test]
fn a_turned_row_moves_along_its_normal_with_the_rows_forces() {
    let basis = basis(6);
    let amplitude = 20.0;
    let settings = settings(2e-6, 0.04);
    let row = run(&shaken_row(&basis, amplitude), &settings);
    let impacts: u64 = row.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts > 10, "the case must exercise contacts: {impacts} impacts");
    let peak_force = peak(&row.contact_forces);
    let peak_deflection = row.deflections.iter().map(peak).fold(0.0, f64::max);
    let peak_impulse = row
        .contact_statistics
        .iter()
        .map(|s| s.impulse)
        .fold(0.0, f64::max);
    let energy_scale = row.energy.external_work.abs() + row.energy.initial;
    for theta in [0.3, PI / 3.0, 2.0] {
        let plane = run(&turned_row(&basis, amplitude, theta), &settings);
        let (cos, sin) = (theta.cos(), theta.sin());
        assert_eq!(plane.contact_forces.len(), row.contact_forces.len());
        for (c, (expected, measured)) in row.contact_forces.iter().zip(&plane.contact_forces).enumerate() {
            for (k, (e, m)) in expected.iter().zip(measured).enumerate() {
                assert_close(
                    &format!("θ {theta}: force of contact {c} at sample {k}"),
                    *m,
                    *e,
                    1e-9,
                    peak_force,
                );
            }
        }
        for (c, (e, m)) in row
            .contact_statistics
            .iter()
            .zip(&plane.contact_statistics)
            .enumerate()
        {
            let what = |field: &str| format!("θ {theta}: {field} of contact {c}");
            assert_eq!(m.impacts, e.impacts, "{}", what("impacts"));
            assert_close(&what("max force"), m.max_force, e.max_force, 1e-9, peak_force);
            assert_close(&what("impulse"), m.impulse, e.impulse, 1e-9, peak_impulse);
            assert_close(
                &what("contact time"),
                m.contact_time,
                e.contact_time,
                1e-9,
                settings.duration,
            );
            assert_close(
                &what("max penetration"),
                m.max_penetration,
                e.max_penetration,
                1e-9,
                peak_deflection,
            );
        }
        // Line p is pin p along x, line 2 + p along y.
        for (h, (expected, measured)) in row.deflections.iter().zip(&plane.deflections).enumerate() {
            assert_eq!(measured.len(), 4, "two lines per pin");
            for p in 0..2 {
                for (k, w) in expected[p].iter().enumerate() {
                    let (x, y) = (measured[p][k], measured[2 + p][k]);
                    let what = format!("θ {theta}: pin {p} at height {h}, sample {k}");
                    assert_close(
                        &format!("{what}, along n"),
                        cos * x + sin * y,
                        *w,
                        1e-9,
                        peak_deflection,
                    );
                    assert_close(
                        &format!("{what}, across n"),
                        -sin * x + cos * y,
                        0.0,
                        1e-9,
                        peak_deflection,
                    );
                }
            }
        }
        for (what, m, e) in [
            (
                "external work",
                plane.energy.external_work,
                row.energy.external_work,
            ),
            ("kinetic energy", plane.energy.kinetic, row.energy.kinetic),
            ("strain energy", plane.energy.strain, row.energy.strain),
            (
                "contact dissipation",
                plane.energy.dissipated_contact,
                row.energy.dissipated_contact,
            ),
            (
                "modal dissipation",
                plane.energy.dissipated_modal,
                row.energy.dissipated_modal,
            ),
        ] {
            assert_close(&format!("θ {theta}: {what}"), m, e, 1e-9, energy_scale);
        }
        // Sliding the peak force over the peak deflection would wear this much.
        let sliding_scale = peak_force * peak_deflection;
        for (c, wear) in plane.wear_work.iter().enumerate() {
            assert_close(
                &format!("θ {theta}: wear of contact {c}"),
                *wear,
                0.0,
                1e-9,
                sliding_scale,
            );
        }
    }
}

/// A normal at θ = 0 is +x: the plane's x lines are the row and its y lines stay at
/// exactly zero, bit for bit (multiplying by 1 and adding 0 are exact).
#[test]
fn the_plane_with_normals_along_x_is_the_row_bit_for_bit() {
    let basis = basis(6);
    let settings = settings(2e-6, 0.03);
    let row = run(&shaken_row(&basis, 20.0), &settings);
    let plane = run(&turned_row(&basis, 20.0, 0.0), &settings);
    assert_eq!(plane.contact_forces, row.contact_forces);
    assert_eq!(plane.contact_force_peaks, row.contact_force_peaks);
    assert_eq!(plane.contact_statistics, row.contact_statistics);
    assert_eq!(plane.energy, row.energy);
    assert_eq!(plane.mechanical_energy, row.mechanical_energy);
    for (h, (x, lines)) in row.deflections.iter().zip(&plane.deflections).enumerate() {
        assert_eq!(lines[..2], x[..], "x lines at height {h}");
        assert!(
            lines[2..].iter().flatten().all(|w| *w == 0.0),
            "y lines at height {h}"
        );
        assert_eq!(plane.peak_deflections[h][..2], row.peak_deflections[h][..]);
    }
    assert_eq!(plane.pin_extremes[..2], row.pin_extremes[..]);
    assert!(
        plane.pin_extremes[2..]
            .iter()
            .all(|e| e.max_abs_deflection == 0.0)
    );
    assert!(row.wear_work.is_empty(), "the row has no wear");
    assert_eq!(plane.wear_work, vec![0.0; row.contact_statistics.len()]);
}

/// Three pins in a triangle (p0 at (0, 0), p1 at (1, 0), p2 at (½, √3/2), in pitches),
/// each touching its two neighbours and two wall stops, at two heights: every normal
/// oblique but two, dashpots, an initial release along x, a half-sine shock along x and
/// a sine along y.
fn triangle(basis: &ModalBasis) -> Model<'_> {
    let s3 = 3f64.sqrt() / 2.0;
    let pairs: [(Body, Body, [f64; 2]); 9] = [
        (Body::Pin(0), Body::Pin(1), [1.0, 0.0]),
        (Body::Pin(0), Body::Pin(2), [0.5, s3]),
        (Body::Pin(1), Body::Pin(2), [-0.5, s3]),
        (Body::Pin(0), Body::Wall, [-1.0, 0.0]),
        (Body::Pin(0), Body::Wall, [-0.5, -s3]),
        (Body::Pin(1), Body::Wall, [1.0, 0.0]),
        (Body::Wall, Body::Pin(1), [-0.5, s3]),
        (Body::Pin(2), Body::Wall, [0.0, 1.0]),
        (Body::Wall, Body::Pin(2), [0.6, -0.8]),
    ];
    let (mut contacts, mut normals) = (Vec::new(), Vec::new());
    for (level, height) in [0.6, 1.0].into_iter().enumerate() {
        for (k, (left, right, normal)) in pairs.iter().enumerate() {
            contacts.push(Contact {
                left: *left,
                right: *right,
                height,
                gap: 2e-5 * (1.0 + 0.2 * ((k + level) % 3) as f64),
                stiffness: 3e4,
                damping: 1.5,
                law: Law::LINEAR,
            });
            normals.push(*normal);
        }
    }
    Model {
        basis,
        pins: 3,
        damping_ratios: vec![0.02; basis.modes()],
        contacts,
        // Along x (lines 0..3); the y lines 3..6 start straight.
        initial_tip_displacements: vec![2e-4, 0.0, -1e-4, 0.0, 0.0, 0.0],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 15.0,
            duration: 0.01,
        }),
        point_forces: vec![],
        walls: None,
        plane: Some(Plane {
            normals,
            base_acceleration_y: Some(BaseAcceleration::Sine {
                amplitude: 10.0,
                frequency: 30.0,
                cycles: 2.0,
            }),
        }),
        kinds: Vec::new(),
    }
}

/// Energy balance in the plane: kinetic + strain + contact + dissipated − work of both
/// excitation components stays equal to the initial energy, as on the row; the
/// step-halving check and the verdict run on the plane too.
#[test]
fn energy_balance_closes_in_the_plane_with_oblique_normals() {
    let basis = basis(8);
    let model = triangle(&basis);
    let result = run(&model, &settings(2e-6, 0.1));
    let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts > 10, "the case must exercise contacts: {impacts} impacts");
    assert!(result.energy.dissipated_contact > 0.0 && result.energy.dissipated_modal > 0.0);
    let across = result.deflections[0][3..]
        .iter()
        .map(|w| peak([w]))
        .fold(0.0, f64::max);
    assert!(across > 1e-5, "the pins move along y: {across:e} m");
    assert!(
        result.wear_work.iter().any(|w| *w > 0.0),
        "oblique contacts slide"
    );
    let residual = result.energy.relative_residual();
    assert!(
        residual < 1e-3,
        "energy balance residual {residual:e}: {:?}",
        result.energy
    );

    let checked = Settings {
        time_step: TimeStep::Auto,
        check: Check::StepHalving,
        ..settings(0.0, 0.05)
    };
    let assessed = Plan::new(&model, &checked)
        .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
        .expect("runs");
    let quality = &assessed.quality;
    let halving = quality.step_halving.as_ref().expect("the check ran");
    assert!(
        quality.energy_residual < DEFAULT_TOLERANCE && halving.estimated_peak_force_error < 0.1,
        "{quality:?}"
    );
}

/// Newton's third law: a contact between two pins pushes them equal and opposite along
/// its normal, so the sum of their displacements (x and y) obeys the free, unloaded pin
/// equation. Released from opposite shapes, the sum stays zero while each pin is thrown
/// sideways (along y) by the oblique contacts.
#[test]
fn a_contact_between_two_pins_exchanges_equal_and_opposite_impulses() {
    let basis = basis(6);
    let normal = [0.6f64.cos(), 0.6f64.sin()];
    let contact = |height, gap| Contact {
        left: Body::Pin(0),
        right: Body::Pin(1),
        height,
        gap,
        stiffness: 5e4,
        damping: 3.0,
        law: Law::LINEAR,
    };
    let model = Model {
        basis: &basis,
        pins: 2,
        damping_ratios: vec![0.01; basis.modes()],
        contacts: vec![contact(1.0, 2e-5), contact(0.7, 1e-5)],
        initial_tip_displacements: vec![-3e-4, 3e-4, 0.0, 0.0],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        point_forces: vec![],
        walls: None,
        plane: Some(Plane {
            normals: vec![normal, [normal[1], normal[0]]],
            base_acceleration_y: None,
        }),
        kinds: Vec::new(),
    };
    let result = run(&model, &settings(2e-6, 0.05));
    let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts >= 2, "the pins must collide: {impacts} impacts");
    for (h, lines) in result.deflections.iter().enumerate() {
        let scale = peak(lines);
        let across = peak([&lines[2], &lines[3]]);
        assert!(
            across > 0.05 * scale,
            "height {h}: the contacts throw the pins along y: {across:e} m"
        );
        for (axis, (first, second)) in [("x", (0, 1)), ("y", (2, 3))] {
            for (k, (a, b)) in lines[first].iter().zip(&lines[second]).enumerate() {
                assert_close(
                    &format!("height {h}, sum along {axis} at sample {k}"),
                    a + b,
                    0.0,
                    1e-12,
                    scale,
                );
            }
        }
    }
}

/// The wear work is ∫ F |v_t| dt with v_t = t·(u̇_L − u̇_R), t = (−n_y, n_x), at the
/// contact: recomputed from the force and deflection histories recorded at every step
/// (sliding speed by central differences), it agrees to O((ωΔt)²).
#[test]
fn wear_work_is_the_integral_of_force_times_sliding_speed() {
    let basis = basis(8);
    let model = triangle(&basis);
    let dt = 2e-6;
    let settings = Settings {
        output_interval: None,
        output_heights: vec![1.0, 0.6],
        ..settings(dt, 0.03)
    };
    let result = run(&model, &settings);
    let normals = &model.plane.as_ref().expect("a plane model").normals;
    let pins = model.pins;
    let mut worn = 0;
    for (c, contact) in model.contacts.iter().enumerate() {
        let lines = &result.deflections[if contact.height == 1.0 { 0 } else { 1 }];
        // Displacement of a body along x (axis 0) or y (axis 1) at sample k.
        let u = |body: Body, axis: usize, k: usize| match body {
            Body::Wall => 0.0,
            Body::Pin(p) => lines[axis * pins + p][k],
        };
        let [nx, ny] = normals[c];
        let slide = |k: usize| {
            let relative = |axis| u(contact.left, axis, k) - u(contact.right, axis, k);
            -ny * relative(0) + nx * relative(1)
        };
        let forces = &result.contact_forces[c];
        let expected: f64 = (1..forces.len() - 1)
            .map(|k| forces[k] * ((slide(k + 1) - slide(k - 1)) / (2.0 * dt)).abs() * dt)
            .sum();
        worn += usize::from(expected > 0.0);
        assert_close(
            &format!("wear of contact {c}"),
            result.wear_work[c],
            expected,
            2e-3,
            expected,
        );
    }
    assert!(
        worn > 10,
        "most contacts slide: {worn} of {}",
        model.contacts.len()
    );
}

/// The plane's normals (one per contact, finite, unit length to 1e-9), its y
/// excitation and the recorded contacts (existing, each once) are checked before the
/// run, each problem named by its slash path.
#[test]
fn bad_normals_and_recorded_contacts_are_refused_with_their_paths() {
    let basis = basis(4);
    let fields = |issues: Vec<crate::InputIssue>| issues.into_iter().map(|i| i.field).collect::<Vec<_>>();
    let mut model = triangle(&basis);
    assert_eq!(model.validate(), vec![]);
    let plane = model.plane.as_mut().expect("a plane model");
    plane.normals[2] = [1.0 + 0.5 * NORMAL_LENGTH_TOLERANCE, 0.0];
    plane.normals[3] = [0.6, 0.81];
    plane.normals[5] = [f64::NAN, 0.0];
    plane.normals[7] = [0.0, 0.0];
    plane.base_acceleration_y = Some(BaseAcceleration::HalfSine {
        amplitude: 1.0,
        duration: -1.0,
    });
    assert_eq!(
        fields(model.validate()),
        [
            "plane/normals/3",
            "plane/normals/5",
            "plane/normals/7",
            "plane/base_acceleration_y/duration"
        ]
    );
    let mut model = triangle(&basis);
    model.plane.as_mut().expect("a plane model").normals.pop();
    let settings = settings(1e-6, 0.01);
    let Err(SimulationError::InvalidModel(issues)) = Plan::new(&model, &settings) else {
        panic!("a normal short must be refused");
    };
    assert_eq!(fields(issues), ["plane/normals"]);

    let model = triangle(&basis);
    let settings = Settings {
        recorded_contacts: Some(vec![0, 18, 3, 0]),
        impacts: Default::default(),
        ..settings
    };
    let Err(SimulationError::InvalidSettings(issues)) = Plan::new(&model, &settings) else {
        panic!("contact 18 of 18 must be refused");
    };
    assert_eq!(fields(issues), ["recorded_contacts/1", "recorded_contacts/3"]);
}

/// The same plane run twice gives the same results bit for bit, and the scalar
/// fallback (one level per lane, every contact its own group) agrees with this CPU's
/// SIMD level (four levels per lane with AVX2, the wall pairs in separate groups) to
/// rounding.
#[test]
fn plane_runs_are_deterministic_and_agree_on_every_simd_level() {
    let basis = basis(7);
    let model = triangle(&basis);
    let settings = Settings {
        time_step: TimeStep::Auto,
        ..settings(0.0, 0.03)
    };
    let plan = Plan::new(&model, &settings).expect("a valid model");
    let on = |arch| {
        plan.run_on(arch, &mut |_| ControlFlow::Continue(()))
            .expect("runs")
            .simulation
    };
    let (first, second) = (on(pulp::Arch::new()), on(pulp::Arch::new()));
    assert_eq!(first, second);
    let scalar = on(pulp::Arch::Scalar);
    let peak_force = peak(&first.contact_forces);
    for (c, (s, v)) in scalar
        .contact_forces
        .iter()
        .zip(&first.contact_forces)
        .enumerate()
    {
        for (k, (a, b)) in s.iter().zip(v).enumerate() {
            assert_close(
                &format!("force of contact {c} at sample {k}"),
                *b,
                *a,
                1e-9,
                peak_force,
            );
        }
    }
    for (c, (s, v)) in scalar
        .contact_statistics
        .iter()
        .zip(&first.contact_statistics)
        .enumerate()
    {
        assert_eq!(s.impacts, v.impacts, "impacts of contact {c}");
        assert_close(
            &format!("impulse of contact {c}"),
            v.impulse,
            s.impulse,
            1e-9,
            1e-3 + s.impulse,
        );
    }
    for (c, (s, v)) in scalar.wear_work.iter().zip(&first.wear_work).enumerate() {
        assert_close(&format!("wear of contact {c}"), *v, *s, 1e-9, 1e-6 + s);
    }
}

/// Only the recorded contacts have histories, in the order asked, identical to the ones
/// of a run that records every contact; statistics and wear cover every contact.
#[test]
fn only_the_recorded_contacts_have_histories_in_their_order() {
    let basis = basis(6);
    let model = triangle(&basis);
    let every = settings(2e-6, 0.02);
    let recorded = vec![7, 0, 12];
    let some = Settings {
        recorded_contacts: Some(recorded.clone()),
        impacts: Default::default(),
        ..every.clone()
    };
    let (all, thinned) = (run(&model, &every), run(&model, &some));
    assert_eq!(thinned.contact_forces.len(), recorded.len());
    for (k, c) in recorded.iter().enumerate() {
        assert_eq!(thinned.contact_forces[k], all.contact_forces[*c], "contact {c}");
        assert_eq!(
            thinned.contact_force_peaks[k], all.contact_force_peaks[*c],
            "contact {c}"
        );
    }
    assert!(peak(&thinned.contact_forces) > 0.0, "the recorded contacts close");
    assert_eq!(thinned.contact_statistics, all.contact_statistics);
    assert_eq!(thinned.wear_work, all.wear_work);
    assert_eq!(thinned.deflections, all.deflections);
}

/// The plane's critical step is the true stability limit, as on the row: a pin held by
/// a constant force along x against a stiff wall spring whose normal is oblique stays
/// in contact; 1 % below the critical step the run is bounded, 1 % above it diverges.
#[test]
fn the_planes_critical_step_matches_brute_force_divergence() {
    let basis = basis(4);
    let model = Model {
        basis: &basis,
        pins: 1,
        damping_ratios: vec![0.0; basis.modes()],
        contacts: vec![Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: 1.0,
            gap: 0.0,
            stiffness: 1e6,
            damping: 0.0,
            law: Law::LINEAR,
        }],
        initial_tip_displacements: vec![0.0, 0.0],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        // Toward the wall: δ = n·(0 − u) = −0.6 u_x − 0.8 u_y > 0 for u_x < 0.
        point_forces: vec![crate::loads::PointForce {
            line: 0,
            height: 1.0,
            force: crate::loads::Table {
                time: vec![0.0, 10.0],
                values: vec![-1.0, -1.0],
            },
        }],
        walls: None,
        plane: Some(Plane {
            normals: vec![[0.6, 0.8]],
            base_acceleration_y: None,
        }),
        kinds: Vec::new(),
    };
    let critical = critical_time_step(&model, Scheme::CentralDifference);
    let row = Model {
        walls: None,
        plane: None,
        ..model.clone()
    };
    assert_close(
        "critical step, one contact: the plane's is the row's",
        critical,
        critical_time_step(&row, Scheme::CentralDifference),
        1e-9,
        critical,
    );
    let below = settings(0.99 * critical, 2000.0 * critical);
    let stable = simulate(&model, &below, &mut |_| ControlFlow::Continue(()));
    assert!(stable.is_ok(), "stable below critical: {:?}", stable.err());
    let contact_time = stable.expect("checked").contact_statistics[0].contact_time;
    assert!(
        contact_time > 1000.0 * critical,
        "the contact stays closed: {contact_time:e} s"
    );
    let above = Plan::unchecked(&model, &below, 1.01 * critical)
        .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())));
    assert!(
        matches!(above, Err(SimulationError::Diverged { .. })),
        "diverges above critical: {:?}",
        above.map(|a| a.simulation.energy)
    );
}

/// A synthetic bundle the size of the 217-pin hexagonal one: pins on a hexagonal
/// lattice of 8 rings, 120 levels, at each level about half the neighbour pairs along
/// one of the three lattice directions and the outer pins against the wrapper
/// (about 14 000 contacts), 20 modes, released apart and shaken along x and y. Prints its lane packing
/// and steps per second: `cargo test -p chocmodal-physics --lib
/// large_plane_speed -- --ignored --nocapture`.
#[test]
#[ignore = "a timing, not a check"]
fn large_plane_speed() {
    let basis = ModalBasis::compute(&default_tube(40), 20).expect("valid beam");
    let rings = 8i64;
    let mut pins = Vec::new();
    for q in -rings..=rings {
        for r in (-rings).max(-q - rings)..=rings.min(-q + rings) {
            pins.push((q, r));
        }
    }
    let index = |at: (i64, i64)| pins.iter().position(|p| *p == at);
    let s3 = 3f64.sqrt() / 2.0;
    let directions = [((1, 0), [1.0, 0.0]), ((0, 1), [0.5, s3]), ((-1, 1), [-0.5, s3])];
    let (mut contacts, mut normals) = (Vec::new(), Vec::new());
    let levels = 120;
    for level in 0..levels {
        let height = 0.1 + 0.85 * level as f64 / levels as f64;
        let ((dq, dr), normal) = directions[level % 3];
        for (p, &(q, r)) in pins.iter().enumerate() {
            let (left, right) = match index((q + dq, r + dr)) {
                Some(neighbour) if (p + level / 3) % 2 == 0 => (Body::Pin(p), Body::Pin(neighbour)),
                None => (Body::Pin(p), Body::Wall),
                Some(_) => continue,
            };
            contacts.push(Contact {
                left,
                right,
                height,
                gap: 1e-5 * (1.0 + (p % 7) as f64 / 7.0),
                stiffness: 1e6,
                damping: 10.0,
                law: Law::LINEAR,
            });
            normals.push(normal);
        }
    }
    let count = contacts.len();
    let model = Model {
        basis: &basis,
        pins: pins.len(),
        damping_ratios: vec![0.01; basis.modes()],
        contacts,
        // Neighbours released apart (along x: lines 0..pins), so that pairs collide.
        initial_tip_displacements: (0..2 * pins.len())
            .map(|line| match line {
                line if line >= pins.len() => 0.0,
                line if line % 2 == 0 => 2e-4,
                _ => -2e-4,
            })
            .collect(),
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 30.0,
            duration: 0.005,
        }),
        point_forces: vec![],
        walls: None,
        plane: Some(Plane {
            normals,
            base_acceleration_y: Some(BaseAcceleration::HalfSine {
                amplitude: -20.0,
                duration: 0.005,
            }),
        }),
        kinds: Vec::new(),
    };
    let settings = Settings {
        time_step: TimeStep::Auto,
        output_interval: Some(1e-3),
        recorded_contacts: Some(vec![0, 1, 2]),
        impacts: Default::default(),
        ..settings(0.0, 0.015)
    };
    let plan = Plan::new(&model, &settings).expect("a valid model");
    let layout = super::layout::Layout::new(pulp::Arch::new(), &model, &settings, plan.step());
    let groups = layout.contacts.left.len();
    println!(
        "{} pins, {count} contacts in {groups} groups of {} lanes ({:.0} % of lanes used)",
        model.pins,
        layout.lanes,
        100.0 * count as f64 / (groups * layout.lanes) as f64
    );
    let start = std::time::Instant::now();
    let result = plan
        .run(&mut |_| ControlFlow::Continue(()))
        .expect("runs")
        .simulation;
    let seconds = start.elapsed().as_secs_f64();
    let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
    println!(
        "{} steps in {seconds:.2} s: {:.0} steps/s ({:.1} µs/step), {impacts} impacts, energy residual {:.1e}",
        result.steps,
        result.steps as f64 / seconds,
        1e6 * seconds / result.steps as f64,
        result.energy.relative_residual()
    );
}

/// One pin in the hexagonal wrapper, a wall contact on every flat at three heights, all
/// with one gap: the wrapper is 6-fold symmetric, so the shake at θ + 60° gives the
/// response at θ turned by 60°: the contact on flat j + 1 carries what flat j carried,
/// and the deflection (x, y) is turned by 60° at every sample.
#[test]
fn one_pin_in_the_wrapper_shaken_sixty_degrees_further_gives_the_turned_response() {
    let basis = basis(6);
    let geometry = crate::hex::single_pin_in_wrapper(&[0.5, 0.8, 1.0], 5e-5);
    let shaken = |theta: f64| Model {
        basis: &basis,
        pins: 1,
        damping_ratios: vec![0.02; basis.modes()],
        contacts: geometry
            .iter()
            .map(|c| Contact {
                left: Body::Pin(0),
                right: Body::Wall,
                height: c.height,
                gap: c.clearance,
                stiffness: 2e4,
                damping: 2.0,
                law: Law::LINEAR,
            })
            .collect(),
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 20.0 * theta.cos(),
            duration: 0.01,
        }),
        point_forces: vec![],
        walls: None,
        plane: Some(Plane {
            normals: geometry.iter().map(|c| [c.normal.x, c.normal.y]).collect(),
            base_acceleration_y: Some(BaseAcceleration::HalfSine {
                amplitude: 20.0 * theta.sin(),
                duration: 0.01,
            }),
        }),
        kinds: Vec::new(),
    };
    let theta = 0.2;
    let settings = settings(2e-5, 0.05);
    let (a, b) = (
        run(&shaken(theta), &settings),
        run(&shaken(theta + PI / 3.0), &settings),
    );
    let turned = |k: usize| 6 * (k / 6) + (k % 6 + 1) % 6;
    let peak = a
        .contact_statistics
        .iter()
        .map(|s| s.max_force)
        .fold(0.0, f64::max);
    assert!(
        peak > 0.0,
        "the pin must hit the wrapper for the check to mean anything"
    );
    let impacts: u64 = a.contact_statistics.iter().map(|s| s.impacts).sum();
    assert!(impacts >= 2);
    for (k, s) in a.contact_statistics.iter().enumerate() {
        let t = &b.contact_statistics[turned(k)];
        assert!(
            (s.max_force - t.max_force).abs() <= 1e-9 * peak,
            "contact {k}: {s:?} vs {t:?}"
        );
        assert!((s.impulse - t.impulse).abs() <= 1e-9 * peak * 0.05);
        assert_eq!(s.impacts, t.impacts, "contact {k}");
        for (f, g) in a.contact_forces[k].iter().zip(&b.contact_forces[turned(k)]) {
            assert!((f - g).abs() <= 1e-9 * peak);
        }
    }
    let (cos, sin) = ((PI / 3.0).cos(), (PI / 3.0).sin());
    for (h, (da, db)) in a.deflections.iter().zip(&b.deflections).enumerate() {
        let scale = da.iter().flatten().fold(0.0f64, |m, w| m.max(w.abs()));
        for (i, (x, y)) in da[0].iter().zip(&da[1]).enumerate() {
            let (u, v) = (cos * x - sin * y, sin * x + cos * y);
            assert!((u - db[0][i]).abs() <= 1e-9 * scale, "height {h}, sample {i}");
            assert!((v - db[1][i]).abs() <= 1e-9 * scale, "height {h}, sample {i}");
        }
    }
}
