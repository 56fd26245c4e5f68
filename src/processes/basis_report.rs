//! The `basis` entry of a results document: the modal basis a run actually used
//! (eigenmodes, static-correction pseudo-modes and their heights) and what it cost.

use serde::Serialize;
use utoipa::ToSchema;

use super::common_inputs::BeamInput;
use crate::physics::discretisation::auto::Choice;
use crate::physics::integrate::{Model, critical_time_step};
use crate::physics::modal::ModalBasis;
use crate::physics::stability::Scheme;

/// The basis of a run, as reported in its results.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct BasisReport {
    /// `none` or `contacts`, as used.
    pub static_correction: &'static str,
    /// Eigenmodes kept (m).
    pub modes: usize,
    /// Elements of the mesh the basis was computed on.
    pub elements: usize,
    /// How `modes` and `elements` were set: `given` or `auto`.
    pub chosen_by: ChosenBy,
    /// What `auto` saw when it chose (null when both counts were given): the impact
    /// probes' estimates for the chosen mesh and basis and the bound they meet.
    pub auto: Option<AutoReport>,
    /// Their frequencies (Hz), increasing.
    pub mode_frequencies_hz: Vec<f64>,
    /// Distinct contact heights (m) that got a pseudo-mode.
    pub correction_heights: Vec<f64>,
    /// Contact heights (m) whose static shape the modes already hold (e.g. at a fixed
    /// support): no pseudo-mode.
    pub dropped_correction_heights: Vec<f64>,
    /// Frequencies of the pseudo-modes (Hz), increasing, all above the last mode's.
    /// With several heights a pseudo-mode mixes their static shapes, so they are not
    /// paired with heights.
    pub pseudo_mode_frequencies_hz: Vec<f64>,
    pub cost: BasisCost,
}

/// How the counts of a basis were set.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ChosenBy {
    /// `given` or `auto`.
    pub modes: &'static str,
    /// `given` or `auto`.
    pub elements: &'static str,
}

/// What `auto` saw when it chose the mesh and the basis.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct AutoReport {
    /// The bound every estimate had to meet: 10 × `solver.tolerance` (dimensionless).
    pub target: f64,
    /// Estimated relative error of the peak contact force due to the chosen basis, the
    /// largest over the probed contacts (dimensionless; 3 × the probe's).
    pub estimated_basis_error: f64,
    /// The same due to the chosen mesh (dimensionless).
    pub estimated_mesh_error: f64,
    /// Distinct contacts (height, spring) probed for the choice (count).
    pub probed_contacts: usize,
}

/// What the basis costs the run.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct BasisCost {
    /// Modal coordinates per pin (modes + pseudo-modes).
    pub modal_dofs_per_pin: usize,
    /// Modal coordinates of the whole run (pins × per pin).
    pub modal_dofs: usize,
    /// Critical step of this basis (s), every contact closed; null under `exact_modal`,
    /// which has none (its step follows the contacts, not the basis).
    pub critical_time_step: Option<f64>,
    /// Critical step (s) the eigenmodes alone would have: the pseudo-modes' share of the
    /// cost shows in the ratio (equal without correction); null under `exact_modal`.
    pub critical_time_step_without_correction: Option<f64>,
}

impl BasisReport {
    /// Report of `model`'s basis; `critical` is the run's critical step (s); `chosen`
    /// the beam's input and what `auto` chose for it (`None` when both were given).
    pub fn of(
        model: &Model<'_>,
        scheme: Scheme,
        critical: f64,
        (beam, choice): (&BeamInput, Option<&Choice>),
    ) -> Self {
        let basis: &ModalBasis = model.basis;
        let m = basis.eigenmodes();
        let frequencies = basis.frequencies_hz();
        let correction = basis.static_correction();
        let without = if basis.modes() > m {
            let truncated = basis.without_static_correction();
            let mut plain = model.clone();
            plain.basis = &truncated;
            plain.damping_ratios.truncate(m);
            critical_time_step(&plain, scheme)
        } else {
            critical
        };
        Self {
            static_correction: if correction.is_some() { "contacts" } else { "none" },
            modes: m,
            elements: basis.spec().elements,
            chosen_by: ChosenBy {
                modes: beam.modes.rule(),
                elements: beam.elements.rule(),
            },
            auto: choice.map(|c| AutoReport {
                target: c.target,
                estimated_basis_error: c.basis_error,
                estimated_mesh_error: c.mesh_error,
                probed_contacts: c.probed_contacts,
            }),
            mode_frequencies_hz: frequencies[..m].to_vec(),
            correction_heights: correction.map(|c| c.heights.clone()).unwrap_or_default(),
            dropped_correction_heights: correction.map(|c| c.dropped_heights.clone()).unwrap_or_default(),
            pseudo_mode_frequencies_hz: frequencies[m..].to_vec(),
            cost: BasisCost {
                modal_dofs_per_pin: basis.modes(),
                modal_dofs: basis.modes() * model.pins,
                critical_time_step: crate::physics::finite(critical),
                critical_time_step_without_correction: crate::physics::finite(without),
            },
        }
    }
}
