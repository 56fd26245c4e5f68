//! The assembly's contacts: their count and gaps from the geometry, bodies that never
//! touch their cells moving as lone bodies on their supports, and a body clamped by a
//! preloaded cell moving with its grid below the load that unloads a side.

use std::ops::ControlFlow;

use super::*;
use crate::beam::tests::default_tube;
use crate::beam::{BeamSpec, Support};
use crate::integrate::{Check, Model, Plane, Settings, TimeStep, simulate};
use crate::loads::{BaseAcceleration, PointForce, Table};
use crate::modal::ModalBasis;
use crate::pwr::lattice::SquareLattice;
use crate::stability::Scheme;

const PITCH: f64 = 0.0126;
const DIAMETERS: [f64; 3] = [0.0095, 0.01224, 0.01224];

/// A 1 m tube held at both ends (the nozzles).
fn pinned_tube() -> BeamSpec {
    BeamSpec {
        foot: Support::Pinned,
        top: Support::Pinned,
        ..default_tube(20)
    }
}

fn loose() -> CellSupport {
    CellSupport {
        spring: 1e5,
        dimple: 2e5,
        preload: 0.0,
        spring_gap: 0.1,
        dimple_gap: 0.1,
        damping: 0.0,
    }
}

fn grid(height: f64, support: CellSupport) -> Grid {
    Grid {
        height,
        rods: support,
        guide_tubes: support,
        instrument: support,
    }
}

fn spec(
    lattice: &SquareLattice,
    grids: Vec<Grid>,
    span_points: usize,
    body_stiffness: f64,
) -> AssemblySpec<'_> {
    AssemblySpec {
        lattice,
        pitch: PITCH,
        diameters: DIAMETERS,
        length: 1.0,
        grids,
        span_points,
        body_stiffness,
        body_damping: 0.0,
    }
}

fn plane_model<'a>(basis: &'a ModalBasis, pins: usize, contacts: &AssemblyContacts) -> Model<'a> {
    Model {
        basis,
        pins,
        damping_ratios: vec![0.02; basis.modes()],
        contacts: contacts.contacts.clone(),
        initial_tip_displacements: vec![],
        initial_tip_velocities: vec![],
        base_acceleration: None,
        walls: None,
        plane: Some(Plane {
            normals: contacts.normals.clone(),
            base_acceleration_y: None,
        }),
        point_forces: vec![],
        kinds: Vec::new(),
    }
}

fn settings(dt: f64, duration: f64, heights: Vec<f64>) -> Settings {
    Settings {
        scheme: Scheme::CentralDifference,
        time_step: TimeStep::Fixed(dt),
        tolerance: crate::integrate::DEFAULT_TOLERANCE,
        check: Check::None,
        duration,
        output_interval: Some(1e-3),
        recorded_contacts: None,
        impacts: Default::default(),
        threads: 1,
        output_heights: heights,
    }
}

#[test]
fn the_standard_assembly_has_four_contacts_per_body_and_grid_and_its_gaps_from_the_pitch() {
    let lattice = SquareLattice::standard(17).expect("built in");
    let grids: Vec<Grid> = (0..8).map(|g| grid(0.1 + 0.5 * g as f64, loose())).collect();
    let assembly = AssemblyContacts::of(&AssemblySpec {
        length: 4.0,
        ..spec(&lattice, grids, 2, 1e5)
    })
    .expect("valid");
    assert_eq!(assembly.grid_contacts, 8 * 289 * 4);
    assert_eq!(assembly.contacts.len(), 8 * 289 * 4 + 7 * 2 * 544);
    assert_eq!(assembly.normals.len(), assembly.contacts.len());
    // Two span heights at the thirds of each span; rod–rod and rod–tube gaps.
    let spans = &assembly.contacts[assembly.grid_contacts..];
    assert!((spans[0].height - (0.1 + 0.5 / 3.0)).abs() < 1e-12);
    let gap = |a: usize, b: usize| {
        spans
            .iter()
            .find(|c| c.left == Body::Pin(a) && c.right == Body::Pin(b))
            .expect("a pair")
            .gap
    };
    assert!((gap(0, 1) - (PITCH - 0.0095)).abs() < 1e-15);
    // Cell 2·17 + 5 is a guide tube; its left neighbour a rod.
    assert!((gap(2 * 17 + 4, 2 * 17 + 5) - (PITCH - 0.5 * (0.0095 + 0.01224))).abs() < 1e-15);
    // Each cell's four: spring toward −x, dimple toward +x, spring toward −y, dimple toward +y.
    assert_eq!(
        &assembly.normals[..4],
        &[[-1.0, 0.0], [1.0, 0.0], [0.0, -1.0], [0.0, 1.0]]
    );
    // Bad geometry is refused at its field.
    let issues = AssemblyContacts::of(&AssemblySpec {
        diameters: [0.013, 0.01224, 0.01224],
        grids: vec![grid(0.5, loose()), grid(0.4, loose())],
        ..spec(&lattice, vec![], 1, 1e5)
    })
    .unwrap_err();
    let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
    assert_eq!(fields, ["diameters/0", "grids/1/height"]);
}

/// Cells and neighbours that never push (gaps wider than any motion, bodies without
/// contact stiffness): every body moves as one lone body on its supports, to rounding.
#[test]
fn bodies_that_never_touch_their_cells_move_as_lone_bodies_on_their_supports() {
    let basis = ModalBasis::compute(&pinned_tube(), 6).expect("valid beam");
    let lattice = SquareLattice::new(3, &[(1, 1)], None).expect("valid");
    let assembly = AssemblyContacts::of(&spec(
        &lattice,
        vec![grid(0.3, loose()), grid(0.7, loose())],
        1,
        0.0,
    ))
    .expect("valid");
    let shake = |model: &mut Model<'_>| {
        model.base_acceleration = Some(BaseAcceleration::HalfSine {
            amplitude: 30.0,
            duration: 0.01,
        });
        model.plane.as_mut().expect("plane").base_acceleration_y = Some(BaseAcceleration::HalfSine {
            amplitude: -20.0,
            duration: 0.01,
        });
    };
    let mut bundle = plane_model(&basis, 9, &assembly);
    shake(&mut bundle);
    let lone_contacts = AssemblyContacts {
        contacts: vec![],
        normals: vec![],
        grid_contacts: 0,
    };
    let mut lone = plane_model(&basis, 1, &lone_contacts);
    shake(&mut lone);
    let settings = settings(2e-5, 0.05, vec![0.3, 0.5]);
    let run =
        |model: &Model<'_>| simulate(model, &settings, &mut |_| ControlFlow::Continue(())).expect("runs");
    let (all, one) = (run(&bundle), run(&lone));
    let peak = one.deflections[1][0].iter().fold(0.0_f64, |m, w| m.max(w.abs()));
    assert!(peak > 1e-4, "the shock bends the bodies: {peak}");
    for body in 0..9 {
        for (h, heights) in all.deflections.iter().enumerate() {
            for (line, own) in [(body, 0), (9 + body, 1)] {
                let off = heights[line]
                    .iter()
                    .zip(&one.deflections[h][own])
                    .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(off <= 1e-12 * peak, "body {body}, line {line}: {off}");
            }
        }
    }
    assert!(all.contact_statistics.iter().all(|s| s.impacts == 0));
}

/// One rod held at mid-span by a preloaded cell (spring k_s and dimple k_d, preload P
/// along x and y), a force F on it there along x: it stays clamped and settles at
/// F/(k_b + k_s + k_d) (k_b = 48EI/L³ the pinned rod's own stiffness there) while the
/// dimple keeps a force P − k_d u > 0; above F = P (k_b + k_s + k_d)/k_d the dimple
/// opens.
#[test]
fn a_rod_clamped_by_a_preloaded_cell_moves_with_its_grid_below_the_load_that_unloads_it() {
    let spec_beam = pinned_tube();
    let basis = ModalBasis::compute_with_static_correction(&spec_beam, 3, &[0.5]).expect("valid beam");
    let lattice = SquareLattice::new(1, &[], None).expect("valid");
    let (k_s, k_d, preload) = (4e4, 8e4, 5.0);
    let clamp = CellSupport {
        spring: k_s,
        dimple: k_d,
        preload,
        spring_gap: 0.0,
        dimple_gap: 0.0,
        damping: 5.0,
    };
    let assembly = AssemblyContacts::of(&spec(&lattice, vec![grid(0.5, clamp)], 0, 0.0)).expect("valid");
    let k_b = 48.0 * spec_beam.bending_stiffness();
    let opening = preload * (k_b + k_s + k_d) / k_d;
    let first = basis.angular_frequencies()[0];
    let ramp = 60.0 / first;
    for (load, holds) in [(0.6 * opening, true), (1.4 * opening, false)] {
        let mut model = plane_model(&basis, 1, &assembly);
        model.damping_ratios = vec![0.1; basis.modes()];
        model.point_forces = vec![PointForce {
            line: 0,
            height: 0.5,
            force: Table::ramp_and_hold(ramp, load),
        }];
        assert!(model.validate().is_empty(), "{:?}", model.validate());
        let dt = 0.5 * crate::integrate::critical_time_step(&model, Scheme::CentralDifference);
        let result = simulate(&model, &settings(dt, ramp + 60.0 / first, vec![0.5]), &mut |_| {
            ControlFlow::Continue(())
        })
        .expect("runs");
        // Contacts: spring and dimple along x, then along y.
        let lowest = |c: usize| {
            result.contact_forces[c]
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min)
        };
        let settled = *result.deflections[0][0].last().expect("samples");
        if holds {
            assert!((0..4).all(|c| lowest(c) > 0.0), "the cell opened");
            let statics = load / (k_b + k_s + k_d);
            assert!(
                (settled - statics).abs() < 2e-3 * statics,
                "{settled} vs statics {statics}"
            );
            // The y contacts keep their preload: nothing loads the rod along y.
            let y = *result.contact_forces[2].last().expect("samples");
            assert!((y - preload).abs() < 1e-6 * preload, "{y}");
        } else {
            assert_eq!(lowest(1), 0.0, "the dimple must open");
            assert!(lowest(0) > 0.0, "the spring stays closed");
        }
    }
}
