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
use crate::contact::{Body, Contact};
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
            });
        }
    }
    Model {
        basis,
        pins: 2,
        damping_ratios: vec![0.02; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude,
            duration: 0.01,
        }),
        point_forces: vec![],
        plane: None,
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

fn settings(dt: f64, duration: f64) -> Settings {
    Settings {
        scheme: Scheme::CentralDifference,
        time_step: TimeStep::Fixed(dt),
        tolerance: DEFAULT_TOLERANCE,
        check: Check::None,
        duration,
        output_interval: Some(1e-4),
        output_heights: vec![1.0, 0.8],
        recorded_contacts: None,
    }
}

fn run(model: &Model<'_>, settings: &Settings) -> Simulation {
    simulate(model, settings, &mut |_| ControlFlow::Continue(())).expect("run succeeds")
}

/// |a − b| ≤ tolerance × scale, with a message that prints both.
#[track_caller]
fn assert_close(what: &str, measured: f64, expected: f64, tolerance: f64, scale: f64) {
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
    let peak_deflection = row.deflections.iter().map(|h| peak(h)).fold(0.0, f64::max);
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
            });
            normals.push(*normal);
        }
    }
    Model {
        basis,
        pins: 3,
        damping_ratios: vec![0.02; basis.modes()],
        contacts,
        initial_tip_displacements: vec![2e-4, 0.0, -1e-4],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 15.0,
            duration: 0.01,
        }),
        point_forces: vec![],
        plane: Some(Plane {
            normals,
            base_acceleration_y: Some(BaseAcceleration::Sine {
                amplitude: 10.0,
                frequency: 30.0,
                cycles: 2.0,
            }),
        }),
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
    let halving = quality.step_halving.expect("the check ran");
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
    };
    let model = Model {
        basis: &basis,
        pins: 2,
        damping_ratios: vec![0.01; basis.modes()],
        contacts: vec![contact(1.0, 2e-5), contact(0.7, 1e-5)],
        initial_tip_displacements: vec![-3e-4, 3e-4],
        base_acceleration: None,
        point_forces: vec![],
        plane: Some(Plane {
            normals: vec![normal, [normal[1], normal[0]]],
            base_acceleration_y: None,
        }),
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
