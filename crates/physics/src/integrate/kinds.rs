//! Bodies of several kinds in one model: fuel rods beside guide tubes, a stiffer tube in
//! a row of pins, each with its own section, material, mass and damping.
//!
//! A kind is the model's beam with another section, material and mass: the same
//! length, supports, mesh, modes and static correction. Its stiffness and mass matrices
//! are then those of the basis's beam scaled, K' = (EI'/EI) K and M' = (m'/m) M (an
//! Euler–Bernoulli beam), and so are its modes: the same shapes, mass-normalised by
//! 1/√μ with μ = m'/m, at the frequencies ω' = ω √((EI'/EI)/μ). The integrator keeps
//! every line on the basis's shapes ψ and writes a line of kind μ in the coordinates
//! η = √μ q' (w = Σ ψᵢ ηᵢ as for any line): its modal equations are
//! η̈ᵢ + 2ξ'ᵢω'ᵢ η̇ᵢ + ω'ᵢ² ηᵢ = ψᵢ(z)·F / μ − Γᵢ a(t), with the same participation Γ and the
//! same tip-load and transport shapes, and its energy is μ times its line's sum. So a
//! kind costs one multiply per modal coordinate and per step; the kernels, the contact
//! lanes and the level shapes are the basis's.
//!
//! The kind is given by its own basis ([`BodyKind::basis`], computed like the model's),
//! and [`Model::validate`] checks that it is the basis's beam scaled: every mode's shape
//! along the mesh, times √μ, is the basis's to [`SHAPE_TOLERANCE`] (up to its sign),
//! with one μ for every mode. A Timoshenko kind whose shear or rotary inertia is not in
//! the same proportion, other supports, another length, mesh or number of modes are
//! refused at `kinds/<k>/basis`: their shapes differ, and the lines would need shapes
//! of their own.

use crate::InputIssue;
use crate::modal::ModalBasis;

/// Pins of another kind than the basis's beam.
#[derive(Debug, Clone)]
pub struct BodyKind<'a> {
    /// The kind's own modal basis: the model's beam with this kind's section, material
    /// and mass, the same length, supports, mesh, modes and static correction.
    pub basis: &'a ModalBasis,
    /// Modal damping ratio ξ of each mode (length = modes).
    pub damping_ratios: Vec<f64>,
    /// The pins of this kind (each at most once in every kind); the others are the
    /// basis's.
    pub pins: Vec<usize>,
    /// The factor its curvatures take where the bending envelope compares pins at a
    /// height ([`super::Simulation::curvature_envelope`]): its outer-fibre stress per
    /// unit curvature E c relative to the basis's beam's, so that the envelope holds the
    /// most stressed pin; 1 compares curvatures. The envelope reports the pin's own
    /// curvature.
    pub envelope_weight: f64,
}

/// How far a kind's mass-scaled shapes may be from the basis's (relative to the largest
/// nodal value of each mode), and its per-mode masses from one another.
pub const SHAPE_TOLERANCE: f64 = 1e-6;

/// What the integrator needs of one kind (kind 0 is the basis's): its relative mass μ
/// (m'/m), its angular frequencies and its damping ratios.
#[derive(Debug, Clone, Copy)]
pub struct KindScale<'a> {
    pub mass: f64,
    pub frequencies: &'a [f64],
    pub damping_ratios: &'a [f64],
}

/// The relative mass μ of `kind` against `basis` when its modes are the basis's scaled
/// (every mode's √μ the same, the shapes equal up to sign), or why not.
pub fn relative_mass(basis: &ModalBasis, kind: &ModalBasis) -> Result<f64, String> {
    let (modes, length, elements) = (basis.modes(), basis.length(), basis.model().elements);
    if kind.modes() != modes {
        return Err(format!("has {} modes where the pins have {modes}", kind.modes()));
    }
    if kind.length() != length {
        return Err(format!(
            "is {} m long where the pins are {length} m",
            kind.length()
        ));
    }
    if kind.model().elements != elements {
        return Err(format!(
            "has {} elements where the pins have {elements}",
            kind.model().elements
        ));
    }
    let (spec, own) = (basis.spec(), kind.spec());
    if (own.foot, own.top) != (spec.foot, spec.top) {
        return Err("has other supports than the pins".into());
    }
    if kind.eigenmodes() != basis.eigenmodes() {
        return Err("has another static correction than the pins".into());
    }
    let mut scale: Option<f64> = None;
    for i in 0..modes {
        let (reference, shape) = (basis.shape(i), kind.shape(i));
        let largest = reference.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let dot: f64 = reference.iter().zip(shape).map(|(a, b)| a * b).sum();
        let norm: f64 = shape.iter().map(|b| b * b).sum();
        // √μ with the sign that lines the shape up with the basis's.
        let s = dot / norm;
        let misfit = reference
            .iter()
            .zip(shape)
            .fold(0.0_f64, |m, (a, b)| m.max((a - s * b).abs()));
        if !(s.is_finite() && misfit <= SHAPE_TOLERANCE * largest) {
            return Err(format!(
                "mode {} has another shape than the pins' (a Timoshenko beam whose shear or \
                 rotary inertia is in another proportion to its bending): a kind must be the \
                 pins' beam with another section, material or mass",
                i + 1
            ));
        }
        match scale {
            None => scale = Some(s.abs()),
            Some(first) if (s.abs() - first).abs() > SHAPE_TOLERANCE * first => {
                return Err(format!(
                    "mode {} is scaled by another mass than mode 1 (the mass is not in the \
                     same proportion along the beam)",
                    i + 1
                ));
            }
            Some(_) => {}
        }
    }
    Ok(scale.map_or(1.0, |s| s * s))
}

/// Every problem with `kinds` in a model of `pins` pins on `basis`: pins that exist and
/// belong to one kind, one finite non-negative damping ratio per mode, and a basis that
/// is the model's beam scaled ([`relative_mass`]).
pub fn validate(kinds: &[BodyKind<'_>], basis: &ModalBasis, pins: usize) -> Vec<InputIssue> {
    let mut issues = Vec::new();
    let mut owner: Vec<Option<usize>> = vec![None; pins];
    for (k, kind) in kinds.iter().enumerate() {
        let field = |name: &str| format!("kinds/{k}/{name}");
        if let Err(reason) = relative_mass(basis, kind.basis) {
            issues.push(InputIssue::new(
                field("basis"),
                format!("the kind's beam {reason}"),
            ));
        }
        if kind.damping_ratios.len() != basis.modes() {
            issues.push(InputIssue::new(
                field("damping_ratios"),
                format!(
                    "needs one ratio per mode of the basis ({}), got {}",
                    basis.modes(),
                    kind.damping_ratios.len()
                ),
            ));
        }
        crate::require_positive(&mut issues, &field("envelope_weight"), kind.envelope_weight);
        for (i, xi) in kind.damping_ratios.iter().enumerate() {
            crate::require_non_negative(&mut issues, &field(&format!("damping_ratios/{i}")), *xi);
        }
        for (j, pin) in kind.pins.iter().enumerate() {
            let at = field(&format!("pins/{j}"));
            match owner.get_mut(*pin) {
                None => issues.push(InputIssue::new(
                    at,
                    format!("pin {pin} does not exist: the model has {pins} pins"),
                )),
                Some(Some(other)) => issues.push(InputIssue::new(
                    at,
                    format!("pin {pin} is already of kind {other}"),
                )),
                Some(slot) => *slot = Some(k),
            }
        }
    }
    issues
}

/// The kind of every pin: 0 for the basis's, k + 1 for `kinds[k]` (pins out of range
/// ignored: [`validate`] refuses them).
pub fn pin_kinds(kinds: &[BodyKind<'_>], pins: usize) -> Vec<usize> {
    pin_kinds_of(kinds.iter().map(|k| &k.pins[..]), pins)
}

/// The kind of every pin from each kind's list of pins (kind k + 1 for the k-th list, 0
/// for a pin in none; the last list naming a pin wins, pins out of range ignored).
pub fn pin_kinds_of<'p>(lists: impl IntoIterator<Item = &'p [usize]>, pins: usize) -> Vec<usize> {
    let mut of = vec![0; pins];
    for (k, list) in lists.into_iter().enumerate() {
        for pin in list {
            if let Some(slot) = of.get_mut(*pin) {
                *slot = k + 1;
            }
        }
    }
    of
}
