//! The spacer wires' helix and the contact levels it makes.
//!
//! Every wire starts at the same angle θ₀ at the pin foot (z = 0) and turns with the same
//! handedness s = ±1 and lead H: its direction from the pin axis is
//! φ(z) = θ₀ + s·2πz/H (rad, counter-clockwise from +x seen from above). All wires point
//! the same way at a given height, so contacts happen only where φ is a multiple of 30°:
//! - φ = k·60°: every pin's wire points at its neighbour in direction k (if it has one)
//!   and touches that neighbour's clad;
//! - φ = k·60° + 30°: the wires of the pins facing flat k point along its outward normal
//!   and touch the wrapper.
//!
//! Those heights are the *levels*: one every H/12, pin–pin and wall levels alternating, a
//! new neighbour direction every H/6 (each pair met twice per lead, H/2 apart: once by
//! each pin's wire). Levels are numbered from 0 upward.
//!
//! Only these closest approaches are contacts, as the model specifies: 30° away from its
//! target a wire reaches (D + d_w)(1 − cos 30°)/2 less far toward it (0.7 mm for D 9.7 mm,
//! d_w 1 mm), and a wire pointing at a wrapper corner (an outer pin's missing neighbour)
//! touches nothing.
//!
//! # Endpoints
//! Levels lie in (0, L]: a contact exactly at the clamped foot would never move and is
//! left out; one at the top is kept. A height within 1e-9·L above L is snapped onto L, and
//! a start angle within 1e-9 × 30° of a multiple of 30° is taken as that multiple (so the
//! first level is H/12 up, not a rounding error above the foot). Heights are rounded to 12
//! significant digits ([`crate::decimal`]): H = 0.18 m gives levels at 0.015, 0.03, … m.

use super::lattice::Direction;
use super::vector::{Vec2, twelfth_turn};
use crate::bundle::HEIGHT_SNAP_TOLERANCE;

/// A start angle this close (in units of 30°) to a multiple of 30° is snapped onto it.
pub const ANGLE_SNAP_TOLERANCE: f64 = 1e-9;

/// Sense in which the wires turn as z rises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Handedness {
    /// s = +1: φ grows with z (counter-clockwise seen from above, a right-hand thread).
    Right,
    /// s = −1: φ decreases with z (clockwise seen from above).
    Left,
}

impl Handedness {
    /// s = +1 (right) or −1 (left).
    pub fn sign(self) -> i64 {
        match self {
            Self::Right => 1,
            Self::Left => -1,
        }
    }
}

/// What every wire points at on a level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Aim {
    /// The neighbour in this lattice direction (φ = k·60°).
    Neighbour(Direction),
    /// Flat k of the wrapper, along its outward normal (φ = k·60° + 30°).
    Flat(super::wrapper::Flat),
}

impl Aim {
    /// φ modulo 360° in twelfths of a turn (0..12).
    pub fn twelfth(self) -> usize {
        match self {
            Self::Neighbour(direction) => 2 * direction.index(),
            Self::Flat(flat) => 2 * flat.index() + 1,
        }
    }

    fn from_twelfth(twelfth: i64) -> Self {
        let twelfth = twelfth.rem_euclid(12) as usize;
        if twelfth.is_multiple_of(2) {
            Self::Neighbour(Direction::ALL[twelfth / 2])
        } else {
            Self::Flat(super::wrapper::Flat::ALL[twelfth / 2])
        }
    }

    /// The wires' direction, exact to the last bit.
    pub fn unit(self) -> Vec2 {
        twelfth_turn(self.twelfth())
    }
}

/// One contact level: a height and what the wires point at there.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Level {
    /// Height from the pin feet (m), in (0, L].
    pub height: f64,
    pub aim: Aim,
}

/// The common helix of every wire (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Helix {
    /// θ₀ (rad): direction of every wire at the pin foot.
    pub start_angle: f64,
    /// H (m): axial length of one turn, > 0.
    pub lead: f64,
    pub handedness: Handedness,
}

impl Helix {
    /// φ(z) = θ₀ + s·2πz/H (rad, not reduced) at height `height` (m).
    pub fn angle(&self, height: f64) -> f64 {
        self.start_angle + self.handedness.sign() as f64 * std::f64::consts::TAU * height / self.lead
    }

    /// The levels on a pin of length `pin_length` (m), lowest first. O(levels).
    pub fn levels(&self, pin_length: f64) -> Vec<Level> {
        let plan = self.plan(pin_length);
        (0..plan.count)
            .map(|k| Level {
                height: plan.height(k),
                aim: Aim::from_twelfth(plan.first_twelfth + self.handedness.sign() * k as i64),
            })
            .collect()
    }

    /// How many levels [`Self::levels`] gives, without building them.
    pub fn level_count(&self, pin_length: f64) -> usize {
        self.plan(pin_length).count
    }

    fn plan(&self, pin_length: f64) -> LevelPlan {
        let sign = self.handedness.sign();
        // θ₀ in twelfths of a turn; a level is where θ₀/30° + s·τ is an integer, τ = 12z/H.
        let mut start = self.start_angle / std::f64::consts::FRAC_PI_6;
        if (start - start.round()).abs() <= ANGLE_SNAP_TOLERANCE {
            start = start.round();
        }
        let remainder = (-(sign as f64) * start).rem_euclid(1.0);
        let first = if remainder == 0.0 || remainder >= 1.0 {
            1.0
        } else {
            remainder
        };
        let mut plan = LevelPlan {
            first,
            twelfth_height: self.lead / 12.0,
            pin_length,
            first_twelfth: (start + sign as f64 * first).round() as i64,
            count: 0,
        };
        let top = pin_length / plan.twelfth_height;
        if !top.is_finite() {
            return plan;
        }
        // An estimate, then exact by the heights themselves (rounded and snapped).
        plan.count = if top >= first {
            (top - first).floor() as usize + 1
        } else {
            0
        };
        while plan.count > 0 && plan.height(plan.count - 1) > pin_length {
            plan.count -= 1;
        }
        while plan.height(plan.count) <= pin_length {
            plan.count += 1;
        }
        plan
    }
}

/// Level k sits at τ = first + k twelfths of a lead.
struct LevelPlan {
    first: f64,
    twelfth_height: f64,
    pin_length: f64,
    first_twelfth: i64,
    count: usize,
}

impl LevelPlan {
    /// Height of level k (m): rounded to 12 digits and snapped onto the top when within
    /// tolerance above or below it; beyond the top when the level does not exist.
    fn height(&self, k: usize) -> f64 {
        let height = crate::decimal((self.first + k as f64) * self.twelfth_height);
        if (height - self.pin_length).abs() <= HEIGHT_SNAP_TOLERANCE * self.pin_length {
            self.pin_length
        } else {
            height
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::wrapper::Flat;
    use super::*;
    use std::f64::consts::{FRAC_PI_6, PI, TAU};

    fn helix(start_angle: f64, handedness: Handedness) -> Helix {
        Helix {
            start_angle,
            lead: 0.18,
            handedness,
        }
    }

    /// The wires' direction at `height`, reduced to [0, 2π).
    fn wire_direction(helix: &Helix, height: f64) -> f64 {
        helix.angle(height).rem_euclid(TAU)
    }

    #[test]
    fn levels_are_where_the_wires_point_at_multiples_of_30_degrees() {
        for handedness in [Handedness::Right, Handedness::Left] {
            for start in [0.0, 0.2, -1.0, PI / 6.0, 7.0 * PI / 6.0, 3.0] {
                let helix = helix(start, handedness);
                let levels = helix.levels(1.8);
                for (k, level) in levels.iter().enumerate() {
                    let direction = wire_direction(&helix, level.height);
                    let error = (level.aim.unit() - Vec2::from_angle(direction)).norm();
                    assert!(
                        error < 1e-9,
                        "θ₀ = {start}, {handedness:?}, level {k} at {} m: aim {:?} vs wire at {direction} rad",
                        level.height,
                        level.aim
                    );
                    assert!(
                        level.height > 0.0 && level.height <= 1.8,
                        "level {k} at {}",
                        level.height
                    );
                }
                // Spacing H/12, and no level missed below the first one or above the last.
                for pair in levels.windows(2) {
                    let spacing = pair[1].height - pair[0].height;
                    assert!(
                        (spacing - 0.015).abs() < 1e-10,
                        "spacing {spacing} (heights to 12 digits)"
                    );
                }
                assert!(
                    levels[0].height <= 0.015 + 1e-10,
                    "first level {}",
                    levels[0].height
                );
                assert!(levels.last().unwrap().height > 1.8 - 0.015 - 1e-10);
            }
        }
    }

    #[test]
    fn a_start_on_a_twelfth_puts_the_first_level_h_over_12_up_and_the_last_on_the_top() {
        // θ₀ = 0: levels at 0.015·k, k = 1..=120, the 120th exactly at the top (1.8 m).
        let levels = helix(0.0, Handedness::Right).levels(1.8);
        assert_eq!(levels.len(), 120);
        assert_eq!(levels[0].height, 0.015);
        assert_eq!(levels[119].height, 1.8);
        assert_eq!(levels[0].aim, Aim::Flat(Flat::ALL[0]), "30° after a start at 0°");
        assert_eq!(levels[1].aim, Aim::Neighbour(Direction::ALL[1]), "then 60°");
        // Same with a start angle that is 30° only up to rounding.
        let rounded = helix(FRAC_PI_6, Handedness::Left).levels(1.8);
        assert_eq!(rounded.len(), 120);
        assert_eq!(rounded[0].height, 0.015);
        assert_eq!(rounded[0].aim, Aim::Neighbour(Direction::ALL[0]), "30° − 30°");
    }

    #[test]
    fn handedness_turns_the_aims_the_other_way() {
        let right = helix(0.4, Handedness::Right).levels(0.18);
        let left = helix(0.4, Handedness::Left).levels(0.18);
        assert_eq!(right.len(), 12);
        assert_eq!(left.len(), 12);
        for pair in right.windows(2) {
            assert_eq!((pair[1].aim.twelfth() + 12 - pair[0].aim.twelfth()) % 12, 1);
        }
        for pair in left.windows(2) {
            assert_eq!((pair[0].aim.twelfth() + 12 - pair[1].aim.twelfth()) % 12, 1);
        }
    }

    #[test]
    fn a_pin_shorter_than_the_first_level_has_none_and_one_within_rounding_of_it_has_it_at_its_top() {
        assert_eq!(helix(0.0, Handedness::Right).level_count(0.01), 0);
        assert_eq!(helix(0.0, Handedness::Right).levels(0.015).len(), 1);
        let just_short = 0.015 * (1.0 - 1e-12);
        let levels = helix(0.0, Handedness::Right).levels(just_short);
        assert_eq!(levels.len(), 1, "within 1e-9·L of the first level");
        assert_eq!(levels[0].height, just_short, "snapped onto the top");
    }
}
