//! Archard wear of a contact after a service time, as code_aster's POST_USURE computes
//! it (docs/contact-laws.md): the worn volume V = K P t from the wear power P (the
//! normal force times the sliding speed, averaged over the run while the contact
//! slips: [`crate::integrate::Simulation::wear_work`] over the duration), the wear
//! coefficient K (m³/(N·m) = Pa⁻¹) and the service time t; the depth worn into the tube
//! from V and the geometry of the contact.

use crate::{InputIssue, number};

/// The geometry of a wearing contact, seen from the tube (the pin's clad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WearGeometry {
    /// A tube of radius R on a flat of width L (clad on a wrapper flat, rod on a grid
    /// spring or dimple; POST_USURE's TUBE_BAV): V = (4/3) L √(2R) d^{3/2}, the lens
    /// a flat cuts into a cylinder to first order in d/R.
    Flat { radius: f64, width: f64 },
    /// Two tubes crossing at an angle θ (given in degrees, as POST_USURE's ANGL_INCLI),
    /// the other of radius R (wire on clad, tube on tube; TUBE_TUBE):
    /// V = (8/15) √(2R) d^{5/2}/θ, θ in radians.
    CrossedTubes { radius: f64, angle_degrees: f64 },
    /// A tube of radius R in a bore of length L, worn evenly around (a support plate;
    /// TUBE_ALESAGE without the bore's radius): V = 2π R L d.
    Bore { radius: f64, length: f64 },
}

/// Archard's law of one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wear {
    /// K (m³/(N·m), i.e. Pa⁻¹): volume worn per unit of normal force and sliding
    /// distance.
    pub coefficient: f64,
    pub geometry: WearGeometry,
}

impl Wear {
    /// The volume (m³) worn in `time` (s) at the wear power `power` (W).
    pub fn volume(&self, power: f64, time: f64) -> f64 {
        self.coefficient * power * time
    }

    /// The depth (m) worn into the tube for the worn volume `volume` (m³).
    pub fn depth(&self, volume: f64) -> f64 {
        if volume <= 0.0 {
            return 0.0;
        }
        match self.geometry {
            WearGeometry::Flat { radius, width } => {
                (1.0 / (2.0 * radius)).powf(1.0 / 3.0) * (3.0 * volume / (4.0 * width)).powf(2.0 / 3.0)
            }
            WearGeometry::CrossedTubes {
                radius,
                angle_degrees,
            } => {
                let angle = angle_degrees.to_radians();
                (1.0 / (2.0 * radius)).powf(0.2) * (15.0 * angle * volume / 8.0).powf(0.4)
            }
            WearGeometry::Bore { radius, length } => volume / (std::f64::consts::TAU * length * radius),
        }
    }

    /// Every problem of this law: K ≥ 0, lengths > 0, an angle in (0, 90] degrees.
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        crate::require_non_negative(&mut issues, "coefficient", self.coefficient);
        let mut positive = |field: &str, value: f64| {
            if !(value.is_finite() && value > 0.0) {
                issues.push(InputIssue::new(
                    format!("geometry/{field}"),
                    format!("must be a length > 0 (m), got {}", number(value)),
                ));
            }
        };
        match self.geometry {
            WearGeometry::Flat { radius, width } => {
                positive("radius", radius);
                positive("width", width);
            }
            WearGeometry::CrossedTubes {
                radius,
                angle_degrees,
            } => {
                positive("radius", radius);
                if !(angle_degrees.is_finite() && angle_degrees > 0.0 && angle_degrees <= 90.0) {
                    issues.push(InputIssue::new(
                        "geometry/angle",
                        "the crossing angle must be in (0, 90] degrees (parallel tubes: a flat of the \
                         contact's length)",
                    ));
                }
            }
            WearGeometry::Bore { radius, length } => {
                positive("radius", radius);
                positive("length", length);
            }
        }
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const YEAR: f64 = 31_536_000.0;

    /// code_aster zzzz405a (POST_USURE, PUIS_USURE = 0.5 W): its TUBE_TUBE case (R = 1,
    /// θ = 7°, K = 1.8e-13) and its TUBE_ALESAGE case (R = 1, L = 10, K = 1.6e-13),
    /// the published depths after 1 to 7 years.
    #[test]
    fn depths_agree_with_code_aster_post_usure() {
        let tubes = Wear {
            coefficient: 1.8e-13,
            geometry: WearGeometry::CrossedTubes {
                radius: 1.0,
                angle_degrees: 7.0,
            },
        };
        for (years, depth) in [
            (1.0, 2.91745602948e-3),
            (3.0, 4.52744122643e-3),
            (5.0, 5.55382666154e-3),
            (7.0, 6.35394622974e-3),
        ] {
            let computed = tubes.depth(tubes.volume(0.5, years * YEAR));
            assert!(
                (computed - depth).abs() < 1e-9 * depth,
                "{years} y: {computed} vs {depth}"
            );
        }
        assert!((tubes.volume(0.5, 2.0 * YEAR) - 5.67648e-6).abs() < 1e-12);
        let bore = Wear {
            coefficient: 1.6e-13,
            geometry: WearGeometry::Bore {
                radius: 1.0,
                length: 10.0,
            },
        };
        for (years, depth) in [
            (2.0, 8.03057645655e-8),
            (4.0, 1.60611529131e-7),
            (6.0, 2.40917293697e-7),
        ] {
            let computed = bore.depth(bore.volume(0.5, years * YEAR));
            assert!(
                (computed - depth).abs() < 1e-9 * depth,
                "{years} y: {computed} vs {depth}"
            );
        }
    }

    /// A flat of width L cuts into a cylinder of radius R the segment
    /// L (R² acos((R − d)/R) − (R − d) √(2Rd − d²)); for d ≪ R the depth of that volume
    /// is the flat law's, to first order in d/R.
    #[test]
    fn the_flat_depth_is_the_depth_of_the_segment_a_flat_cuts_into_a_cylinder() {
        let (radius, width) = (4.25e-3, 2e-3);
        let wear = Wear {
            coefficient: 1e-14,
            geometry: WearGeometry::Flat { radius, width },
        };
        for depth in [1e-7, 1e-6, 1e-5, 5e-5] {
            let r = radius;
            let segment = width
                * (r * r * ((r - depth) / r).acos() - (r - depth) * (2.0 * r * depth - depth * depth).sqrt());
            let computed = wear.depth(segment);
            assert!(
                (computed - depth).abs() < 2.0 * depth / radius * depth,
                "{depth}: {computed}"
            );
        }
    }
}
