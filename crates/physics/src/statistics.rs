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

/// Friction at one contact over the whole run, accumulated at every step while it is
/// closed (docs/contact-laws.md).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct FrictionStatistics {
    /// ∫ |T| dt (N·s) and ∫ T² dt (N²·s) while closed: the tangential force's mean and
    /// RMS over the contact time.
    pub tangential_impulse: f64,
    pub tangential_square: f64,
    /// Largest |T| (N).
    pub max_tangential_force: f64,
    /// ∫ |v_t| dt while slipping (m): the distance slid.
    pub slip_distance: f64,
    /// Time closed and sticking (s).
    pub stick_time: f64,
    /// ∫ |T| |v_t| dt while slipping (J): the friction's wear work.
    pub tangential_wear_work: f64,
}

impl FrictionStatistics {
    /// Adds one step Δt of a closed contact: its tangential state and sliding speed.
    #[inline(always)]
    pub fn record(&mut self, tangential: &crate::contact::Tangential, sliding: f64, dt: f64) {
        let force = tangential.force.abs();
        self.tangential_impulse += force * dt;
        self.tangential_square += force * force * dt;
        self.max_tangential_force = self.max_tangential_force.max(force);
        if tangential.slipping {
            self.slip_distance += sliding.abs() * dt;
            self.tangential_wear_work += force * sliding.abs() * dt;
        } else {
            self.stick_time += dt;
        }
    }
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

/// The largest bending curvature |w''| (1/m) at one place, over the output samples: of
/// one pin along its height, or at one mesh node over every pin. In the plane, the
/// resultant √(κx² + κy²) of the pin's two bending directions (a circular section's
/// outer-fibre strain is c × it, its moment EI × it).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct CurvaturePeak {
    /// max |κ| (1/m), ≥ 0; 0 when the pin never bends.
    pub curvature: f64,
    /// Height (m).
    pub height: f64,
    /// The pin.
    pub pin: usize,
    /// When (s): an output sample's time.
    pub time: f64,
}

/// The largest resultant of the contact forces on one pin at one contact height: the
/// vector sum of every contact there acting on the pin (normal and friction forces;
/// the contacts on both of its sides at once), its magnitude tracked at every step.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct ResultantPeak {
    /// The pin.
    pub pin: usize,
    /// The contact height (m).
    pub height: f64,
    /// How many of the model's contacts act on the pin at this height.
    pub contacts: usize,
    /// max |Σ F| (N), ≥ 0; 0 when none of them ever closed.
    pub force: f64,
    /// When (s): the step's time (0 when it never closed).
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
    /// Σ K δⁿ⁺¹/(n + 1) over closed contacts (½ Kc δ² for the linear law), and the
    /// stick springs' T²/(2 k_t) with friction.
    pub contact: f64,
    /// ∫ Σ 2ξᵢωᵢ q̇ᵢ² dt: modal (structural) damping.
    pub dissipated_modal: f64,
    /// ∫ (F − K δⁿ) δ̇ dt over closed contacts (dashpots, Hunt–Crossley damping and the
    /// force clamp), and the work of friction.
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
