//! Gap states of the hexagonal bundle: each step against its definition (zones found
//! from the pin centres, offsets from the flats' normals), and the invariants they keep.

use std::f64::consts::{FRAC_PI_3, TAU};

use super::super::tests::{astrid, bundle};
use super::*;
use crate::hex::{Handedness, Vec2};

fn gaps_of(
    bundle: &HexBundle,
    state: HexGapState,
    closures: Vec<ZoneClosure>,
    offset: Option<FlatOffset>,
) -> Vec<f64> {
    let spec = HexGaps {
        state,
        closures,
        offset,
    };
    spec.gaps(bundle, &bundle.contacts()).expect("valid gaps")
}

const NOMINAL: HexGapState = HexGapState::Uniform {
    pin_pin: None,
    pin_wall: None,
};

fn fields(issues: &[InputIssue]) -> Vec<&str> {
    issues.iter().map(|issue| issue.field.as_str()).collect()
}

#[test]
fn uniform_gaps_are_the_nominal_clearances_or_the_given_values() {
    let bundle = bundle(3, 0.0, Handedness::Right);
    let contacts = bundle.contacts();
    let nominal = gaps_of(&bundle, NOMINAL, vec![], None);
    assert_eq!(nominal, nominal_gaps(&contacts));
    let given = gaps_of(
        &bundle,
        HexGapState::Uniform {
            pin_pin: Some(1e-5),
            pin_wall: None,
        },
        vec![],
        None,
    );
    for ((contact, gap), nominal) in contacts.iter().zip(&given).zip(&nominal) {
        let expected = if contact.touched_pin().is_some() {
            1e-5
        } else {
            *nominal
        };
        assert_eq!(*gap, expected, "{contact:?}");
    }
}

#[test]
fn random_gaps_are_the_seeded_stream_drawn_in_contact_order() {
    let bundle = bundle(2, 0.3, Handedness::Left);
    let contacts = bundle.contacts();
    let law = GapDistribution::Normal {
        mean: 1e-4,
        std: 5e-5,
    };
    let random = |seed, relative| HexGapState::Random {
        distribution: law.clone(),
        seed,
        relative,
    };
    let drawn = gaps_of(&bundle, random(7, false), vec![], None);
    let mut stream = GapRng::new(7);
    for (k, gap) in drawn.iter().enumerate() {
        assert_eq!(*gap, stream.sample(&law), "contact {k}: the k-th draw of seed 7");
        assert!(*gap >= 0.0);
    }
    assert_eq!(
        drawn,
        gaps_of(&bundle, random(7, false), vec![], None),
        "same seed, same gaps"
    );
    assert_ne!(drawn, gaps_of(&bundle, random(8, false), vec![], None));
    let relative = gaps_of(&bundle, random(7, true), vec![], None);
    for ((gap, draw), contact) in relative.iter().zip(&drawn).zip(&contacts) {
        assert_eq!(*gap, draw * contact.clearance, "{contact:?}");
    }
}

#[test]
fn a_closure_by_rings_scales_exactly_the_contacts_touching_those_rings_on_its_levels() {
    let bundle = bundle(4, 0.0, Handedness::Right);
    let contacts = bundle.contacts();
    let nominal = nominal_gaps(&contacts);
    // Ring from geometry: distance to the centre projected on the nearest flat normal.
    let ring = |pin: usize| {
        let centre = bundle.position(pin);
        let farthest = (0..6)
            .map(|k| centre.dot(Vec2::from_angle(k as f64 * FRAC_PI_3 + FRAC_PI_3 / 2.0)))
            .fold(f64::MIN, f64::max);
        (farthest / (bundle.layout().pitch * 3f64.sqrt() / 2.0)).round() as usize
    };
    let closure = ZoneClosure {
        zone: PinZone::Rings {
            first_ring: 3,
            last_ring: 4,
        },
        first_level: 5,
        last_level: 17,
        factor: 0.25,
    };
    let gaps = gaps_of(&bundle, NOMINAL, vec![closure], None);
    let mut scaled = 0;
    for (k, contact) in contacts.iter().enumerate() {
        let touches = [Some(contact.wire_pin), contact.touched_pin()]
            .into_iter()
            .flatten()
            .any(|pin| (3..=4).contains(&ring(pin)));
        let inside = touches && (5..=17).contains(&contact.level);
        let expected = if inside { 0.25 * nominal[k] } else { nominal[k] };
        assert_eq!(gaps[k], expected, "contact {k}: {contact:?}");
        scaled += inside as usize;
    }
    assert!(scaled > 0, "the zone must hold contacts");
}

#[test]
fn a_closure_by_sectors_follows_the_centre_angles() {
    let bundle = bundle(3, 0.0, Handedness::Right);
    let contacts = bundle.contacts();
    let closure = ZoneClosure {
        zone: PinZone::Sectors {
            first_sector: 1,
            last_sector: 2,
        },
        first_level: 0,
        last_level: bundle.levels().len() - 1,
        factor: 0.0,
    };
    let uniform = HexGapState::Uniform {
        pin_pin: Some(1e-4),
        pin_wall: Some(2e-4),
    };
    let gaps = gaps_of(&bundle, uniform, vec![closure], None);
    // Sectors 1..=2: centre angles in [60°, 180°); the centre pin belongs to no sector.
    let in_zone = |pin: usize| {
        let centre = bundle.position(pin);
        let angle = centre.angle().rem_euclid(TAU) + 1e-9;
        centre.norm() > 0.0 && (FRAC_PI_3..3.0 * FRAC_PI_3).contains(&angle)
    };
    for (contact, gap) in contacts.iter().zip(&gaps) {
        let closed = in_zone(contact.wire_pin) || contact.touched_pin().is_some_and(in_zone);
        assert_eq!(*gap == 0.0, closed, "{contact:?}: gap {gap}");
    }
}

#[test]
fn an_offset_toward_a_flat_moves_every_wall_gap_by_its_normal_and_keeps_pin_gaps() {
    let bundle = bundle(8, 0.0, Handedness::Right);
    let contacts = bundle.contacts();
    let nominal = nominal_gaps(&contacts);
    let wall = bundle.wall_clearance();
    for toward in 0..6 {
        let distance = 0.4 * wall;
        let gaps = gaps_of(
            &bundle,
            NOMINAL,
            vec![],
            Some(FlatOffset {
                flat: toward,
                distance,
            }),
        );
        let shift = distance * Vec2::from_angle(toward as f64 * FRAC_PI_3 + FRAC_PI_3 / 2.0);
        let mut change_per_lead = 0.0;
        for (k, contact) in contacts.iter().enumerate() {
            let expected = match contact.touched {
                Body::Pin(_) => nominal[k],
                // The pins move by `shift`: the wire–flat gap shrinks by shift·n.
                Body::Flat(_) => nominal[k] - shift.dot(contact.normal),
            };
            assert!(
                (gaps[k] - expected).abs() < 1e-15,
                "toward {toward}, {contact:?}: {} vs {expected}",
                gaps[k]
            );
            if contact.level < 12 {
                change_per_lead += gaps[k] - nominal[k];
            }
        }
        // Over one lead each flat is met by n + 1 wires: the changes cancel.
        assert!(
            change_per_lead.abs() < 1e-15,
            "toward {toward}: total change {change_per_lead}"
        );
        let on_flat = |flat: usize| {
            contacts
                .iter()
                .zip(&gaps)
                .filter(move |(c, _)| c.touched == Body::Flat(Flat::ALL[flat]))
                .map(|(_, g)| *g)
        };
        assert!(on_flat(toward).all(|g| (g - (wall - distance)).abs() < 1e-15));
        assert!(on_flat((toward + 3) % 6).all(|g| (g - (wall + distance)).abs() < 1e-15));
    }
}

#[test]
fn an_offset_may_close_the_wall_gaps_but_not_cross_them() {
    let bundle = bundle(2, 0.0, Handedness::Right);
    let wall = bundle.wall_clearance();
    let pressed = gaps_of(
        &bundle,
        NOMINAL,
        vec![],
        Some(FlatOffset {
            flat: 4,
            distance: wall,
        }),
    );
    let contacts = bundle.contacts();
    for (contact, gap) in contacts.iter().zip(&pressed) {
        if contact.touched == Body::Flat(Flat::ALL[4]) {
            assert_eq!(*gap, 0.0, "{contact:?}: pressed onto its flat");
        }
        assert!(*gap >= 0.0);
    }
    let spec = HexGaps {
        state: NOMINAL,
        closures: vec![],
        offset: Some(FlatOffset {
            flat: 4,
            distance: 1.5 * wall,
        }),
    };
    let issues = spec.gaps(&bundle, &contacts).unwrap_err();
    assert_eq!(fields(&issues), ["offset/distance"]);
    assert!(
        issues[0].reason.contains(&format!("≤ {wall} m")),
        "{}",
        issues[0].reason
    );
}

#[test]
fn each_bad_gap_input_is_refused_at_its_field_with_the_bound_it_broke() {
    let bundle = bundle(8, 0.0, Handedness::Right);
    let levels = bundle.levels().len();
    let closure = |zone, last_level, factor| ZoneClosure {
        zone,
        first_level: 0,
        last_level,
        factor,
    };
    let rings = |first_ring, last_ring| PinZone::Rings {
        first_ring,
        last_ring,
    };
    let sectors = |first_sector, last_sector| PinZone::Sectors {
        first_sector,
        last_sector,
    };
    let with = |state: HexGapState, closures: Vec<ZoneClosure>, offset| HexGaps {
        state,
        closures,
        offset,
    };
    let cases = [
        (
            with(NOMINAL, vec![closure(rings(0, 9), 3, 0.0)], None),
            "closures/0/last_ring",
            "≤ 8",
        ),
        (
            with(NOMINAL, vec![closure(rings(5, 2), 3, 0.0)], None),
            "closures/0/last_ring",
            "≥ first_ring (5)",
        ),
        (
            with(NOMINAL, vec![closure(sectors(0, 6), 3, 0.0)], None),
            "closures/0/last_sector",
            "≤ 5",
        ),
        (
            with(NOMINAL, vec![closure(rings(0, 1), levels, 0.0)], None),
            "closures/0/last_level",
            "≤ 119",
        ),
        (
            with(NOMINAL, vec![closure(rings(0, 1), 3, -1.0)], None),
            "closures/0/factor",
            "negative",
        ),
        (
            with(
                NOMINAL,
                vec![],
                Some(FlatOffset {
                    flat: 6,
                    distance: 0.0,
                }),
            ),
            "offset/flat",
            "≤ 5",
        ),
        (
            with(
                NOMINAL,
                vec![],
                Some(FlatOffset {
                    flat: 0,
                    distance: -1e-4,
                }),
            ),
            "offset/distance",
            "negative",
        ),
        (
            with(
                HexGapState::Uniform {
                    pin_pin: Some(-1e-4),
                    pin_wall: None,
                },
                vec![],
                None,
            ),
            "gaps/pin_pin",
            "negative",
        ),
        (
            with(HexGapState::PerContact(vec![0.0; 3]), vec![], None),
            "gaps/values",
            "expected 12540 gaps",
        ),
        (
            with(
                HexGapState::Random {
                    distribution: GapDistribution::Uniform {
                        low: 2e-4,
                        high: 1e-4,
                    },
                    seed: 1,
                    relative: false,
                },
                vec![],
                None,
            ),
            "gaps/distribution/high",
            "≥ low",
        ),
    ];
    for (spec, field, bound) in cases {
        let issues = spec.validate(&bundle);
        assert_eq!(fields(&issues), [field], "{spec:?}: {issues:?}");
        assert!(
            issues[0].reason.contains(bound),
            "{field}: '{}' should state '{bound}'",
            issues[0].reason
        );
        assert_eq!(spec.gaps(&bundle, &bundle.contacts()).unwrap_err(), issues);
    }
    let mut values = vec![1e-4; bundle.contact_count()];
    values[3] = -1.0;
    let issues = with(HexGapState::PerContact(values), vec![], None).validate(&bundle);
    assert_eq!(fields(&issues), ["gaps/values/3"]);
    // Sanity: the layout these tests use is the documented one.
    assert_eq!(astrid(8, 0.0, Handedness::Right).rings, 8);
}
