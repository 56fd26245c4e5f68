//! The compact description of a wire-wrapped hexagonal bundle ([`HexLayout`]), its
//! validation, and the validated bundle ([`HexBundle`]) that knows its lattice, wrapper
//! and levels and generates the contacts ([`super::contacts`]).

use super::helix::{Handedness, Helix, Level};
use super::lattice::{Lattice, pin_count};
use super::vector::Vec2;
use super::wrapper::{Flat, minimum_flat_to_flat, wall_clearance};
use crate::{InputIssue, decimal, require_positive};

/// Most rings a bundle may have: 9 rings, 271 pins (the largest common designs).
pub const MAX_RINGS: usize = 9;
/// Most contact levels (one every H/12) on a pin.
pub const MAX_LEVELS: usize = 100_000;
/// Relative tolerance on the geometric bounds: inputs given exactly at a bound in decimals
/// (P = D + d_w = 10.7 mm, where 9.7e-3 + 1e-3 rounds to 0.010700000000000001) pass, and
/// the clearance they leave is 0.
const BOUND_ROUNDING: f64 = 1e-12;

/// A wire-wrapped hexagonal bundle in its wrapper tube (lengths in m, angles in rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HexLayout {
    /// n, rings of pins around the centre pin: 1..=[`MAX_RINGS`], N = 3n(n + 1) + 1 pins.
    pub rings: usize,
    /// P, distance between neighbouring pin centres (m), ≥ D + d_w.
    pub pitch: f64,
    /// D, outer diameter of the clad (m), > 0: the pin section's outer diameter.
    pub pin_diameter: f64,
    /// d_w, spacer wire diameter (m), > 0.
    pub wire_diameter: f64,
    /// H, axial length of one wire turn (m), ≥ 6 element lengths.
    pub wire_lead: f64,
    /// F, inner flat-to-flat distance of the wrapper (m), ≥ √3·n·P + D + 2d_w.
    pub wrapper_flat_to_flat: f64,
    /// θ₀, direction of every wire at the pin foot (rad, counter-clockwise from +x).
    pub wire_start_angle: f64,
    pub handedness: Handedness,
}

impl HexLayout {
    /// The wires' common helix.
    pub fn helix(&self) -> Helix {
        Helix {
            start_angle: self.wire_start_angle,
            lead: self.wire_lead,
            handedness: self.handedness,
        }
    }

    /// Every problem with the layout on pins of `pin_length` m meshed with `elements`
    /// beam elements. Field paths are the layout's field names; the pin's own data are
    /// reported at `pin_length` and `elements`.
    pub fn validate(&self, pin_length: f64, elements: usize) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if self.rings == 0 {
            issues.push(InputIssue::new(
                "rings",
                format!("must be at least 1 (7 pins) and at most {MAX_RINGS}, got 0"),
            ));
        } else if self.rings > MAX_RINGS {
            issues.push(InputIssue::new(
                "rings",
                format!(
                    "must be at most {MAX_RINGS} ({} pins), got {}",
                    pin_count(MAX_RINGS),
                    self.rings
                ),
            ));
        }
        let before = issues.len();
        require_positive(&mut issues, "pitch", self.pitch);
        require_positive(&mut issues, "pin_diameter", self.pin_diameter);
        require_positive(&mut issues, "wire_diameter", self.wire_diameter);
        require_positive(&mut issues, "wrapper_flat_to_flat", self.wrapper_flat_to_flat);
        let sizes_ok = issues.len() == before;
        let lead_ok = {
            let before = issues.len();
            require_positive(&mut issues, "wire_lead", self.wire_lead);
            issues.len() == before
        };
        if !self.wire_start_angle.is_finite() {
            issues.push(InputIssue::new("wire_start_angle", "must be a finite number"));
        }
        let length_ok = {
            let before = issues.len();
            require_positive(&mut issues, "pin_length", pin_length);
            issues.len() == before
        };
        if elements == 0 {
            issues.push(InputIssue::new("elements", "must be at least 1"));
        }

        let touching = self.pin_diameter + self.wire_diameter;
        if sizes_ok && self.pitch < touching * (1.0 - BOUND_ROUNDING) {
            issues.push(InputIssue::new(
                "pitch",
                format!(
                    "must be ≥ D + d_w = {} m (clad and wire of neighbours would \
                     overlap), got {} m",
                    decimal(touching),
                    self.pitch
                ),
            ));
        }
        if sizes_ok && (1..=MAX_RINGS).contains(&self.rings) {
            let needed = minimum_flat_to_flat(self.rings, self.pitch, self.pin_diameter, self.wire_diameter);
            let clearance = wall_clearance(
                self.wrapper_flat_to_flat,
                self.rings,
                self.pitch,
                self.pin_diameter,
                self.wire_diameter,
            );
            if clearance < -BOUND_ROUNDING * needed {
                issues.push(InputIssue::new(
                    "wrapper_flat_to_flat",
                    format!(
                        "must be ≥ √3·n·P + D + 2·d_w = {} m to hold {} rings, got {} m \
                         (wall clearance {} m)",
                        decimal(needed),
                        self.rings,
                        self.wrapper_flat_to_flat,
                        decimal(clearance)
                    ),
                ));
            }
        }
        if lead_ok && length_ok && elements > 0 {
            let element_length = pin_length / elements as f64;
            let shortest = 6.0 * element_length;
            if self.wire_lead < shortest * (1.0 - BOUND_ROUNDING) {
                issues.push(InputIssue::new(
                    "wire_lead",
                    format!(
                        "must be ≥ 6 element lengths = {} m (a new neighbour every H/6 \
                         needs at least one element between levels; element L/{elements} = \
                         {} m), got {} m",
                        decimal(shortest),
                        decimal(element_length),
                        self.wire_lead
                    ),
                ));
            } else if self.wire_start_angle.is_finite() {
                let levels = self.helix().level_count(pin_length);
                if levels > MAX_LEVELS {
                    issues.push(InputIssue::new(
                        "wire_lead",
                        format!(
                            "gives {levels} contact levels (one every H/12), more than \
                             {MAX_LEVELS}: must be ≥ {} m",
                            decimal(12.0 * pin_length / MAX_LEVELS as f64)
                        ),
                    ));
                }
            }
        }
        issues
    }
}

/// A validated bundle: lattice, wrapper and levels, ready to generate contacts.
#[derive(Debug, Clone, PartialEq)]
pub struct HexBundle {
    layout: HexLayout,
    pin_length: f64,
    lattice: Lattice,
    levels: Vec<Level>,
    /// `facing[k]`: the pins facing flat k, in pin order.
    facing: [Vec<usize>; 6],
}

impl HexBundle {
    /// The bundle of `layout` on pins of `pin_length` m meshed with `elements` elements,
    /// or every problem ([`HexLayout::validate`]). O(pins + levels).
    pub fn new(layout: HexLayout, pin_length: f64, elements: usize) -> Result<Self, Vec<InputIssue>> {
        let issues = layout.validate(pin_length, elements);
        if !issues.is_empty() {
            return Err(issues);
        }
        let lattice = Lattice::new(layout.rings);
        let facing = Flat::ALL.map(|flat| {
            (0..lattice.pin_count())
                .filter(|&pin| flat.faced_by(lattice.site(pin), layout.rings))
                .collect()
        });
        Ok(Self {
            levels: layout.helix().levels(pin_length),
            layout,
            pin_length,
            lattice,
            facing,
        })
    }

    pub fn layout(&self) -> &HexLayout {
        &self.layout
    }

    /// L (m).
    pub fn pin_length(&self) -> f64 {
        self.pin_length
    }

    pub fn lattice(&self) -> &Lattice {
        &self.lattice
    }

    pub fn pin_count(&self) -> usize {
        self.lattice.pin_count()
    }

    /// Centre of `pin` (m).
    pub fn position(&self, pin: usize) -> Vec2 {
        self.lattice.position(pin, self.layout.pitch)
    }

    /// The contact levels, lowest first ([`super::helix`]).
    pub fn levels(&self) -> &[Level] {
        &self.levels
    }

    /// The pins facing `flat`, in pin order (n + 1 of them).
    pub fn facing(&self, flat: Flat) -> &[usize] {
        &self.facing[flat.index()]
    }

    /// The flats `pin` faces: none for inner pins, one on a side, two at a corner.
    pub fn flats_faced(&self, pin: usize) -> impl Iterator<Item = Flat> + '_ {
        let site = self.lattice.site(pin);
        Flat::ALL
            .into_iter()
            .filter(move |flat| flat.faced_by(site, self.layout.rings))
    }

    /// Nominal wire-to-clad clearance between neighbours, P − D − d_w (m); within
    /// rounding of 0 (P = D + d_w given in decimals) it is 0.
    pub fn pin_clearance(&self) -> f64 {
        let layout = &self.layout;
        snap_to_zero(
            layout.pitch - layout.pin_diameter - layout.wire_diameter,
            layout.pitch,
        )
    }

    /// Nominal wire-to-flat clearance of the pins facing a flat,
    /// F/2 − n·P·√3/2 − D/2 − d_w (m): the same for every flat and facing pin; within
    /// rounding of 0 (F given at its minimum) it is 0.
    pub fn wall_clearance(&self) -> f64 {
        let layout = &self.layout;
        let clearance = wall_clearance(
            layout.wrapper_flat_to_flat,
            layout.rings,
            layout.pitch,
            layout.pin_diameter,
            layout.wire_diameter,
        );
        snap_to_zero(clearance, layout.wrapper_flat_to_flat)
    }
}

/// `clearance`, or 0 when it is within [`BOUND_ROUNDING`] × `scale` of 0 (or below: only
/// rounding can leave it negative once the layout is valid).
fn snap_to_zero(clearance: f64, scale: f64) -> f64 {
    if clearance <= BOUND_ROUNDING * scale {
        0.0
    } else {
        clearance
    }
}
