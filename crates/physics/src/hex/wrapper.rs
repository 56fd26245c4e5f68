//! The hexagonal wrapper tube: its six inner flats, their outward normals, which outer
//! pins face which flat, and the wire-to-flat clearance.
//!
//! The wrapper is concentric with the bundle and parallel to its outer rows: the corners
//! of the pin hexagon (ring n, on the 0°, 60°, … rays) point at the wrapper's corners, so
//! flat k (k = 0..6) has its outward normal at k·60° + 30°, inside sector k
//! ([`super::lattice`]). Its inner face lies F/2 from the axis (F the inner flat-to-flat
//! distance). The centre of site (q, r) projects on the normals at 30°, 90°, …, 330° as
//! c·P·√3/2 with c = q + r, r, −q, −(q + r), −r, q: an integer, at most n. The pins with
//! c = n *face* the flat: the n + 1 pins of that side of ring n (its two corner pins face
//! two flats each), 6(n + 1) pin–flat pairs in all.
//!
//! Clearance of a facing pin's wire when it points along the normal (its closest
//! approach): g = F/2 − n·P·√3/2 − D/2 − d_w.

use super::lattice::Axial;
use super::vector::{HALF_SQRT_3, Vec2, twelfth_turn};

/// One of the wrapper's six flats, k = 0..6, outward normal at k·60° + 30°.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub struct Flat(u8);

impl Flat {
    pub const ALL: [Self; 6] = [Self(0), Self(1), Self(2), Self(3), Self(4), Self(5)];

    /// Flat k (k < 6), or `None`.
    pub fn new(index: usize) -> Option<Self> {
        (index < 6).then_some(Self(index as u8))
    }

    /// k, in 0..6.
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// Direction of the outward normal, k·π/3 + π/6 (rad).
    pub fn angle(self) -> f64 {
        (2 * self.index() + 1) as f64 * std::f64::consts::FRAC_PI_6
    }

    /// The outward unit normal, exact to the last bit (opposite flats: exact negatives).
    pub fn normal(self) -> Vec2 {
        twelfth_turn(2 * self.index() + 1)
    }

    pub fn opposite(self) -> Self {
        self.turned(3)
    }

    /// The flat `sixths` × 60° further counter-clockwise.
    pub fn turned(self, sixths: i64) -> Self {
        Self((self.index() as i64 + sixths).rem_euclid(6) as u8)
    }

    /// nₐ·n_b = cos((b − a)·60°), exactly: 1, ½, −½, −1, −½, ½.
    pub fn normal_cosine(self, other: Self) -> f64 {
        const COSINES: [f64; 6] = [1.0, 0.5, -0.5, -1.0, -0.5, 0.5];
        COSINES[(other.index() + 6 - self.index()) % 6]
    }

    /// The integer c with (centre of `site`)·normal = c·P·√3/2 (module doc).
    pub fn coordinate(self, site: Axial) -> i64 {
        match self.index() {
            0 => site.q + site.r,
            1 => site.r,
            2 => -site.q,
            3 => -(site.q + site.r),
            4 => -site.r,
            _ => site.q,
        }
    }

    /// Whether the pin at `site` of a bundle of `rings` rings faces this flat.
    pub fn faced_by(self, site: Axial, rings: usize) -> bool {
        self.coordinate(site) == rings as i64
    }
}

/// Clearance (m) between a flat and the wire of a pin facing it, pointing along the
/// flat's normal: F/2 − n·P·√3/2 − D/2 − d_w, for inner flat-to-flat F, `rings` n, pitch
/// P, clad diameter D and wire diameter d_w (m). Negative when the bundle does not fit.
pub fn wall_clearance(
    flat_to_flat: f64,
    rings: usize,
    pitch: f64,
    pin_diameter: f64,
    wire_diameter: f64,
) -> f64 {
    0.5 * flat_to_flat - rings as f64 * pitch * HALF_SQRT_3 - 0.5 * pin_diameter - wire_diameter
}

/// The smallest inner flat-to-flat (m) holding `rings` rings: √3·n·P + D + 2d_w (zero wall
/// clearance).
pub fn minimum_flat_to_flat(rings: usize, pitch: f64, pin_diameter: f64, wire_diameter: f64) -> f64 {
    2.0 * rings as f64 * pitch * HALF_SQRT_3 + pin_diameter + 2.0 * wire_diameter
}

#[cfg(test)]
mod tests {
    use super::super::lattice::Lattice;
    use super::*;
    use std::f64::consts::FRAC_PI_3;

    #[test]
    fn normals_are_unit_outward_and_turn_by_60_degrees() {
        for flat in Flat::ALL {
            let n = flat.normal();
            assert!((n.norm() - 1.0).abs() < 1e-15, "{flat:?}: |n| = {}", n.norm());
            let expected = Vec2::from_angle(FRAC_PI_3 * flat.index() as f64 + FRAC_PI_3 / 2.0);
            assert!((n - expected).norm() < 1e-14, "{flat:?}: {n:?} vs {expected:?}");
            assert_eq!(flat.opposite().normal(), -n);
            assert!((flat.normal_cosine(flat.turned(1)) - n.dot(flat.turned(1).normal())).abs() < 1e-15);
        }
    }

    #[test]
    fn the_pins_facing_a_flat_are_the_outer_row_nearest_to_it() {
        let (rings, pitch) = (4, 1.0);
        let lattice = Lattice::new(rings);
        let mut incidences = 0;
        for flat in Flat::ALL {
            let projections: Vec<f64> = (0..lattice.pin_count())
                .map(|p| lattice.position(p, pitch).dot(flat.normal()))
                .collect();
            let farthest = projections.iter().copied().fold(f64::MIN, f64::max);
            assert!((farthest - rings as f64 * pitch * 3f64.sqrt() / 2.0).abs() < 1e-12);
            let facing: Vec<usize> = (0..lattice.pin_count())
                .filter(|&p| flat.faced_by(lattice.site(p), rings))
                .collect();
            let nearest: Vec<usize> = (0..lattice.pin_count())
                .filter(|&p| projections[p] > farthest - 1e-9)
                .collect();
            assert_eq!(facing, nearest, "{flat:?}");
            assert_eq!(facing.len(), rings + 1, "{flat:?}: one side of the outer ring");
            incidences += facing.len();
        }
        assert_eq!(incidences, 6 * (rings + 1));
        // A corner pin faces the two flats on either side of its corner.
        let corner = Axial::new(rings as i64, 0);
        let faced: Vec<usize> = Flat::ALL
            .iter()
            .filter(|f| f.faced_by(corner, rings))
            .map(|f| f.index())
            .collect();
        assert_eq!(faced, [0, 5]);
    }

    #[test]
    fn wall_clearance_is_the_flat_distance_minus_the_centre_projection_and_the_wire() {
        // ASTRID-like: 217 pins, D 9.7 mm, P 10.7 mm, d_w 1 mm, 0.5 mm to the wrapper.
        let (rings, pitch, d, wire) = (8, 10.7e-3, 9.7e-3, 1.0e-3);
        let flat_to_flat = minimum_flat_to_flat(rings, pitch, d, wire) + 2.0 * 0.5e-3;
        let clearance = wall_clearance(flat_to_flat, rings, pitch, d, wire);
        assert!(
            (clearance - 0.5e-3).abs() < 1e-15,
            "clearance {clearance} vs 0.5 mm"
        );
        let corner_centre = Vec2::new(rings as f64 * pitch, 0.0);
        let by_projection = flat_to_flat / 2.0 - corner_centre.dot(Flat::ALL[0].normal()) - d / 2.0 - wire;
        assert!(
            (clearance - by_projection).abs() < 1e-15,
            "{clearance} vs {by_projection}"
        );
    }
}
