//! Acceptance of the hexagonal geometry (issue 18), checked against the geometry itself:
//! pin centres, distances and projections computed here with plain trigonometry, and the
//! wire direction φ(z) = θ₀ + s·2πz/H evaluated here, never against the generator's own
//! tables. The design is ASTRID-like (BRIEF §12): 217 pins, D 9.7 mm, P 10.7 mm, wire
//! 1 mm, lead 0.18 m, pins 1.8 m, 0.5 mm between wires and wrapper.

use std::collections::{HashMap, HashSet};
use std::f64::consts::{FRAC_PI_3, PI, TAU};

use super::*;
use crate::InputIssue;

const PITCH: f64 = 10.7e-3;
const PIN_DIAMETER: f64 = 9.7e-3;
const WIRE: f64 = 1.0e-3;
const LEAD: f64 = 0.18;
const LENGTH: f64 = 1.8;
const ELEMENTS: usize = 100;
const WALL_GAP: f64 = 0.5e-3;
/// Heights are rounded to 12 significant digits (helix module doc): 1e-12 m on a 1.8 m pin.
const HEIGHT_ROUNDING: f64 = 1e-10;

pub(super) fn astrid(rings: usize, start: f64, handedness: Handedness) -> HexLayout {
    HexLayout {
        rings,
        pitch: PITCH,
        pin_diameter: PIN_DIAMETER,
        wire_diameter: WIRE,
        wire_lead: LEAD,
        // Flat-to-flat from its definition: twice (ring-n row distance + radius + wire + gap).
        wrapper_flat_to_flat: 2.0
            * (rings as f64 * PITCH * 3f64.sqrt() / 2.0 + PIN_DIAMETER / 2.0 + WIRE + WALL_GAP),
        wire_start_angle: start,
        handedness,
    }
}

pub(super) fn bundle(rings: usize, start: f64, handedness: Handedness) -> HexBundle {
    HexBundle::new(astrid(rings, start, handedness), LENGTH, ELEMENTS).expect("a valid layout")
}

/// Wire direction at height z, from the helix's definition.
fn wire_direction(layout: &HexLayout, height: f64) -> Vec2 {
    let sign = match layout.handedness {
        Handedness::Right => 1.0,
        Handedness::Left => -1.0,
    };
    Vec2::from_angle(layout.wire_start_angle + sign * TAU * height / layout.wire_lead)
}

/// Pin centres by trigonometry: ring k's corners at k·P on the rays j·60°, its sides
/// walked counter-clockwise, the numbering the module documents.
fn centres(rings: usize) -> Vec<Vec2> {
    let mut centres = vec![Vec2::ZERO];
    for ring in 1..=rings {
        for side in 0..6 {
            let corner = (ring as f64 * PITCH) * Vec2::from_angle(side as f64 * FRAC_PI_3);
            let along = PITCH * Vec2::from_angle((side + 2) as f64 * FRAC_PI_3);
            for t in 0..ring {
                centres.push(corner + t as f64 * along);
            }
        }
    }
    centres
}

/// The pin whose centre is within 1e-9 m of `point`, if any.
fn pin_near(centres: &[Vec2], point: Vec2) -> Option<usize> {
    centres.iter().position(|c| (*c - point).norm() < 1e-9)
}

fn flat_normal(flat: Flat) -> Vec2 {
    Vec2::from_angle(FRAC_PI_3 * flat.index() as f64 + PI / 6.0)
}

/// A contact as a comparable key: (wire pin, touched pin or 1000 + flat).
fn key(contact: &HexContact) -> (usize, usize) {
    let touched = match contact.touched {
        Body::Pin(pin) => pin,
        Body::Flat(flat) => 1000 + flat.index(),
    };
    (contact.wire_pin, touched)
}

fn by_level(contacts: &[HexContact]) -> Vec<Vec<&HexContact>> {
    let levels = contacts.iter().map(|c| c.level).max().map_or(0, |l| l + 1);
    let mut grouped = vec![Vec::new(); levels];
    for contact in contacts {
        grouped[contact.level].push(contact);
    }
    grouped
}

#[test]
fn the_numbering_puts_pins_where_trigonometry_does() {
    let bundle = bundle(8, 0.0, Handedness::Right);
    let expected = centres(8);
    assert_eq!(bundle.pin_count(), 217);
    assert_eq!(expected.len(), 217);
    for (pin, centre) in expected.iter().enumerate() {
        let error = (bundle.position(pin) - *centre).norm();
        assert!(
            error < 1e-15,
            "pin {pin}: {:?} vs {centre:?}",
            bundle.position(pin)
        );
    }
}

#[test]
fn a_217_pin_bundle_has_600_pairs_met_twice_per_lead_1200_pin_pin_contacts() {
    // Pairs counted from the centres: pins one pitch apart.
    let centres = centres(8);
    let mut pairs = 0;
    for a in 0..centres.len() {
        for b in a + 1..centres.len() {
            if ((centres[b] - centres[a]).norm() - PITCH).abs() < 1e-9 {
                pairs += 1;
            }
        }
    }
    assert_eq!(pairs, 600, "pairs one pitch apart among 217 centres");
    for start in [0.0, 0.37, -2.9] {
        let bundle = bundle(8, start, Handedness::Right);
        let contacts = bundle.contacts();
        assert_eq!(contacts.len(), bundle.contact_count());
        // Every window of one lead (z0, z0 + H] meets each pair twice, once per wire.
        for window_start in [0.0, 0.07, 0.9, LENGTH - LEAD] {
            let mut met: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
            for contact in &contacts {
                if let Body::Pin(b) = contact.touched
                    && contact.height > window_start + HEIGHT_ROUNDING
                    && contact.height <= window_start + LEAD + HEIGHT_ROUNDING
                {
                    let a = contact.wire_pin;
                    met.entry((a.min(b), a.max(b))).or_default().push(a);
                }
            }
            let count: usize = met.values().map(Vec::len).sum();
            assert_eq!(
                count, 1200,
                "θ₀ = {start}: pin–pin contacts in ({window_start}, +H]"
            );
            assert_eq!(met.len(), 600, "θ₀ = {start}: pairs met in ({window_start}, +H]");
            for ((a, b), wires) in &met {
                let mut wires = wires.clone();
                wires.sort_unstable();
                assert_eq!(wires, [*a, *b], "pair ({a}, {b}): once by each pin's wire");
            }
        }
    }
    // θ₀ = 0 on 1.8 m: exactly ten leads, 12 000 pin–pin and 10 × 6 × 9 wall contacts.
    let contacts = bundle(8, 0.0, Handedness::Right).contacts();
    let walls = contacts
        .iter()
        .filter(|c| matches!(c.touched, Body::Flat(_)))
        .count();
    assert_eq!((contacts.len() - walls, walls), (12_000, 540));
}

#[test]
fn the_two_contacts_of_a_pair_are_half_a_lead_apart() {
    for handedness in [Handedness::Right, Handedness::Left] {
        let contacts = bundle(4, 0.8, handedness).contacts();
        let mut by_pair: HashMap<(usize, usize), Vec<&HexContact>> = HashMap::new();
        for contact in &contacts {
            if let Body::Pin(b) = contact.touched {
                let a = contact.wire_pin;
                by_pair.entry((a.min(b), a.max(b))).or_default().push(contact);
            }
        }
        assert_eq!(by_pair.len(), 3 * 4 * (3 * 4 + 1));
        for ((a, b), meetings) in by_pair {
            for pair in meetings.windows(2) {
                let spacing = pair[1].height - pair[0].height;
                assert!(
                    (spacing - LEAD / 2.0).abs() < HEIGHT_ROUNDING,
                    "pair ({a}, {b}): contacts at {} and {} m, {spacing} apart, expected H/2 = {}",
                    pair[0].height,
                    pair[1].height,
                    LEAD / 2.0
                );
                assert_ne!(
                    pair[0].wire_pin, pair[1].wire_pin,
                    "pair ({a}, {b}): wires alternate"
                );
            }
        }
    }
}

#[test]
fn every_level_holds_exactly_the_contacts_the_wire_direction_makes() {
    let layout = astrid(3, 0.45, Handedness::Left);
    let bundle = HexBundle::new(layout, LENGTH, ELEMENTS).unwrap();
    let centres = centres(3);
    let outer_row = 3.0 * PITCH * 3f64.sqrt() / 2.0;
    let contacts = bundle.contacts();
    let levels = by_level(&contacts);
    assert_eq!(levels.len(), bundle.levels().len());
    for (level, found) in levels.iter().enumerate() {
        let height = bundle.levels()[level].height;
        let wire = wire_direction(&layout, height);
        // Expected: each pin with a centre one pitch along the wire, or each outer-row pin
        // when the wire points along a flat's normal.
        let mut expected = HashSet::new();
        for (a, centre) in centres.iter().enumerate() {
            if let Some(b) = pin_near(&centres, *centre + PITCH * wire) {
                expected.insert((a, b));
            }
            for flat in Flat::ALL {
                let along_normal = (wire - flat_normal(flat)).norm() < 1e-9;
                if along_normal && (centre.dot(flat_normal(flat)) - outer_row).abs() < 1e-12 {
                    expected.insert((a, 1000 + flat.index()));
                }
            }
        }
        let keys: HashSet<(usize, usize)> = found.iter().map(|c| key(c)).collect();
        assert_eq!(keys.len(), found.len(), "level {level}: a contact listed twice");
        assert_eq!(keys, expected, "level {level} at {height} m, wire at {:?}", wire);
        assert!(!found.is_empty(), "level {level}: a level without contacts");
        for contact in found {
            assert_eq!(contact.height, height);
            assert!(
                (contact.normal - wire).norm() < 1e-9,
                "level {level}: normal along the wire"
            );
        }
    }
    // The wire points at a multiple of 30° once per H/12: no level missed.
    assert_eq!(levels.len(), (LENGTH / (LEAD / 12.0)).floor() as usize);
}

#[test]
fn a_sixth_of_a_lead_up_the_contacts_are_those_below_turned_by_60_degrees() {
    // The whole bundle, wrapper included, is 6-fold symmetric, so the rotation holds for
    // the wall contacts too: flat k's become flat k ± 1's (± the handedness).
    for handedness in [Handedness::Right, Handedness::Left] {
        let bundle = bundle(8, 1.1, handedness);
        let centres = centres(8);
        let turn = match handedness {
            Handedness::Right => FRAC_PI_3,
            Handedness::Left => -FRAC_PI_3,
        };
        let contacts = bundle.contacts();
        let levels = by_level(&contacts);
        for level in 0..levels.len() - 2 {
            let rise = bundle.levels()[level + 2].height - bundle.levels()[level].height;
            assert!(
                (rise - LEAD / 6.0).abs() < HEIGHT_ROUNDING,
                "levels {level}, +2: {rise} m apart"
            );
            let turned: HashSet<(usize, usize)> = levels[level]
                .iter()
                .map(|c| {
                    let a = pin_near(&centres, centres[c.wire_pin].rotated(turn)).unwrap();
                    let b = match c.touched {
                        Body::Pin(b) => pin_near(&centres, centres[b].rotated(turn)).unwrap(),
                        Body::Flat(flat) => {
                            let normal = flat_normal(flat).rotated(turn);
                            1000 + Flat::ALL
                                .iter()
                                .position(|f| (flat_normal(*f) - normal).norm() < 1e-9)
                                .unwrap()
                        }
                    };
                    (a, b)
                })
                .collect();
            let above: HashSet<(usize, usize)> = levels[level + 2].iter().map(|c| key(c)).collect();
            assert_eq!(
                above,
                turned,
                "{handedness:?}: level {} vs level {level} turned",
                level + 2
            );
        }
    }
}

#[test]
fn nominal_clearances_come_from_the_geometry_and_are_6_fold_symmetric() {
    let layout = astrid(8, 0.0, Handedness::Right);
    let bundle = HexBundle::new(layout, LENGTH, ELEMENTS).unwrap();
    let centres = centres(8);
    for contact in bundle.contacts() {
        let expected = match contact.touched {
            Body::Pin(_) => (PITCH - PIN_DIAMETER - WIRE).max(0.0),
            Body::Flat(flat) => {
                let projection = centres[contact.wire_pin].dot(flat_normal(flat));
                layout.wrapper_flat_to_flat / 2.0 - projection - PIN_DIAMETER / 2.0 - WIRE
            }
        };
        assert!(
            (contact.clearance - expected).abs() < 1e-15,
            "{contact:?}: clearance {} vs {expected}",
            contact.clearance
        );
        if matches!(contact.touched, Body::Flat(_)) {
            // Same on every flat, i.e. unchanged by any turn of 60°.
            assert!((contact.clearance - WALL_GAP).abs() < 1e-15, "{contact:?}");
        }
    }
    // A design with a real pin–pin clearance: P − D − d_w.
    let loose = HexBundle::new(
        HexLayout {
            pitch: 11.0e-3,
            wrapper_flat_to_flat: 0.2,
            ..layout
        },
        LENGTH,
        ELEMENTS,
    )
    .unwrap();
    let pin_pin = loose
        .contacts()
        .into_iter()
        .find(|c| c.touched_pin().is_some())
        .unwrap();
    assert!(
        (pin_pin.clearance - 0.3e-3).abs() < 1e-15,
        "{}",
        pin_pin.clearance
    );
}

#[test]
fn normals_are_unit_centre_to_centre_and_opposite_for_the_two_wires_of_a_pair() {
    let bundle = bundle(5, 0.0, Handedness::Right);
    let centres = centres(5);
    let contacts = bundle.contacts();
    let mut normals: HashMap<(usize, usize), Vec2> = HashMap::new();
    for contact in &contacts {
        assert!((contact.normal.norm() - 1.0).abs() < 1e-15, "{contact:?}");
        if let Body::Pin(b) = contact.touched {
            let between = centres[b] - centres[contact.wire_pin];
            let error = (contact.normal - (1.0 / between.norm()) * between).norm();
            assert!(
                error < 1e-12,
                "{contact:?}: normal off the centre line by {error}"
            );
            normals.insert((contact.wire_pin, b), contact.normal);
        }
    }
    for (&(a, b), &normal) in &normals {
        assert_eq!(normals[&(b, a)], -normal, "pair ({a}, {b}): n_ba = −n_ab exactly");
    }
}

fn fields(issues: &[InputIssue]) -> Vec<&str> {
    issues.iter().map(|issue| issue.field.as_str()).collect()
}

#[test]
fn the_astrid_design_passes_validation_at_its_exact_bounds() {
    // P = D + d_w exactly in decimals (9.7e-3 + 1e-3 rounds above 10.7e-3), and the
    // wrapper at its minimum: zero clearances, not refusals.
    let tight = HexLayout {
        wrapper_flat_to_flat: minimum_flat_to_flat(8, PITCH, PIN_DIAMETER, WIRE),
        ..astrid(8, 0.0, Handedness::Right)
    };
    let bundle = HexBundle::new(tight, LENGTH, 60).expect("lead = 6 elements exactly is enough");
    assert_eq!(bundle.pin_clearance(), 0.0);
    assert_eq!(bundle.wall_clearance(), 0.0);
}

#[test]
fn each_bad_layout_is_refused_at_its_field_with_the_bound_it_broke() {
    let good = astrid(8, 0.0, Handedness::Right);
    let cases: Vec<(HexLayout, f64, usize, &str, &str)> = vec![
        (
            HexLayout { rings: 0, ..good },
            LENGTH,
            ELEMENTS,
            "rings",
            "at least 1",
        ),
        (
            HexLayout { rings: 10, ..good },
            LENGTH,
            ELEMENTS,
            "rings",
            "at most 9 (271 pins)",
        ),
        (
            HexLayout {
                pitch: 10.0e-3,
                ..good
            },
            LENGTH,
            ELEMENTS,
            "pitch",
            "≥ D + d_w = 0.0107",
        ),
        (
            HexLayout {
                wrapper_flat_to_flat: 0.15,
                ..good
            },
            LENGTH,
            ELEMENTS,
            "wrapper_flat_to_flat",
            "√3·n·P + D + 2·d_w = 0.15996",
        ),
        (
            HexLayout {
                wire_lead: 0.1,
                ..good
            },
            LENGTH,
            ELEMENTS,
            "wire_lead",
            "6 element lengths = 0.108",
        ),
        (
            HexLayout {
                wire_start_angle: f64::NAN,
                ..good
            },
            LENGTH,
            ELEMENTS,
            "wire_start_angle",
            "finite",
        ),
        (
            HexLayout {
                wire_diameter: 0.0,
                ..good
            },
            LENGTH,
            ELEMENTS,
            "wire_diameter",
            "positive",
        ),
        (good, -1.0, ELEMENTS, "pin_length", "positive"),
        (good, LENGTH, 0, "elements", "at least 1"),
    ];
    for (layout, length, elements, field, bound) in cases {
        let issues = layout.validate(length, elements);
        assert_eq!(fields(&issues), [field], "{layout:?}: {issues:?}");
        assert!(
            issues[0].reason.contains(bound),
            "{field}: '{}' should state '{bound}'",
            issues[0].reason
        );
        assert_eq!(HexBundle::new(layout, length, elements).unwrap_err(), issues);
    }
    assert!(good.validate(LENGTH, ELEMENTS).is_empty());
}

#[test]
fn a_lead_giving_too_many_levels_is_refused() {
    let layout = HexLayout {
        wire_lead: 1e-6,
        ..astrid(1, 0.0, Handedness::Right)
    };
    let issues = layout.validate(LENGTH, usize::MAX);
    assert_eq!(fields(&issues), ["wire_lead"]);
    assert!(
        issues[0].reason.contains("more than 100000"),
        "{}",
        issues[0].reason
    );
}
