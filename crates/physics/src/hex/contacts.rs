//! The explicit contact list of a hexagonal bundle, from the wire helix
//! ([`super::helix`]).
//!
//! # Contact, bodies, normal
//! A contact joins body a, always a pin (the one whose wire touches: `wire_pin`), and body
//! b (`touched`): a neighbour's clad or a wrapper flat. Its unit normal n lies in the
//! transverse plane and points from a toward b: the direction the wire points (centre to
//! centre for two pins, the flat's outward normal for the wrapper). A displacement of a
//! along n closes the gap: δ = n·(u_a − u_b) − gap ([`super::kinematics`]).
//!
//! # Order (stable: part of the results' contract)
//! Level by level from the lowest; within a level by `wire_pin` in pin numbering order
//! ([`super::lattice`]). A pin–pin level with aim k holds one contact per pin having a
//! neighbour in direction k; a wall level with flat k holds one per pin facing flat k.
//!
//! # Symmetry
//! The bundle, wrapper included, is 6-fold symmetric and every wire turns by s·60° in H/6:
//! the contacts of level k + 2 are those of level k turned by s·60° (pins by
//! [`super::Lattice::rotated`], flat j to flat j + s), wall contacts included.
//!
//! # Counts
//! Each neighbour pair is met twice per lead (by each pin's wire, H/2 apart):
//! 2·3n(3n + 1) pin–pin contacts per lead (n = 8: 1200), and 6(n + 1) wall contacts per
//! lead (n = 8: 54). Generation is O(contacts).

use super::helix::Aim;
use super::layout::HexBundle;
use super::vector::Vec2;
use super::wrapper::Flat;

/// Body b of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Body {
    /// A pin's clad (pin number).
    Pin(usize),
    /// A flat of the wrapper (fixed in the wrapper frame: it moves with the base).
    Flat(Flat),
}

/// One potential contact of the bundle (module doc: conventions).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct HexContact {
    /// Index of the level in [`HexBundle::levels`] (0 = lowest).
    pub level: usize,
    /// Height from the pin feet (m).
    pub height: f64,
    /// Body a: the pin whose wire makes the contact.
    pub wire_pin: usize,
    /// Body b: the clad or flat the wire touches.
    pub touched: Body,
    /// Unit normal from a toward b in the transverse plane (dimensionless).
    pub normal: Vec2,
    /// Nominal clearance from geometry (m): P − D − d_w between pins,
    /// F/2 − n·P·√3/2 − D/2 − d_w to a flat.
    pub clearance: f64,
}

impl HexContact {
    /// The touched pin, if body b is a pin.
    pub fn touched_pin(&self) -> Option<usize> {
        match self.touched {
            Body::Pin(pin) => Some(pin),
            Body::Flat(_) => None,
        }
    }

    /// Whether `pin` is one of the contact's bodies.
    pub fn involves(&self, pin: usize) -> bool {
        self.wire_pin == pin || self.touched_pin() == Some(pin)
    }
}

impl HexBundle {
    /// How many contacts [`Self::contacts`] gives, without building them. O(levels).
    pub fn contact_count(&self) -> usize {
        self.levels()
            .iter()
            .map(|level| self.contacts_on(level.aim))
            .sum()
    }

    fn contacts_on(&self, aim: Aim) -> usize {
        match aim {
            Aim::Neighbour(direction) => self.lattice().toward(direction).len(),
            Aim::Flat(flat) => self.facing(flat).len(),
        }
    }

    /// Every contact over the pin length, in the module's order. O(contacts).
    pub fn contacts(&self) -> Vec<HexContact> {
        let mut contacts = Vec::with_capacity(self.contact_count());
        let (pin_clearance, wall_clearance) = (self.pin_clearance(), self.wall_clearance());
        for (index, level) in self.levels().iter().enumerate() {
            let normal = level.aim.unit();
            let at = |wire_pin, touched, clearance| HexContact {
                level: index,
                height: level.height,
                wire_pin,
                touched,
                normal,
                clearance,
            };
            match level.aim {
                Aim::Neighbour(direction) => contacts.extend(
                    self.lattice()
                        .toward(direction)
                        .iter()
                        .map(|pair| at(pair.pin, Body::Pin(pair.neighbour), pin_clearance)),
                ),
                Aim::Flat(flat) => contacts.extend(
                    self.facing(flat)
                        .iter()
                        .map(|&pin| at(pin, Body::Flat(flat), wall_clearance)),
                ),
            }
        }
        contacts
    }
}
