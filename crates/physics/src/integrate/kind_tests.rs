//! Bodies of several kinds ([`super::kinds`]) through every step loop: a kind that is
//! the basis's beam changes nothing, a pin of another kind moves as a model of that
//! kind alone, two kinds pressed together share a load as statics says, the energy
//! balance closes, and what a kind cannot be is refused.

use super::tests::{LOOPS, Loop, on_loop, run, settings, threads};
use super::*;
use crate::beam::tests::default_tube;
use crate::beam::{BeamSpec, Section, Shear};
use crate::contact::{Body, Contact, Law};
use crate::loads::{BaseAcceleration, PointForce, Table};
use crate::modal::ModalBasis;
use crate::stability::Scheme;

/// Every loop under central difference, and the exact modal scheme's (the row and the
/// plane: it takes no walls of their own motion).
const SCHEMES: [(Loop, Scheme); 6] = [
    (Loop::Row, Scheme::CentralDifference),
    (Loop::Plane { threads: 1 }, Scheme::CentralDifference),
    (Loop::Plane { threads: 2 }, Scheme::CentralDifference),
    (Loop::Walls, Scheme::CentralDifference),
    (Loop::Row, Scheme::ExactModal),
    (Loop::Plane { threads: 1 }, Scheme::ExactModal),
];

/// The default tube's beam with a thicker steel wall, a lighter material and an added
/// mass: EI × 2.56 and the mass per length × 2.42, the same shapes.
fn guide_tube(elements: usize) -> BeamSpec {
    BeamSpec {
        young_modulus: 1.9e11,
        density: 6500.0,
        section: Section::Tube {
            outer_diameter: 0.0114,
            inner_diameter: 0.0092,
        },
        added_mass_per_length: 0.05,
        ..default_tube(elements)
    }
}

/// A model of `pins` pins of `basis` with `contacts`, released by `tips` along x, the
/// base shaken along x; on `kind` (the plane with every normal +x).
fn model<'a>(
    basis: &'a ModalBasis,
    pins: usize,
    contacts: Vec<Contact>,
    tips: Vec<f64>,
    kind: Loop,
) -> Model<'a> {
    let model = Model {
        basis,
        pins,
        damping_ratios: vec![0.02; basis.modes()],
        contacts,
        initial_tip_displacements: tips,
        initial_tip_velocities: vec![],
        base_acceleration: Some(BaseAcceleration::HalfSine {
            amplitude: 30.0,
            duration: 0.008,
        }),
        walls: None,
        plane: None,
        point_forces: vec![],
        kinds: Vec::new(),
    };
    on_loop(model, kind)
}

fn contact(left: Body, right: Body, height: f64, gap: f64) -> Contact {
    Contact {
        left,
        right,
        height,
        gap,
        stiffness: 5e4,
        damping: 0.0,
        law: Law::LINEAR,
    }
}

/// Largest |a − b| over two histories, against the largest |b| (absolute where b is
/// all zeros: a y line that nothing moves).
fn misfit(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / if scale > 0.0 { scale } else { 1.0 }
}

/// Three pins touching each other and the walls at mid-height and at the tip.
fn three_pin_contacts() -> Vec<Contact> {
    let mut contacts = Vec::new();
    for height in [0.5, 1.0] {
        contacts.push(contact(Body::Wall, Body::Pin(0), height, 1e-4));
        contacts.push(contact(Body::Pin(0), Body::Pin(1), height, 5e-5));
        contacts.push(contact(Body::Pin(1), Body::Pin(2), height, 5e-5));
        contacts.push(contact(Body::Pin(2), Body::Wall, height, 1e-4));
    }
    contacts
}

#[test]
fn a_kind_that_is_the_basis_beam_changes_nothing_on_every_loop() {
    let basis = ModalBasis::compute(&default_tube(20), 6).expect("valid beam");
    let same = ModalBasis::compute(&default_tube(20), 6).expect("valid beam");
    for kind in LOOPS {
        let plain = model(&basis, 3, three_pin_contacts(), vec![2e-4, 0.0, -1e-4], kind);
        let mut kinds = plain.clone();
        kinds.kinds = vec![BodyKind {
            basis: &same,
            damping_ratios: plain.damping_ratios.clone(),
            pins: vec![1],
            envelope_weight: 1.0,
        }];
        assert!(kinds.validate().is_empty(), "{:?}", kinds.validate());
        let settings = Settings {
            threads: threads(kind),
            output_interval: Some(1e-4),
            ..settings(Scheme::CentralDifference, 5e-6, 0.03)
        };
        let (a, b) = (run(&plain, &settings), run(&kinds, &settings));
        for c in 0..plain.contacts.len() {
            assert!(
                misfit(&b.contact_forces[c], &a.contact_forces[c]) < 1e-9,
                "{kind:?}: contact {c}"
            );
        }
        for line in 0..plain.lines() {
            assert!(
                misfit(&b.deflections[0][line], &a.deflections[0][line]) < 1e-9,
                "{kind:?}: line {line}"
            );
        }
        let (ea, eb) = (a.energy, b.energy);
        assert!((ea.mechanical() - eb.mechanical()).abs() < 1e-9 * ea.initial.max(ea.external_work.abs()));
    }
}

#[test]
fn a_pin_of_another_kind_moves_as_a_model_of_that_kind_alone_on_every_loop() {
    let (rod, tube) = (default_tube(20), guide_tube(20));
    let heights = [0.5, 1.0];
    let rods = ModalBasis::compute_with_static_correction(&rod, 4, &heights).expect("valid beam");
    let tubes = ModalBasis::compute_with_static_correction(&tube, 4, &heights).expect("valid beam");
    let mass = relative_mass(&rods, &tubes).expect("the same beam scaled");
    let expected = tube.mass_per_length() / rod.mass_per_length();
    assert!(
        (mass - expected).abs() < 1e-9 * expected,
        "μ {mass} vs {expected}"
    );
    for (kind, scheme) in SCHEMES {
        // Pin 0 a rod against the left wall, pin 1 a guide tube against the right one:
        // nothing couples them.
        let contacts = vec![
            contact(Body::Wall, Body::Pin(0), 1.0, 1e-4),
            contact(Body::Pin(1), Body::Wall, 1.0, 5e-5),
            contact(Body::Pin(1), Body::Wall, 0.5, 2e-5),
        ];
        let mut mixed = model(&rods, 2, contacts, vec![-2e-4, 3e-4], kind);
        mixed.kinds = vec![BodyKind {
            basis: &tubes,
            damping_ratios: vec![0.03; tubes.modes()],
            pins: vec![1],
            envelope_weight: 1.0,
        }];
        assert!(mixed.validate().is_empty(), "{:?}", mixed.validate());
        let alone_contacts = vec![
            contact(Body::Pin(0), Body::Wall, 1.0, 5e-5),
            contact(Body::Pin(0), Body::Wall, 0.5, 2e-5),
        ];
        let mut alone = model(&tubes, 1, alone_contacts, vec![3e-4], kind);
        alone.damping_ratios = vec![0.03; tubes.modes()];
        let settings = Settings {
            threads: threads(kind),
            output_interval: Some(1e-4),
            output_heights: vec![0.5, 1.0],
            ..settings(scheme, 1e-5, 0.15)
        };
        let (a, b) = (run(&mixed, &settings), run(&alone, &settings));
        let impacts: u64 = b.contact_statistics.iter().map(|s| s.impacts).sum();
        assert!(
            impacts >= 2,
            "{kind:?} {scheme:?}: the tube rattles ({impacts} impacts)"
        );
        for (c, own) in [(1, 0), (2, 1)] {
            let off = misfit(&a.contact_forces[c], &b.contact_forces[own]);
            assert!(off < 1e-8, "{kind:?} {scheme:?}: contact {c} off by {off}");
        }
        for height in 0..2 {
            let off = misfit(&a.deflections[height][1], &b.deflections[height][0]);
            assert!(off < 1e-8, "{kind:?} {scheme:?}: deflection off by {off}");
        }
        // The energies add: the mixed model's is the rod's and the tube's.
        let residual = a.energy.residual().abs();
        assert!(
            residual < 1e-3 * a.energy.initial,
            "{kind:?} {scheme:?}: energy residual {residual}"
        );
    }
}

/// A rod and a stiffer guide tube touching at their tips, a force P pushing the rod
/// against the tube: at rest the contact carries F = (Kc/k_r) P / (1 + Kc/k_r + Kc/k_t)
/// with k = 3EI/L³ each (a cantilever's tip stiffness, which Hermite elements and the
/// static correction at the tip hold exactly), and the tips sit at (P − F)/k_r and F/k_t.
#[test]
fn a_rod_pressed_against_a_guide_tube_shares_the_load_as_statics_says_on_every_loop() {
    let (rod, tube) = (default_tube(20), guide_tube(20));
    let rods = ModalBasis::compute_with_static_correction(&rod, 2, &[1.0]).expect("valid beam");
    let tubes = ModalBasis::compute_with_static_correction(&tube, 2, &[1.0]).expect("valid beam");
    let tip = |spec: &BeamSpec| 3.0 * spec.bending_stiffness() / spec.length.powi(3);
    let (k_rod, k_tube, kc) = (tip(&rod), tip(&tube), 2e3);
    let load = 20.0;
    let force = kc / k_rod * load / (1.0 + kc / k_rod + kc / k_tube);
    let (u_rod, u_tube) = ((load - force) / k_rod, force / k_tube);
    let first = rods.angular_frequencies()[0];
    let ramp = 40.0 / first;
    for (kind, scheme) in SCHEMES {
        let contacts = vec![Contact {
            stiffness: kc,
            ..contact(Body::Pin(0), Body::Pin(1), 1.0, 0.0)
        }];
        let mut pair = model(&rods, 2, contacts, vec![0.0, 0.0], kind);
        pair.base_acceleration = None;
        pair.damping_ratios = vec![0.1; rods.modes()];
        pair.kinds = vec![BodyKind {
            basis: &tubes,
            damping_ratios: vec![0.1; tubes.modes()],
            pins: vec![1],
            envelope_weight: 1.0,
        }];
        pair.point_forces = vec![PointForce {
            line: 0,
            height: 1.0,
            force: Table::ramp_and_hold(ramp, load),
        }];
        let dt = 0.5 * critical_time_step(&pair, Scheme::CentralDifference);
        let result = run(
            &pair,
            &Settings {
                threads: threads(kind),
                output_interval: Some(1e-3),
                ..settings(scheme, dt, ramp + 80.0 / first)
            },
        );
        let settled = |history: &[f64]| *history.last().expect("samples");
        let (f, rod_tip, tube_tip) = (
            settled(&result.contact_forces[0]),
            settled(&result.deflections[0][0]),
            settled(&result.deflections[0][1]),
        );
        assert!(
            (f - force).abs() < 1e-3 * force,
            "{kind:?} {scheme:?}: F {f} vs statics {force}"
        );
        assert!(
            (rod_tip - u_rod).abs() < 1e-3 * u_rod,
            "{kind:?}: rod {rod_tip} vs {u_rod}"
        );
        assert!(
            (tube_tip - u_tube).abs() < 1e-3 * u_tube,
            "{kind:?}: tube {tube_tip} vs {u_tube}"
        );
    }
}

/// The critical step of a row of two kinds is that of the generalised eigenproblem
/// (K̄, M̄) with each pin's modal masses μ: checked against the dense eigenvalues of
/// M̄^{-½} K̄ M̄^{-½} assembled here by hand.
#[test]
fn the_critical_step_of_two_kinds_is_that_of_their_masses_and_stiffnesses() {
    let (rod, tube) = (default_tube(10), guide_tube(10));
    let rods = ModalBasis::compute(&rod, 3).expect("valid beam");
    let tubes = ModalBasis::compute(&tube, 3).expect("valid beam");
    let mu = relative_mass(&rods, &tubes).expect("scaled");
    let contacts = vec![Contact {
        stiffness: 1e7,
        ..contact(Body::Pin(0), Body::Pin(1), 1.0, 0.0)
    }];
    let mut pair = model(&rods, 2, contacts, vec![], Loop::Row);
    pair.kinds = vec![BodyKind {
        basis: &tubes,
        damping_ratios: vec![0.0; 3],
        pins: vec![1],
        envelope_weight: 1.0,
    }];
    // K̄ in η: diag(ω_r², μ ω_t²) + Kc b bᵀ, M̄ = diag(1, μ); b = (ψ(L), −ψ(L)).
    let psi = rods.deflection_at(1.0);
    let n = 3;
    let mut k = faer::Mat::<f64>::zeros(2 * n, 2 * n);
    let masses = [1.0, mu];
    for i in 0..n {
        k[(i, i)] = rods.angular_frequencies()[i].powi(2);
        k[(n + i, n + i)] = mu * tubes.angular_frequencies()[i].powi(2);
    }
    for (a, sa) in [(0, 1.0), (1, -1.0)] {
        for (b, sb) in [(0, 1.0), (1, -1.0)] {
            for i in 0..n {
                for j in 0..n {
                    k[(a * n + i, b * n + j)] += 1e7 * sa * sb * psi[i] * psi[j];
                }
            }
        }
    }
    let scaled = faer::Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| {
        k[(i, j)] / (masses[i / n] * masses[j / n]).sqrt()
    });
    let top = scaled
        .self_adjoint_eigenvalues(faer::Side::Lower)
        .expect("symmetric")
        .into_iter()
        .fold(0.0_f64, f64::max);
    let expected = 2.0 / top.sqrt();
    let step = critical_time_step(&pair, Scheme::CentralDifference);
    assert!((step - expected).abs() < 1e-9 * expected, "{step} vs {expected}");
    // A light guide tube (μ < 1) would be quicker than the rods: the mass matters.
    assert!((mu - 1.0).abs() > 0.1);
}

#[test]
fn kinds_that_are_not_the_basis_beam_scaled_and_pins_without_a_kind_are_refused() {
    let rods = ModalBasis::compute(&default_tube(20), 4).expect("valid beam");
    let pinned = ModalBasis::compute(
        &BeamSpec {
            top: crate::beam::Support::Pinned,
            ..guide_tube(20)
        },
        4,
    )
    .expect("valid beam");
    let coarse = ModalBasis::compute(&guide_tube(10), 4).expect("valid beam");
    let sheared = ModalBasis::compute(
        &BeamSpec {
            shear: Some(Shear {
                coefficient: 0.5,
                poisson_ratio: 0.3,
            }),
            ..guide_tube(20)
        },
        4,
    )
    .expect("valid beam");
    let tubes = ModalBasis::compute(&guide_tube(20), 4).expect("valid beam");
    let contacts = vec![contact(Body::Pin(0), Body::Pin(1), 1.0, 1e-4)];
    for (basis, pins, ratios, field, reason) in [
        (&pinned, vec![1], 4, "kinds/0/basis", "supports"),
        (&coarse, vec![1], 4, "kinds/0/basis", "elements"),
        (&sheared, vec![1], 4, "kinds/0/basis", "shape"),
        (&tubes, vec![2], 4, "kinds/0/pins/0", "does not exist"),
        (&tubes, vec![1, 1], 4, "kinds/0/pins/1", "already"),
        (&tubes, vec![1], 3, "kinds/0/damping_ratios", "one ratio per mode"),
    ] {
        let mut pair = model(&rods, 2, contacts.clone(), vec![], Loop::Row);
        pair.kinds = vec![BodyKind {
            basis,
            damping_ratios: vec![0.01; ratios],
            pins,
            envelope_weight: 1.0,
        }];
        let issues = pair.validate();
        assert!(
            issues
                .iter()
                .any(|i| i.field == field && i.reason.contains(reason)),
            "{field} ({reason}): {issues:?}"
        );
    }
}

/// The bending envelope compares pins by their curvature times their kind's weight (its
/// stress per unit curvature) and reports the chosen pin's own curvature: a guide tube
/// bent half as much as a rod but five times as stressed per unit curvature is the one
/// at the foot.
#[test]
fn the_bending_envelope_holds_the_pin_its_weights_make_the_most_stressed() {
    let rods = ModalBasis::compute(&default_tube(20), 3).expect("valid beam");
    let tubes = ModalBasis::compute(&guide_tube(20), 3).expect("valid beam");
    for (weight, expected) in [(1.0, 0), (5.0, 1)] {
        let mut pair = model(&rods, 2, vec![], vec![2e-3, 1e-3], Loop::Row);
        pair.base_acceleration = None;
        pair.kinds = vec![BodyKind {
            basis: &tubes,
            damping_ratios: vec![0.0; 3],
            pins: vec![1],
            envelope_weight: weight,
        }];
        let result = run(
            &pair,
            &Settings {
                output_interval: Some(1e-4),
                ..settings(Scheme::CentralDifference, 2e-6, 0.05)
            },
        );
        let foot = result.curvature_envelope[0];
        assert_eq!(foot.pin, expected, "weight {weight}: {foot:?}");
        let own = result.pin_curvatures[expected].curvature;
        assert!((foot.curvature - own).abs() <= 1e-12 * own, "{foot:?} vs {own}");
    }
}
