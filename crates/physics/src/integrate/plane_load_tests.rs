//! Point forces and tip releases in the plane.
//!
//! In the plane, pin p along x is line p and along y line pins + p; a load along an
//! angle θ is two line loads, cos θ on the x line and sin θ on the y line. The two
//! directions of a pin are uncoupled while no contact closes and the equations are
//! linear, so a lone pin pushed (or released) along θ moves along θ exactly as the
//! one-pin row moves under the same load along x: x(t) = cos θ u(t), y(t) = sin θ u(t),
//! to rounding. Once contacts close, the point force's work ∫ F·u̇ dt, counted per line,
//! still closes the energy balance.

use std::f64::consts::PI;
use std::ops::ControlFlow;

use super::plane_tests::{assert_close, run};
use super::*;
use crate::beam::tests::default_tube;
use crate::contact::{Body, Contact, Law};
use crate::loads::{PointForce, Table};
use crate::modal::ModalBasis;

fn basis() -> ModalBasis {
    ModalBasis::compute(&default_tube(20), 6).expect("valid beam")
}

/// A push of about 0.1 N at 0.7 m that reverses, then stops at 30 ms (a third of the
/// first period): the pin moves by tenths of a millimetre (stiffness 3EI/z³ ≈ 310 N/m
/// at z = 0.7 m).
fn push(scale: f64) -> Table {
    Table {
        time: vec![0.0, 0.01, 0.02, 0.03],
        values: [0.0, 0.12, -0.05, 0.0].map(|f| scale * f).to_vec(),
    }
}

/// One pin without contacts, at rest and unloaded: a row, or the plane with `plane`.
fn lone_pin(basis: &ModalBasis, plane: bool) -> Model<'_> {
    Model {
        basis,
        pins: 1,
        damping_ratios: vec![0.02; basis.modes()],
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

/// The plane tests' settings, with the loads' height among the outputs.
fn settings(dt: f64, duration: f64) -> Settings {
    Settings {
        output_heights: vec![1.0, 0.7],
        ..super::plane_tests::settings(dt, duration)
    }
}

/// The plane's two lines at every output height and sample are (cos θ u, sin θ u), u the
/// row's line; the energies are the row's.
#[track_caller]
fn assert_turned(what: &str, row: &Simulation, plane: &Simulation, theta: f64) {
    let (cos, sin) = (theta.cos(), theta.sin());
    for (h, (expected, lines)) in row.deflections.iter().zip(&plane.deflections).enumerate() {
        assert_eq!(lines.len(), 2, "one pin, two lines");
        let scale = expected[0].iter().fold(0.0f64, |m, w| m.max(w.abs()));
        assert!(scale > 1e-5, "{what}: the pin must move ({scale:e} m)");
        for (k, u) in expected[0].iter().enumerate() {
            let at = format!("{what}, θ {theta}: height {h}, sample {k}");
            assert_close(&format!("{at}, x"), lines[0][k], cos * u, 1e-12, scale);
            assert_close(&format!("{at}, y"), lines[1][k], sin * u, 1e-12, scale);
        }
    }
    let scale = row.energy.external_work.abs() + row.energy.initial;
    for (name, m, e) in [
        (
            "external work",
            plane.energy.external_work,
            row.energy.external_work,
        ),
        ("kinetic energy", plane.energy.kinetic, row.energy.kinetic),
        ("strain energy", plane.energy.strain, row.energy.strain),
        ("initial energy", plane.energy.initial, row.energy.initial),
        (
            "modal dissipation",
            plane.energy.dissipated_modal,
            row.energy.dissipated_modal,
        ),
    ] {
        assert_close(&format!("{what}, θ {theta}: {name}"), m, e, 1e-12, scale);
    }
}

/// A force F along θ on the lone pin (cos θ F on line 0, sin θ F on line 1) moves it
/// along θ by the row's response to F along x. θ = 2 points past the y axis, 3π/2
/// straight down y (its cos a rounding of zero).
#[test]
fn a_point_force_along_theta_moves_a_lone_pin_along_theta_by_the_rows_response() {
    let basis = basis();
    let settings = settings(2e-5, 0.05);
    let mut row = lone_pin(&basis, false);
    row.point_forces = vec![PointForce {
        line: 0,
        height: 0.7,
        force: push(1.0),
    }];
    let row = run(&row, &settings);
    assert!(row.energy.external_work.abs() > 0.0, "the force works");
    for theta in [0.0, 0.3, 37f64.to_radians(), 2.0, 1.5 * PI] {
        let mut plane = lone_pin(&basis, true);
        plane.point_forces = [(0, theta.cos()), (1, theta.sin())]
            .map(|(line, factor)| PointForce {
                line,
                height: 0.7,
                force: push(factor),
            })
            .to_vec();
        assert_turned("point force", &row, &run(&plane, &settings), theta);
    }
}

/// A release along θ (tip deflections x0 cos θ on line 0, x0 sin θ on line 1) swings the
/// lone pin along θ as the row's release by x0 swings it along x.
#[test]
fn a_tip_release_along_theta_swings_a_lone_pin_along_theta_like_the_row() {
    let basis = basis();
    let settings = settings(2e-5, 0.05);
    let release = 1e-3;
    let mut row = lone_pin(&basis, false);
    row.initial_tip_displacements = vec![release];
    let row = run(&row, &settings);
    assert!(row.energy.initial > 0.0, "the release stores strain energy");
    for theta in [0.0, 0.3, 37f64.to_radians(), 2.0, 1.5 * PI] {
        let mut plane = lone_pin(&basis, true);
        plane.initial_tip_displacements = vec![release * theta.cos(), release * theta.sin()];
        assert_turned("release", &row, &run(&plane, &settings), theta);
    }
}

/// One pin in the hexagonal wrapper (a dashpot-damped contact on every flat at two
/// heights) pushed along an oblique direction into the flats, from a release along
/// another: the contacts close on several flats, and the energy balance (kinetic +
/// strain + contact + dissipated − the point force's work = initial) closes, in the run
/// and in its quality report.
#[test]
fn energy_balance_closes_with_a_point_force_in_the_plane() {
    let basis = basis();
    let geometry = crate::hex::single_pin_in_wrapper(&[0.7, 1.0], 2e-4);
    let theta = 0.4f64;
    let model = Model {
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
        initial_tip_displacements: vec![-1e-4, 5e-5],
        initial_tip_velocities: vec![],
        point_forces: [(0, theta.cos()), (1, theta.sin())]
            .map(|(line, factor)| PointForce {
                line,
                height: 0.7,
                force: push(3.0 * factor),
            })
            .to_vec(),
        plane: Some(Plane {
            normals: geometry.iter().map(|c| [c.normal.x, c.normal.y]).collect(),
            base_acceleration_y: None,
        }),
        ..lone_pin(&basis, true)
    };
    let fixed = settings(2e-6, 0.05);
    let result = run(&model, &fixed);
    let touched = result
        .contact_statistics
        .iter()
        .enumerate()
        .filter(|(_, s)| s.impacts > 0)
        .map(|(k, _)| k % 6)
        .collect::<std::collections::BTreeSet<_>>();
    assert!(touched.len() >= 2, "the pin must hit several flats: {touched:?}");
    let energy = &result.energy;
    assert!(energy.external_work.abs() > energy.initial, "{energy:?}");
    assert!(energy.dissipated_contact > 0.0, "{energy:?}");
    let residual = energy.relative_residual();
    assert!(
        residual < 1e-3,
        "energy balance residual {residual:e}: {energy:?}"
    );

    let checked = Settings {
        time_step: TimeStep::Auto,
        check: Check::StepHalving,
        ..settings(0.0, 0.03)
    };
    let assessed = Plan::new(&model, &checked)
        .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
        .expect("runs");
    assert!(
        assessed.quality.energy_residual < DEFAULT_TOLERANCE,
        "{:?}",
        assessed.quality
    );
}

/// In the plane a point force may load any of the 2 × pins lines and a release gives one
/// value per line; beyond, the model is refused at the field, naming the line count.
#[test]
fn loads_in_the_plane_are_checked_against_its_lines() {
    let basis = basis();
    let mut model = lone_pin(&basis, true);
    model.point_forces = (1..3)
        .map(|line| PointForce {
            line,
            height: 0.7,
            force: push(1.0),
        })
        .collect();
    model.initial_tip_displacements = vec![1e-3];
    let issues = model.validate();
    let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
    assert_eq!(
        fields,
        ["initial_tip_displacements", "point_forces/1/line"],
        "{issues:?}"
    );
    for issue in &issues {
        assert!(
            issue.reason.contains("2, two per pin") || issue.reason.contains("2 deflection lines"),
            "{issue:?}"
        );
    }
    model.point_forces.pop();
    model.initial_tip_displacements = vec![1e-3, -1e-3];
    assert_eq!(model.validate(), vec![]);
}
