//! The hexagonal lattice of pin centres: `rings` n rings around a central pin, their
//! numbering, positions, rings, sectors and neighbour pairs. Pure topology; lengths enter
//! only through the pitch passed to [`Lattice::position`].
//!
//! # Coordinates
//! Axial coordinates (q, r) (Amit Patel's "hexagonal grids"): the centre of pin (q, r) is
//! q·P·e₀ + r·P·e₁, with eₖ the unit vector at k·60° from +x (k = 0..6, the six
//! [`Direction`]s toward the neighbours). A pin's ring is its hexagonal distance to the
//! centre, (|q| + |r| + |q + r|)/2; ring k holds 6k pins, so n rings hold
//! N = 1 + Σ 6k = 3n(n + 1) + 1.
//!
//! # Numbering (stable: part of the results' contract)
//! Pin 0 is the centre; then ring by ring outward. Ring k (k ≥ 1) starts at 3k(k − 1) + 1
//! with the corner pin at angle 0° (axial (k, 0), centre (kP, 0)) and walks
//! counter-clockwise along the ring's six sides: side s (s = 0..6) holds the k pins
//! k·eₛ + t·eₛ₊₂ (t = 0..k), from the corner at s·60° (included) toward the corner at
//! (s + 1)·60° (excluded). Pin number = 3k(k − 1) + 1 + s·k + t. The side s is also the
//! pin's *sector*: the sextant of centre angles [s·60°, (s + 1)·60°), the triangle
//! between the centre and the wrapper flat s (whose normal is at s·60° + 30°).
//!
//! # Neighbour pairs
//! Along each of the three lattice axes the hexagon has 2n + 1 rows of 2n + 1 − |j|
//! pins (j = −n..n), hence Σⱼ (2n − |j|) = 3n² + n pairs per axis and 9n² + 3n =
//! 3n(3n + 1) pairs in all (n = 8: 600).

use super::vector::{HALF_SQRT_3, Vec2, twelfth_turn};

/// Pins of a lattice with `rings` rings: 3n(n + 1) + 1.
pub const fn pin_count(rings: usize) -> usize {
    3 * rings * (rings + 1) + 1
}

/// Neighbour pairs of a lattice with `rings` rings: 3n(3n + 1) (module doc).
pub const fn pair_count(rings: usize) -> usize {
    3 * rings * (3 * rings + 1)
}

/// Axial coordinates of a lattice site (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Axial {
    pub q: i64,
    pub r: i64,
}

impl Axial {
    pub const fn new(q: i64, r: i64) -> Self {
        Self { q, r }
    }

    /// Hexagonal distance to the centre: the ring this site lies on.
    pub fn ring(self) -> usize {
        ((self.q.abs() + self.r.abs() + (self.q + self.r).abs()) / 2) as usize
    }

    /// The neighbouring site in `direction`.
    pub fn neighbour(self, direction: Direction) -> Self {
        self.plus(direction.step(), 1)
    }

    /// This site turned about the centre by `sixths` × 60° (counter-clockwise when
    /// positive): one sixth maps (q, r) to (−r, q + r).
    pub fn rotated(self, sixths: i64) -> Self {
        let mut site = self;
        for _ in 0..sixths.rem_euclid(6) {
            site = Self::new(-site.r, site.q + site.r);
        }
        site
    }

    /// Centre (m) for pitch `pitch` (m): (P(q + r/2), P·r·√3/2).
    pub fn position(self, pitch: f64) -> Vec2 {
        let (q, r) = (self.q as f64, self.r as f64);
        Vec2::new(pitch * (q + 0.5 * r), pitch * (HALF_SQRT_3 * r))
    }

    fn plus(self, step: Self, times: i64) -> Self {
        Self::new(self.q + times * step.q, self.r + times * step.r)
    }
}

/// One of the six lattice directions eₖ, at k·60° from +x (k = 0..6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub struct Direction(u8);

impl Direction {
    pub const ALL: [Self; 6] = [Self(0), Self(1), Self(2), Self(3), Self(4), Self(5)];

    /// Direction k (k < 6), or `None`.
    pub fn new(index: usize) -> Option<Self> {
        (index < 6).then_some(Self(index as u8))
    }

    /// k, in 0..6.
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// k·π/3 (rad).
    pub fn angle(self) -> f64 {
        self.index() as f64 * std::f64::consts::FRAC_PI_3
    }

    /// eₖ, exact to the last bit (opposite directions are exact negatives).
    pub fn unit(self) -> Vec2 {
        twelfth_turn(2 * self.index())
    }

    pub fn opposite(self) -> Self {
        self.turned(3)
    }

    /// The direction `sixths` × 60° further counter-clockwise.
    pub fn turned(self, sixths: i64) -> Self {
        Self((self.index() as i64 + sixths).rem_euclid(6) as u8)
    }

    /// eₖ in axial coordinates.
    fn step(self) -> Axial {
        const STEPS: [Axial; 6] = [
            Axial::new(1, 0),
            Axial::new(0, 1),
            Axial::new(-1, 1),
            Axial::new(-1, 0),
            Axial::new(0, -1),
            Axial::new(1, -1),
        ];
        STEPS[self.index()]
    }
}

/// Pin `pin` and its neighbour `neighbour`, whose centre is one pitch away in `direction`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NeighbourPair {
    pub pin: usize,
    pub neighbour: usize,
    pub direction: Direction,
}

/// The lattice of a bundle of `rings` rings (module doc: numbering).
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice {
    rings: usize,
    sites: Vec<Axial>,
    /// `toward[k]`: every pin having a neighbour in direction k, in pin order.
    toward: [Vec<NeighbourPair>; 6],
}

impl Lattice {
    /// The lattice of `rings` rings (0 gives the single centre pin). O(N).
    pub fn new(rings: usize) -> Self {
        let mut sites = Vec::with_capacity(pin_count(rings));
        sites.push(Axial::new(0, 0));
        for ring in 1..=rings {
            for side in Direction::ALL {
                let corner = Axial::new(0, 0).plus(side.step(), ring as i64);
                let along = side.turned(2).step();
                for t in 0..ring as i64 {
                    sites.push(corner.plus(along, t));
                }
            }
        }
        let mut lattice = Self {
            rings,
            sites,
            toward: Default::default(),
        };
        for direction in Direction::ALL {
            lattice.toward[direction.index()] = (0..lattice.pin_count())
                .filter_map(|pin| {
                    let site = lattice.sites[pin].neighbour(direction);
                    lattice.pin_at(site).map(|neighbour| NeighbourPair {
                        pin,
                        neighbour,
                        direction,
                    })
                })
                .collect();
        }
        lattice
    }

    pub fn rings(&self) -> usize {
        self.rings
    }

    pub fn pin_count(&self) -> usize {
        self.sites.len()
    }

    /// Axial coordinates of `pin`.
    pub fn site(&self, pin: usize) -> Axial {
        self.sites[pin]
    }

    /// Centre of `pin` (m) for pitch `pitch` (m).
    pub fn position(&self, pin: usize, pitch: f64) -> Vec2 {
        self.sites[pin].position(pitch)
    }

    /// The ring of `pin` (0 for the centre).
    pub fn ring(&self, pin: usize) -> usize {
        ring_of_number(pin)
    }

    /// The sector (sextant 0..6, module doc) of `pin`; `None` for the centre pin.
    pub fn sector(&self, pin: usize) -> Option<usize> {
        let ring = ring_of_number(pin);
        (ring > 0).then(|| (pin - ring_start(ring)) / ring)
    }

    /// The pin at `site`, if the bundle has one there. O(1).
    pub fn pin_at(&self, site: Axial) -> Option<usize> {
        let ring = site.ring();
        if ring > self.rings {
            return None;
        }
        if ring == 0 {
            return Some(0);
        }
        let k = ring as i64;
        Direction::ALL.into_iter().find_map(|side| {
            let from_corner = Axial::new(site.q - k * side.step().q, site.r - k * side.step().r);
            let along = side.turned(2).step();
            let t = if along.q != 0 {
                from_corner.q / along.q
            } else {
                from_corner.r / along.r
            };
            ((0..k).contains(&t) && Axial::new(0, 0).plus(along, t) == from_corner)
                .then(|| ring_start(ring) + side.index() * ring + t as usize)
        })
    }

    /// The pin that `pin` becomes when the bundle is turned by `sixths` × 60°
    /// (counter-clockwise when positive): the bundle is 6-fold symmetric.
    pub fn rotated(&self, pin: usize, sixths: i64) -> usize {
        self.pin_at(self.sites[pin].rotated(sixths))
            .expect("a turn by a multiple of 60° maps the hexagon onto itself")
    }

    /// Every pin having a neighbour in `direction`, with that neighbour, in pin order.
    pub fn toward(&self, direction: Direction) -> &[NeighbourPair] {
        &self.toward[direction.index()]
    }

    /// Every neighbour pair once (directions 0°, 60°, 120° from the first pin of each):
    /// 3n(3n + 1) pairs.
    pub fn pairs(&self) -> impl Iterator<Item = NeighbourPair> + '_ {
        self.toward[..3].iter().flatten().copied()
    }
}

/// First pin number of ring `ring` ≥ 1: 3k(k − 1) + 1.
fn ring_start(ring: usize) -> usize {
    3 * ring * (ring - 1) + 1
}

/// The ring holding pin number `pin`: the largest k with 3k(k − 1) + 1 ≤ pin.
fn ring_of_number(pin: usize) -> usize {
    if pin == 0 {
        return 0;
    }
    // Estimate from k ≈ √(pin/3), then correct the rounding of the square root.
    let mut ring = ((pin as f64 / 3.0).sqrt() as usize).max(1);
    while ring_start(ring) > pin {
        ring -= 1;
    }
    while ring_start(ring + 1) <= pin {
        ring += 1;
    }
    ring
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    /// Every site of the plane within `rings` of the centre, found by scanning a square.
    fn sites_by_scan(rings: usize) -> HashSet<Axial> {
        let n = rings as i64;
        let mut sites = HashSet::new();
        for q in -n..=n {
            for r in -n..=n {
                if q.abs().max(r.abs()).max((q + r).abs()) <= n {
                    sites.insert(Axial::new(q, r));
                }
            }
        }
        sites
    }

    #[test]
    fn n_rings_hold_3n_n_plus_1_plus_1_pins_each_site_once() {
        for rings in 0..=9 {
            let lattice = Lattice::new(rings);
            let expected = sites_by_scan(rings);
            let numbered: HashSet<Axial> = (0..lattice.pin_count()).map(|p| lattice.site(p)).collect();
            assert_eq!(
                numbered.len(),
                lattice.pin_count(),
                "rings {rings}: a site numbered twice"
            );
            assert_eq!(
                numbered, expected,
                "rings {rings}: numbered sites vs scanned hexagon"
            );
            assert_eq!(lattice.pin_count(), pin_count(rings), "rings {rings}");
        }
        assert_eq!(pin_count(8), 217);
        assert_eq!(pin_count(9), 271);
    }

    #[test]
    fn numbering_starts_at_the_centre_then_walks_each_ring_counter_clockwise_from_0_degrees() {
        let pitch = 1.0;
        let lattice = Lattice::new(4);
        assert_eq!(lattice.position(0, pitch), Vec2::ZERO);
        let mut previous_ring = 0;
        for pin in 1..lattice.pin_count() {
            let centre = lattice.position(pin, pitch);
            // Ring from geometry: the hexagon of ring k has its corners at distance k·P
            // on the 0°, 60°, … rays and its sides at k·P·√3/2.
            let ring = (0..6)
                .map(|k| centre.dot(Vec2::from_angle((k as f64 + 0.5) * std::f64::consts::FRAC_PI_3)))
                .fold(f64::MIN, f64::max)
                / (3f64.sqrt() / 2.0);
            let ring = ring.round() as usize;
            assert_eq!(lattice.ring(pin), ring, "pin {pin} at {centre:?}");
            assert!(
                ring >= previous_ring,
                "pin {pin}: ring {ring} after ring {previous_ring}"
            );
            if ring > previous_ring {
                assert_eq!(
                    centre,
                    Vec2::new(ring as f64, 0.0),
                    "pin {pin} opens ring {ring}: it must be the corner at 0°"
                );
            } else {
                // Consecutive pins of a ring: one pitch apart, turning counter-clockwise.
                let before = lattice.position(pin - 1, pitch);
                assert!(
                    ((centre - before).norm() - 1.0).abs() < 1e-12,
                    "pins {} → {pin}",
                    pin - 1
                );
                assert!(
                    before.x * centre.y - before.y * centre.x > 0.0,
                    "pins {} → {pin} must turn counter-clockwise",
                    pin - 1
                );
            }
            previous_ring = ring;
        }
    }

    #[test]
    fn sectors_are_the_sextants_of_centre_angles() {
        let lattice = Lattice::new(5);
        assert_eq!(lattice.sector(0), None);
        for pin in 1..lattice.pin_count() {
            let angle = lattice
                .position(pin, 1.0)
                .angle()
                .rem_euclid(std::f64::consts::TAU);
            // Half-open sextants [s·60°, (s + 1)·60°); nudge by 1e-9 so corners land on their own.
            let expected = ((angle + 1e-9) / std::f64::consts::FRAC_PI_3).floor() as usize % 6;
            assert_eq!(lattice.sector(pin), Some(expected), "pin {pin} at {angle} rad");
        }
    }

    #[test]
    fn neighbour_pairs_are_the_centres_one_pitch_apart_each_once() {
        for rings in 0..=9 {
            let pitch = 10.7e-3;
            let lattice = Lattice::new(rings);
            let centres: Vec<Vec2> = (0..lattice.pin_count())
                .map(|p| lattice.position(p, pitch))
                .collect();
            let mut by_distance = HashSet::new();
            for a in 0..centres.len() {
                for b in a + 1..centres.len() {
                    let distance = (centres[b] - centres[a]).norm();
                    assert!(distance > pitch * (1.0 - 1e-9), "pins {a}, {b} overlap");
                    if distance < pitch * (1.0 + 1e-9) {
                        by_distance.insert((a, b));
                    }
                }
            }
            let listed: Vec<(usize, usize)> = lattice
                .pairs()
                .map(|pair| (pair.pin.min(pair.neighbour), pair.pin.max(pair.neighbour)))
                .collect();
            let unique: HashSet<(usize, usize)> = listed.iter().copied().collect();
            assert_eq!(unique.len(), listed.len(), "rings {rings}: a pair listed twice");
            assert_eq!(
                unique, by_distance,
                "rings {rings}: pairs vs centres one pitch apart"
            );
            let n = rings;
            assert_eq!(listed.len(), 9 * n * n + 3 * n, "rings {rings}: 9n² + 3n");
            assert_eq!(listed.len(), pair_count(rings), "rings {rings}");
        }
        assert_eq!(Lattice::new(8).pairs().count(), 600, "217 pins");
    }

    #[test]
    fn neighbours_lie_one_pitch_away_in_their_direction() {
        let lattice = Lattice::new(3);
        for direction in Direction::ALL {
            for pair in lattice.toward(direction) {
                let step = lattice.position(pair.neighbour, 2.0) - lattice.position(pair.pin, 2.0);
                let error = (step - 2.0 * direction.unit()).norm();
                assert!(error < 1e-12, "{pair:?}: step {step:?}");
            }
            // Pins lacking a neighbour in this direction are outer pins facing outward.
            let with: HashSet<usize> = lattice.toward(direction).iter().map(|p| p.pin).collect();
            for pin in (0..lattice.pin_count()).filter(|p| !with.contains(p)) {
                assert_eq!(
                    lattice.ring(pin),
                    3,
                    "pin {pin} has no neighbour at {direction:?}"
                );
            }
        }
    }

    #[test]
    fn turning_by_60_degrees_maps_pins_onto_pins_at_the_turned_centre() {
        let lattice = Lattice::new(6);
        for pin in 0..lattice.pin_count() {
            let turned = lattice.rotated(pin, 1);
            let expected = lattice.position(pin, 1.0).rotated(std::f64::consts::FRAC_PI_3);
            let error = (lattice.position(turned, 1.0) - expected).norm();
            assert!(error < 1e-12, "pin {pin} → {turned}: off by {error}");
            assert_eq!(lattice.rotated(turned, -1), pin);
            assert_eq!(lattice.rotated(pin, 6), pin);
        }
    }

    #[test]
    fn ring_of_a_number_is_exact_at_every_ring_boundary() {
        for ring in 1..2000 {
            let start = ring_start(ring);
            assert_eq!(ring_of_number(start), ring);
            assert_eq!(ring_of_number(start - 1), ring - 1);
            assert_eq!(ring_of_number(start + 6 * ring - 1), ring);
        }
    }
}
