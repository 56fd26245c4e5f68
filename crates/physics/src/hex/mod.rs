//! Geometry of a wire-wrapped hexagonal bundle (BRIEF §12, issue 18): expands a dozen
//! numbers ([`HexLayout`]: rings, pitch, diameters, wire lead and start angle, wrapper)
//! into the pins' centres and the explicit list of wire contacts ([`HexContact`]) with
//! their normals in the transverse plane and nominal clearances, then sets their gaps
//! ([`HexGaps`]). Pure geometry: nothing here integrates anything.
//!
//! Each submodule's doc holds its conventions (their items are re-exported here):
//! - pin numbering, rings, sectors, neighbour pairs: [`lattice`];
//! - the wrapper's flats, which pins face them, the wall clearance: [`wrapper`];
//! - the wire helix, the levels and the endpoint rule (0 < z ≤ L): [`helix`];
//! - the contact bodies, normal direction and order: [`contacts`];
//! - penetration, force and sliding-velocity signs: [`kinematics`];
//! - gap states, zones, offsets: [`gaps`];
//! - special cases for the equivalence checks (a row along any angle, one pin): [`special`].
//!
//! Frame: x, y transverse, z along the pins from their feet, right-handed; angles in
//! radians, counter-clockwise from +x seen from above.
//!
//! [`HexLayout`]: crate::hex::HexLayout
//! [`HexContact`]: crate::hex::HexContact
//! [`HexGaps`]: crate::hex::HexGaps
//! [`lattice`]: crate::hex::lattice
//! [`wrapper`]: crate::hex::wrapper
//! [`helix`]: crate::hex::helix
//! [`contacts`]: crate::hex::contacts
//! [`kinematics`]: crate::hex::kinematics
//! [`gaps`]: crate::hex::gaps
//! [`special`]: crate::hex::special

pub mod contacts;
pub mod gaps;
pub mod helix;
pub mod kinematics;
pub mod lattice;
pub mod layout;
pub mod special;
pub mod vector;
pub mod wrapper;

pub use contacts::{Body, HexContact};
pub use gaps::{
    FlatOffset, HexGapState, HexGaps, PinZone, ZoneClosure, close_zone, nominal_gaps, offset_toward_flat,
    random_gaps, uniform_gaps,
};
pub use helix::{ANGLE_SNAP_TOLERANCE, Aim, Handedness, Helix, Level};
pub use kinematics::{
    PairForces, contact_forces, penetration, penetration_rate, tangential_velocity, wear_power,
};
pub use lattice::{Axial, Direction, Lattice, NeighbourPair, pair_count, pin_count};
pub use layout::{HexBundle, HexLayout, MAX_LEVELS, MAX_RINGS};
pub use special::{RowEquivalent, row_along, single_pin_in_wrapper};
pub use vector::Vec2;
pub use wrapper::{Flat, minimum_flat_to_flat, wall_clearance};

#[cfg(test)]
mod tests;
