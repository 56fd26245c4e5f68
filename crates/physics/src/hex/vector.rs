//! A vector of the transverse plane (x, y) of a pin: positions (m), displacements (m),
//! velocities (m/s) and unit normals. The frame is right-handed (x, y, z) with z along
//! the pins from their feet; angles are counter-clockwise from +x seen from above.

use std::ops::{Add, Mul, Neg, Sub};

/// √3/2, the sine of 60° (and cosine of 30°), as the nearest `f64`.
pub(crate) const HALF_SQRT_3: f64 = 0.866_025_403_784_438_6;

/// A vector (x, y) of the transverse plane; its unit is the quantity it carries.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Vec2 {
    pub x: f64,
    pub y: f64,
}

impl Vec2 {
    pub const ZERO: Self = Self { x: 0.0, y: 0.0 };

    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }

    /// The unit vector at `angle` (rad, counter-clockwise from +x).
    pub fn from_angle(angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self { x: cos, y: sin }
    }

    pub fn dot(self, other: Self) -> f64 {
        self.x * other.x + self.y * other.y
    }

    pub fn norm(self) -> f64 {
        self.x.hypot(self.y)
    }

    /// This vector turned by +90°: (−y, x). For a contact normal n it is the tangent t
    /// of the transverse plane, (n, t) right-handed.
    pub fn perpendicular(self) -> Self {
        Self {
            x: -self.y,
            y: self.x,
        }
    }

    /// This vector turned by `angle` (rad, counter-clockwise).
    pub fn rotated(self, angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self {
            x: cos * self.x - sin * self.y,
            y: sin * self.x + cos * self.y,
        }
    }

    /// Its direction (rad, in (−π, π]).
    pub fn angle(self) -> f64 {
        self.y.atan2(self.x)
    }
}

impl Add for Vec2 {
    type Output = Self;
    fn add(self, other: Self) -> Self {
        Self::new(self.x + other.x, self.y + other.y)
    }
}

impl Sub for Vec2 {
    type Output = Self;
    fn sub(self, other: Self) -> Self {
        Self::new(self.x - other.x, self.y - other.y)
    }
}

impl Neg for Vec2 {
    type Output = Self;
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y)
    }
}

impl Mul<Vec2> for f64 {
    type Output = Vec2;
    fn mul(self, vector: Vec2) -> Vec2 {
        Vec2::new(self * vector.x, self * vector.y)
    }
}

impl Mul<f64> for Vec2 {
    type Output = Vec2;
    fn mul(self, factor: f64) -> Vec2 {
        factor * self
    }
}

/// The unit vectors at k·30° (k = 0..12), exact to the last bit: cos and sin of a
/// multiple of 30° from the constants 0, ½, √3/2, 1, so that opposite directions are
/// exact negatives of each other and a rotation by a multiple of 60° permutes them.
pub(crate) fn twelfth_turn(k: usize) -> Vec2 {
    const TABLE: [Vec2; 12] = [
        Vec2::new(1.0, 0.0),
        Vec2::new(HALF_SQRT_3, 0.5),
        Vec2::new(0.5, HALF_SQRT_3),
        Vec2::new(0.0, 1.0),
        Vec2::new(-0.5, HALF_SQRT_3),
        Vec2::new(-HALF_SQRT_3, 0.5),
        Vec2::new(-1.0, 0.0),
        Vec2::new(-HALF_SQRT_3, -0.5),
        Vec2::new(-0.5, -HALF_SQRT_3),
        Vec2::new(0.0, -1.0),
        Vec2::new(0.5, -HALF_SQRT_3),
        Vec2::new(HALF_SQRT_3, -0.5),
    ];
    TABLE[k % 12]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_twelfth_turn_table_matches_the_trigonometric_functions() {
        for k in 0..12 {
            let exact = Vec2::from_angle(k as f64 * PI / 6.0);
            let table = twelfth_turn(k);
            let error = (table - exact).norm();
            assert!(error < 1e-15, "k = {k}: table {table:?} vs cos/sin {exact:?}");
            assert_eq!(twelfth_turn(k + 6), -table, "k = {k}: opposite must be exact");
        }
    }

    #[test]
    fn perpendicular_turns_by_a_quarter() {
        let n = Vec2::from_angle(0.3);
        let t = n.perpendicular();
        assert!(n.dot(t).abs() < 1e-16);
        assert!(
            (t.angle() - (0.3 + PI / 2.0)).abs() < 1e-15,
            "angle {}",
            t.angle()
        );
        assert!((n.rotated(PI / 2.0) - t).norm() < 1e-16);
    }
}
