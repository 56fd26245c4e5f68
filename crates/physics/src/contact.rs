//! Point contacts between a pin and a wall or between two pins (BRIEF §3, API.md).
//!
//! In a row (pins bending along x) a contact at height z between `left` L and `right` R
//! has penetration δ = w_L(z) − w_R(z) − gap (a wall's deflection is 0 in the wrapper
//! frame). While δ > 0 it pushes L to the left and R to the right with
//! F = max(0, Kc δ + cc δ̇): the clamp keeps the dashpot from pulling the bodies
//! together while they separate.
//!
//! For pins bending in the transverse plane (x, y) each contact also has a unit normal n
//! from L toward R ([`crate::integrate::Plane`]): δ = n·(u_L(z) − u_R(z)) − gap, the
//! same force law, −F n on L and +F n on R. The row is the plane with every n = +x.
//! There is no friction: the sliding velocity t·(u̇_L − u̇_R), t = (−n_y, n_x), only
//! enters the wear work ∫ F |v_t| dt.

use super::{InputIssue, require_non_negative};

/// One side of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Body {
    /// The wrapper wall (moves with the base: zero deflection in the wrapper frame).
    Wall,
    /// Pin number (0-based, counted from the left wall).
    Pin(usize),
}

/// A potential contact.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    pub left: Body,
    pub right: Body,
    /// Height from the pin feet (m).
    pub height: f64,
    /// Gap at rest (m), ≥ 0.
    pub gap: f64,
    /// Penalty stiffness Kc (N/m), ≥ 0.
    pub stiffness: f64,
    /// Dashpot cc (N·s/m), ≥ 0.
    pub damping: f64,
}

impl Contact {
    /// Force magnitude (N) for penetration δ (m) and its rate δ̇ (m/s): Kc δ + cc δ̇
    /// clamped at ≥ 0 while δ > 0, zero otherwise.
    #[inline]
    pub fn force(&self, penetration: f64, penetration_rate: f64) -> f64 {
        if penetration > 0.0 {
            (self.stiffness * penetration + self.damping * penetration_rate).max(0.0)
        } else {
            0.0
        }
    }

    /// Every problem with this contact for a row of `pins` pins of length `length`.
    pub fn validate(&self, pins: usize, length: f64) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        for (field, body) in [("left", self.left), ("right", self.right)] {
            if let Body::Pin(p) = body
                && p >= pins
            {
                let reason = match pins {
                    0 => format!("pin {p} does not exist (the row has no pin)"),
                    _ => format!("pin {p} does not exist (pins are 0..{})", pins - 1),
                };
                issues.push(InputIssue::new(field, reason));
            }
        }
        if self.left == self.right {
            issues.push(InputIssue::new("right", "a contact needs two different bodies"));
        }
        if !self.height.is_finite() || self.height < 0.0 || self.height > length {
            issues.push(InputIssue::new(
                "height",
                format!("must be within the pin, between 0 and {length} m"),
            ));
        }
        require_non_negative(&mut issues, "gap", self.gap);
        require_non_negative(&mut issues, "stiffness", self.stiffness);
        require_non_negative(&mut issues, "damping", self.damping);
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_acts_only_in_penetration_and_never_pulls() {
        let contact = Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: 1.0,
            gap: 0.0,
            stiffness: 100.0,
            damping: 10.0,
        };
        assert_eq!(contact.force(-1e-3, 5.0), 0.0);
        assert!((contact.force(1e-3, 0.0) - 0.1).abs() < 1e-15);
        assert_eq!(
            contact.force(1e-3, -1.0),
            0.0,
            "separating fast: the dashpot must not pull"
        );
    }

    #[test]
    fn invalid_contact_names_fields() {
        let contact = Contact {
            left: Body::Pin(3),
            right: Body::Wall,
            height: 2.0,
            gap: -1.0,
            stiffness: f64::NAN,
            damping: 0.0,
        };
        let fields: Vec<String> = contact.validate(2, 1.8).into_iter().map(|i| i.field).collect();
        assert_eq!(fields, ["left", "height", "gap", "stiffness"]);
    }
}
