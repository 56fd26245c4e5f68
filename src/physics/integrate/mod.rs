//! Explicit time integration of a row of identical pins on their shared modal basis,
//! with penalty point contacts, base excitation and point forces.
//!
//! Modal equations per pin p: q̈ᵢ + 2ξᵢωᵢ q̇ᵢ + ωᵢ² qᵢ = ψᵢ(z)·(contact and point forces)
//! − Γᵢ a(t). Coordinates are stored mode-major (`q[i * pins + p]`) so that the
//! deflection at every contact level, w = Ψ q, is a sweep of contiguous rows.
//!
//! **Velocity-dependent forces.** Central difference (velocity form):
//! v½ = vₙ + ½Δt aₙ, qₙ₊₁ = qₙ + Δt v½, vₙ₊₁ = v½ + ½Δt aₙ₊₁. Modal damping is diagonal,
//! so it is taken at vₙ₊₁ exactly: aₙ₊₁ = (f − ω²qₙ₊₁ − 2ξω v½)/(1 + ξωΔt), still explicit
//! and second order. Contact dashpots couple modes; they use the predicted velocity
//! ṽₙ₊₁ = vₙ + Δt aₙ (error O(Δt²), which keeps the scheme second order).
//! Tchamwa–Wielgosz: qₙ₊₁ = qₙ + Δt vₙ + φΔt² aₙ, vₙ₊₁ = vₙ + Δt aₙ, and all
//! velocity-dependent forces use that vₙ₊₁, which is exact for the scheme.
//!
//! A step above the critical one ([`super::stability`]) is refused before running. A run
//! whose mechanical energy exceeds what the initial energy and the external work can
//! supply (or stops being finite) is stopped at once with [`SimulationError::Diverged`]:
//! no NaN ever leaves this module.

use std::ops::ControlFlow;

use super::contact::{Body, Contact};
use super::loads::{BaseAcceleration, PointForce};
use super::modal::ModalBasis;
use super::stability::{Scheme, max_angular_frequency};
pub use super::statistics::{ContactStatistics, EnergyBalance, PinExtreme};

/// Fraction of the critical step used by `time_step: auto`.
pub const AUTO_SAFETY_FACTOR: f64 = 0.8;
/// Steps between two calls of the progress callback.
const PROGRESS_EVERY: u64 = 4096;
/// Steps between two divergence checks.
const DIVERGENCE_CHECK_EVERY: u64 = 32;

/// The row being integrated.
#[derive(Debug, Clone)]
pub struct Model<'a> {
    /// Modal basis shared by every pin.
    pub basis: &'a ModalBasis,
    /// Number of pins (≥ 1).
    pub pins: usize,
    /// Modal damping ratio ξᵢ of each mode (length = modes).
    pub damping_ratios: Vec<f64>,
    pub contacts: Vec<Contact>,
    /// Release of each pin from its static tip-load shape with this tip deflection (m);
    /// empty means all at rest.
    pub initial_tip_displacements: Vec<f64>,
    pub base_acceleration: Option<BaseAcceleration>,
    pub point_forces: Vec<PointForce>,
}

/// Time step choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// This step (s); refused when above the critical step.
    Fixed(f64),
    /// [`AUTO_SAFETY_FACTOR`] × the critical step.
    Auto,
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub scheme: Scheme,
    pub time_step: TimeStep,
    /// Simulated duration (s).
    pub duration: f64,
    /// Time between two history samples (s), rounded to a whole number of steps;
    /// `None` samples every step. Samples are uniform: t = 0, k·interval, ... ≤ duration.
    pub output_interval: Option<f64>,
    /// Heights (m) where every pin's deflection is recorded.
    pub output_heights: Vec<f64>,
}

/// Why a run produced no result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimulationError {
    #[error(
        "time step {time_step:e} s exceeds the critical time step {critical_time_step:e} s of this model \
         (contact stiffness included); use at most the critical step or \"auto\""
    )]
    TimeStepAboveCritical { time_step: f64, critical_time_step: f64 },
    #[error("the integration diverged at t = {time:e} s ({detail}); reduce the time step")]
    Diverged { time: f64, detail: String },
    #[error("cancelled")]
    Cancelled,
}

/// Everything a run produces.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// Step used (s).
    pub time_step: f64,
    /// Critical step of the scheme with every contact closed (s).
    pub critical_time_step: f64,
    /// Number of steps taken.
    pub steps: u64,
    /// Sample times (s).
    pub time: Vec<f64>,
    /// `deflections[h][p]`: deflection (m) of pin p at output height h, per sample.
    pub deflections: Vec<Vec<Vec<f64>>>,
    /// Contact force (N) of each contact, per sample.
    pub contact_forces: Vec<Vec<f64>>,
    /// Per contact, accumulated at every step.
    pub contact_statistics: Vec<ContactStatistics>,
    /// Per pin.
    pub pin_extremes: Vec<PinExtreme>,
    /// Energy balance at the end of the run.
    pub energy: EnergyBalance,
    /// Mechanical energy (kinetic + strain + contact) per sample (J).
    pub mechanical_energy: Vec<f64>,
}

/// Critical time step (s) of `scheme` for this model, all contacts closed.
pub fn critical_time_step(model: &Model<'_>, scheme: Scheme) -> f64 {
    let shapes: Vec<Vec<f64>> = model
        .contacts
        .iter()
        .map(|c| model.basis.deflection_at(c.height))
        .collect();
    let omega_max = max_angular_frequency(
        model.basis.angular_frequencies(),
        model.pins,
        &model.contacts,
        &shapes,
    );
    scheme.stability_limit() / omega_max
}

/// The step a run will use, or why it cannot run.
pub fn resolve_time_step(model: &Model<'_>, settings: &Settings) -> Result<(f64, f64), SimulationError> {
    let critical = critical_time_step(model, settings.scheme);
    match settings.time_step {
        TimeStep::Auto => Ok((AUTO_SAFETY_FACTOR * critical, critical)),
        TimeStep::Fixed(dt) if dt > critical * (1.0 + 1e-12) => Err(SimulationError::TimeStepAboveCritical {
            time_step: dt,
            critical_time_step: critical,
        }),
        TimeStep::Fixed(dt) => Ok((dt, critical)),
    }
}

/// Integrates the model. `progress` is called every few thousand steps with the
/// fraction done; `ControlFlow::Break` stops the run with [`SimulationError::Cancelled`].
pub fn simulate(
    model: &Model<'_>,
    settings: &Settings,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let (dt, critical) = resolve_time_step(model, settings)?;
    integrate_with_step(model, settings, dt, critical, progress)
}

/// Runs with step `dt` whatever the critical step (tests probe instability with it).
#[cfg(test)]
fn simulate_unchecked(
    model: &Model<'_>,
    settings: &Settings,
    dt: f64,
) -> Result<Simulation, SimulationError> {
    integrate_with_step(model, settings, dt, f64::NAN, &mut |_| ControlFlow::Continue(()))
}

fn integrate_with_step(
    model: &Model<'_>,
    settings: &Settings,
    dt: f64,
    critical: f64,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let mut run = Integrator::new(model, settings, dt, critical);
    // Never past the duration: the last step ends at or (by rounding) just before it.
    let total_steps = ((settings.duration / dt) * (1.0 + 1e-12)).floor().max(1.0) as u64;
    let output_every = settings
        .output_interval
        .map_or(1, |interval| ((interval / dt).round() as u64).max(1));
    run.record_sample(0.0);
    for n in 1..=total_steps {
        let t = n as f64 * dt;
        run.step(t);
        if n % DIVERGENCE_CHECK_EVERY == 0 || n == total_steps {
            run.check_divergence(t)?;
        }
        if n % output_every == 0 {
            run.record_sample(t);
        }
        if n % PROGRESS_EVERY == 0 && progress(n as f64 / total_steps as f64).is_break() {
            return Err(SimulationError::Cancelled);
        }
    }
    Ok(run.finish(dt, critical, total_steps))
}

/// Pre-computed geometry and state of one run.
struct Integrator<'m> {
    model: &'m Model<'m>,
    scheme: Scheme,
    dt: f64,
    pins: usize,
    modes: usize,
    omega_squared: Vec<f64>,
    /// 2ξᵢωᵢ.
    damping: Vec<f64>,
    /// Central difference: 1/(1 + ξᵢωᵢΔt).
    implicit_damping_factor: Vec<f64>,
    /// Distinct contact heights and their ψ (level-major, `levels × modes`).
    level_shapes: Vec<f64>,
    contact_level: Vec<usize>,
    /// Deflection at every level for every pin (`levels × pins`).
    level_deflections: Vec<f64>,
    point_force_shapes: Vec<Vec<f64>>,
    output_shapes: Vec<Vec<f64>>,
    /// Nodal deflection of each mode (`nodes × modes`), for pin extremes.
    node_shapes: Vec<f64>,
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    force: Vec<f64>,
    /// Per contact: penetration at the previous step, force at this step, closed flag.
    previous_penetration: Vec<f64>,
    contact_force: Vec<f64>,
    statistics: Vec<ContactStatistics>,
    energy: EnergyBalance,
    /// Power of dissipation and external loads at the previous step (trapezoidal rule).
    previous_power: Powers,
    /// Created energy allowed per joule involved before declaring divergence.
    divergence_allowance: f64,
    /// Largest |net external work| so far (J).
    external_work_peak: f64,
    // Histories.
    time: Vec<f64>,
    deflections: Vec<Vec<Vec<f64>>>,
    contact_forces: Vec<Vec<f64>>,
    mechanical_energy: Vec<f64>,
    pin_extremes: Vec<PinExtreme>,
}

#[derive(Debug, Clone, Copy, Default)]
struct Powers {
    modal_damping: f64,
    contact_damping: f64,
    external: f64,
}

impl<'m> Integrator<'m> {
    fn new(model: &'m Model<'m>, settings: &Settings, dt: f64, critical: f64) -> Self {
        let basis = model.basis;
        let (pins, modes) = (model.pins, basis.modes());
        let omega = basis.angular_frequencies();
        let omega_squared: Vec<f64> = omega.iter().map(|w| w * w).collect();
        let damping: Vec<f64> = omega
            .iter()
            .zip(&model.damping_ratios)
            .map(|(w, xi)| 2.0 * xi * w)
            .collect();
        let implicit_damping_factor = damping.iter().map(|c| 1.0 / (1.0 + 0.5 * c * dt)).collect();

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
        let level_shapes = heights.iter().flat_map(|h| basis.deflection_at(*h)).collect();
        let nodes = basis.model().elements + 1;
        let node_shapes = (0..nodes)
            .flat_map(|n| (0..modes).map(move |i| basis.shape(i)[2 * n]))
            .collect();

        let mut q = vec![0.0; modes * pins];
        if let Some(unit) = basis.unit_tip_release() {
            for (p, tip) in model.initial_tip_displacements.iter().enumerate().take(pins) {
                for i in 0..modes {
                    q[i * pins + p] = tip * unit[i];
                }
            }
        }
        let contacts = model.contacts.len();
        let mut integrator = Self {
            model,
            scheme: settings.scheme,
            dt,
            pins,
            modes,
            omega_squared,
            damping,
            implicit_damping_factor,
            level_deflections: vec![0.0; heights.len() * pins],
            level_shapes,
            contact_level,
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
            node_shapes,
            q,
            v: vec![0.0; modes * pins],
            a: vec![0.0; modes * pins],
            force: vec![0.0; modes * pins],
            previous_penetration: vec![0.0; contacts],
            contact_force: vec![0.0; contacts],
            statistics: vec![ContactStatistics::default(); contacts],
            energy: EnergyBalance::default(),
            previous_power: Powers::default(),
            divergence_allowance: {
                let r2 = (dt / critical).powi(2);
                if r2 < 1.0 { 2.0 / (1.0 - r2) } else { 1.0 }
            },
            external_work_peak: 0.0,
            time: Vec::new(),
            deflections: vec![vec![Vec::new(); pins]; settings.output_heights.len()],
            contact_forces: vec![Vec::new(); contacts],
            mechanical_energy: Vec::new(),
            pin_extremes: vec![PinExtreme::default(); pins],
        };
        // Equilibrium at t = 0 gives a₀; the contact state at t = 0 seeds the statistics.
        integrator.compute_level_deflections();
        for (c, contact) in model.contacts.iter().enumerate() {
            let penetration = integrator.penetration(c, contact);
            integrator.previous_penetration[c] = penetration;
            let stats = &mut integrator.statistics[c];
            stats.max_penetration = penetration;
            // Released already pressed together: the first impact is at t = 0.
            if penetration > 0.0 && (contact.stiffness > 0.0 || contact.damping > 0.0) {
                stats.impacts = 1;
                stats.first_impact_time = Some(0.0);
            }
        }
        integrator.assemble_forces(0.0, 0.0);
        for i in 0..modes {
            for p in 0..pins {
                let k = i * pins + p;
                integrator.a[k] = integrator.force[k] - integrator.omega_squared[i] * integrator.q[k];
            }
        }
        integrator.energy.initial = integrator.mechanical_energy_now();
        integrator.previous_power = integrator.powers(0.0);
        integrator
    }

    /// w at every contact level for every pin: one sweep of Ψ (levels × modes) over q.
    fn compute_level_deflections(&mut self) {
        let (pins, modes) = (self.pins, self.modes);
        for (level, row) in self.level_deflections.chunks_exact_mut(pins).enumerate() {
            row.fill(0.0);
            let shape = &self.level_shapes[level * modes..(level + 1) * modes];
            for (i, weight) in shape.iter().enumerate() {
                let q_row = &self.q[i * pins..(i + 1) * pins];
                for (w, q) in row.iter_mut().zip(q_row) {
                    *w += weight * q;
                }
            }
        }
    }

    fn deflection_of(&self, body: Body, level: usize) -> f64 {
        match body {
            Body::Wall => 0.0,
            Body::Pin(p) => self.level_deflections[level * self.pins + p],
        }
    }

    fn penetration(&self, c: usize, contact: &Contact) -> f64 {
        let level = self.contact_level[c];
        self.deflection_of(contact.left, level) - self.deflection_of(contact.right, level) - contact.gap
    }

    /// Velocity of `body` at a level: ψ·(v + scale·a) (scale Δt gives the predictor).
    fn velocity_of(&self, body: Body, level: usize, acceleration_weight: f64) -> f64 {
        let Body::Pin(p) = body else { return 0.0 };
        let shape = &self.level_shapes[level * self.modes..(level + 1) * self.modes];
        let pins = self.pins;
        shape
            .iter()
            .enumerate()
            .map(|(i, s)| s * (self.v[i * pins + p] + acceleration_weight * self.a[i * pins + p]))
            .sum()
    }

    fn penetration_rate(&self, c: usize, contact: &Contact, acceleration_weight: f64) -> f64 {
        let level = self.contact_level[c];
        self.velocity_of(contact.left, level, acceleration_weight)
            - self.velocity_of(contact.right, level, acceleration_weight)
    }

    /// Fills `force` with external and contact loads at time t from the current
    /// positions; contact dashpots see the velocity ψ·(v + acceleration_weight · a).
    fn assemble_forces(&mut self, t: f64, acceleration_weight: f64) {
        let (pins, modes) = (self.pins, self.modes);
        let base = self.model.base_acceleration.as_ref().map_or(0.0, |b| b.at(t));
        let participation = self.model.basis.participation();
        for i in 0..modes {
            self.force[i * pins..(i + 1) * pins].fill(-participation[i] * base);
        }
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let value = point.force.at(t);
            for i in 0..modes {
                self.force[i * pins + point.pin] += value * shape[i];
            }
        }
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let penetration = self.penetration(c, contact);
            let force = if penetration > 0.0 {
                let rate = if contact.damping > 0.0 {
                    self.penetration_rate(c, contact, acceleration_weight)
                } else {
                    0.0
                };
                contact.force(penetration, rate)
            } else {
                0.0
            };
            self.contact_force[c] = force;
            if force != 0.0 {
                let level = self.contact_level[c];
                let shape = &self.level_shapes[level * modes..(level + 1) * modes];
                if let Body::Pin(p) = contact.left {
                    for i in 0..modes {
                        self.force[i * pins + p] -= force * shape[i];
                    }
                }
                if let Body::Pin(p) = contact.right {
                    for i in 0..modes {
                        self.force[i * pins + p] += force * shape[i];
                    }
                }
            }
        }
    }

    /// Advances from t − Δt to t.
    fn step(&mut self, t: f64) {
        let (pins, modes, dt) = (self.pins, self.modes, self.dt);
        match self.scheme {
            Scheme::CentralDifference => {
                // v ← v½ and q ← qₙ₊₁; a still holds aₙ, so v + ½Δt a is the predictor.
                for k in 0..modes * pins {
                    self.v[k] += 0.5 * dt * self.a[k];
                    self.q[k] += dt * self.v[k];
                }
                self.compute_level_deflections();
                self.assemble_forces(t, 0.5 * dt);
                for i in 0..modes {
                    let (stiffness, damping, factor) = (
                        self.omega_squared[i],
                        self.damping[i],
                        self.implicit_damping_factor[i],
                    );
                    for k in i * pins..(i + 1) * pins {
                        let a = (self.force[k] - stiffness * self.q[k] - damping * self.v[k]) * factor;
                        self.a[k] = a;
                        self.v[k] += 0.5 * dt * a;
                    }
                }
            }
            Scheme::Tchamwa { phi } => {
                for k in 0..modes * pins {
                    self.q[k] += dt * self.v[k] + phi * dt * dt * self.a[k];
                    self.v[k] += dt * self.a[k];
                }
                self.compute_level_deflections();
                self.assemble_forces(t, 0.0);
                for i in 0..modes {
                    let (stiffness, damping) = (self.omega_squared[i], self.damping[i]);
                    for k in i * pins..(i + 1) * pins {
                        self.a[k] = self.force[k] - stiffness * self.q[k] - damping * self.v[k];
                    }
                }
            }
        }
        self.update_statistics(t);
        let powers = self.powers(t);
        let half = 0.5 * dt;
        self.energy.dissipated_modal += half * (self.previous_power.modal_damping + powers.modal_damping);
        self.energy.dissipated_contact +=
            half * (self.previous_power.contact_damping + powers.contact_damping);
        self.energy.external_work += half * (self.previous_power.external + powers.external);
        self.external_work_peak = self.external_work_peak.max(self.energy.external_work.abs());
        self.previous_power = powers;
    }

    fn update_statistics(&mut self, t: f64) {
        let dt = self.dt;
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let penetration = self.penetration(c, contact);
            let previous = self.previous_penetration[c];
            let stats = &mut self.statistics[c];
            // A contact without stiffness or dashpot exerts nothing: it never impacts.
            let active = contact.stiffness > 0.0 || contact.damping > 0.0;
            if penetration > 0.0 && active {
                if previous <= 0.0 {
                    stats.impacts += 1;
                    if stats.first_impact_time.is_none() {
                        stats.first_impact_time = Some(t - dt * penetration / (penetration - previous));
                    }
                }
                stats.contact_time += dt;
                let force = self.contact_force[c];
                stats.impulse += force * dt;
                if force > stats.max_force {
                    stats.max_force = force;
                    stats.max_force_time = t;
                }
            }
            stats.max_penetration = stats.max_penetration.max(penetration);
            self.previous_penetration[c] = penetration;
        }
    }

    /// Dissipation and external powers with the current state (velocities at t).
    fn powers(&self, t: f64) -> Powers {
        let (pins, modes) = (self.pins, self.modes);
        let mut powers = Powers::default();
        let base = self.model.base_acceleration.as_ref().map_or(0.0, |b| b.at(t));
        let participation = self.model.basis.participation();
        for i in 0..modes {
            let row = &self.v[i * pins..(i + 1) * pins];
            let (sum_v, sum_v2) = row.iter().fold((0.0, 0.0), |(s, s2), v| (s + v, s2 + v * v));
            powers.modal_damping += self.damping[i] * sum_v2;
            powers.external -= participation[i] * base * sum_v;
        }
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let velocity: f64 = (0..modes).map(|i| shape[i] * self.v[i * pins + point.pin]).sum();
            powers.external += point.force.at(t) * velocity;
        }
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let force = self.contact_force[c];
            let penetration = self.previous_penetration[c];
            if penetration > 0.0 {
                let rate = self.penetration_rate(c, contact, 0.0);
                powers.contact_damping += (force - contact.stiffness * penetration) * rate;
            }
        }
        powers
    }

    fn mechanical_energy_now(&self) -> f64 {
        let pins = self.pins;
        let mut energy = 0.0;
        for i in 0..self.modes {
            for k in i * pins..(i + 1) * pins {
                energy += 0.5 * (self.v[k] * self.v[k] + self.omega_squared[i] * self.q[k] * self.q[k]);
            }
        }
        energy + self.contact_energy_now()
    }

    fn contact_energy_now(&self) -> f64 {
        self.model
            .contacts
            .iter()
            .zip(&self.previous_penetration)
            .filter(|(_, d)| **d > 0.0)
            .map(|(c, d)| 0.5 * c.stiffness * d * d)
            .sum()
    }

    /// An unstable scheme creates energy: mechanical + dissipated − work − initial grows
    /// like the unstable mode. A stable explicit scheme conserves a shadow energy instead
    /// of the plain one; the plain energy of a mode with ωΔt = r × limit exceeds it by
    /// at most a factor 1/(1 − r²), so the alarm rings when the created energy exceeds
    /// 2/(1 − r²) times the energy involved (r = Δt / critical step). Non-finite too.
    fn check_divergence(&self, t: f64) -> Result<(), SimulationError> {
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

    fn record_sample(&mut self, t: f64) {
        let (pins, modes) = (self.pins, self.modes);
        self.time.push(t);
        for (h, shape) in self.output_shapes.iter().enumerate() {
            for p in 0..pins {
                let w = (0..modes).map(|i| shape[i] * self.q[i * pins + p]).sum();
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
                let w: f64 = (0..modes).map(|i| shape[i] * self.q[i * pins + p]).sum();
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

    fn finish(mut self, dt: f64, critical: f64, steps: u64) -> Simulation {
        self.energy.kinetic = 0.5 * self.v.iter().map(|v| v * v).sum::<f64>();
        self.energy.contact = self.contact_energy_now();
        self.energy.strain = self.mechanical_energy_now() - self.energy.kinetic - self.energy.contact;
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

#[cfg(test)]
mod tests;
