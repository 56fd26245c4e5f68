//! State and step of one run: the hot loop.
//!
//! Layout: pin-major. Each pin's modal coordinates are one contiguous row of `row`
//! values (the modes rounded up to whole SIMD vectors; padded modes have ω = 0, Γ = 0,
//! ψ = 0 and stay 0). A closed contact then reads and writes whole rows: its dashpot
//! velocity ψ·ṽ is one contiguous dot product and its force projection one contiguous
//! axpy. The deflections at the contact levels are block-major (a vector holds one
//! pin's deflections at `lanes` consecutive levels), and the contacts are laid out by
//! the lanes of those vectors ([`ContactLanes`]): every per-contact array is stored by
//! lane and mapped back to contact order for samples and results.
//!
//! The step is instantiated for rows of 1 to 8 vectors (up to 32 modes with AVX2), so
//! that every per-row loop is unrolled; longer rows take the same code with a run-time
//! length. Steps run in batches between two checks or samples, in one SIMD context.
//!
//! Where the time goes (row17: 17 pins × 20 modes, 10 levels, 180 contacts, about 15
//! of them closed at a time; about 12 000 instructions per step counted with
//! callgrind, against 16 000 for the previous pin-major version and 41 000 for the
//! first, mode-major one; shares of the step from `perf` samples):
//! 1. the deflection of every pin at every contact level ([`level_deflections`]): two
//!    pins at a time, 20 coordinates broadcast against 3 blocks of 4 levels, ~1 000
//!    FMAs, close to the FMA throughput of the CPU (~20 %);
//! 2. one vector pass over the groups of contacts ([`penetrations`]): penetration,
//!    running maximum, and a bit per group holding a closed contact (~20 %);
//! 3. the closed contacts only, in two passes: dashpot rate, force and statistics, then
//!    the force projection (~25 %);
//! 4. the modal update ([`modal_update`]), which also applies the base excitation,
//!    clears the loads and accumulates the dissipated and external powers (~16 %),
//!    and the first half of the update ([`advance_positions`], ~7 %).
//!
//! Two things measured slower and are not done: a masked store of zero forces for the
//! open contacts (microcoded on AMD), and reading lanes back as scalars right after a
//! vector store (the store cannot be forwarded).
//!
//! The step is dispatched through `pulp` so that it is compiled for the SIMD level of
//! the running CPU (AVX2 + FMA on x86-64-v3) without unsafe code; see [`kernels`] for
//! what that means for reproducibility.

use pulp::Simd;

use super::kernels::{
    self, ContactLanes, ContactState, Lanes, LevelShapes, ModalCoefficients, advance_positions, axpy, lanes,
    level_deflections, modal_update, penetration_rate, penetrations, row_axpy,
};
use super::{
    ContactStatistics, EnergyBalance, Model, PeakDeflection, PinExtreme, Settings, Simulation,
    SimulationError, StepSize,
};
use crate::contact::Body;
use crate::stability::Scheme;

pub(super) struct Integrator<'m> {
    arch: pulp::Arch,
    model: &'m Model<'m>,
    scheme: Scheme,
    dt: f64,
    step: StepSize,
    /// f64 values per SIMD vector of `arch`.
    lanes: usize,
    /// Length of one pin's row: the modes rounded up to whole vectors.
    row: usize,
    /// Slots per block of the block-major deflections: `[wall, pin 0, …, pin n−1, wall]`.
    stride: usize,
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
    /// The contacts by lanes of the level deflections; everything below that is per
    /// contact is stored by lane (see [`ContactLanes`]).
    layout: ContactLanes,
    /// Per lane: what a closed contact needs, and the gap (∞ in empty lanes).
    lane_contacts: Vec<LaneContact>,
    gaps: Vec<f64>,
    /// Offset (in vectors) of the row of zeros after the pins' rows in `v` and `a`,
    /// read for a wall.
    wall_row: usize,
    /// Per lane: penetration now, a step ago (the two buffers swap every step) and
    /// largest so far.
    penetration: Vec<f64>,
    previous_penetration: Vec<f64>,
    max_penetration: Vec<f64>,
    /// Scratch: the lanes closed now (the only ones that need more than a penetration),
    /// and the groups holding them.
    closed: Vec<u32>,
    closed_groups: Vec<u64>,
    /// w of every pin at every level, block-major (see [`level_deflections`]); the wall
    /// slots stay 0.
    level_deflections: Vec<f64>,
    /// ψ at each point force's height (padded to `row`).
    point_force_shapes: Vec<Vec<f64>>,
    /// Where pin 0's deflection at each output height is in `level_deflections` (output
    /// heights that are no contact level are levels with no contact), and per output
    /// height and pin the deflection of largest magnitude since the last sample.
    output_offsets: Vec<usize>,
    deflection_high: Vec<f64>,
    deflection_low: Vec<f64>,
    /// Per output height and pin, the deflection of largest magnitude over the run.
    peak_deflections: Vec<PeakDeflection>,
    /// Nodal deflection of each mode, for pin extremes, and the nodal deflections of
    /// every pin at the last sample (laid out as `level_deflections`).
    node_shapes: LevelShapes,
    node_deflections: Vec<f64>,
    /// Pin-major state (`pins × row`): coordinates, velocities, accelerations, and the
    /// contact and point loads of the step (zeroed by the modal update). `v` and `a`
    /// have one more row, of zeros, for the walls.
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    force: Vec<f64>,
    /// Per lane; only meaningful where the penetration is positive (see [`penetrations`]).
    contact_force: Vec<f64>,
    /// Per lane, the largest force since the last sample.
    force_peak: Vec<f64>,
    statistics: Vec<ContactStatistics>,
    energy: EnergyBalance,
    previous_power: Powers,
    /// Created energy allowed per joule involved before declaring divergence.
    divergence_allowance: f64,
    /// Largest |net external work| so far (J).
    external_work_peak: f64,
    time: Vec<f64>,
    deflections: Vec<Vec<Vec<f64>>>,
    deflection_peaks: Vec<Vec<Vec<f64>>>,
    /// Per contact (not by lane).
    contact_forces: Vec<Vec<f64>>,
    contact_force_peaks: Vec<Vec<f64>>,
    mechanical_energy: Vec<f64>,
    pin_extremes: Vec<PinExtreme>,
}

/// What [`StepOp`] does.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Operation {
    /// The contact and point forces at t = 0.
    Initial,
    /// The steps of this range (step n ends at t = n·Δt).
    Steps(std::ops::RangeInclusive<u64>),
    /// The deflection of every pin at every node, into `node_deflections`.
    NodeDeflections,
}

/// An operation on the state as a [`pulp::WithSimd`] operation: everything it inlines
/// is compiled with the target features [`pulp::Arch`] detected at run time.
struct StepOp<'a, 'm> {
    integrator: &'a mut Integrator<'m>,
    operation: Operation,
}

impl pulp::WithSimd for StepOp<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let integrator = self.integrator;
        let vectors = integrator.row / lanes::<S>();
        debug_assert_eq!(integrator.lanes, lanes::<S>());
        match self.operation {
            Operation::Initial => {
                integrator.contact_forces_and_statistics(simd, 0.0, false, vectors);
            }
            // The usual row lengths get a copy of the step where the row length is a
            // constant: every per-row loop is then unrolled, without bounds checks.
            Operation::Steps(steps) => match vectors {
                1 => integrator.steps_body(simd, steps, 1),
                2 => integrator.steps_body(simd, steps, 2),
                3 => integrator.steps_body(simd, steps, 3),
                4 => integrator.steps_body(simd, steps, 4),
                5 => integrator.steps_body(simd, steps, 5),
                6 => integrator.steps_body(simd, steps, 6),
                7 => integrator.steps_body(simd, steps, 7),
                8 => integrator.steps_body(simd, steps, 8),
                _ => integrator.steps_body(simd, steps, vectors),
            },
            Operation::NodeDeflections => level_deflections(
                simd,
                &integrator.node_shapes,
                integrator.row,
                &integrator.q,
                S::as_mut_simd_f64s(&mut integrator.node_deflections).0,
                integrator.stride,
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
        kernels::modal_energy(
            simd,
            S::as_simd_f64s(self.stiffness).0,
            S::as_simd_f64s(self.q).0,
            S::as_simd_f64s(self.v).0,
        )
    }
}

/// A contact as its lane needs it; offsets are in SIMD vectors.
#[derive(Debug, Clone, Copy, Default)]
struct LaneContact {
    stiffness: f64,
    dashpot: f64,
    /// Offset of ψ at the contact's level in `level_shapes`.
    shape: usize,
    /// Offsets of the left and right body's rows in the state (`wall_row` for a wall).
    left: usize,
    right: usize,
    /// Whether it can push at all (stiffness or dashpot > 0): only those count impacts.
    active: bool,
}

#[derive(Debug, Clone, Copy, Default)]
struct Powers {
    modal_damping: f64,
    contact_damping: f64,
    external: f64,
}

/// `values` followed by `fill` up to `row`.
fn padded(values: &[f64], row: usize, fill: f64) -> Vec<f64> {
    let mut out = values.to_vec();
    out.resize(row, fill);
    out
}

impl<'m> Integrator<'m> {
    /// The state at t = 0, for the SIMD level `arch` (normally `pulp::Arch::new()`).
    pub(super) fn new(arch: pulp::Arch, model: &'m Model<'m>, settings: &Settings, step: &StepSize) -> Self {
        let (dt, critical) = (step.time_step, step.critical_time_step);
        let lanes = arch.dispatch(Lanes);
        let basis = model.basis;
        let (pins, modes) = (model.pins, basis.modes());
        let row = modes.div_ceil(lanes) * lanes;
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
        // The output heights are levels too (with no contact unless one is there).
        let output_levels: Vec<usize> = settings
            .output_heights
            .iter()
            .map(|h| match heights.iter().position(|level| level == h) {
                Some(level) => level,
                None => {
                    heights.push(*h);
                    heights.len() - 1
                }
            })
            .collect();
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
        let contacts = &model.contacts;
        // Offsets in vectors of one row of `row` values; a wall reads the row of zeros
        // after the pins' rows.
        let vectors = row / lanes;
        let state_row = |body: Body| match body {
            Body::Wall => vectors * pins,
            Body::Pin(pin) => vectors * pin,
        };
        // A wall on the left reads the zero slot before the first pin, on the right the one
        // after the last.
        let stride = pins + 2;
        let slot = |body: Body, wall: usize| match body {
            Body::Wall => wall,
            Body::Pin(pin) => 1 + pin,
        };
        let layout = ContactLanes::new(
            contacts.iter().enumerate().map(|(c, contact)| {
                (
                    contact_level[c],
                    slot(contact.left, 0),
                    slot(contact.right, pins + 1),
                )
            }),
            lanes,
            stride,
        );
        let lane_count = layout.len();
        let groups = lane_count / lanes;
        let level_shapes: Vec<f64> = heights.iter().flat_map(|h| shape_at(*h)).collect();
        let grouped_level_shapes = LevelShapes::new(&level_shapes, row, lanes);
        let node_shapes = LevelShapes::new(
            &(0..nodes)
                .flat_map(|n| (0..row).map(move |i| if i < modes { basis.shape(i)[2 * n] } else { 0.0 }))
                .collect::<Vec<_>>(),
            row,
            lanes,
        );
        let node_blocks = node_shapes.blocks;
        let level_blocks = grouped_level_shapes.blocks;
        let r2 = (dt / critical).powi(2);
        let mut integrator = Self {
            arch,
            model,
            scheme: settings.scheme,
            dt,
            step: *step,
            lanes,
            row,
            stride,
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
            lane_contacts: layout.by_lane(
                &contacts
                    .iter()
                    .enumerate()
                    .map(|(c, contact)| LaneContact {
                        stiffness: contact.stiffness,
                        dashpot: contact.damping,
                        shape: vectors * contact_level[c],
                        left: state_row(contact.left),
                        right: state_row(contact.right),
                        active: contact.stiffness > 0.0 || contact.damping > 0.0,
                    })
                    .collect::<Vec<_>>(),
                LaneContact::default(),
            ),
            wall_row: state_row(Body::Wall),
            gaps: layout.by_lane(&contacts.iter().map(|c| c.gap).collect::<Vec<_>>(), f64::INFINITY),
            layout,
            penetration: vec![0.0; lane_count],
            previous_penetration: vec![0.0; lane_count],
            max_penetration: vec![f64::NEG_INFINITY; lane_count],
            closed: vec![0; lane_count],
            closed_groups: vec![0; groups.div_ceil(64)],
            level_deflections: vec![0.0; level_blocks * stride * lanes],
            point_force_shapes: model.point_forces.iter().map(|f| shape_at(f.height)).collect(),
            deflection_high: vec![0.0; output_levels.len() * pins],
            deflection_low: vec![0.0; output_levels.len() * pins],
            peak_deflections: vec![PeakDeflection::default(); output_levels.len() * pins],
            output_offsets: output_levels
                .iter()
                .map(|level| Self::level_offset(lanes, stride, *level))
                .collect(),
            node_shapes,
            node_deflections: vec![0.0; node_blocks * stride * lanes],
            q,
            v: vec![0.0; (pins + 1) * row],
            a: vec![0.0; (pins + 1) * row],
            force: vec![0.0; pins * row],
            contact_force: vec![0.0; lane_count],
            force_peak: vec![0.0; lane_count],
            statistics: vec![ContactStatistics::default(); lane_count],
            energy: EnergyBalance::default(),
            previous_power: Powers::default(),
            divergence_allowance: if r2 < 1.0 { 2.0 / (1.0 - r2) } else { 1.0 },
            external_work_peak: 0.0,
            time: Vec::new(),
            deflections: vec![vec![Vec::new(); pins]; settings.output_heights.len()],
            deflection_peaks: vec![vec![Vec::new(); pins]; settings.output_heights.len()],
            contact_forces: vec![Vec::new(); contacts.len()],
            contact_force_peaks: vec![Vec::new(); contacts.len()],
            mechanical_energy: Vec::new(),
            pin_extremes: vec![PinExtreme::default(); pins],
        };
        // The state at t = 0: contacts already closed count as impacts at t = 0; a₀ from
        // equilibrium (velocities are zero).
        arch.dispatch(StepOp {
            integrator: &mut integrator,
            operation: Operation::Initial,
        });
        for (contact, lane) in contacts.iter().zip(&integrator.layout.lane) {
            let lane = *lane as usize;
            if integrator.penetration[lane] > 0.0 && (contact.stiffness > 0.0 || contact.damping > 0.0) {
                let stats = &mut integrator.statistics[lane];
                stats.impacts = 1;
                stats.first_impact_time = Some(0.0);
                // The force at t = 0 counts for the peak, as it does in the samples.
                stats.max_force = integrator.contact_force[lane];
                stats.max_force_time = 0.0;
            }
        }
        let base = model.base_acceleration.as_ref().map_or(0.0, |b| b.at(0.0));
        for ((a, f), q) in integrator
            .a
            .chunks_exact_mut(row)
            .zip(integrator.force.chunks_exact_mut(row))
            .zip(integrator.q.chunks_exact(row))
        {
            for k in 0..row {
                a[k] = f[k] - base * integrator.participation[k] - integrator.omega_squared[k] * q[k];
                f[k] = 0.0;
            }
        }
        integrator.energy.initial = integrator.mechanical_energy_now();
        integrator
    }

    /// Point loads at time t added to `force` (which holds no other load yet), contact
    /// forces from the current positions and the dashpot velocity v + lookahead · a
    /// added too; updates the per-step statistics when `record` and returns the contact
    /// dissipation power Σ (F − Kc δ) δ̇. `vectors`: the row length in vectors.
    #[inline(always)]
    fn contact_forces_and_statistics<S: Simd>(
        &mut self,
        simd: S,
        t: f64,
        record: bool,
        vectors: usize,
    ) -> f64 {
        // The row length from `vectors`, so that it is a constant where `vectors` is.
        let (row, dt) = (vectors * lanes::<S>(), self.dt);
        for (point, shape) in self.model.point_forces.iter().zip(&self.point_force_shapes) {
            let value = point.force.at(t);
            axpy(simd, value, shape, &mut self.force[point.pin * row..][..row]);
        }
        let deflections = S::as_mut_simd_f64s(&mut self.level_deflections).0;
        level_deflections(
            simd,
            &self.grouped_level_shapes,
            row,
            &self.q,
            deflections,
            self.stride,
        );
        // Every contact, in vectors: penetration, its running maximum, a zero force
        // where open, and the list of closed contacts (about one in seven).
        std::mem::swap(&mut self.penetration, &mut self.previous_penetration);
        let count = penetrations(
            simd,
            &self.layout,
            deflections,
            &self.gaps,
            ContactState {
                now: &mut self.penetration,
                max: &mut self.max_penetration,
                closed: &mut self.closed,
                closed_groups: &mut self.closed_groups,
            },
        );

        let mut dissipation_power = 0.0;
        let (lookahead, wall, n) = (self.dashpot_lookahead, self.wall_row, vectors);
        let shapes = S::as_simd_f64s(&self.level_shapes).0;
        let (v, a) = (S::as_simd_f64s(&self.v).0, S::as_simd_f64s(&self.a).0);
        let loads = S::as_mut_simd_f64s(&mut self.force).0;
        // Per lane, all of one length (so that one bounds check covers them all).
        let lane_contacts = self.lane_contacts.as_slice();
        let lanes = lane_contacts.len();
        let (now, before) = (&self.penetration[..lanes], &self.previous_penetration[..lanes]);
        let (forces, statistics) = (&mut self.contact_force[..lanes], &mut self.statistics[..lanes]);
        let peaks = &mut self.force_peak[..lanes];
        let closed = &self.closed[..count];
        // Two passes over the closed contacts: the forces first (their dot products are
        // independent of each other, so they overlap), then their projection on the
        // modes (whose only dependencies are through the rows they update).
        for &j in closed {
            let j = j as usize;
            let contact = lane_contacts[j];
            let (penetration, previous) = (now[j], before[j]);
            let rate = if contact.dashpot > 0.0 {
                let rows = |offset: usize| (&v[offset..], &a[offset..]);
                let shape = &shapes[contact.shape..][..n];
                penetration_rate(simd, shape, rows(contact.left), rows(contact.right), lookahead)
            } else {
                0.0
            };
            // The penetration is positive: F = max(0, Kc δ + cc δ̇) (`Contact::force`).
            let force = (contact.stiffness * penetration + contact.dashpot * rate).max(0.0);
            forces[j] = force;
            dissipation_power += (force - contact.stiffness * penetration) * rate;
            if record && force > peaks[j] {
                peaks[j] = force;
            }
            if record && contact.active {
                let stats = &mut statistics[j];
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
        }
        for &j in closed {
            let j = j as usize;
            let (contact, force) = (lane_contacts[j], forces[j]);
            if force != 0.0 {
                let shape = &shapes[contact.shape..][..n];
                if contact.left != wall {
                    row_axpy(simd, -force, shape, &mut loads[contact.left..]);
                }
                if contact.right != wall {
                    row_axpy(simd, force, shape, &mut loads[contact.right..]);
                }
            }
        }
        dissipation_power
    }

    /// Takes the steps of `steps` (step n advances to t = n·Δt), compiled for the best
    /// SIMD level of this CPU.
    pub(super) fn steps(&mut self, steps: std::ops::RangeInclusive<u64>) {
        let arch = self.arch;
        arch.dispatch(StepOp {
            integrator: self,
            operation: Operation::Steps(steps),
        });
    }

    #[inline(always)]
    fn steps_body<S: Simd>(&mut self, simd: S, steps: std::ops::RangeInclusive<u64>, vectors: usize) {
        for n in steps {
            self.step_body(simd, n as f64 * self.dt, vectors);
        }
    }

    /// One step; `vectors` is the row length in vectors (a constant in the usual cases).
    #[inline(always)]
    fn step_body<S: Simd>(&mut self, simd: S, t: f64, vectors: usize) {
        let dt = self.dt;
        let half = 0.5 * dt;
        // q ← qₙ₊₁ and v ← v½ (central difference), or vₙ₊₁ (Tchamwa).
        let first_half = match self.scheme {
            Scheme::CentralDifference => (dt, half, half * dt),
            Scheme::Tchamwa { phi } => (dt, dt, phi * dt * dt),
        };
        // The pins' rows (`v` and `a` have the walls' row of zeros after them).
        let state = self.q.len();
        advance_positions(
            simd,
            first_half,
            S::as_mut_simd_f64s(&mut self.q).0,
            S::as_mut_simd_f64s(&mut self.v[..state]).0,
            S::as_simd_f64s(&self.a[..state]).0,
        );
        let contact_damping = self.contact_forces_and_statistics(simd, t, true, vectors);
        self.track_deflection_peaks();
        let base = self.model.base_acceleration.as_ref().map_or(0.0, |b| b.at(t));
        let second_half = match self.scheme {
            Scheme::CentralDifference => half,
            Scheme::Tchamwa { .. } => 0.0,
        };
        let n = vectors;
        let sums = modal_update(
            simd,
            &ModalCoefficients::<S> {
                stiffness: &S::as_simd_f64s(&self.omega_squared).0[..n],
                damping: &S::as_simd_f64s(&self.damping).0[..n],
                factor: &S::as_simd_f64s(&self.implicit_damping_factor).0[..n],
                participation: &S::as_simd_f64s(&self.participation).0[..n],
            },
            base,
            second_half,
            (
                S::as_simd_f64s(&self.q).0,
                S::as_mut_simd_f64s(&mut self.v[..state]).0,
                S::as_mut_simd_f64s(&mut self.a[..state]).0,
                S::as_mut_simd_f64s(&mut self.force).0,
            ),
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

    /// Index in `level_deflections` of pin 0 at `level` (block-major, the walls in slots
    /// 0 and pins + 1); pin p is `lanes` × p further.
    fn level_offset(lanes: usize, stride: usize, level: usize) -> usize {
        ((level / lanes) * stride + 1) * lanes + level % lanes
    }

    /// Keeps, per output height and pin, the highest and the lowest deflection since the
    /// last sample (branch-free: this runs at every step).
    #[inline(always)]
    fn track_deflection_peaks(&mut self) {
        let (pins, lanes) = (self.model.pins, self.lanes);
        for (h, &offset) in self.output_offsets.iter().enumerate() {
            let column = &self.level_deflections[offset..][..(pins - 1) * lanes + 1];
            let highs = &mut self.deflection_high[h * pins..][..pins];
            let lows = &mut self.deflection_low[h * pins..][..pins];
            for (p, (high, low)) in highs.iter_mut().zip(lows.iter_mut()).enumerate() {
                let w = column[p * lanes];
                *high = if w > *high { w } else { *high };
                *low = if w < *low { w } else { *low };
            }
        }
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
            .zip(&self.layout.lane)
            .map(|(c, lane)| (c, self.penetration[*lane as usize]))
            .filter(|(_, d)| *d > 0.0)
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
                time_step: self.dt,
                critical_time_step: self.step.critical_time_step,
            });
        }
        let dissipated = self.energy.dissipated_modal + self.energy.dissipated_contact;
        let created = mechanical + dissipated - self.energy.external_work - self.energy.initial;
        let scale = self.energy.initial + self.external_work_peak + dissipated;
        if created > self.divergence_allowance * scale + f64::MIN_POSITIVE {
            return Err(SimulationError::Diverged {
                time: t,
                detail: format!("the scheme created {created:e} J of energy from {scale:e} J supplied"),
                time_step: self.dt,
                critical_time_step: self.step.critical_time_step,
            });
        }
        Ok(())
    }

    /// Records the samples at time `t` (the state is the one of the last step) and the
    /// peaks since the previous sample, then starts new peaks.
    pub(super) fn record_sample(&mut self, t: f64) {
        self.time.push(t);
        let (pins, lanes) = (self.model.pins, self.lanes);
        for (h, &offset) in self.output_offsets.iter().enumerate() {
            for p in 0..pins {
                // From the same values as the peaks, so that no sample exceeds its peak.
                let w = self.level_deflections[offset + p * lanes];
                let k = h * pins + p;
                let (high, low) = (self.deflection_high[k].max(w), self.deflection_low[k].min(w));
                // The extreme of largest magnitude, signed (the highest on a tie).
                let peak = if high >= -low { high } else { low };
                let run = &mut self.peak_deflections[k];
                if peak.abs() > run.deflection.abs() {
                    // Located to within the interval that ends at this sample.
                    *run = PeakDeflection {
                        deflection: peak,
                        time: t,
                    };
                }
                self.deflections[h][p].push(w);
                self.deflection_peaks[h][p].push(peak);
                (self.deflection_high[k], self.deflection_low[k]) = (0.0, 0.0);
            }
        }
        for ((history, peaks), lane) in self
            .contact_forces
            .iter_mut()
            .zip(&mut self.contact_force_peaks)
            .zip(&self.layout.lane)
        {
            // Forces are only updated while closed.
            let lane = *lane as usize;
            let force = if self.penetration[lane] > 0.0 {
                self.contact_force[lane]
            } else {
                0.0
            };
            history.push(force);
            peaks.push(self.force_peak[lane].max(force));
            self.force_peak[lane] = 0.0;
        }
        self.mechanical_energy.push(self.mechanical_energy_now());
        let element_length = self.model.basis.model().element_length;
        let arch = self.arch;
        arch.dispatch(StepOp {
            integrator: self,
            operation: Operation::NodeDeflections,
        });
        let (lanes, stride) = (self.lanes, self.stride);
        for node in 0..=self.model.basis.model().elements {
            let (block, lane) = (node / lanes, node % lanes);
            for (p, extreme) in self.pin_extremes.iter_mut().enumerate() {
                let w = self.node_deflections[(block * stride + 1 + p) * lanes + lane];
                if w.abs() > extreme.max_abs_deflection {
                    *extreme = PinExtreme {
                        max_abs_deflection: w.abs(),
                        height: crate::decimal(node as f64 * element_length),
                        time: t,
                    };
                }
            }
        }
    }

    pub(super) fn finish(mut self, steps: u64, output_interval: f64) -> Simulation {
        self.energy.kinetic = 0.5 * self.v.iter().map(|v| v * v).sum::<f64>();
        self.energy.contact = self.contact_energy_now();
        self.energy.strain = self.mechanical_energy_now() - self.energy.kinetic - self.energy.contact;
        for (stats, max) in self.statistics.iter_mut().zip(&self.max_penetration) {
            stats.max_penetration = *max;
        }
        Simulation {
            step: self.step,
            steps,
            output_interval,
            time: self.time,
            deflections: self.deflections,
            deflection_peaks: self.deflection_peaks,
            peak_deflections: self
                .peak_deflections
                .chunks(self.model.pins.max(1))
                .map(<[_]>::to_vec)
                .collect(),
            contact_forces: self.contact_forces,
            contact_force_peaks: self.contact_force_peaks,
            contact_statistics: self.layout.by_contact(&self.statistics),
            pin_extremes: self.pin_extremes,
            energy: self.energy,
            mechanical_energy: self.mechanical_energy,
        }
    }
}
