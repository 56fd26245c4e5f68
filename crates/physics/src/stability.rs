//! Stability of the explicit schemes: the critical time step including contact stiffness.
//!
//! On the modal basis (M̄ = I) the stiffest state of the row is every contact closed:
//! K̄ = diag(ωᵢ²) per pin + Σ_c Kc b_c b_cᵀ, where b_c holds −ψ(z_c) on the left pin's
//! modes and +ψ(z_c) on the right pin's (nothing for a wall). Each scheme is stable for
//! ω_max Δt ≤ its limit, ω_max² = λ_max(K̄). Up to [`DENSE_LIMIT`] modal DOFs λ_max is
//! computed exactly (dense symmetric eigenvalues); above, it is bounded by the largest
//! λ_max over pins of diag(ω²) + Σ Kc ψψᵀ (walls) + Σ 2 Kc ψψᵀ (pin–pin), since
//! (a − b)(a − b)ᵀ ≼ 2(aaᵀ + bbᵀ): a proven, slightly conservative bound.
//!
//! **Pins in the plane** (x and y lines on the same basis, contact normal n):
//! b_c holds −n_x ψ, −n_y ψ on the left pin's x and y modes and +n_x ψ, +n_y ψ on the
//! right pin's ([`max_angular_frequency_in_plane`]), the same two paths with 2 × modes
//! per pin. Since (n·(a_x, a_y))² ≤ a_x² + a_y² for a unit n, its λ_max never exceeds
//! the row's with the same contacts (every normal +x): equal when the normals are all
//! parallel, smaller when they spread (a pin held from six directions). A contact with
//! friction adds its stick spring k_t along the tangent t = (−n_y, n_x) the same way.

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
                                contact.stability_stiffness() * sign_a * sign_b * shape[i] * shape[j];
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
                            stiffness[(i, j)] += factor * contact.stability_stiffness() * shape[i] * shape[j];
                        }
                    }
                }
                largest_eigenvalue(&stiffness)
            })
            .fold(0.0, f64::max)
    };
    eigenvalue.max(0.0).sqrt()
}

/// ω_max (rad/s) of `pins` pins bending along x and y with every contact closed, contact
/// c pushing along the unit normal `normals[c]` (see the module doc); the other
/// arguments as in [`max_angular_frequency`].
pub fn max_angular_frequency_in_plane(
    frequencies: &[f64],
    pins: usize,
    contacts: &[Contact],
    contact_shapes: &[Vec<f64>],
    normals: &[[f64; 2]],
) -> f64 {
    let modes = frequencies.len();
    // The whole system, lines ordered as in the integrator (x lines, then y), or one
    // pin's x and y lines.
    let dense = 2 * pins * modes <= DENSE_LIMIT;
    let size = if dense { 2 * pins * modes } else { 2 * modes };
    // The first coordinate of a pin's line along an axis (0: x, 1: y).
    let line = |pin: usize, axis: usize| {
        if dense {
            (axis * pins + pin) * modes
        } else {
            axis * modes
        }
    };
    let diagonal = || {
        Mat::<f64>::from_fn(size, size, |i, j| {
            if i == j {
                frequencies[i % modes].powi(2)
            } else {
                0.0
            }
        })
    };
    // Adds factor · Kc b bᵀ for the sides of `contact` that `include` keeps.
    let add = |stiffness: &mut Mat<f64>,
               (contact, shape, normal): (&Contact, &Vec<f64>, &[f64; 2]),
               factor: f64,
               include: &dyn Fn(usize) -> bool| {
        let sides = [(contact.left, -1.0), (contact.right, 1.0)];
        for (body_a, sign_a) in sides {
            let Body::Pin(pa) = body_a else { continue };
            for (body_b, sign_b) in sides {
                let Body::Pin(pb) = body_b else { continue };
                if !(include(pa) && include(pb)) {
                    continue;
                }
                // The normal spring along n and, with friction, the stick spring k_t
                // along the tangent t = (−n_y, n_x).
                let tangent = [-normal[1], normal[0]];
                let springs = [
                    (normal, contact.stability_stiffness()),
                    (&tangent, contact.tangential_stiffness()),
                ];
                for (direction, spring) in springs.into_iter().filter(|(_, k)| *k > 0.0) {
                    for (axis_a, na) in direction.iter().enumerate() {
                        for (axis_b, nb) in direction.iter().enumerate() {
                            let scale = factor * spring * sign_a * sign_b * na * nb;
                            let (ra, rb) = (line(pa, axis_a), line(pb, axis_b));
                            for i in 0..modes {
                                for j in 0..modes {
                                    stiffness[(ra + i, rb + j)] += scale * shape[i] * shape[j];
                                }
                            }
                        }
                    }
                }
            }
        }
    };
    let closed = || {
        contacts
            .iter()
            .zip(contact_shapes)
            .zip(normals)
            .map(|((c, s), n)| (c, s, n))
    };
    let eigenvalue = if dense {
        let mut stiffness = diagonal();
        for contact in closed() {
            add(&mut stiffness, contact, 1.0, &|_| true);
        }
        largest_eigenvalue(&stiffness)
    } else {
        (0..pins)
            .map(|p| {
                let mut stiffness = diagonal();
                for contact in closed() {
                    let (left, right) = (contact.0.left, contact.0.right);
                    if left != Body::Pin(p) && right != Body::Pin(p) {
                        continue;
                    }
                    // A wall contact as it is, a pin–pin one bounded by twice its own
                    // pin's part.
                    let factor = if left == Body::Wall || right == Body::Wall {
                        1.0
                    } else {
                        2.0
                    };
                    add(&mut stiffness, contact, factor, &|pin| pin == p);
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
    use crate::contact::Law;

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
            law: Law::LINEAR,
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
            law: Law::LINEAR,
        };
        let exact = max_angular_frequency(&[3.0], 2, std::slice::from_ref(&contact), &[vec![1.5]]);
        let expected = (9.0f64 + 2.0 * 50.0 * 2.25).sqrt();
        assert!((exact - expected).abs() < 1e-9, "ω_max {exact} vs {expected}");
        // Force the bound path with a large row of uncoupled pins plus this pair.
        let pins = DENSE_LIMIT + 1;
        let bound = max_angular_frequency(&[3.0], pins, &[contact], &[vec![1.5]]);
        assert!(bound >= exact - 1e-9, "bound {bound} below exact {exact}");
    }

    /// In the plane: two one-mode pins joined along n and each held by a wall along
    /// the perpendicular t. Along n only the pin–pin spring acts (antisymmetric mode
    /// ω² + 2 Kc ψ²), along t only the walls (ω² + Kw ψ²); a row with the same contacts
    /// stacks them all on one axis and is above both. The per-pin bound is safe too.
    #[test]
    fn in_the_plane_springs_along_different_normals_do_not_add_up() {
        let normal = [0.6, 0.8];
        let tangent = [-0.8, 0.6];
        let spring = |left, right, stiffness| Contact {
            left,
            right,
            height: 1.0,
            gap: 0.0,
            stiffness,
            damping: 0.0,
            law: Law::LINEAR,
        };
        let contacts = [
            spring(Body::Pin(0), Body::Pin(1), 50.0),
            spring(Body::Wall, Body::Pin(0), 120.0),
            spring(Body::Pin(1), Body::Wall, 120.0),
        ];
        let shapes = vec![vec![1.5]; 3];
        let normals = [normal, tangent, tangent];
        let exact = max_angular_frequency_in_plane(&[3.0], 2, &contacts, &shapes, &normals);
        let expected = (9.0f64 + 2.0 * 50.0 * 2.25).max(9.0 + 120.0 * 2.25).sqrt();
        assert!((exact - expected).abs() < 1e-9, "ω_max {exact} vs {expected}");
        let row = max_angular_frequency(&[3.0], 2, &contacts, &shapes);
        assert!(
            row > exact + 1.0,
            "the row {row} stacks what the plane splits {exact}"
        );
        let pins = DENSE_LIMIT;
        let bound = max_angular_frequency_in_plane(&[3.0], pins, &contacts, &shapes, &normals);
        assert!(bound >= exact - 1e-9, "bound {bound} below exact {exact}");
    }

    #[test]
    fn tchamwa_limit_reduces_to_central_difference_at_phi_one() {
        assert_eq!(Scheme::Tchamwa { phi: 1.0 }.stability_limit(), 2.0);
        assert!(Scheme::Tchamwa { phi: 1.1 }.stability_limit() < 2.0);
    }
}
