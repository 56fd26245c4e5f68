//! Static correction of a truncated modal basis at the contact heights (residual
//! flexibility, code_aster `MODE_STATIQUE` + `DEFI_BASE_MODALE`, Cast3M `PSMO`).
//!
//! **Why.** A point force F at height z deflects the beam statically by
//! u = K⁻¹ f F, f the consistent nodal load of a unit force at z (fᵢ = Nᵢ(z), the Hermite
//! shape functions of the element holding z). The first m modes only represent
//! Φ Ω⁻² Φᵀ f F of it; the dropped modes carry the residual flexibility
//! R(z) = fᵀ (K⁻¹ − Φ Ω⁻² Φᵀ) f (m/N). A stiff contact feels that missing flexibility:
//! the truncated beam is too stiff at the contact point, impacts are too short and too
//! hard, rebounds come early.
//!
//! **Formulation chosen: Ritz augmentation, then diagonalisation.** For each distinct
//! contact height z_k (k = 1..s), take the static shape sₖ = K⁻¹ f(z_k) and
//! 1. M-orthogonalise it against the modes and the shapes already kept (modified
//!    Gram–Schmidt, twice): s̃ₖ = sₖ − Σᵢ φᵢ (φᵢᵀ M sₖ) − Σ_{j<k} qⱼ (qⱼᵀ M sₖ),
//!    qₖ = s̃ₖ / ‖s̃ₖ‖_M. A shape whose residual M-norm is below [`DEPENDENT_TOLERANCE`]
//!    of its own norm already lies in the basis (a height at a fixed support, where the
//!    static response is zero, or a complete basis) and is dropped;
//! 2. solve the small eigenproblem (Qᵀ K Q) y = ω² y (Q is M-orthonormal, so Qᵀ M Q = I)
//!    and take ψ = Q y as **pseudo-modes**.
//!
//! The basis [Φ, Ψ] spans [Φ, S]: Rayleigh–Ritz on it. Because the φᵢ are exact
//! eigenvectors of (K, M), φᵢᵀ K q = ωᵢ² φᵢᵀ M q = 0 for every q M-orthogonal to them:
//! the reduced matrices of the whole basis are exactly M̄ = I and K̄ = diag(ω², ω̃²),
//! the modes keep their frequencies, and the pseudo-modes behave as extra modes with
//! frequencies ω̃ (the eigen-solver's residue of that coupling, ~1e-9 relative, is
//! dropped). Every vector M-orthogonal to the first m modes has a Rayleigh quotient at
//! least ω²ₘ₊₁ (Courant–Fischer), so ω̃ ≥ ωₘ₊₁ > ωₘ: the pseudo-modes come after the
//! modes, frequencies stay increasing.
//!
//! Consequences: the integrator (diagonal modal equations, contact forces through
//! ψ(z)) runs unchanged on the augmented basis; the static flexibility at every
//! corrected height is now exact (fᵀ K⁻¹ f, since s(z) lies in the span); and the
//! critical step, computed from the basis frequencies and the contact shapes, stays
//! exact for the augmented model. Its cost: s more modal DOFs per pin and ω̃ above
//! ωₘ₊₁, so a shorter critical step (what `auto` sees).
//!
//! Rejected alternative: residual flexibility R in series with the contact spring
//! (effective stiffness Kc/(1 + Kc R)). It adds no DOF and no frequency, but it is
//! quasi-static (no mass on the residual), couples the closed contacts of one pin
//! through the R matrix (a small linear solve per step whenever two close at once),
//! and would have changed the integrator and its stability analysis.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

use super::beam::BeamModel;
use super::modal::{dot, mat_vec};

/// A static shape whose part outside the span of the basis has an M-norm below this
/// fraction of its own M-norm is dropped (it adds nothing but rounding noise).
pub const DEPENDENT_TOLERANCE: f64 = 1e-8;

/// Pseudo-modes of a static correction, over all DOFs (zero on fixed ones).
#[derive(Debug, Clone, PartialEq)]
pub struct PseudoModes {
    /// Distinct heights (m), increasing, whose static shape was added.
    pub heights: Vec<f64>,
    /// Heights (m) whose static shape already lay in the basis (dropped).
    pub dropped_heights: Vec<f64>,
    /// ω̃ (rad/s), increasing, one per pseudo-mode (as many as `heights`).
    pub angular_frequencies: Vec<f64>,
    /// Pseudo-mode shapes, M-orthonormal and M-orthogonal to the modes, over all DOFs.
    pub shapes: Vec<Vec<f64>>,
}

/// Why a static correction could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StaticCorrectionError {
    /// K restricted to the free DOFs is not positive definite: the supports let the
    /// beam move as a rigid body.
    #[error(
        "the static correction needs a stiffness matrix that the supports make invertible: \
         clamp one end or pin both (a free-free pin has no static response)"
    )]
    SingularStiffness,
    #[error("the eigenvalue solver did not converge on the static correction")]
    EigenSolverFailed,
}

/// The static shapes K⁻¹ f(z) at the distinct `heights`, made M-orthonormal to `modes`
/// (mass-normalised mode shapes over all DOFs) and diagonalised (module docs).
pub fn pseudo_modes(
    model: &BeamModel,
    modes: &[&[f64]],
    heights: &[f64],
) -> Result<PseudoModes, StaticCorrectionError> {
    let mut distinct: Vec<f64> = heights.to_vec();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();

    let statics = static_shapes(model, &distinct)?;
    let dofs = model.dof_count();
    let mass = &model.mass;
    let m_dot = |a: &[f64], b: &[f64]| dot(a, &mat_vec(mass, dofs, b));

    let mut kept_heights = Vec::new();
    let mut dropped_heights = Vec::new();
    let mut orthonormal: Vec<Vec<f64>> = Vec::new();
    for (height, shape) in distinct.iter().zip(statics) {
        let norm = m_dot(&shape, &shape).sqrt();
        let mut residual = shape;
        for _pass in 0..2 {
            for basis_vector in modes.iter().copied().chain(orthonormal.iter().map(Vec::as_slice)) {
                let c = m_dot(basis_vector, &residual);
                residual
                    .iter_mut()
                    .zip(basis_vector)
                    .for_each(|(r, b)| *r -= c * b);
            }
        }
        let left = m_dot(&residual, &residual).sqrt();
        if !(norm > 0.0 && left > DEPENDENT_TOLERANCE * norm) {
            dropped_heights.push(*height);
            continue;
        }
        residual.iter_mut().for_each(|r| *r /= left);
        orthonormal.push(residual);
        kept_heights.push(*height);
    }

    let s = orthonormal.len();
    let k_q: Vec<Vec<f64>> = orthonormal
        .iter()
        .map(|q| mat_vec(&model.stiffness, dofs, q))
        .collect();
    let reduced = Mat::from_fn(s, s, |i, j| {
        0.5 * (dot(&orthonormal[i], &k_q[j]) + dot(&orthonormal[j], &k_q[i]))
    });
    let mut angular_frequencies = Vec::with_capacity(s);
    let mut shapes = Vec::with_capacity(s);
    if s > 0 {
        let eigen = reduced
            .self_adjoint_eigen(Side::Lower)
            .map_err(|_| StaticCorrectionError::EigenSolverFailed)?;
        let values = eigen.S().column_vector();
        let vectors = eigen.U();
        for k in 0..s {
            let value = values[k];
            if !(value.is_finite() && value > 0.0) {
                return Err(StaticCorrectionError::EigenSolverFailed);
            }
            angular_frequencies.push(value.sqrt());
            let mut shape = vec![0.0; dofs];
            for (j, q) in orthonormal.iter().enumerate() {
                let y = vectors[(j, k)];
                shape.iter_mut().zip(q).for_each(|(v, q)| *v += y * q);
            }
            shapes.push(shape);
        }
    }
    Ok(PseudoModes {
        heights: kept_heights,
        dropped_heights,
        angular_frequencies,
        shapes,
    })
}

/// Static shapes K⁻¹ f(z) (over all DOFs) of a unit point force at each height, f the
/// consistent nodal load (Hermite shape functions at z) restricted to the free DOFs.
pub fn static_shapes(model: &BeamModel, heights: &[f64]) -> Result<Vec<Vec<f64>>, StaticCorrectionError> {
    if allows_rigid_motion(model) {
        return Err(StaticCorrectionError::SingularStiffness);
    }
    let free = &model.free_dofs;
    let dofs = model.dof_count();
    let n = free.len();
    let stiffness = Mat::from_fn(n, n, |i, j| model.stiffness[free[i] * dofs + free[j]]);
    let llt = stiffness
        .llt(Side::Lower)
        .map_err(|_| StaticCorrectionError::SingularStiffness)?;
    let mut rhs = Mat::<f64>::zeros(n, heights.len());
    for (column, height) in heights.iter().enumerate() {
        let (first_dof, weights) = model.interpolation(*height);
        for (k, weight) in weights.iter().enumerate() {
            if let Some(row) = free.iter().position(|&d| d == first_dof + k) {
                rhs[(row, column)] = *weight;
            }
        }
    }
    let solution = llt.solve(&rhs);
    Ok((0..heights.len())
        .map(|column| {
            let mut full = vec![0.0; dofs];
            for (k, &d) in free.iter().enumerate() {
                full[d] = solution[(k, column)];
            }
            full
        })
        .collect())
}

/// Whether the fixed DOFs leave a rigid motion w = a + b x free: K is then singular
/// (a Cholesky factorisation could still pass on rounding, so this is decided from the
/// supports). The rigid motions are zero on the fixed DOFs only when the 2 columns
/// (translation, rotation) restricted to them have rank < 2.
fn allows_rigid_motion(model: &BeamModel) -> bool {
    let top = 2 * model.elements;
    let rows: Vec<[f64; 2]> = (0..model.dof_count())
        .filter(|d| !model.free_dofs.contains(d))
        .filter_map(|d| match d {
            0 => Some([1.0, 0.0]),
            1 => Some([0.0, 1.0]),
            d if d == top => Some([1.0, model.length]),
            d if d == top + 1 => Some([0.0, 1.0]),
            _ => None,
        })
        .collect();
    // Rank 2 iff some pair of rows is independent.
    !rows.iter().enumerate().any(|(i, a)| {
        rows[i + 1..]
            .iter()
            .any(|b| (a[0] * b[1] - a[1] * b[0]).abs() > 1e-12 * (1.0 + model.length))
    })
}

#[cfg(test)]
mod tests {
    //! Textbook statics of a cantilever (flexibilities a³/3EI and a²(3L − a)/6EI), the
    //! Rayleigh–Ritz structure of the augmented basis (M̄ = I, K̄ diagonal, pseudo
    //! frequencies above ωₘ₊₁ by Courant–Fischer), and its behaviour in the integrator:
    //! critical step against brute-force divergence, energy balance, action–reaction.

    use std::ops::ControlFlow;

    use super::*;
    use crate::beam::tests::default_tube;
    use crate::beam::{BeamSpec, Support};
    use crate::contact::{Body, Contact, Law};
    use crate::integrate::{
        Check, DEFAULT_TOLERANCE, Model, Plan, Settings, Simulation, SimulationError, TimeStep,
        critical_time_step, simulate,
    };
    use crate::loads::{BaseAcceleration, PointForce, Table};
    use crate::modal::ModalBasis;
    use crate::stability::Scheme;

    /// Static flexibility G(a, b) = Σᵢ ψᵢ(a) ψᵢ(b) / ωᵢ² of a basis (m/N): the deflection
    /// at a under a unit force at b, as the modal basis represents it.
    fn flexibility(basis: &ModalBasis, a: f64, b: f64) -> f64 {
        let (pa, pb) = (basis.deflection_at(a), basis.deflection_at(b));
        pa.iter()
            .zip(&pb)
            .zip(basis.angular_frequencies())
            .map(|((x, y), w)| x * y / (w * w))
            .sum()
    }

    /// Cantilever (Euler–Bernoulli, exact with Hermite elements at nodes): deflection at
    /// a under a unit force at b ≥ a is a²(3b − a)/6EI; at b itself b³/3EI.
    fn cantilever_flexibility(spec: &BeamSpec, a: f64, b: f64) -> f64 {
        let (a, b) = (a.min(b), a.max(b));
        a * a * (3.0 * b - a) / (6.0 * spec.bending_stiffness())
    }

    /// With pseudo-modes at the tip and mid-height the basis holds the exact static
    /// flexibility there (direct and cross terms), whatever the number of modes; the
    /// modes alone miss the dropped modes' share.
    #[test]
    fn corrected_heights_get_the_exact_static_flexibility() {
        let spec = default_tube(40);
        for modes in [1, 3, 8] {
            let plain = ModalBasis::compute(&spec, modes).unwrap();
            let corrected = ModalBasis::compute_with_static_correction(&spec, modes, &[1.0, 0.5]).unwrap();
            assert_eq!(corrected.modes(), modes + 2, "{modes} modes + 2 pseudo-modes");
            for (a, b) in [(1.0, 1.0), (0.5, 0.5), (0.5, 1.0)] {
                let exact = cantilever_flexibility(&spec, a, b);
                let measured = flexibility(&corrected, a, b);
                // 1e-7: the modes come from a dense eigen-solver (residual ~1e-9 of ‖Kφ‖),
                // whose leftover coupling with the pseudo-modes is dropped.
                assert!(
                    (measured - exact).abs() < 1e-7 * exact,
                    "{modes} modes + correction: G({a}, {b}) = {measured:e} vs a²(3b − a)/6EI = {exact:e}"
                );
                let truncated = flexibility(&plain, a, b);
                assert!(
                    (truncated - exact).abs() > 1e-6 * exact,
                    "{modes} modes alone should miss some flexibility: {truncated:e} vs {exact:e}"
                );
            }
        }
    }

    fn mat_vec_full(matrix: &[f64], vector: &[f64]) -> Vec<f64> {
        mat_vec(matrix, vector.len(), vector)
    }

    /// Rayleigh–Ritz on [Φ, static shapes]: the whole basis is M-orthonormal and its
    /// reduced stiffness is diag(ω²) (the integrator's assumption), the eigenmodes are
    /// unchanged, and every pseudo frequency is at least ωₘ₊₁ (Courant–Fischer).
    #[test]
    fn augmented_basis_is_mass_orthonormal_with_diagonal_stiffness() {
        let spec = default_tube(30);
        let modes = 4;
        let plain = ModalBasis::compute(&spec, modes + 1).unwrap();
        let basis = ModalBasis::compute_with_static_correction(&spec, modes, &[0.3, 0.7, 1.0]).unwrap();
        let model = basis.model();
        let omega = basis.angular_frequencies();
        assert_eq!(basis.eigenmodes(), modes);
        assert_eq!(basis.modes(), modes + 3);
        for i in 0..modes {
            let relative = (omega[i] - plain.angular_frequencies()[i]).abs() / omega[i];
            assert!(relative < 1e-12, "mode {i}: ω moved by {relative:e}");
        }
        let next = plain.angular_frequencies()[modes];
        for (k, w) in omega[modes..].iter().enumerate() {
            assert!(
                *w >= next * (1.0 - 1e-9),
                "pseudo-mode {k}: ω̃ = {w} below ωₘ₊₁ = {next}"
            );
        }
        for i in 0..basis.modes() {
            let m_i = mat_vec_full(&model.mass, basis.shape(i));
            let k_i = mat_vec_full(&model.stiffness, basis.shape(i));
            for j in 0..basis.modes() {
                let mass = dot(basis.shape(j), &m_i);
                let expected_mass = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (mass - expected_mass).abs() < 1e-9,
                    "ψ{j}ᵀMψ{i} = {mass} vs {expected_mass}"
                );
                let stiffness = dot(basis.shape(j), &k_i);
                let expected = if i == j { omega[i] * omega[i] } else { 0.0 };
                let scale = omega[i] * omega[j];
                assert!(
                    (stiffness - expected).abs() < 1e-8 * scale,
                    "ψ{j}ᵀKψ{i} = {stiffness:e} vs {expected:e} (scale ω{i}ω{j} = {scale:e})"
                );
            }
        }
    }

    /// One pseudo-mode per distinct height; a height at the clamped foot (zero static
    /// response) and a complete basis add none.
    #[test]
    fn heights_are_shared_and_shapes_already_in_the_basis_are_dropped() {
        let spec = default_tube(10);
        let basis = ModalBasis::compute_with_static_correction(&spec, 3, &[1.0, 0.0, 1.0, 0.5, 0.5]).unwrap();
        let correction = basis.static_correction().unwrap();
        assert_eq!(correction.heights, vec![0.5, 1.0], "kept heights");
        assert_eq!(correction.dropped_heights, vec![0.0], "dropped heights");
        assert_eq!(basis.modes(), 5, "3 modes + 2 pseudo-modes");
        let complete = spec.free_dof_count();
        let full = ModalBasis::compute_with_static_correction(&spec, complete, &[1.0]).unwrap();
        assert_eq!(
            full.modes(),
            complete,
            "a complete basis holds every static shape"
        );
        assert_eq!(full.static_correction().unwrap().dropped_heights, vec![1.0]);
    }

    /// A free-free beam (or one only pinned at one end) has a singular stiffness: no
    /// static response exists, a typed error says so.
    #[test]
    fn a_beam_free_to_move_rigidly_has_no_static_correction() {
        for (foot, top) in [(Support::Free, Support::Free), (Support::Pinned, Support::Free)] {
            let mut spec = default_tube(10);
            spec.foot = foot;
            spec.top = top;
            let model = BeamModel::assemble(&spec);
            let error = static_shapes(&model, &[1.0]).unwrap_err();
            assert_eq!(
                error,
                StaticCorrectionError::SingularStiffness,
                "{foot:?}-{top:?}"
            );
        }
        for (foot, top) in [
            (Support::Pinned, Support::Pinned),
            (Support::Free, Support::Clamped),
        ] {
            let mut spec = default_tube(10);
            spec.foot = foot;
            spec.top = top;
            assert!(
                static_shapes(&BeamModel::assemble(&spec), &[0.5]).is_ok(),
                "{foot:?}-{top:?}"
            );
        }
    }

    fn tip_wall(stiffness: f64) -> Contact {
        Contact {
            left: Body::Wall,
            right: Body::Pin(0),
            height: 1.0,
            gap: 0.0,
            stiffness,
            damping: 0.0,
            law: Law::LINEAR,
        }
    }

    fn settings(dt: f64, duration: f64) -> Settings {
        Settings {
            scheme: Scheme::CentralDifference,
            time_step: TimeStep::Fixed(dt),
            tolerance: DEFAULT_TOLERANCE,
            check: Check::None,
            duration,
            output_interval: None,
            recorded_contacts: None,
            impacts: Default::default(),
            threads: 1,
            output_heights: vec![1.0],
        }
    }

    /// The critical step of the corrected basis (diag(ω², ω̃²) + Kc ψψᵀ) is the true
    /// stability limit: a pin pushed onto a stiff tip spring runs bounded 1 % below it
    /// and diverges 1 % above it. It is shorter than the modes-only step (the
    /// pseudo-mode is stiffer than every mode).
    #[test]
    fn critical_step_with_the_correction_matches_brute_force_divergence() {
        let spec = default_tube(20);
        let basis = ModalBasis::compute_with_static_correction(&spec, 4, &[1.0]).unwrap();
        let plain = basis.without_static_correction();
        let model = |basis| Model {
            basis,
            pins: 1,
            damping_ratios: vec![0.0; 5],
            contacts: vec![tip_wall(1e5)],
            initial_tip_displacements: vec![0.0],
            initial_tip_velocities: vec![],
            base_acceleration: None,
            walls: None,
            plane: None,
            point_forces: vec![PointForce {
                line: 0,
                height: 1.0,
                force: Table {
                    time: vec![0.0, 10.0],
                    values: vec![-1.0, -1.0],
                },
            }],
            kinds: Vec::new(),
        };
        let corrected = model(&basis);
        let critical = critical_time_step(&corrected, Scheme::CentralDifference);
        let mut modes_only = model(&plain);
        modes_only.damping_ratios.truncate(4);
        let without = critical_time_step(&modes_only, Scheme::CentralDifference);
        assert!(
            critical < without,
            "the pseudo-mode must shorten the step: {critical:e} vs {without:e} s"
        );
        let duration = 3000.0 * critical;
        let below = simulate(&corrected, &settings(0.99 * critical, duration), &mut |_| {
            ControlFlow::Continue(())
        });
        assert!(
            below.is_ok(),
            "bounded at 0.99 × critical ({critical:e} s): {:?}",
            below.err()
        );
        let dt = 1.01 * critical;
        // Run past the refusal.
        let settings = settings(dt, duration);
        let above = Plan::unchecked(&corrected, &settings, dt)
            .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
            .map(|assessed| assessed.simulation);
        assert!(
            matches!(above, Err(SimulationError::Diverged { .. })),
            "diverges at 1.01 × critical ({critical:e} s): {:?}",
            above.map(|s| s.energy)
        );
    }

    /// A damped two-pin row with wall and pin–pin contacts at two levels, shaken by a
    /// half-sine base shock, on a basis corrected at both levels.
    fn shaken_row(basis: &ModalBasis, tips: [f64; 2], with_contacts: bool, shock: bool) -> Model<'_> {
        let contact = |left, right, height| Contact {
            left,
            right,
            height,
            gap: 5e-5,
            stiffness: 2e4,
            damping: 2.0,
            law: Law::LINEAR,
        };
        let contacts = if with_contacts {
            vec![
                contact(Body::Wall, Body::Pin(0), 0.5),
                contact(Body::Pin(0), Body::Pin(1), 0.5),
                contact(Body::Pin(1), Body::Wall, 0.5),
                contact(Body::Pin(0), Body::Pin(1), 1.0),
            ]
        } else {
            vec![]
        };
        Model {
            basis,
            pins: 2,
            damping_ratios: vec![0.02; basis.modes()],
            contacts,
            initial_tip_displacements: tips.to_vec(),
            initial_tip_velocities: vec![],
            base_acceleration: shock.then_some(BaseAcceleration::HalfSine {
                amplitude: 20.0,
                duration: 0.01,
            }),
            walls: None,
            plane: None,
            point_forces: vec![],
            kinds: Vec::new(),
        }
    }

    fn run(model: &Model<'_>, duration: f64) -> Simulation {
        let settings = Settings {
            output_interval: Some(1e-4),
            ..settings(2e-6, duration)
        };
        simulate(model, &settings, &mut |_| ControlFlow::Continue(())).expect("run succeeds")
    }

    /// Energy balance with pseudo-modes: kinetic + strain + contact + dissipated − base
    /// work equals the initial energy (the pseudo-modes are ordinary modal coordinates of
    /// the same M and K, so the balance must close as without them).
    #[test]
    fn energy_balance_closes_with_the_correction() {
        let basis = ModalBasis::compute_with_static_correction(&default_tube(20), 6, &[0.5, 1.0]).unwrap();
        assert_eq!(basis.modes(), 8);
        let result = run(&shaken_row(&basis, [2e-4, -1e-4], true, true), 0.1);
        let impacts: u64 = result.contact_statistics.iter().map(|s| s.impacts).sum();
        assert!(impacts > 5, "the case must exercise contacts: {impacts} impacts");
        let residual = result.energy.relative_residual();
        assert!(
            residual < 1e-3,
            "energy balance residual {residual:e} vs < 1e-3: {:?}",
            result.energy
        );
    }

    /// Action and reaction: pin–pin contacts push both pins with equal and opposite
    /// forces, so with two identical linear pins the sum of their deflections does not
    /// feel those contacts. Without walls, w₀ + w₁ of the colliding pair equals the
    /// deflection of one contact-free pin released from the sum of the two releases, at
    /// every sample (to rounding), pseudo-modes included.
    #[test]
    fn pin_to_pin_contacts_obey_action_and_reaction_with_the_correction() {
        let basis = ModalBasis::compute_with_static_correction(&default_tube(20), 6, &[0.5, 1.0]).unwrap();
        let mut pair = shaken_row(&basis, [4e-4, -3e-4], true, false);
        pair.contacts
            .retain(|c| c.left != Body::Wall && c.right != Body::Wall);
        let collided = run(&pair, 0.05);
        let impacts: u64 = collided.contact_statistics.iter().map(|s| s.impacts).sum();
        assert!(impacts >= 2, "the pins must collide: {impacts} impacts");
        let mut single = shaken_row(&basis, [1e-4, 0.0], false, false);
        single.pins = 1;
        single.initial_tip_displacements = vec![1e-4];
        let free = run(&single, 0.05);
        let scale = 4e-4;
        for (k, ((w0, w1), w)) in collided.deflections[0][0]
            .iter()
            .zip(&collided.deflections[0][1])
            .zip(&free.deflections[0][0])
            .enumerate()
        {
            assert!(
                (w0 + w1 - w).abs() < 1e-9 * scale,
                "sample {k}: w₀ + w₁ = {:e} vs contact-free {w:e}",
                w0 + w1
            );
        }
    }
}
