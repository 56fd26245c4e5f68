//! Stability of the explicit schemes: the critical time step including contact stiffness.
//!
//! On the modal basis (M̄ = I) the stiffest state of the row is every contact closed:
//! K̄ = diag(ωᵢ²) per pin + Σ_c Kc b_c b_cᵀ, where b_c holds −ψ(z_c) on the left pin's
//! modes and +ψ(z_c) on the right pin's (nothing for a wall). Each scheme is stable for
//! ω_max Δt ≤ its limit, ω_max² = λ_max(K̄). Up to [`DENSE_LIMIT`] modal DOFs λ_max is
//! computed exactly (dense symmetric eigenvalues). Above, K̄ is never formed: Lanczos
//! iterations on its product with a vector (diag(ω²) x + Σ Kc b (bᵀx), a few operations
//! per contact and mode) converge to λ_max, and the run takes the top Ritz value plus
//! its residual |β s_k|, an upper estimate (some eigenvalue lies within the residual of
//! the Ritz value; the start vector is fixed, so the value is the same at every call).
//! It is capped by the per-pin bound, the largest λ_max over pins of diag(ω²) + Σ Kc ψψᵀ
//! (walls) + Σ 2 Kc ψψᵀ (pin–pin), since (a − b)(a − b)ᵀ ≼ 2(aaᵀ + bbᵀ): proven, and up to
//! twice λ_max in a dense bundle (a step up to √2 shorter than it need be), which was
//! the value used before.
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

/// Integration scheme on the modal coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    /// Central difference, velocity form: second order, no numerical dissipation.
    CentralDifference,
    /// Tchamwa–Wielgosz with parameter φ ≥ 1 (φ = 1: no dissipation): first order,
    /// damps high frequencies.
    Tchamwa { phi: f64 },
    /// Every mode propagated exactly over the step, the contact forces implicit
    /// (`crate::integrate`'s `exact` module; no friction, no walls with their own motion): second order, no stability limit; the step
    /// resolves the contacts and the excitation, not the top of the basis.
    ExactModal,
}

impl Scheme {
    /// Stability limit of ω Δt for an undamped oscillator: 2 (central difference),
    /// 2/√(2φ − 1) (Tchamwa–Wielgosz), none (∞) for the exact modal scheme.
    pub fn stability_limit(&self) -> f64 {
        match *self {
            Scheme::CentralDifference => 2.0,
            Scheme::Tchamwa { phi } => 2.0 / (2.0 * phi - 1.0).sqrt(),
            Scheme::ExactModal => f64::INFINITY,
        }
    }

    /// Whether a step is bounded by stability (the explicit schemes).
    pub fn is_explicit(&self) -> bool {
        !matches!(self, Scheme::ExactModal)
    }
}

/// The pins' modes as the stability analysis sees them: each pin's angular frequencies
/// ωᵢ and the factor s = 1/√μ its shapes take in mass-normalised coordinates (a body of
/// another kind, of modal mass μ relative to the basis's beam, `crate::integrate::
/// BodyKind`: K̄ = M̄^{-½} (diag(μ ω²) + Σ Kc b bᵀ) M̄^{-½} has ω² on its diagonal and
/// s ψ in b on that pin's lines).
#[derive(Debug, Clone)]
pub struct PinModes<'a> {
    pub frequencies: Vec<&'a [f64]>,
    pub shape_scales: Vec<f64>,
}

impl<'a> PinModes<'a> {
    /// `pins` pins of one kind, of these frequencies.
    pub fn uniform(frequencies: &'a [f64], pins: usize) -> Self {
        Self {
            frequencies: vec![frequencies; pins],
            shape_scales: vec![1.0; pins],
        }
    }

    fn pins(&self) -> usize {
        self.frequencies.len()
    }

    fn modes(&self) -> usize {
        self.frequencies.first().map_or(0, |f| f.len())
    }

    /// ω² of pin p's mode i.
    fn omega_squared(&self, p: usize, i: usize) -> f64 {
        self.frequencies[p][i].powi(2)
    }
}

/// ω_max (rad/s) of the row of pins `pin_modes` with every contact closed.
/// `contact_shapes[c]` is ψ(z_c) for contact c (on the basis's beam).
pub fn max_angular_frequency(
    pin_modes: &PinModes<'_>,
    contacts: &[Contact],
    contact_shapes: &[Vec<f64>],
) -> f64 {
    let (pins, modes) = (pin_modes.pins(), pin_modes.modes());
    let scale = &pin_modes.shape_scales;
    let size = pins * modes;
    let eigenvalue = if size <= DENSE_LIMIT {
        let mut stiffness = Mat::<f64>::zeros(size, size);
        for p in 0..pins {
            for i in 0..modes {
                stiffness[(p * modes + i, p * modes + i)] = pin_modes.omega_squared(p, i);
            }
        }
        for (contact, shape) in contacts.iter().zip(contact_shapes) {
            let sides = [(contact.left, -1.0), (contact.right, 1.0)];
            for (body_a, sign_a) in sides {
                let Body::Pin(pa) = body_a else { continue };
                for (body_b, sign_b) in sides {
                    let Body::Pin(pb) = body_b else { continue };
                    let k = contact.stability_stiffness() * sign_a * sign_b * scale[pa] * scale[pb];
                    for i in 0..modes {
                        for j in 0..modes {
                            stiffness[(pa * modes + i, pb * modes + j)] += k * shape[i] * shape[j];
                        }
                    }
                }
            }
        }
        largest_eigenvalue(&stiffness)
    } else {
        let springs: Vec<Spring> = contacts
            .iter()
            .zip(contact_shapes)
            .map(|(contact, shape)| Spring {
                stiffness: contact.stability_stiffness(),
                shape,
                parts: [(contact.left, -1.0), (contact.right, 1.0)]
                    .into_iter()
                    .filter_map(|(body, sign)| match body {
                        Body::Pin(p) => Some((p * modes, sign * scale[p])),
                        Body::Wall => None,
                    })
                    .collect(),
            })
            .collect();
        let bound = (0..pins)
            .map(|p| {
                let mut stiffness = Mat::<f64>::from_fn(modes, modes, |i, j| {
                    if i == j {
                        pin_modes.omega_squared(p, i)
                    } else {
                        0.0
                    }
                });
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
                    let k = factor * contact.stability_stiffness() * scale[p] * scale[p];
                    for i in 0..modes {
                        for j in 0..modes {
                            stiffness[(i, j)] += k * shape[i] * shape[j];
                        }
                    }
                }
                largest_eigenvalue(&stiffness)
            })
            .fold(0.0, f64::max);
        let diagonal: Vec<f64> = (0..size)
            .map(|k| pin_modes.omega_squared(k / modes, k % modes))
            .collect();
        largest_eigenvalue_of_springs(&diagonal, modes, &springs).min(bound)
    };
    eigenvalue.max(0.0).sqrt()
}

/// ω_max (rad/s) of `pins` pins bending along x and y with every contact closed, contact
/// c pushing along the unit normal `normals[c]` (see the module doc); the other
/// arguments as in [`max_angular_frequency`].
pub fn max_angular_frequency_in_plane(
    pin_modes: &PinModes<'_>,
    contacts: &[Contact],
    contact_shapes: &[Vec<f64>],
    normals: &[[f64; 2]],
) -> f64 {
    let (pins, modes) = (pin_modes.pins(), pin_modes.modes());
    let scale = &pin_modes.shape_scales;
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
    // ω² of the whole system's coordinate k (lines ordered as in the integrator), or of
    // pin p's x and y lines alone.
    let omega_squared = |k: usize| pin_modes.omega_squared((k / modes) % pins, k % modes);
    let diagonal = |pin: Option<usize>| {
        Mat::<f64>::from_fn(size, size, |i, j| match (i == j, pin) {
            (false, _) => 0.0,
            (true, None) => omega_squared(i),
            (true, Some(p)) => pin_modes.omega_squared(p, i % modes),
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
                            let k = factor * spring * sign_a * sign_b * na * nb * scale[pa] * scale[pb];
                            let (ra, rb) = (line(pa, axis_a), line(pb, axis_b));
                            for i in 0..modes {
                                for j in 0..modes {
                                    stiffness[(ra + i, rb + j)] += k * shape[i] * shape[j];
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
        let mut stiffness = diagonal(None);
        for contact in closed() {
            add(&mut stiffness, contact, 1.0, &|_| true);
        }
        largest_eigenvalue(&stiffness)
    } else {
        // The whole system's lines, as in the integrator.
        let line = |pin: usize, axis: usize| (axis * pins + pin) * modes;
        let mut springs = Vec::new();
        for (contact, shape, normal) in closed() {
            let tangent = [-normal[1], normal[0]];
            for (direction, stiffness) in [
                (*normal, contact.stability_stiffness()),
                (tangent, contact.tangential_stiffness()),
            ] {
                if stiffness <= 0.0 {
                    continue;
                }
                let mut parts = Vec::with_capacity(4);
                for (body, sign) in [(contact.left, -1.0), (contact.right, 1.0)] {
                    if let Body::Pin(p) = body {
                        parts.push((line(p, 0), sign * scale[p] * direction[0]));
                        parts.push((line(p, 1), sign * scale[p] * direction[1]));
                    }
                }
                springs.push(Spring {
                    stiffness,
                    shape,
                    parts,
                });
            }
        }
        let bound = (0..pins)
            .map(|p| {
                let mut stiffness = diagonal(Some(p));
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
            .fold(0.0, f64::max);
        let diagonal: Vec<f64> = (0..2 * pins * modes).map(omega_squared).collect();
        largest_eigenvalue_of_springs(&diagonal, modes, &springs).min(bound)
    };
    eigenvalue.max(0.0).sqrt()
}

/// One closed spring of K̄ = diag(ω²) + Σ k b bᵀ: b holds `coefficient` × ψ on the modal
/// line starting at each `parts` offset (−1 and +1 on the two pins of a row contact;
/// ∓n_x, ∓n_y on their x and y lines in the plane), nothing elsewhere.
struct Spring<'a> {
    stiffness: f64,
    shape: &'a [f64],
    parts: Vec<(usize, f64)>,
}

/// Most Lanczos iterations (the top eigenvalue converges in far fewer).
const LANCZOS_ITERATIONS: usize = 300;
/// Relative residual of the top Ritz pair at which Lanczos stops.
const LANCZOS_TOLERANCE: f64 = 1e-10;

/// λ_max of K̄ = diag(`diagonal`) + Σ k b bᵀ over `springs` (`diagonal`: each
/// coordinate's ω², lines of `modes` coordinates), by Lanczos with full reorthogonalisation, never
/// forming K̄: the top Ritz value plus its residual (see the module doc).
fn largest_eigenvalue_of_springs(diagonal: &[f64], modes: usize, springs: &[Spring]) -> f64 {
    let size = diagonal.len();
    let apply = |x: &[f64], y: &mut [f64]| {
        for ((yk, xk), d) in y.iter_mut().zip(x).zip(diagonal) {
            *yk = d * xk;
        }
        for spring in springs {
            let projection: f64 = spring
                .parts
                .iter()
                .map(|&(at, c)| c * dot(spring.shape, &x[at..at + modes]))
                .sum();
            let scale = spring.stiffness * projection;
            for &(at, c) in &spring.parts {
                for (yk, psi) in y[at..at + modes].iter_mut().zip(spring.shape) {
                    *yk += scale * c * psi;
                }
            }
        }
    };
    // A fixed start with a part along every eigenvector (no symmetry of the bundle makes
    // a coordinate pattern of it orthogonal to the top one): a linear congruential sequence.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut start: Vec<f64> = (0..size)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let norm = dot(&start, &start).sqrt();
    start.iter_mut().for_each(|v| *v /= norm);
    let mut basis = vec![start];
    let (mut alpha, mut beta) = (Vec::new(), Vec::<f64>::new());
    let mut w = vec![0.0; size];
    let mut estimate = 0.0;
    for j in 0..LANCZOS_ITERATIONS.min(size) {
        apply(&basis[j], &mut w);
        alpha.push(dot(&w, &basis[j]));
        // Full reorthogonalisation, twice (Kahan's "twice is enough").
        for _ in 0..2 {
            for v in &basis {
                let c = dot(&w, v);
                w.iter_mut().zip(v).for_each(|(wk, vk)| *wk -= c * vk);
            }
        }
        let b = dot(&w, &w).sqrt();
        let last = j + 1 == LANCZOS_ITERATIONS.min(size);
        let invariant = b <= 1e-14 * alpha.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        if last || invariant || (j + 1) % 10 == 0 {
            let (theta, tail) = top_ritz_pair(&alpha, &beta);
            estimate = theta + (b * tail).abs();
            if last || invariant || (b * tail).abs() <= LANCZOS_TOLERANCE * theta {
                break;
            }
        }
        beta.push(b);
        basis.push(w.iter().map(|wk| wk / b).collect());
    }
    estimate
}

/// The largest eigenvalue of the tridiagonal matrix of `alpha` (diagonal) and `beta`
/// (off-diagonal), with the last component of its unit eigenvector.
fn top_ritz_pair(alpha: &[f64], beta: &[f64]) -> (f64, f64) {
    let n = alpha.len();
    let t = Mat::<f64>::from_fn(n, n, |i, j| {
        if i == j {
            alpha[i]
        } else if i.abs_diff(j) == 1 {
            beta[i.min(j)]
        } else {
            0.0
        }
    });
    match t.self_adjoint_eigen(Side::Lower) {
        Ok(eigen) => (eigen.S().column_vector()[n - 1], eigen.U()[(n - 1, n - 1)]),
        // Gershgorin, with no claim of convergence.
        Err(_) => (
            (0..n)
                .map(|i| {
                    alpha[i].abs()
                        + beta.get(i).map_or(0.0, |b| b.abs())
                        + i.checked_sub(1).map_or(0.0, |k| beta[k].abs())
                })
                .fold(0.0, f64::max),
            1.0,
        ),
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
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
        let omega = max_angular_frequency(&PinModes::uniform(&[10.0], 1), &[contact], &[vec![2.0]]);
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
        let exact = max_angular_frequency(
            &PinModes::uniform(&[3.0], 2),
            std::slice::from_ref(&contact),
            &[vec![1.5]],
        );
        let expected = (9.0f64 + 2.0 * 50.0 * 2.25).sqrt();
        assert!((exact - expected).abs() < 1e-9, "ω_max {exact} vs {expected}");
        // Force the bound path with a large row of uncoupled pins plus this pair.
        let pins = DENSE_LIMIT + 1;
        let bound = max_angular_frequency(&PinModes::uniform(&[3.0], pins), &[contact], &[vec![1.5]]);
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
        let exact =
            max_angular_frequency_in_plane(&PinModes::uniform(&[3.0], 2), &contacts, &shapes, &normals);
        let expected = (9.0f64 + 2.0 * 50.0 * 2.25).max(9.0 + 120.0 * 2.25).sqrt();
        assert!((exact - expected).abs() < 1e-9, "ω_max {exact} vs {expected}");
        let row = max_angular_frequency(&PinModes::uniform(&[3.0], 2), &contacts, &shapes);
        assert!(
            row > exact + 1.0,
            "the row {row} stacks what the plane splits {exact}"
        );
        let pins = DENSE_LIMIT;
        let bound =
            max_angular_frequency_in_plane(&PinModes::uniform(&[3.0], pins), &contacts, &shapes, &normals);
        assert!(bound >= exact - 1e-9, "bound {bound} below exact {exact}");
    }

    /// Above the dense limit λ_max comes from Lanczos without forming K̄: on a triangular
    /// lattice of two-mode pins in the plane (springs along three directions, friction
    /// on some) it equals the dense eigenvalue of the assembled K̄ to 1e-9; on a row of
    /// 501 three-mode pins, whose top eigenvalues crowd, it is at most 1e-4 above it.
    #[test]
    fn above_the_dense_limit_lanczos_finds_the_exact_eigenvalue() {
        let frequencies = [40.0, 250.0];
        let shapes = |n: usize| vec![vec![1.3, -0.7]; n];
        // 20 × 19 pins, each joined to its right, upper and upper-right neighbours.
        let (columns, rows) = (20, 19);
        let pins = columns * rows;
        let index = |c: usize, r: usize| r * columns + c;
        let half = 0.5f64;
        let root = 0.75f64.sqrt();
        let (mut contacts, mut normals) = (Vec::new(), Vec::new());
        for r in 0..rows {
            for c in 0..columns {
                let mut join = |other: usize, normal: [f64; 2], stiffness: f64, friction: bool| {
                    let mut law = Law::LINEAR;
                    if friction {
                        law.friction = crate::contact::Friction {
                            coefficient: 0.3,
                            tangential_stiffness: 0.4 * stiffness,
                        };
                    }
                    contacts.push(Contact {
                        left: Body::Pin(index(c, r)),
                        right: Body::Pin(other),
                        height: 1.0,
                        gap: 0.0,
                        stiffness,
                        damping: 0.0,
                        law,
                    });
                    normals.push(normal);
                };
                let k = 1e4 * (1.0 + 0.1 * ((c * 7 + r * 3) % 5) as f64);
                if c + 1 < columns {
                    join(index(c + 1, r), [1.0, 0.0], k, (c + r) % 3 == 0);
                }
                if r + 1 < rows {
                    join(index(c, r + 1), [half, root], k, false);
                    if c + 1 < columns {
                        join(index(c + 1, r + 1), [-half, root], 1.5 * k, false);
                    }
                }
            }
        }
        // Walls along x at both ends of the first row.
        for (left, right) in [(Body::Wall, Body::Pin(0)), (Body::Pin(columns - 1), Body::Wall)] {
            contacts.push(Contact {
                left,
                right,
                height: 1.0,
                gap: 0.0,
                stiffness: 3e4,
                damping: 0.0,
                law: Law::LINEAR,
            });
            normals.push([1.0, 0.0]);
        }
        let modes = frequencies.len();
        assert!(2 * pins * modes > DENSE_LIMIT);
        let lanczos = max_angular_frequency_in_plane(
            &PinModes::uniform(&frequencies, pins),
            &contacts,
            &shapes(contacts.len()),
            &normals,
        );

        let size = 2 * pins * modes;
        let mut dense = Mat::<f64>::from_fn(size, size, |i, j| {
            if i == j {
                frequencies[i % modes].powi(2)
            } else {
                0.0
            }
        });
        for (contact, normal) in contacts.iter().zip(&normals) {
            let tangent = [-normal[1], normal[0]];
            for (direction, spring) in [
                (*normal, contact.stability_stiffness()),
                (tangent, contact.tangential_stiffness()),
            ] {
                let mut b = vec![0.0; size];
                for (body, sign) in [(contact.left, -1.0), (contact.right, 1.0)] {
                    if let Body::Pin(p) = body {
                        for axis in 0..2 {
                            for i in 0..modes {
                                b[(axis * pins + p) * modes + i] += sign * direction[axis] * shapes(1)[0][i];
                            }
                        }
                    }
                }
                add_outer(&mut dense, spring, &b);
            }
        }
        let exact = largest_eigenvalue(&dense).sqrt();
        assert!(
            (lanczos - exact).abs() <= 1e-9 * exact,
            "Lanczos {lanczos}, dense {exact}"
        );

        // A row of 501 three-mode pins between two walls.
        let frequencies = [10.0, 60.0, 170.0];
        let pins = 501;
        let contacts: Vec<Contact> = (0..=pins)
            .map(|k| Contact {
                left: if k == 0 { Body::Wall } else { Body::Pin(k - 1) },
                right: if k == pins { Body::Wall } else { Body::Pin(k) },
                height: 1.0,
                gap: 0.0,
                stiffness: 2e3 * (1.0 + (k % 7) as f64),
                damping: 0.0,
                law: Law::LINEAR,
            })
            .collect();
        let shape = vec![0.9, -1.1, 0.4];
        let shapes = vec![shape.clone(); contacts.len()];
        let lanczos = max_angular_frequency(&PinModes::uniform(&frequencies, pins), &contacts, &shapes);
        let size = pins * 3;
        let mut dense =
            Mat::<f64>::from_fn(
                size,
                size,
                |i, j| if i == j { frequencies[i % 3].powi(2) } else { 0.0 },
            );
        for contact in &contacts {
            let mut b = vec![0.0; size];
            for (body, sign) in [(contact.left, -1.0), (contact.right, 1.0)] {
                if let Body::Pin(p) = body {
                    for i in 0..3 {
                        b[p * 3 + i] += sign * shape[i];
                    }
                }
            }
            add_outer(&mut dense, contact.stiffness, &b);
        }
        // The chain's top eigenvalues crowd (spacing ~ 1/pins²): Lanczos stops at its
        // iteration limit with the residual added, just above.
        let exact = largest_eigenvalue(&dense).sqrt();
        assert!(
            lanczos >= exact && lanczos <= exact * (1.0 + 1e-4),
            "row: Lanczos {lanczos}, dense {exact}"
        );
    }

    /// matrix += k b bᵀ over the nonzero entries of b.
    fn add_outer(matrix: &mut Mat<f64>, k: f64, b: &[f64]) {
        let nonzero: Vec<usize> = (0..b.len()).filter(|&i| b[i] != 0.0).collect();
        for &i in &nonzero {
            for &j in &nonzero {
                matrix[(i, j)] += k * b[i] * b[j];
            }
        }
    }

    #[test]
    fn tchamwa_limit_reduces_to_central_difference_at_phi_one() {
        assert_eq!(Scheme::Tchamwa { phi: 1.0 }.stability_limit(), 2.0);
        assert!(Scheme::Tchamwa { phi: 1.1 }.stability_limit() < 2.0);
    }
}
