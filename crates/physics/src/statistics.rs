//! What a run reports besides its histories: per-contact statistics accumulated at
//! every step, per-pin deflection extremes, and the energy balance.

/// Statistics of one contact over the whole run, accumulated at every time step (not
/// from thinned histories).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct ContactStatistics {
    /// Largest contact force (N).
    pub max_force: f64,
    /// Time of the largest force (s); 0 when the contact never closed.
    pub max_force_time: f64,
    /// Number of closures after a separation (the first closure counts).
    pub impacts: u64,
    /// Total time with penetration δ > 0 (s).
    pub contact_time: f64,
    /// ∫ F dt (N·s).
    pub impulse: f64,
    /// Largest penetration δ (m); ≤ 0 when the contact never closed (smallest clearance).
    pub max_penetration: f64,
    /// Time of the first closure (s), linearly interpolated between steps.
    pub first_impact_time: Option<f64>,
}

/// Largest deflection of one pin over the run.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct PinExtreme {
    /// max |w| (m), sampled at the mesh nodes at every output time.
    pub max_abs_deflection: f64,
    /// Height where it occurred (m).
    pub height: f64,
    /// When it occurred (s).
    pub time: f64,
}

/// The deflection of largest magnitude at one height of one pin, over every step.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct PeakDeflection {
    /// Signed deflection (m).
    pub deflection: f64,
    /// When it occurred (s): the end of the output interval that holds it (the peak is
    /// tracked at every step, its time to within `output.interval`).
    pub time: f64,
}

/// Energy balance of the row in the wrapper frame (J). With exact integration,
/// kinetic + strain + contact + dissipated − external_work = initial.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct EnergyBalance {
    /// ½ Σ q̇ᵢ² (modal, M̄ = I).
    pub kinetic: f64,
    /// ½ Σ ωᵢ² qᵢ².
    pub strain: f64,
    /// ½ Σ Kc δ² over closed contacts.
    pub contact: f64,
    /// ∫ Σ 2ξᵢωᵢ q̇ᵢ² dt: modal (structural) damping.
    pub dissipated_modal: f64,
    /// ∫ (F − Kc δ) δ̇ dt over closed contacts: contact dashpots (and the force clamp).
    pub dissipated_contact: f64,
    /// ∫ f_ext · q̇ dt: work of the base excitation (inertial load) and point forces.
    pub external_work: f64,
    /// kinetic + strain + contact at t = 0.
    pub initial: f64,
}

impl EnergyBalance {
    /// kinetic + strain + contact.
    pub fn mechanical(&self) -> f64 {
        self.kinetic + self.strain + self.contact
    }

    /// mechanical + dissipated − external_work − initial: zero for exact integration.
    pub fn residual(&self) -> f64 {
        self.mechanical() + self.dissipated_modal + self.dissipated_contact
            - self.external_work
            - self.initial
    }

    /// |residual| relative to the largest energy involved.
    pub fn relative_residual(&self) -> f64 {
        let scale = self
            .initial
            .abs()
            .max(self.external_work.abs())
            .max(self.mechanical())
            .max(self.dissipated_modal + self.dissipated_contact);
        if scale > 0.0 {
            self.residual().abs() / scale
        } else {
            0.0
        }
    }
}
