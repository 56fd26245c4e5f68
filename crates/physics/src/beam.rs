//! Euler–Bernoulli or Timoshenko beam: section, material, supports, and the
//! finite-element model with 2-node elements (DOFs per node: deflection w (m), rotation θ
//! (rad)) and consistent mass: Hermite cubics for Euler–Bernoulli; for Timoshenko (shear
//! deformation and rotary inertia), the interdependent interpolation of Friedman and
//! Kosmatka (1993), exact for a uniform beam under end loads, with Φ = 12EI/(κGAh²) and
//! the Hermite element recovered at Φ = 0.
//!
//! Nodes are numbered from the foot (x = 0) to the top (x = L); the global DOF of node
//! `n` are `2n` (w) and `2n + 1` (θ). Matrices are dense, row-major, over all DOFs;
//! [`BeamModel::free_dofs`] lists the DOFs left free by the supports.

use super::{InputIssue, number, number_beside, require_non_negative, require_positive};

/// A beam's widest plausible values, each `(field, lowest, highest, unit, why)`: far
/// outside any structure (a value in the wrong unit, 1000 times off, stays inside them
/// and gets a plausibility warning), and inside them every combination keeps the
/// element matrices, the eigen-solver and the time step within the range of doubles.
/// Outside, the modal analysis fails in ways that name no input (an overflowing mass
/// matrix "not positive definite", an eigen-solver that does not converge, a run that
/// diverges), so the value is refused at its own field, with the bound.
pub const PLAUSIBLE_RANGES: [(&str, f64, f64, &str, &str); 5] = [
    (
        "length",
        1e-6,
        1e5,
        "m",
        "from a micro-cantilever to a hundred kilometres",
    ),
    (
        "young_modulus",
        1.0,
        1e15,
        "Pa",
        "from a gel to a thousand times diamond's 1.2e12 Pa",
    ),
    ("density", 1e-3, 1e9, "kg/m³", "a model's lumped masses included"),
    (
        "section/outer_diameter",
        1e-7,
        1e3,
        "m",
        "from a fibre to a kilometre",
    ),
    (
        "section/area",
        1e-15,
        1e6,
        "m²",
        "from a fibre's to a square kilometre",
    ),
];
/// Widest second moment of area (m⁴), for explicit sections: those of the diameters of
/// [`PLAUSIBLE_RANGES`].
pub const INERTIA_RANGE: (f64, f64) = (1e-30, 1e12);
/// Most added mass per unit length (kg/m).
pub const MAX_ADDED_MASS_PER_LENGTH: f64 = 1e9;

/// An issue at `field` when the finite positive `value` is outside `[low, high]`.
fn require_within(
    issues: &mut Vec<InputIssue>,
    field: &str,
    value: f64,
    (low, high): (f64, f64),
    unit: &str,
    why: &str,
) {
    if !(value.is_finite() && value > 0.0) {
        return; // refused as not a positive number already
    }
    if value < low || value > high {
        issues.push(InputIssue::new(
            field,
            format!(
                "must be between {} and {} {unit} ({why}; got {} {unit}): outside, the modal analysis \
                 leaves the range of floating-point numbers",
                number(low),
                number(high),
                number_beside(value, if value < low { low } else { high })
            ),
        ));
    }
}

/// Cross-section of the beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// Circular tube: outer and inner diameters (m); inner 0 gives a solid rod.
    Tube {
        outer_diameter: f64,
        inner_diameter: f64,
    },
    /// Explicit area (m²) and second moment of area (m⁴).
    Explicit { area: f64, inertia: f64 },
}

impl Section {
    /// Area A (m²).
    pub fn area(&self) -> f64 {
        match *self {
            Section::Tube {
                outer_diameter: d_o,
                inner_diameter: d_i,
            } => std::f64::consts::PI / 4.0 * (d_o * d_o - d_i * d_i),
            Section::Explicit { area, .. } => area,
        }
    }

    /// Second moment of area I (m⁴).
    pub fn inertia(&self) -> f64 {
        match *self {
            Section::Tube {
                outer_diameter: d_o,
                inner_diameter: d_i,
            } => std::f64::consts::PI / 64.0 * (d_o.powi(4) - d_i.powi(4)),
            Section::Explicit { inertia, .. } => inertia,
        }
    }

    fn validate(&self, issues: &mut Vec<InputIssue>) {
        match *self {
            Section::Tube {
                outer_diameter,
                inner_diameter,
            } => {
                require_positive(issues, "section/outer_diameter", outer_diameter);
                require_non_negative(issues, "section/inner_diameter", inner_diameter);
                if inner_diameter.is_finite()
                    && outer_diameter.is_finite()
                    && inner_diameter >= outer_diameter
                {
                    issues.push(InputIssue::new(
                        "section/inner_diameter",
                        format!(
                            "must be smaller than the outer diameter ({} m)",
                            number(outer_diameter)
                        ),
                    ));
                }
            }
            Section::Explicit { area, inertia } => {
                require_positive(issues, "section/area", area);
                require_positive(issues, "section/inertia", inertia);
            }
        }
    }
}

/// Boundary condition at one end of the beam.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// No constraint.
    Free,
    /// Deflection fixed, rotation free.
    Pinned,
    /// Deflection and rotation fixed.
    Clamped,
}

/// A beam as the user describes it (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct BeamSpec {
    /// Length L (m).
    pub length: f64,
    /// Young's modulus E (Pa).
    pub young_modulus: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
    pub section: Section,
    /// Added mass per unit length (kg/m): fuel column, surrounding fluid.
    pub added_mass_per_length: f64,
    /// Number of finite elements along the beam.
    pub elements: usize,
    /// Support at the foot (x = 0); clamped by default.
    pub foot: Support,
    /// Support at the top (x = L); free by default.
    pub top: Support,
    /// Shear deformation and rotary inertia (Timoshenko); `None` for Euler–Bernoulli.
    pub shear: Option<Shear>,
}

/// What a Timoshenko beam adds to Euler–Bernoulli: the shear stiffness κGA (with
/// G = E / 2(1 + ν)) and the rotary inertia ρI of the section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shear {
    /// Shear coefficient κ (dimensionless): 0.5 to 0.53 for a thin tube, 0.9 for a solid
    /// rod (Cowper: 6(1 + ν)/(7 + 6ν) for a solid circle).
    pub coefficient: f64,
    /// Poisson's ratio ν (dimensionless).
    pub poisson_ratio: f64,
}

/// Timoshenko shear coefficient of a tube (Cowper 1966), m = d_i / d_o:
/// κ = 6(1 + ν)(1 + m²)² / ((7 + 6ν)(1 + m²)² + (20 + 12ν) m²).
pub fn tube_shear_coefficient(outer_diameter: f64, inner_diameter: f64, poisson_ratio: f64) -> f64 {
    let (m2, nu) = ((inner_diameter / outer_diameter).powi(2), poisson_ratio);
    let a = (1.0 + m2).powi(2);
    6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)
}

/// Largest mesh accepted: the eigenproblem is dense, O(n³).
pub const MAX_ELEMENTS: usize = 400;

impl BeamSpec {
    /// Mass per unit length m = ρA + added mass (kg/m).
    pub fn mass_per_length(&self) -> f64 {
        self.density * self.section.area() + self.added_mass_per_length
    }

    /// Bending stiffness EI (N·m²).
    pub fn bending_stiffness(&self) -> f64 {
        self.young_modulus * self.section.inertia()
    }

    /// Φ = 12 EI / (κ G A h²) of an element of length `h`: the ratio of its shear to its
    /// bending flexibility; 0 for Euler–Bernoulli.
    pub fn shear_factor(&self, h: f64) -> f64 {
        self.shear.map_or(0.0, |shear| {
            let g = self.young_modulus / (2.0 * (1.0 + shear.poisson_ratio));
            12.0 * self.bending_stiffness() / (shear.coefficient * g * self.section.area() * h * h)
        })
    }

    /// Every problem with this beam (empty when valid). Fields are relative to the beam.
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        require_positive(&mut issues, "length", self.length);
        require_positive(&mut issues, "young_modulus", self.young_modulus);
        require_positive(&mut issues, "density", self.density);
        require_non_negative(&mut issues, "added_mass_per_length", self.added_mass_per_length);
        self.section.validate(&mut issues);
        let value = |field: &str| match (field, self.section) {
            ("length", _) => Some(self.length),
            ("young_modulus", _) => Some(self.young_modulus),
            ("density", _) => Some(self.density),
            ("section/outer_diameter", Section::Tube { outer_diameter, .. }) => Some(outer_diameter),
            ("section/area", Section::Explicit { area, .. }) => Some(area),
            _ => None,
        };
        for (field, low, high, unit, why) in PLAUSIBLE_RANGES {
            if let Some(v) = value(field) {
                require_within(&mut issues, field, v, (low, high), unit, why);
            }
        }
        if let Section::Explicit { inertia, .. } = self.section {
            require_within(
                &mut issues,
                "section/inertia",
                inertia,
                INERTIA_RANGE,
                "m⁴",
                "those of diameters from 1e-7 m to 1e3 m",
            );
        }
        if self.added_mass_per_length.is_finite() && self.added_mass_per_length > MAX_ADDED_MASS_PER_LENGTH {
            issues.push(InputIssue::new(
                "added_mass_per_length",
                format!(
                    "must be at most {} kg/m (got {} kg/m): beyond, the modal analysis leaves the range of \
                     floating-point numbers",
                    number(MAX_ADDED_MASS_PER_LENGTH),
                    number_beside(self.added_mass_per_length, MAX_ADDED_MASS_PER_LENGTH)
                ),
            ));
        }
        if let Some(shear) = self.shear {
            if !(shear.coefficient.is_finite() && shear.coefficient > 0.0 && shear.coefficient <= 1.0) {
                issues.push(InputIssue::new(
                    "shear/coefficient",
                    format!("must be in (0, 1] (got {})", number(shear.coefficient)),
                ));
            }
            if !(shear.poisson_ratio.is_finite() && shear.poisson_ratio > -1.0 && shear.poisson_ratio < 0.5) {
                issues.push(InputIssue::new(
                    "shear/poisson_ratio",
                    format!(
                        "must be in (−1, 0.5), the range of a stable isotropic material (got {})",
                        number(shear.poisson_ratio)
                    ),
                ));
            }
        }
        if !(1..=MAX_ELEMENTS).contains(&self.elements) {
            issues.push(InputIssue::new(
                "elements",
                format!("must be between 1 and {MAX_ELEMENTS}"),
            ));
        }
        let translation_held = self.foot != Support::Free || self.top != Support::Free;
        let rotation_held = self.foot == Support::Clamped
            || self.top == Support::Clamped
            || (self.foot == Support::Pinned && self.top == Support::Pinned);
        if !(translation_held && rotation_held) {
            issues.push(InputIssue::new(
                "supports",
                "must prevent rigid-body motion: clamp one end, or pin both",
            ));
        }
        issues
    }

    /// Number of DOFs left free by the supports: the most modes this mesh can give.
    pub fn free_dof_count(&self) -> usize {
        let constrained = |s: Support| match s {
            Support::Free => 0,
            Support::Pinned => 1,
            Support::Clamped => 2,
        };
        2 * (self.elements + 1) - constrained(self.foot) - constrained(self.top)
    }
}

/// Assembled finite-element matrices of a valid beam.
#[derive(Debug, Clone)]
pub struct BeamModel {
    pub length: f64,
    pub elements: usize,
    /// Element length h = L / elements (m).
    pub element_length: f64,
    /// Stiffness matrix over all DOFs, row-major (N/m, N, N·m).
    pub stiffness: Vec<f64>,
    /// Consistent mass matrix over all DOFs, row-major (kg, kg·m, kg·m²).
    pub mass: Vec<f64>,
    /// DOFs not fixed by the supports, increasing.
    pub free_dofs: Vec<usize>,
    /// Φ of its elements: 0 for Euler–Bernoulli ([`BeamSpec::shear_factor`]).
    pub shear_factor: f64,
}

impl BeamModel {
    /// Assembles K and M. The spec must be valid ([`BeamSpec::validate`]).
    pub fn assemble(spec: &BeamSpec) -> Self {
        let elements = spec.elements;
        let dofs = 2 * (elements + 1);
        let h = spec.length / elements as f64;
        let ei = spec.bending_stiffness();
        let m = spec.mass_per_length();
        let phi = spec.shear_factor(h);
        let (k_elem, m_elem) = match spec.shear {
            None => (element_stiffness(ei, h), element_mass(m, h)),
            Some(_) => (
                timoshenko_stiffness(ei, h, phi),
                timoshenko_mass(m, spec.density * spec.section.inertia(), h, phi),
            ),
        };
        let mut stiffness = vec![0.0; dofs * dofs];
        let mut mass = vec![0.0; dofs * dofs];
        for e in 0..elements {
            for a in 0..4 {
                for b in 0..4 {
                    let (row, col) = (2 * e + a, 2 * e + b);
                    stiffness[row * dofs + col] += k_elem[a][b];
                    mass[row * dofs + col] += m_elem[a][b];
                }
            }
        }
        let mut fixed = Vec::new();
        let mut constrain = |node: usize, support: Support| match support {
            Support::Free => {}
            Support::Pinned => fixed.push(2 * node),
            Support::Clamped => fixed.extend([2 * node, 2 * node + 1]),
        };
        constrain(0, spec.foot);
        constrain(elements, spec.top);
        let free_dofs = (0..dofs).filter(|d| !fixed.contains(d)).collect();
        Self {
            length: spec.length,
            elements,
            element_length: h,
            stiffness,
            mass,
            free_dofs,
            shear_factor: phi,
        }
    }

    /// Total number of DOFs (free and fixed).
    pub fn dof_count(&self) -> usize {
        2 * (self.elements + 1)
    }

    /// Element index and local coordinate ξ ∈ [0, 1] of height `x` (clamped to the beam).
    pub fn locate(&self, x: f64) -> (usize, f64) {
        let position = (x / self.element_length).clamp(0.0, self.elements as f64);
        let element = (position.floor() as usize).min(self.elements - 1);
        (element, position - element as f64)
    }

    /// The curvature w''(x) (1/m) of the displacement field `u` (over all DOFs) at height
    /// `x`: within an element, its linear FE curvature; at a node (to 1e-9 of an element),
    /// the mean of the curvatures the elements on either side give there (they differ
    /// where a point force acts; both are exact for the cubic of a tip load).
    pub fn curvature_at(&self, x: f64, u: &[f64]) -> f64 {
        let h = self.element_length;
        let position = (x / h).clamp(0.0, self.elements as f64);
        let node = position.round();
        let of = |element: usize, xi: f64| {
            let weights = match self.shear_factor {
                0.0 => hermite_curvatures(xi, h),
                phi => timoshenko_curvatures(xi, h, phi),
            };
            (0..4).map(|k| weights[k] * u[2 * element + k]).sum::<f64>()
        };
        if (position - node).abs() <= 1e-9 {
            let node = node as usize;
            let below = (node > 0).then(|| of(node - 1, 1.0));
            let above = (node < self.elements).then(|| of(node, 0.0));
            return match (below, above) {
                (Some(b), Some(a)) => 0.5 * (b + a),
                (Some(one), None) | (None, Some(one)) => one,
                (None, None) => 0.0,
            };
        }
        let (element, xi) = self.locate(x);
        of(element, xi)
    }

    /// Hermite interpolation weights of height `x`: w(x) = Σ weights[k] · u[first_dof + k].
    pub fn interpolation(&self, x: f64) -> (usize, [f64; 4]) {
        let (element, xi) = self.locate(x);
        let weights = match self.shear_factor {
            0.0 => hermite_shape_functions(xi, self.element_length),
            phi => timoshenko_shape_functions(xi, self.element_length, phi),
        };
        (2 * element, weights)
    }
}

/// Second derivatives along the beam (1/m², 1/m) of the Hermite shape functions on an
/// element of length `h` at local coordinate ξ: the curvature w''(x) = Σ N''ₖ uₖ, linear
/// over the element: N1'' = (12ξ − 6)/h², N2'' = (6ξ − 4)/h, N3'' = (6 − 12ξ)/h²,
/// N4'' = (6ξ − 2)/h.
pub fn hermite_curvatures(xi: f64, h: f64) -> [f64; 4] {
    let h2 = h * h;
    [
        (12.0 * xi - 6.0) / h2,
        (6.0 * xi - 4.0) / h,
        (6.0 - 12.0 * xi) / h2,
        (6.0 * xi - 2.0) / h,
    ]
}

/// Hermite cubic shape functions on an element of length `h` at local coordinate ξ:
/// N1 = 1 − 3ξ² + 2ξ³, N2 = h(ξ − 2ξ² + ξ³), N3 = 3ξ² − 2ξ³, N4 = h(ξ³ − ξ²).
pub fn hermite_shape_functions(xi: f64, h: f64) -> [f64; 4] {
    let xi2 = xi * xi;
    let xi3 = xi2 * xi;
    [
        1.0 - 3.0 * xi2 + 2.0 * xi3,
        h * (xi - 2.0 * xi2 + xi3),
        3.0 * xi2 - 2.0 * xi3,
        h * (xi3 - xi2),
    ]
}

/// Deflection w = Σ Nₖ uₖ of the interdependent Timoshenko element (Friedman and
/// Kosmatka 1993) of length `h` and shear factor Φ at ξ: the Hermite cubics at Φ = 0.
pub fn timoshenko_shape_functions(xi: f64, h: f64, phi: f64) -> [f64; 4] {
    let (xi2, xi3, d) = (xi * xi, xi * xi * xi, 1.0 / (1.0 + phi));
    [
        d * (2.0 * xi3 - 3.0 * xi2 - phi * xi + 1.0 + phi),
        d * h * (xi3 - (2.0 + 0.5 * phi) * xi2 + (1.0 + 0.5 * phi) * xi),
        d * (-2.0 * xi3 + 3.0 * xi2 + phi * xi),
        d * h * (xi3 - (1.0 - 0.5 * phi) * xi2 - 0.5 * phi * xi),
    ]
}

/// The bending curvature dθ/dx (the moment over EI) of the interdependent Timoshenko
/// element at ξ, from its rotation interpolation θ = Σ N̂ₖ uₖ
/// (N̂ = [6(ξ² − ξ)/h, 3ξ² − (4 + Φ)ξ + 1 + Φ, −6(ξ² − ξ)/h, 3ξ² − (2 − Φ)ξ] / (1 + Φ)):
/// [`hermite_curvatures`] at Φ = 0.
pub fn timoshenko_curvatures(xi: f64, h: f64, phi: f64) -> [f64; 4] {
    let d = 1.0 / ((1.0 + phi) * h);
    [
        d * 6.0 * (2.0 * xi - 1.0) / h,
        d * (6.0 * xi - 4.0 - phi),
        d * 6.0 * (1.0 - 2.0 * xi) / h,
        d * (6.0 * xi - 2.0 + phi),
    ]
}

/// Timoshenko element stiffness (Przemieniecki): EI/((1 + Φ)h³) [[12, 6h, −12, 6h],
/// [6h, (4 + Φ)h², −6h, (2 − Φ)h²], ...].
fn timoshenko_stiffness(ei: f64, h: f64, phi: f64) -> [[f64; 4]; 4] {
    let c = ei / ((1.0 + phi) * h * h * h);
    let h2 = h * h;
    [
        [12.0 * c, 6.0 * h * c, -12.0 * c, 6.0 * h * c],
        [
            6.0 * h * c,
            (4.0 + phi) * h2 * c,
            -6.0 * h * c,
            (2.0 - phi) * h2 * c,
        ],
        [-12.0 * c, -6.0 * h * c, 12.0 * c, -6.0 * h * c],
        [
            6.0 * h * c,
            (2.0 - phi) * h2 * c,
            -6.0 * h * c,
            (4.0 + phi) * h2 * c,
        ],
    ]
}

/// Timoshenko consistent element mass (Przemieniecki): the translational inertia of the
/// mass per length `m` and the rotary inertia `rho_i` (ρI, kg·m) with the element's
/// interpolation.
fn timoshenko_mass(m: f64, rho_i: f64, h: f64, phi: f64) -> [[f64; 4]; 4] {
    let (p, p2, h2) = (phi, phi * phi, h * h);
    let t = m * h / ((1.0 + p) * (1.0 + p));
    let (a, b) = (
        13.0 / 35.0 + 7.0 * p / 10.0 + p2 / 3.0,
        (11.0 / 210.0 + 11.0 * p / 120.0 + p2 / 24.0) * h,
    );
    let (c, d) = (
        9.0 / 70.0 + 3.0 * p / 10.0 + p2 / 6.0,
        (13.0 / 420.0 + 3.0 * p / 40.0 + p2 / 24.0) * h,
    );
    let (e, f) = (
        (1.0 / 105.0 + p / 60.0 + p2 / 120.0) * h2,
        (1.0 / 140.0 + p / 60.0 + p2 / 120.0) * h2,
    );
    let r = rho_i / ((1.0 + p) * (1.0 + p) * h);
    let (g, k) = (6.0 / 5.0, (1.0 / 10.0 - p / 2.0) * h);
    let (l, n) = (
        (2.0 / 15.0 + p / 6.0 + p2 / 3.0) * h2,
        (-1.0 / 30.0 - p / 6.0 + p2 / 6.0) * h2,
    );
    [
        [t * a + r * g, t * b + r * k, t * c - r * g, -t * d + r * k],
        [t * b + r * k, t * e + r * l, t * d - r * k, -t * f + r * n],
        [t * c - r * g, t * d - r * k, t * a + r * g, -t * b - r * k],
        [-t * d + r * k, -t * f + r * n, -t * b - r * k, t * e + r * l],
    ]
}

/// Element stiffness EI/h³ [[12, 6h, −12, 6h], [6h, 4h², −6h, 2h²], ...].
fn element_stiffness(ei: f64, h: f64) -> [[f64; 4]; 4] {
    let c = ei / (h * h * h);
    let h2 = h * h;
    [
        [12.0 * c, 6.0 * h * c, -12.0 * c, 6.0 * h * c],
        [6.0 * h * c, 4.0 * h2 * c, -6.0 * h * c, 2.0 * h2 * c],
        [-12.0 * c, -6.0 * h * c, 12.0 * c, -6.0 * h * c],
        [6.0 * h * c, 2.0 * h2 * c, -6.0 * h * c, 4.0 * h2 * c],
    ]
}

/// Consistent element mass m h/420 [[156, 22h, 54, −13h], ...].
fn element_mass(mass_per_length: f64, h: f64) -> [[f64; 4]; 4] {
    let c = mass_per_length * h / 420.0;
    let h2 = h * h;
    [
        [156.0 * c, 22.0 * h * c, 54.0 * c, -13.0 * h * c],
        [22.0 * h * c, 4.0 * h2 * c, 13.0 * h * c, -3.0 * h2 * c],
        [54.0 * c, 13.0 * h * c, 156.0 * c, -22.0 * h * c],
        [-13.0 * h * c, -3.0 * h2 * c, -22.0 * h * c, 4.0 * h2 * c],
    ]
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The public default tube (BRIEF §7).
    pub(crate) fn default_tube(elements: usize) -> BeamSpec {
        BeamSpec {
            length: 1.0,
            young_modulus: 2.1e11,
            density: 7800.0,
            section: Section::Tube {
                outer_diameter: 0.010,
                inner_diameter: 0.009,
            },
            added_mass_per_length: 0.0,
            elements,
            foot: Support::Clamped,
            top: Support::Free,
            shear: None,
        }
    }

    /// Total mass: a rigid translation r (w = 1, θ = 0) has kinetic mass rᵀMr = m L, and
    /// strain energy rᵀKr = 0 (rigid motion does not strain the beam).
    #[test]
    fn rigid_translation_has_total_mass_and_no_strain() {
        let spec = default_tube(7);
        let model = BeamModel::assemble(&spec);
        let n = model.dof_count();
        let r: Vec<f64> = (0..n).map(|d| if d % 2 == 0 { 1.0 } else { 0.0 }).collect();
        let quad = |matrix: &[f64]| -> f64 {
            (0..n)
                .map(|i| (0..n).map(|j| r[i] * matrix[i * n + j] * r[j]).sum::<f64>())
                .sum()
        };
        let expected_mass = spec.mass_per_length() * spec.length;
        let mass = quad(&model.mass);
        assert!(
            (mass - expected_mass).abs() < 1e-12 * expected_mass,
            "mass {mass} vs {expected_mass}"
        );
        let strain = quad(&model.stiffness);
        assert!(strain.abs() < 1e-6, "strain energy of rigid translation {strain}");
    }

    /// A static tip load P on a cantilever gives the exact cubic w(L) = P L³ / 3EI with
    /// Hermite elements (the exact solution is a cubic, inside the element space).
    #[test]
    fn cantilever_tip_load_gives_textbook_deflection() {
        let spec = default_tube(3);
        let model = BeamModel::assemble(&spec);
        let n = model.dof_count();
        let free = &model.free_dofs;
        let k: Vec<f64> = free
            .iter()
            .flat_map(|&i| free.iter().map(move |&j| (i, j)))
            .map(|(i, j)| model.stiffness[i * n + j])
            .collect();
        let mut rhs = vec![0.0; free.len()];
        let tip = free.iter().position(|&d| d == 2 * spec.elements).unwrap();
        rhs[tip] = 1.0;
        let solution = solve_dense(&k, &rhs);
        let expected = spec.length.powi(3) / (3.0 * spec.bending_stiffness());
        assert!(
            (solution[tip] - expected).abs() < 1e-9 * expected,
            "tip {} vs {expected}",
            solution[tip]
        );
    }

    /// A thick tube (L/D = 5) as a Timoshenko beam: κ from Cowper, ν = 0.3.
    pub(crate) fn thick_timoshenko_tube(elements: usize) -> BeamSpec {
        let (outer, inner) = (0.2, 0.16);
        BeamSpec {
            length: 1.0,
            section: Section::Tube {
                outer_diameter: outer,
                inner_diameter: inner,
            },
            shear: Some(Shear {
                coefficient: tube_shear_coefficient(outer, inner, 0.3),
                poisson_ratio: 0.3,
            }),
            ..default_tube(elements)
        }
    }

    /// The interdependent Timoshenko element is exact under end loads: a tip load P on
    /// a cantilever deflects it by P L³/3EI + P L/κGA (bending plus shear) on any mesh, and
    /// its static rotation at the tip is the bending one, P L²/2EI; the rigid
    /// translation keeps the total mass and strains nothing.
    #[test]
    fn a_timoshenko_cantilever_adds_the_shear_deflection_exactly() {
        for elements in [1, 3, 8] {
            let spec = thick_timoshenko_tube(elements);
            let model = BeamModel::assemble(&spec);
            assert!(
                model.shear_factor > 0.01,
                "a thick beam: Φ = {}",
                model.shear_factor
            );
            let n = model.dof_count();
            let free = &model.free_dofs;
            let k: Vec<f64> = (free.iter().flat_map(|&i| free.iter().map(move |&j| (i, j))))
                .map(|(i, j)| model.stiffness[i * n + j])
                .collect();
            let mut rhs = vec![0.0; free.len()];
            let tip = free.iter().position(|&d| d == 2 * spec.elements).unwrap();
            rhs[tip] = 1.0;
            let solution = solve_dense(&k, &rhs);
            let shear = spec.shear.unwrap();
            let g = spec.young_modulus / (2.0 * (1.0 + shear.poisson_ratio));
            let ei = spec.bending_stiffness();
            let expected = spec.length.powi(3) / (3.0 * ei)
                + spec.length / (shear.coefficient * g * spec.section.area());
            assert!(
                (solution[tip] - expected).abs() < 1e-9 * expected,
                "{elements}: {} vs {expected}",
                solution[tip]
            );
            let rotation = solution[tip + 1];
            let bending = spec.length.powi(2) / (2.0 * ei);
            assert!(
                (rotation - bending).abs() < 1e-9 * bending,
                "{elements}: θ {rotation} vs {bending}"
            );
            // The moment along the beam is P (L − z), whatever the shear.
            let mut u = vec![0.0; n];
            for (f, d) in free.iter().enumerate() {
                u[*d] = solution[f];
            }
            for z in [0.0, 0.3, 0.5, 1.0] {
                let moment = ei * model.curvature_at(z, &u);
                assert!(
                    (moment - (spec.length - z)).abs() < 1e-9,
                    "{elements}: M({z}) = {moment}"
                );
            }
            let r: Vec<f64> = (0..n).map(|d| if d % 2 == 0 { 1.0 } else { 0.0 }).collect();
            let quad = |matrix: &[f64]| -> f64 {
                (0..n)
                    .map(|i| (0..n).map(|j| r[i] * matrix[i * n + j] * r[j]).sum::<f64>())
                    .sum()
            };
            let mass = spec.mass_per_length() * spec.length;
            assert!((quad(&model.mass) - mass).abs() < 1e-12 * mass);
            assert!(quad(&model.stiffness).abs() < 1e-6);
        }
    }

    /// Cowper's κ: 6(1 + ν)/(7 + 6ν) for a solid circle, → 2(1 + ν)/(4 + 3ν) for a thin tube.
    #[test]
    fn cowpers_shear_coefficients_of_a_rod_and_a_thin_tube() {
        let nu = 0.3;
        assert!((tube_shear_coefficient(1.0, 0.0, nu) - 6.0 * 1.3 / (7.0 + 1.8)).abs() < 1e-15);
        let thin = tube_shear_coefficient(1.0, 0.999_999, nu);
        assert!((thin - 2.0 * 1.3 / (4.0 + 0.9)).abs() < 1e-6, "{thin}");
    }

    fn solve_dense(matrix: &[f64], rhs: &[f64]) -> Vec<f64> {
        let n = rhs.len();
        let a = faer::Mat::from_fn(n, n, |i, j| matrix[i * n + j]);
        let b = faer::Mat::from_fn(n, 1, |i, _| rhs[i]);
        let lu = a.partial_piv_lu();
        let x = faer::linalg::solvers::Solve::solve(&lu, &b);
        (0..n).map(|i| x[(i, 0)]).collect()
    }

    #[test]
    fn invalid_beam_names_each_field() {
        let mut spec = default_tube(0);
        spec.length = -1.0;
        spec.section = Section::Tube {
            outer_diameter: 0.01,
            inner_diameter: 0.02,
        };
        spec.top = Support::Free;
        spec.foot = Support::Pinned;
        let fields: Vec<String> = spec.validate().into_iter().map(|i| i.field).collect();
        assert_eq!(
            fields,
            ["length", "section/inner_diameter", "elements", "supports"]
        );
    }
}
