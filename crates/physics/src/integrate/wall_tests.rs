//! Walls with their own motion: walls given the feet's motion change nothing, opposite
//! wall motions give a mirror-symmetric response, a pin held at both ends ends where
//! the static cubic puts it, and the energy balance closes with the walls' work.

use super::tests::{basis, run, settings, shaken_two_pin_row};
use super::*;
use crate::beam::Support;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Law};
use crate::loads::BaseAcceleration;
use crate::modal::ModalBasis;
use crate::stability::Scheme;

/// The test tube clamped at its foot and pinned at its top: held at both ends.
fn held(elements: usize, modes: usize) -> ModalBasis {
    ModalBasis::compute(
        &crate::beam::BeamSpec {
            top: Support::Pinned,
            ..default_tube(elements)
        },
        modes,
    )
    .expect("valid beam")
}

fn sine(amplitude: f64, frequency: f64, cycles: f64) -> BaseAcceleration {
    BaseAcceleration::Sine {
        amplitude,
        frequency,
        cycles,
    }
}

/// Walls and top supports given the feet's acceleration are walls moving with the
/// feet: the same histories, bit for bit, for a cantilever row and for pins held at
/// both ends (whose transport is then zero).
#[test]
fn walls_given_the_feet_motion_reproduce_walls_moving_with_the_feet() {
    let cantilever = basis(20, 8);
    let held = held(20, 8);
    for basis in [&cantilever, &held] {
        let mut model = shaken_two_pin_row(basis);
        if basis.support_transport().is_some() {
            // A pin held at both ends has no tip to release.
            model.initial_tip_displacements.clear();
        }
        let run_settings = Settings {
            output_interval: Some(1e-4),
            ..settings(Scheme::CentralDifference, 2e-6, 0.05)
        };
        let still = run(&model, &run_settings);
        model.walls = Some(WallMotion::rigid(model.base_acceleration.clone(), None));
        let moving = run(&model, &run_settings);
        let impacts: u64 = still.contact_statistics.iter().map(|s| s.impacts).sum();
        assert!(impacts > 0, "the case must exercise contacts");
        let held = basis.support_transport().is_some();
        assert!(
            moving.contact_forces == still.contact_forces,
            "forces differ (held at both ends: {held})"
        );
        assert!(
            moving.deflections == still.deflections,
            "deflections differ (held: {held})"
        );
        assert!(
            moving.contact_statistics == still.contact_statistics,
            "statistics differ (held: {held})"
        );
        let (a, b) = (moving.energy.external_work, still.energy.external_work);
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-30), "{a:e} vs {b:e}");
    }
}

/// Two identical pins, each facing its own wall (and each other), the left wall driven
/// by a(t) and the right one by −a(t), the feet still: the response is the mirror
/// image of itself (pin 1 = −pin 0, the wall contacts equal).
#[test]
fn opposite_wall_motions_give_a_mirror_symmetric_response() {
    let basis = basis(20, 8);
    let contact = |left, right, height| Contact {
        left,
        right,
        height,
        gap: 5e-5,
        stiffness: 2e4,
        damping: 2.0,
        law: Law::LINEAR,
    };
    let model = Model {
        basis: &basis,
        pins: 2,
        damping_ratios: vec![0.02; basis.modes()],
        contacts: vec![
            contact(Body::Wall, Body::Pin(0), 1.0),
            contact(Body::Pin(0), Body::Pin(1), 0.6),
            contact(Body::Pin(1), Body::Wall, 1.0),
        ],
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        walls: Some(WallMotion {
            left_x: Some(sine(30.0, 25.0, 2.0)),
            right_x: Some(sine(-30.0, 25.0, 2.0)),
            y: None,
        }),
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    };
    let result = run(
        &model,
        &Settings {
            output_interval: Some(1e-4),
            output_heights: vec![0.6, 1.0],
            ..settings(Scheme::CentralDifference, 2e-6, 0.15)
        },
    );
    let forces = &result.contact_forces;
    assert!(forces[0].iter().any(|f| *f > 0.0), "the left wall must hit pin 0");
    assert!(forces[1].iter().any(|f| *f > 0.0), "the pins must hit each other");
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-9 * scale;
    let top = forces[0].iter().fold(0.0_f64, |m, f| m.max(*f));
    for (left, right) in forces[0].iter().zip(&forces[2]) {
        assert!(close(*left, *right, top), "{left} vs {right}");
    }
    for height in &result.deflections {
        let scale = height[0].iter().fold(0.0_f64, |m, w| m.max(w.abs()));
        assert!(scale > 0.0);
        for (w0, w1) in height[0].iter().zip(&height[1]) {
            assert!(close(*w0, -*w1, scale), "{w0} vs {w1}");
        }
    }
}

/// A pin clamped at its foot and pinned at its top, the top support on walls that move
/// by one slow sine cycle of acceleration A over T (velocity back to 0, displacement
/// A T²/2π) while the feet stay still: once the walls stop, the pin sits at the static
/// cubic Ψ(z) = (3ξ² − ξ³)/2 times that displacement (its vibration left decays), so
/// at mid-height 0.3125 × A T²/2π. T is 20 periods of the first mode: the dynamic
/// part is of order (f₁T)⁻² of the static one.
#[test]
fn a_pin_held_at_both_ends_follows_its_moving_top_support_quasi_statically() {
    let spec = crate::beam::BeamSpec {
        top: Support::Pinned,
        ..default_tube(20)
    };
    let basis = ModalBasis::compute(&spec, 6).expect("valid beam");
    let f1 = basis.frequencies_hz()[0];
    let (amplitude, period) = (2.0, 20.0 / f1);
    let model = Model {
        basis: &basis,
        pins: 1,
        damping_ratios: vec![0.05; basis.modes()],
        contacts: vec![],
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        walls: Some(WallMotion::rigid(Some(sine(amplitude, 1.0 / period, 1.0)), None)),
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    };
    let middle = 0.5 * spec.length;
    let result = run(
        &model,
        &Settings {
            output_interval: Some(1e-3),
            output_heights: vec![middle, spec.length],
            ..settings(Scheme::CentralDifference, 2e-5, 1.5 * period)
        },
    );
    let travel = amplitude * period * period / std::f64::consts::TAU;
    let last = result.time.len() - 1;
    let mid = result.deflections[0][0][last];
    let top = result.deflections[1][0][last];
    assert!((top - travel).abs() < 1e-6 * travel, "top {top} vs {travel}");
    assert!(
        (mid - 0.3125 * travel).abs() < 2e-3 * travel,
        "mid-height {mid} vs {}",
        0.3125 * travel
    );
}

/// The shaken row with walls on their own motion (and top supports on them): the
/// energy balance closes once the walls' work on the contacts and the transport's
/// inertial load are counted.
#[test]
fn the_energy_balance_closes_with_moving_walls() {
    let cantilever = basis(20, 8);
    let held = held(20, 8);
    for basis in [&cantilever, &held] {
        let mut model = shaken_two_pin_row(basis);
        model.initial_tip_displacements.clear();
        // Walls oscillating about their place (a cosine acceleration: no drift), 2 mm.
        let omega = std::f64::consts::TAU * 30.0;
        let table = crate::loads::Table::sample(|t| 2e-3 * omega * omega * (omega * t).cos(), 1e-4, 0.1);
        model.walls = Some(WallMotion::rigid(Some(BaseAcceleration::Table(table)), None));
        let result = run(
            &model,
            &Settings {
                output_interval: Some(1e-4),
                ..settings(Scheme::CentralDifference, 2e-6, 0.1)
            },
        );
        let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
        assert!(impacts > 5, "the case must exercise contacts: {impacts} impacts");
        let residual = result.energy.relative_residual();
        assert!(
            residual < 1e-3,
            "energy balance residual {residual:e}: {:?}",
            result.energy
        );
    }
}

/// Bad wall motions are refused at their fields.
#[test]
fn bad_wall_motions_are_refused_at_their_fields() {
    let held = held(12, 4);
    let mut model = shaken_two_pin_row(&held);
    model.initial_tip_displacements.clear();
    model.walls = Some(WallMotion {
        left_x: Some(sine(1.0, f64::NAN, 1.0)),
        right_x: None,
        y: Some(sine(1.0, 1.0, 1.0)),
    });
    let fields: Vec<String> = model.validate().into_iter().map(|i| i.field).collect();
    assert!(fields.iter().any(|f| f.starts_with("walls/left_x")), "{fields:?}");
    assert!(fields.contains(&"walls/y".to_owned()), "{fields:?}");
    assert!(fields.contains(&"walls/right_x".to_owned()), "{fields:?}");
}
