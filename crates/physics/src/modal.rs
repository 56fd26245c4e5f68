//! Modal basis of a beam: the generalized symmetric-definite eigenproblem
//! K φ = ω² M φ on the free DOFs, truncated to the first m modes, mass-normalized
//! (φᵀ M φ = I), with deflection of any mode at any height by Hermite interpolation.
//!
//! Solved by Cholesky M = L Lᵀ, the standard problem (L⁻¹ K L⁻ᵀ) y = ω² y, and
//! φ = L⁻ᵀ y, which is mass-normalized when y is unit. All identical pins share one
//! basis. Shapes are stored over all DOFs (zero on fixed ones); each mode's sign makes
//! its largest deflection positive, so bases are reproducible.
//!
//! A basis may be augmented with pseudo-modes, the static correction at contact heights
//! ([`ModalBasis::compute_with_static_correction`], derivation in
//! [`super::static_correction`]): they follow the m modes as extra "modes" with
//! frequencies above ωₘ, and every accessor below covers modes and pseudo-modes alike.

use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{Mat, Par, Side};

use super::beam::{BeamModel, BeamSpec};
use super::static_correction::{StaticCorrectionError, pseudo_modes};

/// Why a modal basis could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModalError {
    #[error("modes must be between 1 and {max} (the free DOFs of this mesh), got {requested}")]
    TooManyModes { requested: usize, max: usize },
    #[error("the mass matrix is not positive definite")]
    MassNotPositiveDefinite,
    #[error("the eigenvalue solver did not converge")]
    EigenSolverFailed,
    #[error(transparent)]
    StaticCorrection(#[from] StaticCorrectionError),
}

/// The static correction a basis carries: which heights got a pseudo-mode.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticCorrection {
    /// Distinct contact heights (m), increasing, whose static shape was added.
    pub heights: Vec<f64>,
    /// Heights (m) whose static shape already lay in the basis (e.g. at a fixed
    /// support): no pseudo-mode.
    pub dropped_heights: Vec<f64>,
}

/// Truncated, mass-normalized modal basis of one beam.
#[derive(Debug, Clone)]
pub struct ModalBasis {
    /// The beam as described, mesh included (the probes refine it).
    spec: BeamSpec,
    model: BeamModel,
    /// Number m of eigenmodes; the basis holds them first, then the pseudo-modes.
    eigenmodes: usize,
    /// The static correction, `None` when the basis has eigenmodes only.
    correction: Option<StaticCorrection>,
    /// ωᵢ (rad/s), increasing (pseudo-modes last, above every eigenmode).
    angular_frequencies: Vec<f64>,
    /// Mode-major: `shapes[i * dofs + d]` is DOF d of mode i (kg^-½ per unit DOF).
    shapes: Vec<f64>,
    /// Γᵢ = φᵢᵀ M r for the rigid translation r (w = 1, θ = 0): the modal load of a unit
    /// base acceleration is −Γᵢ (kg^½).
    participation: Vec<f64>,
    /// Modal coordinates of the static tip-load shape scaled to a unit tip deflection;
    /// `None` when the top is fixed.
    unit_tip_release: Option<Vec<f64>>,
    /// The static shape of a unit displacement of the top support relative to the foot;
    /// `None` when the top is free.
    transport: Option<SupportTransport>,
}

/// The quasi-static transport of a beam held at both ends when its top support moves
/// by d relative to its foot: w = Ψ d + Σ φᵢ qᵢ, Ψ the static deflection under a unit
/// top displacement (K Ψ = 0 away from the supports), and mode i loaded by −Γᴾᵢ d̈
/// (code_aster's `MULT_APPUI`). Ψ vanishes at the foot and is 1 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportTransport {
    /// Ψ over all DOFs (deflection and rotation at each node).
    pub shape: Vec<f64>,
    /// Γᴾᵢ = φᵢᵀ M Ψ per basis vector (kg^½).
    pub participation: Vec<f64>,
}

/// Eigenpairs: ω² (increasing) and the M-normalised vectors over the free DOFs (columns).
type EigenPairs = (Vec<f64>, Mat<f64>);

/// The first `modes` eigenpairs (ω², M-normalised vectors over the free DOFs,
/// increasing) of K φ = ω² M φ in the stiffness form: M = L Lᵀ, the standard problem
/// (L⁻¹ K L⁻ᵀ) y = ω² y, φ = L⁻ᵀ y. `None` when one of them comes out non-positive
/// (the rounding of the form, ~ε × the highest eigenvalue, above the lowest).
fn stiffness_form(
    stiffness: &Mat<f64>,
    mass: &Mat<f64>,
    modes: usize,
) -> Result<Option<EigenPairs>, ModalError> {
    let n = stiffness.nrows();
    let cholesky = mass
        .llt(Side::Lower)
        .map_err(|_| ModalError::MassNotPositiveDefinite)?;
    let lower = cholesky.L();
    // A = L⁻¹ K L⁻ᵀ: X = L⁻¹ K, then A = L⁻¹ Xᵀ (K symmetric).
    let mut x = stiffness.clone();
    solve_lower_triangular_in_place(lower, x.as_mut(), Par::Seq);
    let mut a = x.transpose().to_owned();
    solve_lower_triangular_in_place(lower, a.as_mut(), Par::Seq);
    let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
    let eigen = a
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| ModalError::EigenSolverFailed)?;
    let values: Vec<f64> = (0..modes).map(|i| eigen.S().column_vector()[i]).collect();
    if !values.iter().all(|v| v.is_finite() && *v > 0.0) {
        return Ok(None);
    }
    let mut vectors = eigen.U().get(.., 0..modes).to_owned();
    solve_upper_triangular_in_place(lower.transpose(), vectors.as_mut(), Par::Seq);
    Ok(Some((values, vectors)))
}

/// The same eigenpairs in the flexibility form: K = L Lᵀ, (L⁻¹ M L⁻ᵀ) y = μ y with
/// μ = 1/ω², whose rounding (~ε × the largest μ, the lowest mode's) leaves the lowest
/// modes exact to ~1e-7 on meshes of 800 elements where the stiffness form fails;
/// φ = L⁻ᵀ y / √μ is M-normalised. Needs K positive definite (supports that hold the
/// beam); the highest modes of a fine mesh come out less accurate than the lowest.
fn flexibility_form(stiffness: &Mat<f64>, mass: &Mat<f64>, modes: usize) -> Result<EigenPairs, ModalError> {
    let n = stiffness.nrows();
    let cholesky = stiffness
        .llt(Side::Lower)
        .map_err(|_| ModalError::EigenSolverFailed)?;
    let lower = cholesky.L();
    let mut x = mass.clone();
    solve_lower_triangular_in_place(lower, x.as_mut(), Par::Seq);
    let mut b = x.transpose().to_owned();
    solve_lower_triangular_in_place(lower, b.as_mut(), Par::Seq);
    let b = Mat::from_fn(n, n, |i, j| 0.5 * (b[(i, j)] + b[(j, i)]));
    let eigen = b
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| ModalError::EigenSolverFailed)?;
    // μ increasing: the lowest modes are the last columns.
    let columns: Vec<usize> = (0..modes).map(|i| n - 1 - i).collect();
    let mu: Vec<f64> = columns.iter().map(|&c| eigen.S().column_vector()[c]).collect();
    if !mu.iter().all(|v| v.is_finite() && *v > 0.0) {
        return Err(ModalError::EigenSolverFailed);
    }
    let mut vectors = Mat::from_fn(n, modes, |r, i| eigen.U()[(r, columns[i])]);
    solve_upper_triangular_in_place(lower.transpose(), vectors.as_mut(), Par::Seq);
    for (i, m) in mu.iter().enumerate() {
        let scale = 1.0 / m.sqrt();
        for r in 0..n {
            vectors[(r, i)] *= scale;
        }
    }
    Ok((mu.iter().map(|m| 1.0 / m).collect(), vectors))
}

impl ModalBasis {
    /// First `modes` modes of a valid beam ([`BeamSpec::validate`]).
    pub fn compute(spec: &BeamSpec, modes: usize) -> Result<Self, ModalError> {
        Self::build(spec, modes, None)
    }

    /// First `modes` modes augmented with one pseudo-mode per distinct height of
    /// `heights` (m): the static correction at those heights
    /// ([`super::static_correction`]). Equal heights share one pseudo-mode; a height
    /// whose static shape the basis already holds adds none. The basis then has
    /// `modes` + (pseudo-modes) entries, each with its own frequency.
    pub fn compute_with_static_correction(
        spec: &BeamSpec,
        modes: usize,
        heights: &[f64],
    ) -> Result<Self, ModalError> {
        Self::build(spec, modes, Some(heights))
    }

    fn build(spec: &BeamSpec, modes: usize, correction_heights: Option<&[f64]>) -> Result<Self, ModalError> {
        let model = BeamModel::assemble(spec);
        let free = model.free_dofs.clone();
        let n = free.len();
        if modes == 0 || modes > n {
            return Err(ModalError::TooManyModes {
                requested: modes,
                max: n,
            });
        }
        let dofs = model.dof_count();
        let stiffness = Mat::from_fn(n, n, |i, j| model.stiffness[free[i] * dofs + free[j]]);
        let mass = Mat::from_fn(n, n, |i, j| model.mass[free[i] * dofs + free[j]]);

        let (eigenvalues, vectors) = match stiffness_form(&stiffness, &mass, modes)? {
            Some(pairs) => pairs,
            // Past a few hundred elements the stiffness form's rounding (relative to its
            // highest eigenvalue) swamps the lowest: the flexibility form keeps them.
            None => flexibility_form(&stiffness, &mass, modes)?,
        };

        let mut angular_frequencies = Vec::with_capacity(modes);
        let mut shapes = vec![0.0; modes * dofs];
        for i in 0..modes {
            angular_frequencies.push(eigenvalues[i].sqrt());
            let row = &mut shapes[i * dofs..(i + 1) * dofs];
            for (k, &d) in free.iter().enumerate() {
                row[d] = vectors[(k, i)];
            }
            let largest = row
                .iter()
                .step_by(2)
                .copied()
                .fold(0.0f64, |m, w| if w.abs() > m.abs() { w } else { m });
            if largest < 0.0 {
                row.iter_mut().for_each(|v| *v = -*v);
            }
        }

        let mut correction = None;
        if let Some(heights) = correction_heights {
            let mode_shapes: Vec<&[f64]> = shapes.chunks_exact(dofs).collect();
            let pseudo = pseudo_modes(&model, &mode_shapes, heights)?;
            for (omega, shape) in pseudo.angular_frequencies.iter().zip(&pseudo.shapes) {
                let mut shape = shape.clone();
                let largest = shape
                    .iter()
                    .step_by(2)
                    .copied()
                    .fold(0.0f64, |m, w| if w.abs() > m.abs() { w } else { m });
                if largest < 0.0 {
                    shape.iter_mut().for_each(|v| *v = -*v);
                }
                angular_frequencies.push(*omega);
                shapes.extend(shape);
            }
            correction = Some(StaticCorrection {
                heights: pseudo.heights,
                dropped_heights: pseudo.dropped_heights,
            });
        }
        let total = angular_frequencies.len();

        let translation: Vec<f64> = (0..dofs).map(|d| if d % 2 == 0 { 1.0 } else { 0.0 }).collect();
        let mass_times_translation = mat_vec(&model.mass, dofs, &translation);
        let participation = (0..total)
            .map(|i| dot(&shapes[i * dofs..(i + 1) * dofs], &mass_times_translation))
            .collect();

        let mut basis = Self {
            spec: spec.clone(),
            model,
            eigenmodes: modes,
            correction,
            angular_frequencies,
            shapes,
            participation,
            unit_tip_release: None,
            transport: None,
        };
        basis.unit_tip_release = basis.static_top_load_shape(&stiffness).map(|u| basis.project(&u));
        basis.transport = basis.top_support_shape(&stiffness).map(|shape| SupportTransport {
            participation: (0..total)
                .map(|i| dot(basis.shape(i), &mat_vec(&basis.model.mass, dofs, &shape)))
                .collect(),
            shape,
        });
        Ok(basis)
    }

    /// Number of basis vectors: eigenmodes and pseudo-modes (what the integrator
    /// treats as modes).
    pub fn modes(&self) -> usize {
        self.angular_frequencies.len()
    }

    /// Number m of eigenmodes (the first m entries of the basis).
    pub fn eigenmodes(&self) -> usize {
        self.eigenmodes
    }

    /// The static correction, `None` for a basis of eigenmodes only.
    pub fn static_correction(&self) -> Option<&StaticCorrection> {
        self.correction.as_ref()
    }

    /// The same basis without its pseudo-modes (the eigenmodes only).
    pub fn without_static_correction(&self) -> Self {
        let (m, dofs) = (self.eigenmodes, self.model.dof_count());
        let mut basis = Self {
            spec: self.spec.clone(),
            model: self.model.clone(),
            eigenmodes: m,
            correction: None,
            angular_frequencies: self.angular_frequencies[..m].to_vec(),
            shapes: self.shapes[..m * dofs].to_vec(),
            participation: self.participation[..m].to_vec(),
            unit_tip_release: None,
            transport: self.transport.as_ref().map(|t| SupportTransport {
                shape: t.shape.clone(),
                participation: t.participation[..m].to_vec(),
            }),
        };
        basis.unit_tip_release = self.unit_tip_release.as_ref().map(|q| q[..m].to_vec());
        basis
    }

    /// ωᵢ (rad/s).
    pub fn angular_frequencies(&self) -> &[f64] {
        &self.angular_frequencies
    }

    /// fᵢ = ωᵢ / 2π (Hz).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.angular_frequencies
            .iter()
            .map(|w| w / std::f64::consts::TAU)
            .collect()
    }

    /// Γᵢ = φᵢᵀ M r (kg^½): a base acceleration a(t) loads mode i with −Γᵢ a(t).
    pub fn participation(&self) -> &[f64] {
        &self.participation
    }

    /// Beam length L (m).
    pub fn length(&self) -> f64 {
        self.model.length
    }

    /// The beam the basis was computed for, its mesh included.
    pub fn spec(&self) -> &BeamSpec {
        &self.spec
    }

    /// The finite-element model the basis was computed on.
    pub fn model(&self) -> &BeamModel {
        &self.model
    }

    /// Mode i over all DOFs.
    pub fn shape(&self, mode: usize) -> &[f64] {
        let dofs = self.model.dof_count();
        &self.shapes[mode * dofs..(mode + 1) * dofs]
    }

    /// ψᵢ(x) for every mode: deflection of each mode at height `x` (m), interpolated with
    /// the Hermite shape functions of the element containing x.
    pub fn deflection_at(&self, x: f64) -> Vec<f64> {
        let (first_dof, weights) = self.model.interpolation(x);
        (0..self.modes())
            .map(|i| {
                let shape = self.shape(i);
                (0..4).map(|k| weights[k] * shape[first_dof + k]).sum()
            })
            .collect()
    }

    /// κᵢ(x) for every mode: the bending curvature φᵢ''(x) of each mode at height `x`
    /// (1/m per unit modal coordinate; [`crate::beam::BeamModel::curvature_at`]).
    pub fn curvature_at(&self, x: f64) -> Vec<f64> {
        (0..self.modes())
            .map(|i| self.model.curvature_at(x, self.shape(i)))
            .collect()
    }

    /// Ψ''(x): the transport's curvature at height `x` (1/m per metre the top support
    /// moves), 0 without one.
    pub fn transport_curvature_at(&self, x: f64) -> f64 {
        self.transport
            .as_ref()
            .map_or(0.0, |t| self.model.curvature_at(x, &t.shape))
    }

    /// Modal coordinates q = Φᵀ M u of a displacement field u given over all DOFs.
    pub fn project(&self, displacement: &[f64]) -> Vec<f64> {
        let dofs = self.model.dof_count();
        let mass_times_u = mat_vec(&self.model.mass, dofs, displacement);
        (0..self.modes())
            .map(|i| dot(self.shape(i), &mass_times_u))
            .collect()
    }

    /// Modal coordinates of the static shape under a point load at the top, scaled to a
    /// unit top deflection; `None` when the top deflection is fixed by its support.
    pub fn unit_tip_release(&self) -> Option<&[f64]> {
        self.unit_tip_release.as_deref()
    }

    /// The quasi-static transport by the top support, `None` when the top is free (or
    /// the beam held by its top alone has no static shape: a mechanism).
    pub fn support_transport(&self) -> Option<&SupportTransport> {
        self.transport.as_ref()
    }

    /// Ψ(x): the transport's deflection at height `x` (m), 0 without one.
    pub fn transport_at(&self, x: f64) -> f64 {
        self.transport.as_ref().map_or(0.0, |t| {
            let (first_dof, weights) = self.model.interpolation(x);
            (0..4).map(|k| weights[k] * t.shape[first_dof + k]).sum()
        })
    }

    /// Ψ: K_ff Ψ_f = −K_f,top for a unit top deflection (the foot's fixed DOFs and the
    /// top's rotation, when clamped, held at 0); `None` when the top is free.
    fn top_support_shape(&self, free_stiffness: &Mat<f64>) -> Option<Vec<f64>> {
        let model = &self.model;
        let (free, dofs, top_dof) = (&model.free_dofs, model.dof_count(), 2 * model.elements);
        if free.contains(&top_dof) {
            return None;
        }
        let llt = free_stiffness.llt(Side::Lower).ok()?;
        let rhs = Mat::from_fn(free.len(), 1, |k, _| -model.stiffness[free[k] * dofs + top_dof]);
        let solution = faer::linalg::solvers::Solve::solve(&llt, &rhs);
        let mut full = vec![0.0; dofs];
        full[top_dof] = 1.0;
        for (k, &d) in free.iter().enumerate() {
            full[d] = solution[(k, 0)];
        }
        full.iter().all(|v| v.is_finite()).then_some(full)
    }

    /// Solves K_ff u = e_top and scales u to a unit top deflection.
    fn static_top_load_shape(&self, free_stiffness: &Mat<f64>) -> Option<Vec<f64>> {
        let free = &self.model.free_dofs;
        let top_dof = 2 * self.model.elements;
        let top = free.iter().position(|&d| d == top_dof)?;
        let llt = free_stiffness.llt(Side::Lower).ok()?;
        let mut rhs = Mat::<f64>::zeros(free.len(), 1);
        rhs[(top, 0)] = 1.0;
        let solution = faer::linalg::solvers::Solve::solve(&llt, &rhs);
        let scale = 1.0 / solution[(top, 0)];
        let mut full = vec![0.0; self.model.dof_count()];
        for (k, &d) in free.iter().enumerate() {
            full[d] = solution[(k, 0)] * scale;
        }
        Some(full)
    }
}

/// `matrix` (n × n, row-major) times `vector`.
pub(super) fn mat_vec(matrix: &[f64], n: usize, vector: &[f64]) -> Vec<f64> {
    (0..n).map(|i| dot(&matrix[i * n..(i + 1) * n], vector)).collect()
}

/// Σ aᵢ bᵢ.
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::beam::tests::default_tube;
    use crate::beam::{Section, Support};
    use std::f64::consts::PI;

    /// The curvature of an M-normalised mode is the FE one: its bending energy
    /// ∫ EI φᵢ''² dx (two Gauss points per element, exact for the linear curvature of a
    /// Hermite element) is φᵢᵀ K φᵢ = ωᵢ²; and at a node the curvature is the mean of the
    /// two elements' (here, away from any load, they nearly agree).
    #[test]
    fn a_modes_curvature_carries_its_bending_energy() {
        let spec = default_tube(12);
        let basis = ModalBasis::compute(&spec, 5).unwrap();
        let (h, ei) = (basis.model().element_length, spec.bending_stiffness());
        let gauss = [0.5 - 0.5 / 3f64.sqrt(), 0.5 + 0.5 / 3f64.sqrt()];
        for (i, omega) in basis.angular_frequencies().iter().enumerate() {
            let energy: f64 = (0..spec.elements)
                .flat_map(|e| gauss.map(|g| (e as f64 + g) * h))
                .map(|x| 0.5 * h * ei * basis.curvature_at(x)[i].powi(2))
                .sum();
            assert!(
                (energy / omega.powi(2) - 1.0).abs() < 1e-9,
                "mode {i}: ∫EIφ''² = {energy:e}, ω² = {:e}",
                omega.powi(2)
            );
        }
    }

    /// A pinned–pinned Timoshenko beam's flexural frequencies are the lower roots of
    /// (ρ²I/κG) ω⁴ − (ρA + ρI k² + ρEI k²/κG) ω² + EI k⁴ = 0, k = nπ/L (shear and rotary
    /// inertia); the elements converge to them at second order in h (the error drops about
    /// 4-fold from 20 to 40 elements: the shear strain is constant over an element), and
    /// sit well below Euler–Bernoulli's
    /// (nπ/L)² √(EI/ρA) on this thick tube.
    #[test]
    fn a_pinned_timoshenko_beam_converges_to_its_exact_frequencies() {
        let pinned = |elements: usize| BeamSpec {
            foot: Support::Pinned,
            top: Support::Pinned,
            ..crate::beam::tests::thick_timoshenko_tube(elements)
        };
        let spec = pinned(1);
        let shear = spec.shear.unwrap();
        let (e, rho) = (spec.young_modulus, spec.density);
        let (area, inertia) = (spec.section.area(), spec.section.inertia());
        let kg = shear.coefficient * e / (2.0 * (1.0 + shear.poisson_ratio));
        let exact = |n: usize| {
            let k = n as f64 * PI / spec.length;
            let a = rho * rho * inertia / kg;
            let b = rho * area + rho * inertia * k * k + rho * e * inertia * k * k / kg;
            let c = e * inertia * k.powi(4);
            ((b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)).sqrt()
        };
        let errors = |elements: usize| -> Vec<f64> {
            let basis = ModalBasis::compute(&pinned(elements), 3).unwrap();
            (0..3)
                .map(|i| (basis.angular_frequencies()[i] / exact(i + 1) - 1.0).abs())
                .collect()
        };
        let (coarse, fine) = (errors(20), errors(40));
        for n in 0..3 {
            assert!(
                fine[n] < 5e-3 && (coarse[n] / fine[n]).log2() > 1.8,
                "mode {}: {:e} → {:e}",
                n + 1,
                coarse[n],
                fine[n]
            );
            let euler = ((n + 1) as f64 * PI / spec.length).powi(2) * (e * inertia / (rho * area)).sqrt();
            assert!(
                exact(n + 1) < 0.97 * euler,
                "mode {}: shear and rotary inertia lower it",
                n + 1
            );
        }
    }

    /// The free top carries no moment: its FE curvature (the natural condition, held
    /// weakly) vanishes as h² when the mesh is refined.
    #[test]
    fn the_curvature_at_a_free_top_vanishes_as_the_mesh_is_refined() {
        let ratio = |elements: usize, mode: usize| {
            let spec = default_tube(elements);
            let basis = ModalBasis::compute(&spec, 3).unwrap();
            (basis.curvature_at(spec.length)[mode] / basis.curvature_at(0.0)[mode]).abs()
        };
        for mode in 0..3 {
            let (coarse, fine) = (ratio(12, mode), ratio(24, mode));
            assert!(
                coarse < 0.05 && fine < coarse / 3.0,
                "mode {mode}: {coarse:e} → {fine:e}"
            );
        }
    }

    /// Roots λᵢ of 1 + cos λ cosh λ = 0 (clamped-free Euler-Bernoulli beam).
    const CLAMPED_FREE_ROOTS: [f64; 5] = [
        1.8751040687119611,
        4.694_091_132_974_174,
        7.854_757_438_237_613,
        10.995540734875467,
        14.137_168_391_046_47,
    ];

    fn analytic_omega(spec: &BeamSpec, lambda: f64) -> f64 {
        lambda * lambda * (spec.bending_stiffness() / spec.mass_per_length()).sqrt() / spec.length.powi(2)
    }

    /// Clamped-free frequencies ωᵢ = λᵢ² √(EI/m) / L² are reproduced by 40 Hermite
    /// elements with the textbook error of consistent-mass cubic elements,
    /// ω_h/ω − 1 ≈ (λh/L)⁴/1440: below 2e-6 for the first four modes, 1.1e-5 for the 5th
    /// (plus a few 1e-9 of eigen-solver roundoff, λ_max/λ₁ of the mesh being ~1e11).
    #[test]
    fn clamped_free_frequencies_match_euler_bernoulli_roots() {
        let spec = default_tube(40);
        let basis = ModalBasis::compute(&spec, 5).unwrap();
        for (i, lambda) in CLAMPED_FREE_ROOTS.iter().enumerate() {
            let expected = analytic_omega(&spec, *lambda);
            let measured = basis.angular_frequencies()[i];
            let error = (measured - expected) / expected;
            let estimate = (lambda / 40.0).powi(4) / 1440.0;
            assert!(
                (error - estimate).abs() < 0.05 * estimate + 1e-8,
                "mode {}: ω = {measured} vs analytic {expected} (rel. error {error:e}, estimate {estimate:e})",
                i + 1
            );
        }
        let f1 = basis.frequencies_hz()[0];
        assert!((f1 - 9.76591).abs() < 1e-4, "f1 = {f1} Hz vs public 9.76591 Hz");
    }

    /// The transport by the top support is the cubic static shape of a uniform beam
    /// under a unit top displacement (w⁗ = 0 with the end conditions), which cubic
    /// Hermite elements hold exactly: ξ pinned–pinned, (3ξ² − ξ³)/2 clamped–pinned,
    /// (3ξ − ξ³)/2 pinned–clamped, 3ξ² − 2ξ³ clamped–clamped (ξ = x/L); none with a free
    /// top.
    #[test]
    fn the_top_support_transport_is_the_static_cubic() {
        type Cubic = fn(f64) -> f64;
        let cases: [(Support, Support, Cubic); 4] = [
            (Support::Pinned, Support::Pinned, |x| x),
            (Support::Clamped, Support::Pinned, |x| {
                (3.0 * x * x - x * x * x) / 2.0
            }),
            (Support::Pinned, Support::Clamped, |x| (3.0 * x - x * x * x) / 2.0),
            (Support::Clamped, Support::Clamped, |x| {
                3.0 * x * x - 2.0 * x * x * x
            }),
        ];
        for (foot, top, expected) in cases {
            let spec = BeamSpec {
                foot,
                top,
                ..default_tube(12)
            };
            let basis = ModalBasis::compute(&spec, 4).unwrap();
            for k in 0..=24 {
                let x = spec.length * k as f64 / 24.0;
                let psi = basis.transport_at(x);
                assert!(
                    (psi - expected(x / spec.length)).abs() < 1e-9,
                    "{foot:?}–{top:?} at x = {x}: Ψ = {psi}"
                );
            }
            assert_eq!(basis.support_transport().unwrap().participation.len(), 4);
        }
        assert!(
            ModalBasis::compute(&default_tube(12), 4)
                .unwrap()
                .support_transport()
                .is_none()
        );
    }

    /// Hermite cubic elements converge in frequency as h⁴ (frequency error of the
    /// Rayleigh-Ritz method is the square of the energy-norm error, O(h²)²): halving h
    /// divides the 4th-mode error by about 16.
    #[test]
    fn frequency_error_converges_at_fourth_order() {
        let expected = analytic_omega(&default_tube(1), CLAMPED_FREE_ROOTS[3]);
        let error = |elements: usize| {
            let basis = ModalBasis::compute(&default_tube(elements), 4).unwrap();
            (basis.angular_frequencies()[3] - expected) / expected
        };
        let (coarse, fine) = (error(8), error(16));
        let rate = (coarse / fine).log2();
        assert!(
            coarse > 0.0 && fine > 0.0,
            "Rayleigh-Ritz frequencies are upper bounds: {coarse:e}, {fine:e}"
        );
        assert!(
            (rate - 4.0).abs() < 0.3,
            "observed order {rate} (errors {coarse:e} → {fine:e}), expected 4"
        );
    }

    /// Mass normalization φᵀMφ = I and eigen residual ‖Kφ − ω²Mφ‖ small relative to ‖Kφ‖.
    #[test]
    fn modes_are_mass_normalized_eigenvectors() {
        let spec = default_tube(20);
        let basis = ModalBasis::compute(&spec, 12).unwrap();
        let model = BeamModel::assemble(&spec);
        let dofs = model.dof_count();
        for i in 0..basis.modes() {
            let k_phi = mat_vec(&model.stiffness, dofs, basis.shape(i));
            let m_phi = mat_vec(&model.mass, dofs, basis.shape(i));
            let omega2 = basis.angular_frequencies()[i].powi(2);
            let residual: f64 = model
                .free_dofs
                .iter()
                .map(|&d| (k_phi[d] - omega2 * m_phi[d]).powi(2))
                .sum::<f64>()
                .sqrt();
            let scale: f64 = model
                .free_dofs
                .iter()
                .map(|&d| k_phi[d].powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(
                residual < 1e-8 * scale,
                "mode {i}: residual {residual:e} vs ‖Kφ‖ {scale:e}"
            );
            for j in 0..basis.modes() {
                let product = dot(basis.shape(j), &m_phi);
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((product - expected).abs() < 1e-10, "φ{j}ᵀMφ{i} = {product}");
            }
        }
    }

    /// A complete basis represents any field: Σ Γᵢ² = rᵀMr = total mass (modal mass sum
    /// rule); with a truncated basis the sum stays below it.
    #[test]
    fn participation_factors_sum_to_total_mass_on_a_complete_basis() {
        let spec = default_tube(6);
        let complete = ModalBasis::compute(&spec, spec.free_dof_count()).unwrap();
        let total_mass = spec.mass_per_length() * spec.length;
        // Σ Γᵢ² = (Mr)_fᵀ M_ff⁻¹ (Mr)_f: the mass the free DOFs can move, below the total
        // because the clamped foot node's share is held by the support.
        let movable = total_mass;
        let sum: f64 = complete.participation().iter().map(|g| g * g).sum();
        assert!(
            sum < movable && sum > 0.9 * movable,
            "Σ Γ² = {sum} vs total mass {movable}"
        );
        let truncated = ModalBasis::compute(&spec, 3).unwrap();
        let partial: f64 = truncated.participation().iter().map(|g| g * g).sum();
        assert!(partial < sum);
        // Clamped-free: the first mode carries about 61 % of the mass (textbook value 0.613).
        let first_share = complete.participation()[0].powi(2) / total_mass;
        assert!(
            (first_share - 0.613).abs() < 0.002,
            "first mode mass share {first_share}"
        );
    }

    /// Interpolation: at a node the Hermite value equals the nodal value; between nodes
    /// a fine mesh agrees with a coarse one's interpolation of the same mode.
    #[test]
    fn deflection_at_any_height_interpolates_mode_shapes() {
        let spec = default_tube(40);
        let basis = ModalBasis::compute(&spec, 3).unwrap();
        let node = 17;
        let x = node as f64 * spec.length / 40.0;
        let at_node = basis.deflection_at(x);
        for i in 0..3 {
            assert!((at_node[i] - basis.shape(i)[2 * node]).abs() < 1e-12);
        }
        let coarse = ModalBasis::compute(&default_tube(10), 3).unwrap();
        let x = 0.437;
        let (fine_w, coarse_w) = (basis.deflection_at(x), coarse.deflection_at(x));
        for i in 0..3 {
            let scale = basis.shape(i).iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                (fine_w[i] - coarse_w[i]).abs() < 1e-3 * scale,
                "mode {i}: {} vs {}",
                fine_w[i],
                coarse_w[i]
            );
        }
    }

    /// The release shape of a tip load on a cantilever is the cubic u₀ (x/L)²(3 − x/L)/2;
    /// its modal projection reproduces the tip deflection (almost all of it in mode 1).
    #[test]
    fn unit_tip_release_is_the_tip_load_cubic() {
        let spec = default_tube(40);
        let basis = ModalBasis::compute(&spec, 10).unwrap();
        let q = basis.unit_tip_release().unwrap();
        let tip: f64 = basis.deflection_at(1.0).iter().zip(q).map(|(p, q)| p * q).sum();
        assert!((tip - 1.0).abs() < 1e-4, "truncated tip deflection {tip}");
        let mid: f64 = basis.deflection_at(0.5).iter().zip(q).map(|(p, q)| p * q).sum();
        let cubic = 0.25 * (3.0 - 0.5) / 2.0;
        assert!(
            (mid - cubic).abs() < 1e-4,
            "mid deflection {mid} vs cubic {cubic}"
        );
        let mut pinned_top = spec.clone();
        pinned_top.top = Support::Pinned;
        assert!(
            ModalBasis::compute(&pinned_top, 3)
                .unwrap()
                .unit_tip_release()
                .is_none()
        );
    }

    /// Other supports: pinned-pinned λᵢ = iπ; clamped-clamped λ₁ = 4.730041.
    #[test]
    fn other_supports_match_their_textbook_roots() {
        let mut spec = default_tube(40);
        spec.section = Section::Explicit {
            area: 1e-4,
            inertia: 1e-9,
        };
        for (foot, top, lambda) in [
            (Support::Pinned, Support::Pinned, std::f64::consts::PI),
            (Support::Clamped, Support::Clamped, 4.730040745),
            (Support::Clamped, Support::Pinned, 3.926602312),
        ] {
            spec.foot = foot;
            spec.top = top;
            let basis = ModalBasis::compute(&spec, 1).unwrap();
            let expected = analytic_omega(&spec, lambda);
            let error = (basis.angular_frequencies()[0] - expected).abs() / expected;
            assert!(error < 1e-6, "{foot:?}-{top:?}: ω₁ error {error:e}");
        }
    }

    #[test]
    fn too_many_modes_is_a_typed_error() {
        let spec = default_tube(2);
        let error = ModalBasis::compute(&spec, 5).unwrap_err();
        assert_eq!(error, ModalError::TooManyModes { requested: 5, max: 4 });
    }
}
