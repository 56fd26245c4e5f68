//! The resultant contact force on a pin at a contact height ([`Simulation::resultant_forces`]):
//! the vector sum of its contacts there, at every step. Checked against the same sum
//! formed from the step-by-step force histories (oblique normals, both sides of a pin
//! closed at once), against a lone contact's own peak, on a pin held between two equal
//! preloads (each contact pushes K g, the resultant is nil), and with friction (between
//! the normal force and √(1 + μ²) times it).

use super::plane_tests::{assert_close, run, settings};
use super::*;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Friction, Law};
use crate::loads::BaseAcceleration;
use crate::modal::ModalBasis;

fn basis(modes: usize) -> ModalBasis {
    ModalBasis::compute(&default_tube(20), modes).expect("valid beam")
}

/// Two pins between walls in the plane, shaken along x and y: at 0.6 m and 1.0 m a
/// wall–p0, a p0–p1 and a p1–wall contact, each with its own oblique normal; at 0.8 m a
/// lone p0–wall contact.
fn oblique_pair(basis: &ModalBasis, law: Law) -> Model<'_> {
    let mut contacts = Vec::new();
    let mut normals = Vec::new();
    for (height, gap) in [(0.6, 2e-5), (1.0, 3e-5)] {
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
                gap: gap * (1.0 + 0.4 * k as f64),
                stiffness: 3e4,
                damping: 1.0,
                law,
            });
            let angle = 0.35 * k as f64 + height;
            normals.push([angle.cos(), angle.sin()]);
        }
    }
    contacts.push(Contact {
        left: Body::Pin(0),
        right: Body::Wall,
        height: 0.8,
        gap: 1e-5,
        stiffness: 3e4,
        damping: 1.0,
        law,
    });
    normals.push([0.6, 0.8]);
    Model {
        basis,
        pins: 2,
        damping_ratios: vec![0.02; basis.modes()],
        contacts,
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 30.0,
            duration: 0.01,
        }),
        point_forces: vec![],
        walls: None,
        plane: Some(Plane {
            normals,
            base_acceleration_y: Some(BaseAcceleration::HalfSine {
                amplitude: -20.0,
                duration: 0.007,
            }),
        }),
        kinds: Vec::new(),
    }
}

/// Every step sampled: the histories hold every step's forces.
fn every_step(dt: f64, duration: f64) -> Settings {
    Settings {
        output_interval: Some(dt),
        ..settings(dt, duration)
    }
}

#[test]
fn the_resultant_is_the_vector_sum_of_the_step_by_step_forces() {
    let basis = basis(6);
    let model = oblique_pair(&basis, Law::LINEAR);
    let run = run(&model, &every_step(2e-6, 0.03));
    let normals = &model.plane.as_ref().expect("plane").normals;
    // (pin, height) → (contacts, largest |Σ ±F n| over the samples, when).
    let mut expected: Vec<(usize, f64, usize, f64, f64)> = Vec::new();
    for pin in 0..2 {
        for height in [0.6, 0.8, 1.0] {
            let on_pin: Vec<(usize, f64)> = model
                .contacts
                .iter()
                .enumerate()
                .filter(|(_, c)| c.height == height)
                .filter_map(|(i, c)| match (c.left, c.right) {
                    (Body::Pin(p), _) if p == pin => Some((i, -1.0)),
                    (_, Body::Pin(p)) if p == pin => Some((i, 1.0)),
                    _ => None,
                })
                .collect();
            if on_pin.is_empty() {
                continue;
            }
            let (mut largest, mut when) = (0.0_f64, 0.0);
            for (s, &t) in run.time.iter().enumerate() {
                let [x, y] = on_pin.iter().fold([0.0, 0.0], |[x, y], &(c, sign)| {
                    let f = sign * run.contact_forces[c][s];
                    [x + f * normals[c][0], y + f * normals[c][1]]
                });
                let magnitude = x.hypot(y);
                if magnitude > largest {
                    (largest, when) = (magnitude, t);
                }
            }
            expected.push((pin, height, on_pin.len(), largest, when));
        }
    }
    assert_eq!(
        run.resultant_forces.len(),
        expected.len(),
        "{:?}",
        run.resultant_forces
    );
    let mut both_sides_closed = 0;
    for (peak, (pin, height, contacts, force, time)) in run.resultant_forces.iter().zip(&expected) {
        assert_eq!((peak.pin, peak.height, peak.contacts), (*pin, *height, *contacts));
        assert!(
            *force > 0.0,
            "pin {pin} at {height} m never touched: the test shakes too little"
        );
        assert_close(
            &format!("pin {pin} at {height} m"),
            peak.force,
            *force,
            1e-12,
            *force,
        );
        assert_eq!(peak.time, *time, "pin {pin} at {height} m");
        // Where two contacts act, the resultant is not either one's peak.
        let lone_peaks: Vec<f64> = model
            .contacts
            .iter()
            .zip(&run.contact_statistics)
            .filter(|(c, _)| c.height == *height && (c.left == Body::Pin(*pin) || c.right == Body::Pin(*pin)))
            .map(|(_, s)| s.max_force)
            .collect();
        if *contacts == 1 {
            // |F n| with |n| = 1 to rounding.
            assert_close(
                "a lone contact's resultant",
                peak.force,
                lone_peaks[0],
                1e-12,
                lone_peaks[0],
            );
        } else if lone_peaks.iter().all(|f| (peak.force - f).abs() > 1e-9 * f) {
            both_sides_closed += 1;
        }
    }
    assert!(
        both_sides_closed > 0,
        "no slot saw two contacts closed at once: {:?}",
        run.resultant_forces
    );
}

/// A pin pressed by two equal interferences g from both sides at one height (the row:
/// wall–pin and pin–wall) stays at rest: each contact pushes K g at every step and their
/// resultant on the pin is nil.
#[test]
fn equal_preloads_from_both_sides_cancel() {
    let basis = basis(4);
    let (stiffness, interference) = (5e4, 2e-5);
    let contact = |left, right| Contact {
        left,
        right,
        height: 0.7,
        gap: -interference,
        stiffness,
        damping: 0.0,
        law: Law::LINEAR,
    };
    let model = Model {
        basis: &basis,
        pins: 1,
        damping_ratios: vec![0.01; basis.modes()],
        contacts: vec![
            contact(Body::Wall, Body::Pin(0)),
            contact(Body::Pin(0), Body::Wall),
        ],
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        point_forces: vec![],
        walls: None,
        plane: None,
        kinds: Vec::new(),
    };
    let run = run(&model, &settings(1e-5, 0.01));
    for stats in &run.contact_statistics {
        assert_close(
            "each preload",
            stats.max_force,
            stiffness * interference,
            1e-12,
            stiffness * interference,
        );
    }
    let [peak] = run.resultant_forces.as_slice() else {
        panic!("one slot: {:?}", run.resultant_forces);
    };
    assert_eq!((peak.pin, peak.height, peak.contacts), (0, 0.7, 2));
    assert!(
        peak.force <= 1e-12 * stiffness * interference,
        "resultant {:e} N",
        peak.force
    );
}

/// With Coulomb friction the resultant adds the tangential force T (|T| ≤ μ F) to a lone
/// contact's normal force F: between F's peak and √(1 + μ²) times it, and above F's
/// peak where the contact slides.
#[test]
fn friction_joins_the_resultant() {
    let basis = basis(6);
    let mu = 0.3;
    let law = Law {
        friction: Friction {
            coefficient: mu,
            tangential_stiffness: 1e5,
        },
        ..Law::LINEAR
    };
    let model = oblique_pair(&basis, law);
    let run = run(&model, &settings(2e-6, 0.03));
    let lone = run
        .resultant_forces
        .iter()
        .find(|p| p.contacts == 1)
        .expect("the lone contact at 0.8 m");
    let normal_peak = run.contact_statistics[6].max_force;
    assert!(normal_peak > 0.0);
    assert!(
        lone.force > normal_peak * (1.0 + 1e-9)
            && lone.force <= normal_peak * (1.0 + mu * mu).sqrt() * (1.0 + 1e-12),
        "resultant {:e} N against a normal peak of {normal_peak:e} N",
        lone.force
    );
}
