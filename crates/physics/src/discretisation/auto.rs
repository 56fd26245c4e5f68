//! `elements: "auto"` and `modes: "auto"`: the coarsest mesh and the smallest basis whose
//! impact probes ([`super`]) put the peak contact force within a target, chosen before
//! the run from the model's contacts.
//!
//! **The rule.** The estimates are the ones the verdict reads after the run
//! ([`super::SAFETY_FACTOR`] times the probe's relative error), so a basis chosen here is
//! `good` on the basis and the mesh whatever contacts push during the run: the choice
//! probes every distinct contact (height, spring) of the model, the run only those
//! that pushed.
//! 1. **Mesh.** From `start` elements, double until the mesh estimate (complete basis of
//!    the mesh against the mesh twice as fine) is within the target; past
//!    [`MAX_ELEMENTS`] the target cannot be met and the choice says so.
//! 2. **Modes.** On that mesh, the first count of [`MODE_LADDER`] (then every free DOF)
//!    whose basis estimate (the basis, static correction included when asked, against
//!    the complete basis of the mesh) is within the target.
//!
//! A count given by the user is kept and only measured. The cost of the choice (the
//! step the basis then needs, the work of the run) is the caller's to judge: the service
//! refuses a choice its cost limits do not admit.

use super::{MeshProbes, ProbeContact, SAFETY_FACTOR};
use crate::beam::BeamSpec;
use crate::contact::Contact;
use crate::modal::{ModalBasis, ModalError};

/// The finest mesh `elements: "auto"` may choose: its probe needs the complete basis of
/// the mesh twice as fine (a dense eigenproblem of 4 × this many DOFs, ~1 s). Should a
/// refinement's basis still fail to compute, the finest mesh probed ends the search.
pub const MAX_ELEMENTS: usize = 200;
/// The mesh `elements: "auto"` starts from, when the model asks for no finer one.
pub const START_ELEMENTS: usize = 40;
/// The mode counts `modes: "auto"` tries, in order (then the complete basis).
pub const MODE_LADDER: [usize; 12] = [5, 10, 15, 20, 30, 40, 60, 80, 120, 160, 240, 320];
/// At most this many distinct contacts are probed for the choice (evenly over the
/// heights when there are more).
pub const MAX_DESIGN_PROBES: usize = 48;

/// A count given by the user, or chosen by the rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Count {
    Given(usize),
    Auto,
}

/// What to choose, and within what.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    pub elements: Count,
    /// The coarsest mesh the model admits (e.g. one element between contact levels);
    /// `elements: "auto"` starts from the larger of this and [`START_ELEMENTS`].
    pub min_elements: usize,
    pub modes: Count,
    /// Whether the basis carries the static correction at the contact heights.
    pub static_correction: bool,
    /// Largest estimated relative error of the peak contact force (dimensionless), for
    /// the basis and for the mesh each: the verdict's bound for `good` (10 τ).
    pub target: f64,
}

/// The mesh and basis chosen (or given), and their estimated errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// The bound the estimates had to meet (the request's target).
    pub target: f64,
    pub elements: usize,
    pub modes: usize,
    /// Estimated relative error of the peak contact force due to the basis and to the
    /// mesh ([`SAFETY_FACTOR`] × the probe's), the largest over the probed contacts.
    pub basis_error: f64,
    pub mesh_error: f64,
    /// Distinct contacts probed.
    pub probed_contacts: usize,
}

/// Why the rule could not choose.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AutoError {
    #[error(
        "no mesh up to {elements} elements puts the peak contact force within {target:e} \
         (estimated error {error:e} at {elements} elements)"
    )]
    Mesh {
        elements: usize,
        error: f64,
        target: f64,
    },
    #[error(transparent)]
    Modal(#[from] ModalError),
}

/// The distinct probes of `contacts` on pins of `length` (m), at most
/// [`MAX_DESIGN_PROBES`]: every one when there are fewer, else evenly spaced over the
/// list sorted by height (the stiffest spring first at equal heights).
pub fn design_contacts(contacts: &[Contact], length: f64) -> Vec<ProbeContact> {
    let mut probes: Vec<ProbeContact> = contacts
        .iter()
        .filter_map(|c| ProbeContact::of(c, length))
        .collect();
    probes.sort_by(|a, b| {
        a.height
            .total_cmp(&b.height)
            .then(b.stiffness.total_cmp(&a.stiffness))
    });
    probes.dedup();
    if probes.len() <= MAX_DESIGN_PROBES {
        return probes;
    }
    let last = probes.len() - 1;
    let mut picked: Vec<ProbeContact> = (0..MAX_DESIGN_PROBES)
        .map(|k| probes[k * last / (MAX_DESIGN_PROBES - 1)])
        .collect();
    picked.dedup();
    picked
}

/// The basis of `spec` (its `elements` replaced by the choice's) with `modes` modes,
/// corrected at `heights` when asked.
pub fn basis_of(
    spec: &BeamSpec,
    modes: usize,
    correction_heights: Option<&[f64]>,
) -> Result<ModalBasis, ModalError> {
    match correction_heights {
        Some(heights) => ModalBasis::compute_with_static_correction(spec, modes, heights),
        None => ModalBasis::compute(spec, modes),
    }
}

/// The mesh and basis of `spec` for `request` at `contacts` (module doc);
/// `correction_heights` are the heights of the static correction when it is on. With
/// no contact to probe (none that pushes, or only at fixed supports), every estimate is
/// 0 and `auto` keeps its starting mesh and the ladder's first count.
pub fn choose(
    spec: &BeamSpec,
    request: &Request,
    contacts: &[ProbeContact],
    correction_heights: &[f64],
) -> Result<Choice, AutoError> {
    let mesh_of = |elements: usize| BeamSpec {
        elements,
        ..spec.clone()
    };
    let (elements, probes) = match request.elements {
        Count::Given(elements) => (elements, MeshProbes::new(&mesh_of(elements), contacts)?),
        Count::Auto => {
            let mut elements = request.min_elements.max(START_ELEMENTS);
            // The last mesh probed and its estimate, for the refusal.
            let mut last: Option<(usize, f64)> = None;
            let too_coarse = |(elements, error): (usize, f64)| AutoError::Mesh {
                elements,
                error,
                target: request.target,
            };
            loop {
                let probes = match MeshProbes::new(&mesh_of(elements), contacts) {
                    Ok(probes) => probes,
                    // The eigensolver's limit on the refined mesh (module doc of
                    // [`MAX_ELEMENTS`]): the finest mesh probed is where it ends.
                    Err(_) if last.is_some() => return Err(too_coarse(last.expect("checked"))),
                    Err(e) => return Err(e.into()),
                };
                let error = SAFETY_FACTOR * probes.mesh_error();
                if error <= request.target {
                    break (elements, probes);
                }
                if elements >= MAX_ELEMENTS {
                    return Err(too_coarse((elements, error)));
                }
                last = Some((elements, error));
                elements = (2 * elements).min(MAX_ELEMENTS);
            }
        }
    };
    let mesh = mesh_of(elements);
    let correction = request.static_correction.then_some(correction_heights);
    let basis_error = |modes: usize| -> Result<f64, ModalError> {
        let basis = basis_of(&mesh, modes, correction)?;
        Ok(SAFETY_FACTOR
            * probes
                .compare(&basis)
                .iter()
                .map(|p| p.basis_error)
                .fold(0.0, f64::max))
    };
    let (modes, error) = match request.modes {
        Count::Given(modes) => (modes, basis_error(modes)?),
        Count::Auto => {
            let complete = mesh.free_dof_count();
            let candidates = MODE_LADDER
                .iter()
                .copied()
                .filter(|m| *m < complete)
                .chain(std::iter::once(complete));
            let mut chosen = None;
            for modes in candidates {
                let error = basis_error(modes)?;
                if error <= request.target || modes == complete {
                    chosen = Some((modes, error));
                    break;
                }
            }
            chosen.expect("the complete basis ends the candidates")
        }
    };
    Ok(Choice {
        target: request.target,
        elements,
        modes,
        basis_error: error,
        mesh_error: SAFETY_FACTOR * probes.mesh_error(),
        probed_contacts: probes.len(),
    })
}

#[cfg(test)]
mod tests;
