//! Bending: the curvature histories at the output heights, the envelope over the mesh
//! nodes and each pin's largest curvature, against statics.
//!
//! A load brought on slowly to a critically damped pin leaves it in its static shape
//! without overshoot, so the largest curvature over the samples is the static one:
//! under a tip force F on a cantilever, w'' = F (L − z) / EI (the cubic Hermite
//! elements hold that shape exactly, and the tip's static correction puts it in the
//! basis); in the plane the resultant of the x and y curvatures is the same for a force
//! along any angle; a clamped–pinned pin whose top support has moved by d has the static
//! transport's w'' = 3 d (L − z) / L³.

use std::f64::consts::PI;

use super::plane_tests::{assert_close, run};
use super::*;
use crate::beam::Support;
use crate::beam::tests::default_tube;
use crate::loads::{BaseAcceleration, PointForce, Table};
use crate::modal::ModalBasis;

/// EI of the test tube (N·m²).
fn bending_stiffness() -> f64 {
    default_tube(1).bending_stiffness()
}

/// One pin, critically damped, without contacts.
fn lone_pin(basis: &ModalBasis, plane: bool) -> Model<'_> {
    Model {
        basis,
        pins: 1,
        damping_ratios: vec![1.0; basis.modes()],
        contacts: vec![],
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        point_forces: vec![],
        walls: None,
        plane: plane.then(|| Plane {
            normals: vec![],
            base_acceleration_y: None,
        }),
        kinds: Vec::new(),
    }
}

/// A force ramped from 0 to `force` over 1 s (ten first periods), then held.
fn ramp(force: f64) -> Table {
    Table {
        time: vec![0.0, 1.0, 10.0],
        values: vec![0.0, force, force],
    }
}

fn settings(duration: f64, heights: Vec<f64>) -> Settings {
    Settings {
        output_interval: Some(1e-3),
        output_heights: heights,
        ..super::plane_tests::settings(2e-5, duration)
    }
}

#[test]
fn a_cantilever_under_a_slow_tip_force_bends_as_statics_says() {
    let (force, length) = (0.05, 1.0);
    let basis = ModalBasis::compute_with_static_correction(&default_tube(20), 4, &[length]).unwrap();
    let mut model = lone_pin(&basis, false);
    model.point_forces = vec![PointForce {
        line: 0,
        height: length,
        force: ramp(force),
    }];
    let run = run(&model, &settings(1.6, vec![0.0, 0.35, 0.7]));
    let ei = bending_stiffness();
    let exact = |z: f64| force * (length - z) / ei;
    // The envelope at every node (over the ramp too, where the modes' lags bend the pin
    // by ~1e-5 of the foot's curvature away from statics), the pin's worst at the foot,
    // the histories' last samples (settled) at the output heights (0.35 m is within an
    // element).
    assert_eq!(run.curvature_envelope.len(), 21);
    for node in &run.curvature_envelope {
        assert_close(
            &format!("envelope at {} m", node.height),
            node.curvature,
            exact(node.height),
            1e-4,
            exact(0.0),
        );
        assert_eq!(node.pin, 0);
    }
    let worst = run.pin_curvatures[0];
    assert_close(
        "the pin's worst curvature",
        worst.curvature,
        exact(0.0),
        1e-6,
        exact(0.0),
    );
    assert_eq!(worst.height, 0.0);
    for (h, z) in [0.0, 0.35, 0.7].into_iter().enumerate() {
        let last = *run.curvatures[h][0].last().unwrap();
        assert_close(&format!("curvature at {z} m"), last, exact(z), 1e-6, exact(0.0));
    }
    // Never above statics on the way (no overshoot at critical damping).
    let first = &run.curvatures[0][0];
    assert!(first.iter().all(|k| *k <= exact(0.0) * (1.0 + 1e-9)), "overshoot");
    assert!(first[first.len() / 4] < 0.5 * exact(0.0), "the force is ramped");
}

#[test]
fn in_the_plane_the_envelope_is_the_resultant_of_the_two_directions() {
    let (force, length) = (0.05, 1.0);
    let basis = ModalBasis::compute_with_static_correction(&default_tube(10), 4, &[length]).unwrap();
    let ei = bending_stiffness();
    for theta in [0.0f64, 0.4, 2.5] {
        let mut model = lone_pin(&basis, true);
        model.point_forces = [(0, theta.cos()), (1, theta.sin())]
            .map(|(line, factor)| PointForce {
                line,
                height: length,
                force: ramp(factor * force),
            })
            .to_vec();
        let run = run(&model, &settings(1.6, vec![0.0]));
        let exact = force * length / ei;
        assert_close(
            &format!("θ {theta}: foot"),
            run.curvature_envelope[0].curvature,
            exact,
            1e-6,
            exact,
        );
        let (x, y) = (
            run.curvatures[0][0].last().unwrap(),
            run.curvatures[0][1].last().unwrap(),
        );
        assert_close(&format!("θ {theta}: x"), *x, theta.cos() * exact, 1e-6, exact);
        assert_close(&format!("θ {theta}: y"), *y, theta.sin() * exact, 1e-6, exact);
    }
}

#[test]
fn a_moved_top_support_bends_a_held_pin_by_its_static_transport() {
    let length = 1.0;
    let held = crate::beam::BeamSpec {
        top: Support::Pinned,
        ..default_tube(20)
    };
    let basis = ModalBasis::compute(&held, 6).unwrap();
    // One cycle of a sine of the walls' acceleration moves them by D = A T² / (2π) and
    // stops them there.
    let (period, distance) = (0.5, 2e-3);
    let amplitude = distance * 2.0 * PI / (period * period);
    let mut model = lone_pin(&basis, false);
    model.walls = Some(WallMotion::rigid(
        Some(BaseAcceleration::Sine {
            amplitude,
            frequency: 1.0 / period,
            cycles: 1.0,
        }),
        None,
    ));
    let run = run(&model, &settings(1.1, vec![0.0, 0.5]));
    let exact = |z: f64| 3.0 * distance * (length - z) / length.powi(3);
    for (h, z) in [0.0, 0.5].into_iter().enumerate() {
        let last = *run.curvatures[h][0].last().unwrap();
        assert_close(&format!("curvature at {z} m"), last, exact(z), 1e-5, exact(0.0));
    }
    assert!(run.curvature_envelope[0].curvature >= exact(0.0) * (1.0 - 1e-5));
}
