//! State and step of one run: the hot loop.
//!
//! Where the time goes (row17: 17 pins × 20 modes, 10 levels, 180 contacts, about 9 %
//! of them closed at a time): the dense sweep w = Ψ q over every contact level
//! (levels × modes × pins multiply-adds, in blocks of 4 pins held in registers), the
//! contact loop over every contact (penetration, and for the closed ones the dashpot
//! velocity ψ·ṽ, the statistics and the force projected back on 2 × modes
//! coordinates), and the modal update, which also accumulates the dissipated and
//! external powers. Pins are padded to a multiple of [`LANES`] so every sweep is whole
//! blocks; padded lanes stay 0. The step is dispatched through `pulp` so that it is
//! compiled for the SIMD level of the running CPU (AVX2 on x86-64-v3) without unsafe.

use super::{ContactStatistics, EnergyBalance, Model, PinExtreme, Settings, Simulation, SimulationError};
use crate::physics::contact::Body;
use crate::physics::stability::Scheme;

/// Pins per block of the dense sweeps.
const LANES: usize = 4;

/// Sentinel pin index of a wall (for force projection; reads use the zero lane).
const WALL: usize = usize::MAX;

pub(super) struct Integrator<'m> {
    arch: pulp::Arch,
    model: &'m Model<'m>,
    scheme: Scheme,
    dt: f64,
    pins: usize,
    /// Row length of every mode-major array: pins rounded up to whole blocks.
    stride: usize,
    modes: usize,
    omega_squared: Vec<f64>,
    /// 2ξᵢωᵢ.
    damping: Vec<f64>,
    /// Central difference: 1/(1 + ξᵢωᵢΔt).
    implicit_damping_factor: Vec<f64>,
    participation: Vec<f64>,
    /// ψ at each distinct contact height (`levels × modes`).
    level_shapes: Vec<f64>,
    /// Per contact: level, left and right pin (WALL for a wall).
    contact_level: Vec<usize>,
    contact_left: Vec<usize>,
    contact_right: Vec<usize>,
    /// Per contact: index into `level_deflections` of its left and right side (a wall
    /// reads the always-zero padded lane `pins` of its level).
    left_slot: Vec<usize>,
    right_slot: Vec<usize>,
    gaps: Vec<f64>,
    /// Per contact: penetration at the previous step and largest penetration so far.
    previous_penetration: Vec<f64>,
    max_penetration: Vec<f64>,
    /// Base acceleration at the current step (m/s²).
    base_now: f64,
    /// w at every level for every pin (`levels × stride`).
    level_deflections: Vec<f64>,
    point_force_shapes: Vec<Vec<f64>>,
    output_shapes: Vec<Vec<f64>>,
    /// Nodal deflection of each mode (`nodes × modes`), for pin extremes.
    node_shapes: Vec<f64>,
    /// Mode-major state (`modes × stride`).
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    force: Vec<f64>,
    /// Velocity the dashpots see this step.
    predicted_velocity: Vec<f64>,
    penetration: Vec<f64>,
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

/// One step as a [`pulp::WithSimd`] operation: everything it inlines is compiled with
/// the target features [`pulp::Arch`] detected at run time.
struct StepOp<'a, 'm> {
    integrator: &'a mut Integrator<'m>,
    t: f64,
}

impl pulp::WithSimd for StepOp<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        self.integrator.step_body(self.t);
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Powers {
    modal_damping: f64,
    contact_damping: f64,
    external: f64,
}

/// out[l][p] = Σᵢ shapes[l][i] · coordinates[i][p], in blocks of [`LANES`] pins.
#[inline(always)]
fn sweep(shapes: &[f64], modes: usize, coordinates: &[f64], stride: usize, out: &mut [f64]) {
    for (psi, out_row) in shapes.chunks_exact(modes).zip(out.chunks_exact_mut(stride)) {
        for (block, out_block) in out_row.chunks_exact_mut(LANES).enumerate() {
            let mut acc = [0.0; LANES];
            for (s, row) in psi.iter().zip(coordinates.chunks_exact(stride)) {
                let values: &[f64; LANES] = row[block * LANES..(block + 1) * LANES]
                    .try_into()
                    .expect("whole block");
                for lane in 0..LANES {
                    acc[lane] += s * values[lane];
                }
            }
            out_block.copy_from_slice(&acc);
        }
    }
}

/// Σᵢ shape[i] · values[i·stride + offset] with four partial sums (one running sum
/// chains every addition's latency and defeats vectorization).
#[inline(always)]
fn strided_dot(shape: &[f64], values: &[f64], stride: usize, offset: usize) -> f64 {
    let mut acc = [0.0; 4];
    let mut blocks = shape.chunks_exact(4);
    let mut row = offset;
    for block in &mut blocks {
        for (partial, s) in acc.iter_mut().zip(block) {
            *partial += s * values[row];
            row += stride;
        }
    }
    for (partial, s) in acc.iter_mut().zip(blocks.remainder()) {
        *partial += s * values[row];
        row += stride;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

impl<'m> Integrator<'m> {
    pub(super) fn new(model: &'m Model<'m>, settings: &Settings, dt: f64, critical: f64) -> Self {
        let basis = model.basis;
        let (pins, modes) = (model.pins, basis.modes());
        // At least one padded lane: walls read their (zero) deflection there.
        let stride = (pins + 1).div_ceil(LANES) * LANES;
        let omega = basis.angular_frequencies();
        let damping: Vec<f64> = omega
            .iter()
            .zip(&model.damping_ratios)
            .map(|(w, xi)| 2.0 * xi * w)
            .collect();

        let mut heights: Vec<f64> = Vec::new();
        let contact_level = model
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
        let nodes = basis.model().elements + 1;
        let mut q = vec![0.0; modes * stride];
        if let Some(unit) = basis.unit_tip_release() {
            for (p, tip) in model.initial_tip_displacements.iter().enumerate().take(pins) {
                for i in 0..modes {
                    q[i * stride + p] = tip * unit[i];
                }
            }
        }
        let contacts = model.contacts.len();
        let r2 = (dt / critical).powi(2);
        let mut integrator = Self {
            arch: pulp::Arch::new(),
            model,
            scheme: settings.scheme,
            dt,
            pins,
            stride,
            modes,
            omega_squared: omega.iter().map(|w| w * w).collect(),
            implicit_damping_factor: damping.iter().map(|c| 1.0 / (1.0 + 0.5 * c * dt)).collect(),
            damping,
            participation: basis.participation().to_vec(),
            level_shapes: heights.iter().flat_map(|h| basis.deflection_at(*h)).collect(),
            contact_level,
            contact_left: model.contacts.iter().map(|c| pin_index(c.left)).collect(),
            contact_right: model.contacts.iter().map(|c| pin_index(c.right)).collect(),
            left_slot: Vec::new(),
            right_slot: Vec::new(),
            gaps: model.contacts.iter().map(|c| c.gap).collect(),
            previous_penetration: vec![0.0; contacts],
            max_penetration: vec![f64::NEG_INFINITY; contacts],
            base_now: 0.0,
            level_deflections: vec![0.0; heights.len() * stride],
            point_force_shapes: model
                .point_forces
                .iter()
                .map(|f| basis.deflection_at(f.height))
                .collect(),
            output_shapes: settings
                .output_heights
                .iter()
                .map(|h| basis.deflection_at(*h))
                .collect(),
            node_shapes: (0..nodes)
                .flat_map(|n| (0..modes).map(move |i| basis.shape(i)[2 * n]))
                .collect(),
            q,
            v: vec![0.0; modes * stride],
            a: vec![0.0; modes * stride],
            force: vec![0.0; modes * stride],
            predicted_velocity: vec![0.0; modes * stride],
            penetration: vec![0.0; contacts],
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
        let slot = |c: usize, pin: usize| {
            integrator.contact_level[c] * stride + if pin == WALL { pins } else { pin }
        };
        integrator.left_slot = (0..contacts)
            .map(|c| slot(c, integrator.contact_left[c]))
            .collect();
        integrator.right_slot = (0..contacts)
            .map(|c| slot(c, integrator.contact_right[c]))
            .collect();
        // The state at t = 0: contacts already closed count as impacts at t = 0; a₀ from
        // equilibrium (velocities are zero).
        integrator.contact_forces_and_statistics(0.0, false);
        for (c, contact) in model.contacts.iter().enumerate() {
            let stats = &mut integrator.statistics[c];
            if integrator.penetration[c] > 0.0 && (contact.stiffness > 0.0 || contact.damping > 0.0) {
                stats.impacts = 1;
                stats.first_impact_time = Some(0.0);
            }
        }
        for i in 0..modes {
            for k in i * stride..(i + 1) * stride {
                integrator.a[k] = integrator.force[k] - integrator.omega_squared[i] * integrator.q[k];
            }
        }
        integrator.energy.initial = integrator.mechanical_energy_now();
        integrator
    }

    /// External loads at time t into `force`; keeps the base acceleration a(t) in
    /// `base_now` for the power of the step.
    #[inline(always)]
    fn external_forces(&mut self, t: f64) {
        let (pins, stride) = (self.pins, self.stride);
        let base = self.model.base_acceleration.as_ref().map_or(0.0, |b| b.at(t));
        self.base_now = base;
        for (row, gamma) in self.force.chunks_exact_mut(stride).zip(&self.participation) {
            row[..pins].fill(-gamma * base);
        }
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let value = point.force.at(t);
            for (row, s) in self.force.chunks_exact_mut(stride).zip(shape) {
                row[point.pin] += value * s;
            }
        }
    }

    /// Loads at time t (`force`), contact forces from the current positions and the
    /// dashpot velocity `predicted_velocity`; updates the per-step statistics when
    /// `record` and returns the contact dissipation power Σ (F − Kc δ) δ̇.
    #[inline(always)]
    fn contact_forces_and_statistics(&mut self, t: f64, record: bool) -> f64 {
        self.external_forces(t);
        let (stride, modes, dt) = (self.stride, self.modes, self.dt);
        sweep(
            &self.level_shapes,
            modes,
            &self.q,
            stride,
            &mut self.level_deflections,
        );
        // Pass 1, every contact, branch-free: penetration and its running maximum.
        for c in 0..self.gaps.len() {
            let penetration = self.level_deflections[self.left_slot[c]]
                - self.level_deflections[self.right_slot[c]]
                - self.gaps[c];
            self.previous_penetration[c] = self.penetration[c];
            self.penetration[c] = penetration;
            self.max_penetration[c] = self.max_penetration[c].max(penetration);
        }
        // Pass 2, only contacts closed now or a step ago (a few percent of them).
        let mut dissipation_power = 0.0;
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let (penetration, previous) = (self.penetration[c], self.previous_penetration[c]);
            if penetration <= 0.0 {
                if previous > 0.0 {
                    self.contact_force[c] = 0.0;
                }
                continue;
            }
            let (left, right) = (self.contact_left[c], self.contact_right[c]);
            let shape = &self.level_shapes[self.contact_level[c] * modes..][..modes];
            // Few contacts are closed at a time: their δ̇ = ψ·(ṽ_L − ṽ_R) costs less one by
            // one than a dense sweep of velocities over every level.
            let rate = if contact.damping > 0.0 {
                let velocity = |pin: usize| -> f64 {
                    if pin == WALL {
                        return 0.0;
                    }
                    strided_dot(shape, &self.predicted_velocity, stride, pin)
                };
                velocity(left) - velocity(right)
            } else {
                0.0
            };
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
                // Row by row on a hoisted slice: indexing `self.force` per mode reloads the
                // vector through `self` at every store.
                let loads = self.force.as_mut_slice();
                for (pin, sign) in [(left, -force), (right, force)] {
                    if pin != WALL {
                        for (row, s) in loads.chunks_exact_mut(stride).zip(shape) {
                            row[pin] += sign * s;
                        }
                    }
                }
            }
        }
        dissipation_power
    }

    /// Advances from t − Δt to t, compiled for the best SIMD level of this CPU.
    pub(super) fn step(&mut self, t: f64) {
        let arch = self.arch;
        arch.dispatch(StepOp { integrator: self, t });
    }

    #[inline(always)]
    fn step_body(&mut self, t: f64) {
        let dt = self.dt;
        let half = 0.5 * dt;
        match self.scheme {
            Scheme::CentralDifference => {
                // v ← v½, q ← qₙ₊₁; the dashpots see ṽ = v½ + ½Δt aₙ.
                for ((q, v), (a, predicted)) in self
                    .q
                    .iter_mut()
                    .zip(self.v.iter_mut())
                    .zip(self.a.iter().zip(self.predicted_velocity.iter_mut()))
                {
                    *v += half * a;
                    *q += dt * *v;
                    *predicted = *v + half * a;
                }
            }
            Scheme::Tchamwa { phi } => {
                let curvature = phi * dt * dt;
                for ((q, v), (a, predicted)) in self
                    .q
                    .iter_mut()
                    .zip(self.v.iter_mut())
                    .zip(self.a.iter().zip(self.predicted_velocity.iter_mut()))
                {
                    *q += dt * *v + curvature * a;
                    *v += dt * a;
                    *predicted = *v;
                }
            }
        }
        let contact_damping = self.contact_forces_and_statistics(t, true);
        let base = self.base_now;
        let stride = self.stride;
        let mut modal_damping = 0.0;
        let mut base_power = 0.0;
        for i in 0..self.modes {
            let (stiffness, damping) = (self.omega_squared[i], self.damping[i]);
            let rows = i * stride..(i + 1) * stride;
            let (q, v, a, f) = (
                &self.q[rows.clone()],
                &mut self.v[rows.clone()],
                &mut self.a[rows.clone()],
                &self.force[rows],
            );
            match self.scheme {
                Scheme::CentralDifference => {
                    let factor = self.implicit_damping_factor[i];
                    for (((a, v), q), f) in a.iter_mut().zip(v.iter_mut()).zip(q).zip(f) {
                        *a = (f - stiffness * q - damping * *v) * factor;
                        *v += half * *a;
                    }
                }
                Scheme::Tchamwa { .. } => {
                    for (((a, v), q), f) in a.iter_mut().zip(v.iter()).zip(q).zip(f) {
                        *a = f - stiffness * q - damping * v;
                    }
                }
            }
            // Power sums in a separate pass with one accumulator per lane: a running
            // scalar sum inside the update would keep it from vectorizing.
            let (mut lanes_v, mut lanes_v2) = ([0.0; LANES], [0.0; LANES]);
            for block in v.chunks_exact(LANES) {
                for lane in 0..LANES {
                    lanes_v[lane] += block[lane];
                    lanes_v2[lane] += block[lane] * block[lane];
                }
            }
            let sum_v: f64 = lanes_v.iter().sum();
            let sum_v2: f64 = lanes_v2.iter().sum();
            modal_damping += damping * sum_v2;
            base_power -= self.participation[i] * base * sum_v;
        }
        let mut external = base_power;
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let velocity: f64 = shape
                .iter()
                .enumerate()
                .map(|(i, s)| s * self.v[i * stride + point.pin])
                .sum();
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
        let stride = self.stride;
        let mut energy = 0.0;
        for i in 0..self.modes {
            for k in i * stride..(i + 1) * stride {
                energy += 0.5 * (self.v[k] * self.v[k] + self.omega_squared[i] * self.q[k] * self.q[k]);
            }
        }
        energy + self.contact_energy_now()
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
        let (pins, modes, stride) = (self.pins, self.modes, self.stride);
        self.time.push(t);
        for (h, shape) in self.output_shapes.iter().enumerate() {
            for p in 0..pins {
                let w = (0..modes).map(|i| shape[i] * self.q[i * stride + p]).sum();
                self.deflections[h][p].push(w);
            }
        }
        for (c, force) in self.contact_force.iter().enumerate() {
            self.contact_forces[c].push(*force);
        }
        self.mechanical_energy.push(self.mechanical_energy_now());
        let element_length = self.model.basis.model().element_length;
        for (node, shape) in self.node_shapes.chunks_exact(modes).enumerate() {
            for p in 0..pins {
                let w: f64 = (0..modes).map(|i| shape[i] * self.q[i * stride + p]).sum();
                let extreme = &mut self.pin_extremes[p];
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
