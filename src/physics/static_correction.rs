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
                residual.iter_mut().zip(basis_vector).for_each(|(r, b)| *r -= c * b);
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
    !rows
        .iter()
        .enumerate()
        .any(|(i, a)| rows[i + 1..].iter().any(|b| (a[0] * b[1] - a[1] * b[0]).abs() > 1e-12 * (1.0 + model.length)))
}

fn mat_vec(matrix: &[f64], n: usize, vector: &[f64]) -> Vec<f64> {
    (0..n).map(|i| dot(&matrix[i * n..(i + 1) * n], vector)).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
