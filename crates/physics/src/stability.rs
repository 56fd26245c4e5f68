//! Stability of the explicit schemes: the critical time step including contact stiffness.
//!
//! On the modal basis (M̄ = I) the stiffest state of the row is every contact closed:
//! K̄ = diag(ωᵢ²) per pin + Σ_c Kc b_c b_cᵀ, where b_c holds −ψ(z_c) on the left pin's
//! modes and +ψ(z_c) on the right pin's (nothing for a wall). Each scheme is stable for
//! ω_max Δt ≤ its limit, ω_max² = λ_max(K̄). Up to [`DENSE_LIMIT`] modal DOFs λ_max is
//! computed exactly (dense symmetric eigenvalues); above, it is bounded by the largest
//! λ_max over pins of diag(ω²) + Σ Kc ψψᵀ (walls) + Σ 2 Kc ψψᵀ (pin–pin), since
//! (a − b)(a − b)ᵀ ≼ 2(aaᵀ + bbᵀ): a proven, slightly conservative bound.

use faer::{Mat, Side};

use super::contact::{Body, Contact};

/// Largest modal system (pins × modes) whose λ_max is computed exactly.
pub const DENSE_LIMIT: usize = 1500;

/// Explicit integration scheme on the modal coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    /// Central difference, velocity form: second order, no numerical dissipation.
    CentralDifference,
    /// Tchamwa–Wielgosz with parameter φ ≥ 1 (φ = 1: no dissipation): first order,
    /// damps high frequencies.
    Tchamwa { phi: f64 },
}

impl Scheme {
    /// Stability limit of ω Δt for an undamped oscillator: 2 (central difference),
    /// 2/√(2φ − 1) (Tchamwa–Wielgosz).
    pub fn stability_limit(&self) -> f64 {
        match *self {
            Scheme::CentralDifference => 2.0,
            Scheme::Tchamwa { phi } => 2.0 / (2.0 * phi - 1.0).sqrt(),
        }
    }
}

/// ω_max (rad/s) of the row of `pins` pins with every contact closed.
/// `frequencies` are the modal ωᵢ, `contact_shapes[c]` is ψ(z_c) for contact c.
pub fn max_angular_frequency(
    frequencies: &[f64],
    pins: usize,
    contacts: &[Contact],
    contact_shapes: &[Vec<f64>],
) -> f64 {
    let modes = frequencies.len();
    let size = pins * modes;
    let eigenvalue = if size <= DENSE_LIMIT {
        let mut stiffness = Mat::<f64>::zeros(size, size);
        for p in 0..pins {
            for (i, w) in frequencies.iter().enumerate() {
                stiffness[(p * modes + i, p * modes + i)] = w * w;
            }
        }
        for (contact, shape) in contacts.iter().zip(contact_shapes) {
            let sides = [(contact.left, -1.0), (contact.right, 1.0)];
            for (body_a, sign_a) in sides {
                let Body::Pin(pa) = body_a else { continue };
                for (body_b, sign_b) in sides {
                    let Body::Pin(pb) = body_b else { continue };
                    for i in 0..modes {
                        for j in 0..modes {
                            stiffness[(pa * modes + i, pb * modes + j)] +=
                                contact.stiffness * sign_a * sign_b * shape[i] * shape[j];
                        }
                    }
                }
            }
        }
        largest_eigenvalue(&stiffness)
    } else {
        (0..pins)
            .map(|p| {
                let mut stiffness =
                    Mat::<f64>::from_fn(
                        modes,
                        modes,
                        |i, j| if i == j { frequencies[i].powi(2) } else { 0.0 },
                    );
                for (contact, shape) in contacts.iter().zip(contact_shapes) {
                    let touches = contact.left == Body::Pin(p) || contact.right == Body::Pin(p);
                    if !touches {
                        continue;
                    }
                    let factor = if contact.left == Body::Wall || contact.right == Body::Wall {
                        1.0
                    } else {
                        2.0
                    };
                    for i in 0..modes {
                        for j in 0..modes {
                            stiffness[(i, j)] += factor * contact.stiffness * shape[i] * shape[j];
                        }
                    }
                }
                largest_eigenvalue(&stiffness)
            })
            .fold(0.0, f64::max)
    };
    eigenvalue.max(0.0).sqrt()
}

fn largest_eigenvalue(matrix: &Mat<f64>) -> f64 {
    match matrix.self_adjoint_eigenvalues(Side::Lower) {
        Ok(values) => values.last().copied().unwrap_or(0.0),
        // Gershgorin: λ_max ≤ max row sum of |entries|.
        Err(_) => (0..matrix.nrows())
            .map(|i| (0..matrix.ncols()).map(|j| matrix[(i, j)].abs()).sum::<f64>())
            .fold(0.0, f64::max),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One mode, one wall spring: ω_max² = ω² + Kc ψ² exactly.
    #[test]
    fn single_mode_wall_contact_adds_its_stiffness() {
        let contact = Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: 1.0,
            gap: 0.0,
            stiffness: 300.0,
            damping: 0.0,
        };
        let omega = max_angular_frequency(&[10.0], 1, &[contact], &[vec![2.0]]);
        assert!((omega - (100.0f64 + 1200.0).sqrt()).abs() < 1e-9, "ω_max {omega}");
    }

    /// Two identical one-mode pins joined by a spring: the antisymmetric mode has
    /// ω² + 2 Kc ψ²; the per-pin bound (used for large rows) equals it here.
    #[test]
    fn pin_to_pin_contact_couples_both_pins_and_the_bound_is_safe() {
        let contact = Contact {
            left: Body::Pin(0),
            right: Body::Pin(1),
            height: 1.0,
            gap: 0.0,
            stiffness: 50.0,
            damping: 0.0,
        };
        let exact = max_angular_frequency(&[3.0], 2, std::slice::from_ref(&contact), &[vec![1.5]]);
        let expected = (9.0f64 + 2.0 * 50.0 * 2.25).sqrt();
        assert!((exact - expected).abs() < 1e-9, "ω_max {exact} vs {expected}");
        // Force the bound path with a large row of uncoupled pins plus this pair.
        let pins = DENSE_LIMIT + 1;
        let bound = max_angular_frequency(&[3.0], pins, &[contact], &[vec![1.5]]);
        assert!(bound >= exact - 1e-9, "bound {bound} below exact {exact}");
    }

    #[test]
    fn tchamwa_limit_reduces_to_central_difference_at_phi_one() {
        assert_eq!(Scheme::Tchamwa { phi: 1.0 }.stability_limit(), 2.0);
        assert!(Scheme::Tchamwa { phi: 1.1 }.stability_limit() < 2.0);
    }
}
