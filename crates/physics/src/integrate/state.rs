//! The dynamic state of a run: modal coordinates, velocities, accelerations and loads of
//! every pin, and the contact states (penetrations and forces per lane of the
//! [`super::layout::Layout`]), with the scratch the step needs.

use pulp::Simd;

use super::kernels;
use super::layout::Layout;
use super::walls::WallState;

/// What a step advances.
pub(super) struct State {
    /// Line-major (`lines × row`, see [`Layout`]): coordinates, velocities,
    /// accelerations, and the contact and point loads of the step (zeroed by the modal
    /// update). `v` and `a` have one more row, of zeros, for the walls.
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub force: Vec<f64>,
    /// Per lane: penetration (m) now and a step ago (the two buffers swap every step).
    pub penetration: Vec<f64>,
    pub previous_penetration: Vec<f64>,
    /// Per lane, the contact force (N); only meaningful where the penetration is positive
    /// (see [`kernels::penetrations`]).
    pub contact_force: Vec<f64>,
    /// Per lane, the tangential force T (N) of friction, as `contact_force`.
    pub tangential_force: Vec<f64>,
    /// w of every pin at every level, block-major (see [`kernels::level_deflections`]);
    /// the wall slots stay 0.
    pub level_deflections: Vec<f64>,
    /// Scratch: the lanes closed now (the only ones that need more than a penetration),
    /// and the groups holding them.
    pub closed: Vec<u32>,
    pub closed_groups: Vec<u64>,
    /// Lanes in `closed` this step, and per lane its dissipation and walls' powers (the
    /// plane's step shared between threads, [`super::plane_step::ClosedPass`]).
    pub closed_count: usize,
    pub lane_powers: Vec<[f64; 2]>,
    /// The walls, when they have their own motion.
    pub wall: Option<WallState>,
    /// The first half of the next step is done (q and v advanced with the modal update
    /// of a shared step, [`super::plane_step::update_halves`]).
    pub advanced: bool,
}

impl State {
    /// At rest, or released from the static tip-load shape with the model's initial tip
    /// deflections and moving in it with its initial tip velocities, one per line (in
    /// the plane the x lines, then the y lines); contacts open and no load yet.
    pub fn new(layout: &Layout<'_>) -> Self {
        let (model, row, lines) = (layout.model, layout.row, layout.lines);
        let mut q = vec![0.0; lines * row];
        // The pins' rows of v (the walls' row of zeros after them).
        let mut v = vec![0.0; (lines + 1) * row];
        if let Some(unit) = model.basis.unit_tip_release() {
            for (values, tips) in [
                (&mut q, &model.initial_tip_displacements),
                (&mut v, &model.initial_tip_velocities),
            ] {
                for (coordinates, tip) in values.chunks_exact_mut(row).zip(tips) {
                    for (x, u) in coordinates.iter_mut().zip(unit.iter()) {
                        *x = tip * u;
                    }
                }
            }
        }
        let lanes = layout.contact_lanes();
        let groups = lanes / layout.lanes;
        Self {
            q,
            v,
            a: vec![0.0; (lines + 1) * row],
            force: vec![0.0; lines * row],
            penetration: vec![0.0; lanes],
            previous_penetration: vec![0.0; lanes],
            contact_force: vec![0.0; lanes],
            tangential_force: vec![0.0; lanes],
            level_deflections: vec![0.0; layout.level_deflections_len()],
            closed: vec![0; lanes],
            closed_groups: vec![0; groups.div_ceil(64)],
            closed_count: 0,
            lane_powers: vec![[0.0; 2]; lanes],
            wall: layout.walls.as_ref().map(|walls| WallState::new(walls, model)),
            advanced: false,
        }
    }

    /// Kinetic energy now (J): μ ½ Σ v² per run of lines of one kind.
    pub fn kinetic_energy(&self, layout: &Layout<'_>) -> f64 {
        let row = layout.row;
        layout
            .energy_runs
            .iter()
            .map(|run| {
                let v = &self.v[run.first * row..(run.first + run.lines) * row];
                layout.kinds[run.kind].mass * 0.5 * v.iter().map(|v| v * v).sum::<f64>()
            })
            .sum()
    }

    /// Kinetic + strain + contact energy now (J).
    pub fn mechanical_energy(&self, arch: pulp::Arch, layout: &Layout<'_>) -> f64 {
        // Per run of lines of one kind: μ ½ Σ (v² + ω² q²).
        let row = layout.row;
        let modal: f64 = layout
            .energy_runs
            .iter()
            .map(|run| {
                let kind = &layout.kinds[run.kind];
                let rows = run.first * row..(run.first + run.lines) * row;
                kind.mass
                    * arch.dispatch(ModalEnergyOp {
                        stiffness: &kind.omega_squared,
                        q: &self.q[rows.clone()],
                        v: &self.v[rows],
                    })
            })
            .sum();
        modal + self.contact_energy(layout)
    }

    /// Σ K δⁿ⁺¹/(n + 1) over the closed contacts (J): ½ Kc δ² for the linear law, and
    /// the stick springs' T²/(2 k_t).
    pub fn contact_energy(&self, layout: &Layout<'_>) -> f64 {
        layout
            .model
            .contacts
            .iter()
            .zip(&layout.contacts.lane)
            .map(|(c, lane)| (c, *lane as usize))
            .filter(|(_, lane)| self.penetration[*lane] > 0.0)
            .map(|(c, lane)| {
                let spring = c.normal_law().energy(self.penetration[lane]);
                if c.law.friction.is_on() {
                    spring + c.law.friction.energy(self.tangential_force[lane])
                } else {
                    spring
                }
            })
            .sum()
    }

    /// The force of the contact in `lane` (N): forces are only updated while closed.
    pub fn contact_force_of(&self, lane: usize) -> f64 {
        if self.penetration[lane] > 0.0 {
            self.contact_force[lane]
        } else {
            0.0
        }
    }
}

/// ½ Σ (v² + ω² q²) as a [`pulp::WithSimd`] operation.
struct ModalEnergyOp<'a> {
    stiffness: &'a [f64],
    q: &'a [f64],
    v: &'a [f64],
}

impl pulp::WithSimd for ModalEnergyOp<'_> {
    type Output = f64;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f64 {
        kernels::modal_energy(
            simd,
            S::as_simd_f64s(self.stiffness).0,
            S::as_simd_f64s(self.q).0,
            S::as_simd_f64s(self.v).0,
        )
    }
}
