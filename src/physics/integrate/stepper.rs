//! State and step of one run: the hot loop.
//!
//! Layout: pin-major. Each pin's modal coordinates are one contiguous row of `row`
//! values (the modes rounded up to whole SIMD blocks of [`BLOCK`]; padded modes have
//! ω = 0, Γ = 0, ψ = 0 and stay 0). A closed contact then reads and writes whole rows:
//! its dashpot velocity ψ·ṽ is one contiguous dot product and its force projection one
//! contiguous axpy, both in SIMD blocks.
//!
//! Where the time goes (row17: 17 pins × 20 modes, 10 levels, 180 contacts, about 15 %
//! of them closed at a time; about 16 000 instructions per step, counted with
//! callgrind, against 41 000 for the mode-major, autovectorized version before it):
//! 1. the deflection of every pin at every contact level ([`level_deflections`]): per
//!    pin, 20 coordinates broadcast against 3 blocks of 4 levels, ~1 000 FMAs, plus
//!    the scatter into the level-major layout (about a third of the step);
//! 2. a vector pass over every contact ([`penetrations`], contacts cut in runs of
//!    consecutive slots): penetration, running maximum, zero force where open, and
//!    the list of closed ones;
//! 3. the closed contacts only: dashpot velocity, force, statistics, force projection;
//! 4. the modal update ([`modal_update`]), which also accumulates the dissipated and
//!    external powers.
//!
//! The step is dispatched through `pulp` so that it is compiled for the SIMD level of
//! the running CPU (AVX2 + FMA on x86-64-v3) without unsafe code; see [`kernels`] for
//! what that means for reproducibility.

use pulp::Simd;

use super::kernels::{
    self, BLOCK, ContactState, LevelShapes, ModalCoefficients, Run, advance_positions, axpy, dot_ahead,
    level_deflections, modal_update, penetrations, scale_into,
};
use super::{ContactStatistics, EnergyBalance, Model, PinExtreme, Settings, Simulation, SimulationError};
use crate::physics::contact::Body;
use crate::physics::stability::Scheme;

/// Σ x·y outside the hot loop (samples, energies).
fn dot(x: &[f64], y: &[f64]) -> f64 {
    kernels::dot(pulp::Scalar::new(), x, y)
}

/// Sentinel pin index of a wall (for force projection; reads use the zero slot).
const WALL: usize = usize::MAX;

pub(super) struct Integrator<'m> {
    arch: pulp::Arch,
    model: &'m Model<'m>,
    scheme: Scheme,
    dt: f64,
    /// Length of one pin's row: the modes rounded up to whole blocks.
    row: usize,
    pins: usize,
    /// Per mode (padded to `row`): ωᵢ², 2ξᵢωᵢ, and for central difference 1/(1 + ξᵢωᵢΔt).
    omega_squared: Vec<f64>,
    damping: Vec<f64>,
    implicit_damping_factor: Vec<f64>,
    /// Γᵢ, padded to `row`.
    participation: Vec<f64>,
    /// The dashpots see ṽ = v + `dashpot_lookahead` · a right after the first half of
    /// the update: ½Δt for central difference (ṽ = v½ + ½Δt aₙ), 0 for Tchamwa.
    dashpot_lookahead: f64,
    /// ψ at each distinct contact height (`levels × row`), and by blocks of levels for
    /// [`level_deflections`].
    level_shapes: Vec<f64>,
    grouped_level_shapes: LevelShapes,
    /// Per contact: level, left and right pin (WALL for a wall).
    contact_level: Vec<usize>,
    contact_left: Vec<usize>,
    contact_right: Vec<usize>,
    /// The contacts cut in runs of consecutive slots of `level_deflections`.
    runs: Vec<Run>,
    gaps: Vec<f64>,
    /// Per contact: penetration now, a step ago (the two buffers swap every step) and
    /// largest so far.
    penetration: Vec<f64>,
    previous_penetration: Vec<f64>,
    max_penetration: Vec<f64>,
    /// Scratch: the contacts closed now (the only ones that need more than a penetration).
    closed: Vec<u32>,
    /// Base acceleration at the current step (m/s²).
    base_now: f64,
    /// w of every pin at every level (`levels × (pins + 2)`, level by level with a zero
    /// slot for a wall on each side: `[wall, pin 0, …, pin n−1, wall]`).
    level_deflections: Vec<f64>,
    /// ψ at each point force's and each output height (padded to `row`).
    point_force_shapes: Vec<Vec<f64>>,
    output_shapes: Vec<Vec<f64>>,
    /// Nodal deflection of each mode, for pin extremes, and the nodal deflections of
    /// every pin at the last sample (laid out as `level_deflections`).
    node_shapes: LevelShapes,
    node_deflections: Vec<f64>,
    /// Pin-major state (`pins × row`): coordinates, velocities, accelerations, loads.
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    force: Vec<f64>,
    contact_force: Vec<f64>,
    statistics: Vec<ContactStatistics>,
    energy: EnergyBalance,
    previous_power: Powers,
    /// Created energy allowed per joule involved before declaring divergence.
    divergence_allowance: f64,
    /// Largest |net external work| so far (J).
    external_work_peak: f64,
    time: Vec<f64>,
    deflections: Vec<Vec<Vec<f64>>>,
    contact_forces: Vec<Vec<f64>>,
    mechanical_energy: Vec<f64>,
    pin_extremes: Vec<PinExtreme>,
}

/// What [`StepOp`] does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Operation {
    /// The forces at t = 0.
    Initial,
    /// One step.
    Step,
    /// The deflection of every pin at every node, into `node_deflections`.
    NodeDeflections,
}

/// An operation on the state as a [`pulp::WithSimd`] operation: everything it inlines
/// is compiled with the target features [`pulp::Arch`] detected at run time.
struct StepOp<'a, 'm> {
    integrator: &'a mut Integrator<'m>,
    t: f64,
    operation: Operation,
}

impl pulp::WithSimd for StepOp<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let integrator = self.integrator;
        match self.operation {
            Operation::Initial => {
                integrator.contact_forces_and_statistics(simd, self.t, false);
            }
            Operation::Step => integrator.step_body(simd, self.t),
            Operation::NodeDeflections => level_deflections(
                simd,
                &integrator.node_shapes,
                integrator.row,
                &integrator.q,
                &mut integrator.node_deflections,
            ),
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
        kernels::modal_energy(simd, self.stiffness, self.q, self.v)
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Powers {
    modal_damping: f64,
    contact_damping: f64,
    external: f64,
}

/// `values` followed by zeros up to `row`.
fn padded(values: &[f64], row: usize, fill: f64) -> Vec<f64> {
    let mut out = values.to_vec();
    out.resize(row, fill);
    out
}

impl<'m> Integrator<'m> {
    pub(super) fn new(model: &'m Model<'m>, settings: &Settings, dt: f64, critical: f64) -> Self {
        let basis = model.basis;
        let (pins, modes) = (model.pins, basis.modes());
        let row = modes.div_ceil(BLOCK) * BLOCK;
        let omega = basis.angular_frequencies();
        let damping: Vec<f64> = omega
            .iter()
            .zip(&model.damping_ratios)
            .map(|(w, xi)| 2.0 * xi * w)
            .collect();

        let mut heights: Vec<f64> = Vec::new();
        let contact_level: Vec<usize> = model
            .contacts
            .iter()
            .map(|c| match heights.iter().position(|h| *h == c.height) {
                Some(level) => level,
                None => {
                    heights.push(c.height);
                    heights.len() - 1
                }
            })
            .collect();
        let pin_index = |body: Body| match body {
            Body::Wall => WALL,
            Body::Pin(p) => p,
        };
        let shape_at = |height: f64| padded(&basis.deflection_at(height), row, 0.0);
        let nodes = basis.model().elements + 1;
        let mut q = vec![0.0; pins * row];
        if let Some(unit) = basis.unit_tip_release() {
            for (coordinates, tip) in q.chunks_exact_mut(row).zip(&model.initial_tip_displacements) {
                for (x, u) in coordinates.iter_mut().zip(unit.iter()) {
                    *x = tip * u;
                }
            }
        }
        let contacts = model.contacts.len();
        assert!(
            u32::try_from(contacts).is_ok(),
            "contact indices are stored as u32"
        );
        let contact_left: Vec<usize> = model.contacts.iter().map(|c| pin_index(c.left)).collect();
        let contact_right: Vec<usize> = model.contacts.iter().map(|c| pin_index(c.right)).collect();
        let levels = heights.len().div_ceil(BLOCK) * BLOCK;
        // A wall on the left reads the zero slot before the first pin, on the right the one
        // after the last, so a row between two walls is one run per level.
        let stride = pins + 2;
        let slot =
            |level: usize, pin: usize, wall: usize| level * stride + if pin == WALL { wall } else { 1 + pin };
        let runs = Run::split((0..contacts).map(|c| {
            (
                slot(contact_level[c], contact_left[c], 0),
                slot(contact_level[c], contact_right[c], pins + 1),
            )
        }));
        let level_shapes: Vec<f64> = heights.iter().flat_map(|h| shape_at(*h)).collect();
        let grouped_level_shapes = LevelShapes::new(&level_shapes, row);
        let node_shapes = LevelShapes::new(
            &(0..nodes)
                .flat_map(|n| (0..row).map(move |i| if i < modes { basis.shape(i)[2 * n] } else { 0.0 }))
                .collect::<Vec<_>>(),
            row,
        );
        let node_levels = node_shapes.levels;
        let r2 = (dt / critical).powi(2);
        let mut integrator = Self {
            arch: pulp::Arch::new(),
            model,
            scheme: settings.scheme,
            dt,
            row,
            pins,
            omega_squared: padded(&omega.iter().map(|w| w * w).collect::<Vec<_>>(), row, 0.0),
            implicit_damping_factor: padded(
                &damping
                    .iter()
                    .map(|c| match settings.scheme {
                        Scheme::CentralDifference => 1.0 / (1.0 + 0.5 * c * dt),
                        Scheme::Tchamwa { .. } => 1.0,
                    })
                    .collect::<Vec<_>>(),
                row,
                1.0,
            ),
            damping: padded(&damping, row, 0.0),
            participation: padded(basis.participation(), row, 0.0),
            dashpot_lookahead: match settings.scheme {
                Scheme::CentralDifference => 0.5 * dt,
                Scheme::Tchamwa { .. } => 0.0,
            },
            level_shapes,
            grouped_level_shapes,
            contact_level,
            contact_left,
            contact_right,
            runs,
            gaps: model.contacts.iter().map(|c| c.gap).collect(),
            penetration: vec![0.0; contacts],
            previous_penetration: vec![0.0; contacts],
            max_penetration: vec![f64::NEG_INFINITY; contacts],
            closed: vec![0; contacts],
            base_now: 0.0,
            level_deflections: vec![0.0; levels * stride],
            point_force_shapes: model.point_forces.iter().map(|f| shape_at(f.height)).collect(),
            output_shapes: settings.output_heights.iter().map(|h| shape_at(*h)).collect(),
            node_shapes,
            node_deflections: vec![0.0; node_levels * stride],
            q,
            v: vec![0.0; pins * row],
            a: vec![0.0; pins * row],
            force: vec![0.0; pins * row],
            contact_force: vec![0.0; contacts],
            statistics: vec![ContactStatistics::default(); contacts],
            energy: EnergyBalance::default(),
            previous_power: Powers::default(),
            divergence_allowance: if r2 < 1.0 { 2.0 / (1.0 - r2) } else { 1.0 },
            external_work_peak: 0.0,
            time: Vec::new(),
            deflections: vec![vec![Vec::new(); pins]; settings.output_heights.len()],
            contact_forces: vec![Vec::new(); contacts],
            mechanical_energy: Vec::new(),
            pin_extremes: vec![PinExtreme::default(); pins],
        };
        // The state at t = 0: contacts already closed count as impacts at t = 0; a₀ from
        // equilibrium (velocities are zero).
        let arch = integrator.arch;
        arch.dispatch(StepOp {
            integrator: &mut integrator,
            t: 0.0,
            operation: Operation::Initial,
        });
        for (c, contact) in model.contacts.iter().enumerate() {
            let stats = &mut integrator.statistics[c];
            if integrator.penetration[c] > 0.0 && (contact.stiffness > 0.0 || contact.damping > 0.0) {
                stats.impacts = 1;
                stats.first_impact_time = Some(0.0);
            }
        }
        for ((a, f), q) in integrator
            .a
            .chunks_exact_mut(row)
            .zip(integrator.force.chunks_exact(row))
            .zip(integrator.q.chunks_exact(row))
        {
            for k in 0..row {
                a[k] = f[k] - integrator.omega_squared[k] * q[k];
            }
        }
        integrator.energy.initial = integrator.mechanical_energy_now();
        integrator
    }

    /// External loads at time t into `force`; keeps the base acceleration a(t) in
    /// `base_now` for the power of the step.
    #[inline(always)]
    fn external_forces<S: Simd>(&mut self, simd: S, t: f64) {
        let row = self.row;
        let base = self.model.base_acceleration.as_ref().map_or(0.0, |b| b.at(t));
        self.base_now = base;
        for loads in self.force.chunks_exact_mut(row) {
            scale_into(simd, -base, &self.participation, loads);
        }
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let value = point.force.at(t);
            axpy(simd, value, shape, &mut self.force[point.pin * row..][..row]);
        }
    }

    /// Loads at time t (`force`), contact forces from the current positions and the
    /// dashpot velocity v + lookahead · a; updates the per-step statistics when
    /// `record` and returns the contact dissipation power Σ (F − Kc δ) δ̇.
    #[inline(always)]
    fn contact_forces_and_statistics<S: Simd>(&mut self, simd: S, t: f64, record: bool) -> f64 {
        self.external_forces(simd, t);
        let (row, dt) = (self.row, self.dt);
        level_deflections(
            simd,
            &self.grouped_level_shapes,
            row,
            &self.q,
            &mut self.level_deflections,
        );
        // Every contact, in vectors: penetration, its running maximum, a zero force
        // where open, and the list of closed contacts (about one in seven).
        std::mem::swap(&mut self.penetration, &mut self.previous_penetration);
        let count = penetrations(
            simd,
            &self.runs,
            &self.level_deflections,
            &self.gaps,
            ContactState {
                now: &mut self.penetration,
                max: &mut self.max_penetration,
                force: &mut self.contact_force,
                closed: &mut self.closed,
            },
        );

        let mut dissipation_power = 0.0;
        let lookahead = self.dashpot_lookahead;
        let (v, a) = (self.v.as_slice(), self.a.as_slice());
        let loads = self.force.as_mut_slice();
        for &closed in &self.closed[..count] {
            let c = closed as usize;
            let (penetration, previous) = (self.penetration[c], self.previous_penetration[c]);
            let contact = &self.model.contacts[c];
            let (left, right) = (self.contact_left[c], self.contact_right[c]);
            let shape = &self.level_shapes[self.contact_level[c] * row..][..row];
            // A plain `if` rather than a closure: closures are compiled apart from the
            // SIMD context of the step unless inlined.
            let mut rate = 0.0;
            if contact.damping > 0.0 {
                if left != WALL {
                    let rows = left * row..(left + 1) * row;
                    rate += dot_ahead(simd, shape, &v[rows.clone()], &a[rows], lookahead);
                }
                if right != WALL {
                    let rows = right * row..(right + 1) * row;
                    rate -= dot_ahead(simd, shape, &v[rows.clone()], &a[rows], lookahead);
                }
            }
            let force = contact.force(penetration, rate);
            self.contact_force[c] = force;
            dissipation_power += (force - contact.stiffness * penetration) * rate;
            if record && (contact.stiffness > 0.0 || contact.damping > 0.0) {
                let stats = &mut self.statistics[c];
                if previous <= 0.0 {
                    stats.impacts += 1;
                    if stats.first_impact_time.is_none() {
                        stats.first_impact_time = Some(t - dt * penetration / (penetration - previous));
                    }
                }
                stats.contact_time += dt;
                stats.impulse += force * dt;
                if force > stats.max_force {
                    stats.max_force = force;
                    stats.max_force_time = t;
                }
            }
            if force != 0.0 {
                for (pin, sign) in [(left, -force), (right, force)] {
                    if pin != WALL {
                        axpy(simd, sign, shape, &mut loads[pin * row..][..row]);
                    }
                }
            }
        }
        dissipation_power
    }

    /// Advances from t − Δt to t, compiled for the best SIMD level of this CPU.
    pub(super) fn step(&mut self, t: f64) {
        let arch = self.arch;
        arch.dispatch(StepOp {
            integrator: self,
            t,
            operation: Operation::Step,
        });
    }

    #[inline(always)]
    fn step_body<S: Simd>(&mut self, simd: S, t: f64) {
        let dt = self.dt;
        let half = 0.5 * dt;
        // v ← v½, q ← qₙ₊₁ (central difference); q ← qₙ₊₁, v ← vₙ₊₁ (Tchamwa).
        let first_half = match self.scheme {
            Scheme::CentralDifference => (dt, half, 0.0),
            Scheme::Tchamwa { phi } => (dt, dt, phi * dt * dt),
        };
        advance_positions(simd, first_half, &mut self.q, &mut self.v, &self.a);
        let contact_damping = self.contact_forces_and_statistics(simd, t, true);
        let base = self.base_now;
        let second_half = match self.scheme {
            Scheme::CentralDifference => half,
            Scheme::Tchamwa { .. } => 0.0,
        };
        let sums = modal_update(
            simd,
            &ModalCoefficients {
                stiffness: &self.omega_squared,
                damping: &self.damping,
                factor: &self.implicit_damping_factor,
                participation: &self.participation,
            },
            second_half,
            (&self.q, &mut self.v, &mut self.a, &self.force),
        );
        let modal_damping = sums.damping_power;
        let mut external = -base * sums.participation_velocity;
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let velocity = kernels::dot(simd, shape, &self.v[point.pin * self.row..][..self.row]);
            external += point.force.at(t) * velocity;
        }
        let powers = Powers {
            modal_damping,
            contact_damping,
            external,
        };
        self.energy.dissipated_modal += half * (self.previous_power.modal_damping + powers.modal_damping);
        self.energy.dissipated_contact +=
            half * (self.previous_power.contact_damping + powers.contact_damping);
        self.energy.external_work += half * (self.previous_power.external + powers.external);
        self.external_work_peak = self.external_work_peak.max(self.energy.external_work.abs());
        self.previous_power = powers;
    }

    fn mechanical_energy_now(&self) -> f64 {
        let modal = self.arch.dispatch(ModalEnergyOp {
            stiffness: &self.omega_squared,
            q: &self.q,
            v: &self.v,
        });
        modal + self.contact_energy_now()
    }

    fn contact_energy_now(&self) -> f64 {
        self.model
            .contacts
            .iter()
            .zip(&self.penetration)
            .filter(|(_, d)| **d > 0.0)
            .map(|(c, d)| 0.5 * c.stiffness * d * d)
            .sum()
    }

    /// An unstable scheme creates energy: mechanical + dissipated − work − initial grows
    /// like the unstable mode. A stable explicit scheme conserves a shadow energy instead
    /// of the plain one; the plain energy of a mode with ωΔt = r × limit exceeds it by
    /// at most a factor 1/(1 − r²), so the alarm rings when the created energy exceeds
    /// 2/(1 − r²) times the energy involved (r = Δt / critical step). Non-finite too.
    pub(super) fn check_divergence(&self, t: f64) -> Result<(), SimulationError> {
        let mechanical = self.mechanical_energy_now();
        if !mechanical.is_finite() || self.q.iter().any(|x| !x.is_finite()) {
            return Err(SimulationError::Diverged {
                time: t,
                detail: "non-finite state".into(),
            });
        }
        let dissipated = self.energy.dissipated_modal + self.energy.dissipated_contact;
        let created = mechanical + dissipated - self.energy.external_work - self.energy.initial;
        let scale = self.energy.initial + self.external_work_peak + dissipated;
        if created > self.divergence_allowance * scale + f64::MIN_POSITIVE {
            return Err(SimulationError::Diverged {
                time: t,
                detail: format!("the scheme created {created:e} J of energy from {scale:e} J supplied"),
            });
        }
        Ok(())
    }

    pub(super) fn record_sample(&mut self, t: f64) {
        let row = self.row;
        self.time.push(t);
        for (shape, per_pin) in self.output_shapes.iter().zip(&mut self.deflections) {
            for (coordinates, history) in self.q.chunks_exact(row).zip(per_pin.iter_mut()) {
                history.push(dot(shape, coordinates));
            }
        }
        for (c, force) in self.contact_force.iter().enumerate() {
            self.contact_forces[c].push(*force);
        }
        self.mechanical_energy.push(self.mechanical_energy_now());
        let element_length = self.model.basis.model().element_length;
        let arch = self.arch;
        arch.dispatch(StepOp {
            integrator: self,
            t,
            operation: Operation::NodeDeflections,
        });
        let nodes = self.model.basis.model().elements + 1;
        for (node, deflections) in self
            .node_deflections
            .chunks_exact(self.pins + 2)
            .take(nodes)
            .enumerate()
        {
            for (w, extreme) in deflections[1..].iter().zip(self.pin_extremes.iter_mut()) {
                if w.abs() > extreme.max_abs_deflection {
                    *extreme = PinExtreme {
                        max_abs_deflection: w.abs(),
                        height: node as f64 * element_length,
                        time: t,
                    };
                }
            }
        }
    }

    pub(super) fn finish(mut self, dt: f64, critical: f64, steps: u64) -> Simulation {
        self.energy.kinetic = 0.5 * self.v.iter().map(|v| v * v).sum::<f64>();
        self.energy.contact = self.contact_energy_now();
        self.energy.strain = self.mechanical_energy_now() - self.energy.kinetic - self.energy.contact;
        for (stats, max) in self.statistics.iter_mut().zip(&self.max_penetration) {
            stats.max_penetration = *max;
        }
        Simulation {
            time_step: dt,
            critical_time_step: critical,
            steps,
            time: self.time,
            deflections: self.deflections,
            contact_forces: self.contact_forces,
            contact_statistics: self.statistics,
            pin_extremes: self.pin_extremes,
            energy: self.energy,
            mechanical_energy: self.mechanical_energy,
        }
    }
}
