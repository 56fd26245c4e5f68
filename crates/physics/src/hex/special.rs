//! Special cases built for the equivalence checks of issue 18: contact lists in the
//! hexagonal bundle's conventions whose answer another model already knows.
//! - [`row_along`]: the row's pin–pin contacts laid along any angle α. Two pins (or a
//!   row) whose contact normals are at α, excited along α, must move exactly as the row
//!   (`bundle-dynamics`) does along x: with u_p = w_p·n, δ = n·(u_a − u_b) − gap =
//!   w_a − w_b − gap, the row's δ. The row's wall contacts have no counterpart here (the
//!   wrapper's flats have fixed directions): compare with a row whose wall gaps cannot
//!   close, or keep only the row's pin–pin contacts.
//! - [`single_pin_in_wrapper`]: one pin with a contact on each of the six flats at every
//!   level; the model is 6-fold symmetric, so an excitation at θ + 60° gives the results
//!   at θ turned by 60° (flat k's contact becomes flat k + 1's).

use super::contacts::{Body, HexContact};
use super::vector::Vec2;
use super::wrapper::Flat;

/// A row of pins along a direction, in the hexagonal conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct RowEquivalent {
    /// Centre of pin p (m): p·P·(cos α, sin α).
    pub positions: Vec<Vec2>,
    /// Level by level, pin p → p + 1 (wire_pin p, touched p + 1, normal (cos α, sin α)).
    pub contacts: Vec<HexContact>,
    /// For each contact, the index of the same contact in the row's expansion order
    /// (`bundle.rs`: level·(pins + 1) + slot, slot p + 1 between pins p and p + 1).
    pub row_indices: Vec<usize>,
}

/// The pin–pin contacts of a row of `pins` pins at spacing `pitch` (m) laid along
/// `angle` α (rad), at `heights` (m, the row's levels) with clearance `pin_gap` (m).
pub fn row_along(pins: usize, pitch: f64, angle: f64, heights: &[f64], pin_gap: f64) -> RowEquivalent {
    let normal = Vec2::from_angle(angle);
    let pairs = pins.saturating_sub(1);
    let mut contacts = Vec::with_capacity(heights.len() * pairs);
    let mut row_indices = Vec::with_capacity(heights.len() * pairs);
    for (level, &height) in heights.iter().enumerate() {
        for pin in 0..pairs {
            contacts.push(HexContact {
                level,
                height,
                wire_pin: pin,
                touched: Body::Pin(pin + 1),
                normal,
                clearance: pin_gap,
            });
            row_indices.push(level * (pins + 1) + pin + 1);
        }
    }
    RowEquivalent {
        positions: (0..pins).map(|p| (p as f64 * pitch) * normal).collect(),
        contacts,
        row_indices,
    }
}

/// Pin 0 alone in the wrapper, with a contact on each flat (0..6, in order) at each of
/// `heights` (m), every one with clearance `gap` (m).
pub fn single_pin_in_wrapper(heights: &[f64], gap: f64) -> Vec<HexContact> {
    heights
        .iter()
        .enumerate()
        .flat_map(|(level, &height)| {
            Flat::ALL.into_iter().map(move |flat| HexContact {
                level,
                height,
                wire_pin: 0,
                touched: Body::Flat(flat),
                normal: flat.normal(),
                clearance: gap,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::kinematics::penetration;
    use super::*;

    #[test]
    fn a_row_along_any_angle_sees_the_rows_penetrations() {
        // Pins displaced along the row's direction by w_p: δ must be w_a − w_b − gap.
        let deflections = [3e-4, -1e-4, 2e-4];
        for angle in [0.0, 0.3, 1.0, 2.5, -2.0] {
            let row = row_along(3, 10.7e-3, angle, &[0.9, 1.8], 1e-4);
            assert_eq!(row.contacts.len(), 4);
            assert_eq!(row.row_indices, [1, 2, 5, 6], "row slots 1, 2 of levels 0, 1");
            for contact in &row.contacts {
                let b = contact.touched_pin().unwrap();
                let a = contact.wire_pin;
                let along = (row.positions[b] - row.positions[a]) * (1.0 / 10.7e-3);
                assert!(
                    (along - contact.normal).norm() < 1e-12,
                    "normal from a to b at {angle} rad"
                );
                let displaced = |p: usize| deflections[p] * contact.normal;
                let delta = penetration(contact.normal, contact.clearance, displaced(a), displaced(b));
                let row_delta = deflections[a] - deflections[b] - 1e-4;
                assert!(
                    (delta - row_delta).abs() < 1e-18,
                    "{delta} vs row {row_delta} at {angle} rad"
                );
            }
        }
    }

    #[test]
    fn a_single_pin_touches_every_flat_at_every_level() {
        let contacts = single_pin_in_wrapper(&[0.5, 1.0], 2e-4);
        assert_eq!(contacts.len(), 12);
        for (k, contact) in contacts.iter().enumerate() {
            assert_eq!(contact.touched, Body::Flat(Flat::ALL[k % 6]));
            assert_eq!(contact.height, if k < 6 { 0.5 } else { 1.0 });
        }
    }
}
