//! Kinematics of one contact in the transverse plane (BRIEF §3 in two directions).
//!
//! Body a is the pin whose wire touches, body b the touched clad or flat, n the unit
//! normal from a toward b and t = n turned by +90° (so (n, t) is right-handed). u and v
//! are the transverse displacements (m) and velocities (m/s) of the two pin axes at the
//! contact height; a flat has u = v = 0 in the wrapper frame.
//! - Penetration δ = n·(u_a − u_b) − gap: a moving toward b closes the gap.
//! - Force magnitude F = max(0, Kc δ + cc δ̇) while δ > 0 ([`crate::contact::Contact::force`]),
//!   applied along n, equal and opposite: −F·n on a, +F·n on b (each pushed away from
//!   the other). The row is the case n = +x, a = left, b = right: δ = w_L − w_R − gap.
//! - Relative tangential velocity v_t = t·(v_a − v_b) (m/s), signed; the wear work rate
//!   of a contact is (1/T)∫|F|·|v_t| dt. The beams carry no torsion and no axial motion,
//!   so the contact point moves with the pin axis and v_t is all the sliding there is in
//!   this model.

use super::vector::Vec2;

/// δ = n·(u_a − u_b) − gap (m), positive when the bodies interpenetrate.
#[inline]
pub fn penetration(normal: Vec2, gap: f64, displacement_a: Vec2, displacement_b: Vec2) -> f64 {
    normal.dot(displacement_a - displacement_b) - gap
}

/// δ̇ = n·(v_a − v_b) (m/s), positive while the bodies approach.
#[inline]
pub fn penetration_rate(normal: Vec2, velocity_a: Vec2, velocity_b: Vec2) -> f64 {
    normal.dot(velocity_a - velocity_b)
}

/// v_t = t·(v_a − v_b) (m/s) with t = n turned by +90°: the sliding velocity of a on b.
#[inline]
pub fn tangential_velocity(normal: Vec2, velocity_a: Vec2, velocity_b: Vec2) -> f64 {
    normal.perpendicular().dot(velocity_a - velocity_b)
}

/// The two forces of a contact (N).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairForces {
    /// −F·n: pushes a away from b.
    pub on_a: Vec2,
    /// +F·n: pushes b away from a (dropped for a flat: the wrapper is driven).
    pub on_b: Vec2,
}

/// Forces of magnitude `magnitude` (N, ≥ 0) along `normal`: −F·n on a, +F·n on b.
#[inline]
pub fn contact_forces(normal: Vec2, magnitude: f64) -> PairForces {
    PairForces {
        on_a: -magnitude * normal,
        on_b: magnitude * normal,
    }
}

/// Instantaneous wear power |F|·|v_t| (W) of a contact with force magnitude `force` (N)
/// sliding at `tangential_velocity` (m/s); its time mean is the wear work rate.
#[inline]
pub fn wear_power(force: f64, tangential_velocity: f64) -> f64 {
    force.abs() * tangential_velocity.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn along_x_the_penetration_is_the_rows() {
        // Row: δ = w_L − w_R − gap with L = a on the left and n = +x.
        let (w_left, w_right, gap) = (3e-4, -1e-4, 2e-4);
        let delta = penetration(
            Vec2::new(1.0, 0.0),
            gap,
            Vec2::new(w_left, 0.0),
            Vec2::new(w_right, 0.0),
        );
        assert!((delta - (w_left - w_right - gap)).abs() < 1e-18, "δ = {delta}");
    }

    #[test]
    fn penetration_and_rates_do_not_depend_on_the_frame() {
        // Turning the whole picture (normal, displacements, velocities) changes nothing.
        let normal = Vec2::from_angle(0.7);
        let (u_a, u_b) = (Vec2::new(2e-4, -1e-4), Vec2::new(-3e-4, 5e-5));
        let (v_a, v_b) = (Vec2::new(0.1, 0.3), Vec2::new(-0.2, 0.05));
        for angle in [0.4, 2.0, -1.3] {
            let turn = |v: Vec2| v.rotated(angle);
            let pairs = [
                (
                    penetration(normal, 1e-4, u_a, u_b),
                    penetration(turn(normal), 1e-4, turn(u_a), turn(u_b)),
                ),
                (
                    penetration_rate(normal, v_a, v_b),
                    penetration_rate(turn(normal), turn(v_a), turn(v_b)),
                ),
                (
                    tangential_velocity(normal, v_a, v_b),
                    tangential_velocity(turn(normal), turn(v_a), turn(v_b)),
                ),
            ];
            for (original, turned) in pairs {
                assert!(
                    (original - turned).abs() < 1e-15,
                    "{original} vs {turned} after {angle} rad"
                );
            }
        }
    }

    #[test]
    fn normal_and_tangential_parts_rebuild_the_relative_velocity() {
        let normal = Vec2::from_angle(-2.1);
        let (v_a, v_b) = (Vec2::new(0.4, -0.1), Vec2::new(0.25, 0.3));
        let rebuilt = penetration_rate(normal, v_a, v_b) * normal
            + tangential_velocity(normal, v_a, v_b) * normal.perpendicular();
        assert!(
            (rebuilt - (v_a - v_b)).norm() < 1e-15,
            "{rebuilt:?} vs {:?}",
            v_a - v_b
        );
    }

    #[test]
    fn forces_are_equal_opposite_and_push_the_bodies_apart() {
        let normal = Vec2::from_angle(1.1);
        let forces = contact_forces(normal, 7.5);
        assert_eq!(forces.on_a + forces.on_b, Vec2::ZERO, "Newton's third law");
        assert!((forces.on_b.norm() - 7.5).abs() < 1e-14);
        // a moving along n (closing) is pushed back: the force on a opposes n.
        assert!(forces.on_a.dot(normal) < 0.0 && forces.on_b.dot(normal) > 0.0);
        assert_eq!(wear_power(-2.0, -0.5), 1.0);
    }
}
