//! The time loop and the step: the hot loop. A run is three things with clear owners:
//! the [`Layout`] (read only), the [`State`] (advanced by the step) and the [`Recorder`]
//! (histories, statistics and energy, fed by the step and at samples).
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
//! The plane has its own copy of the step (`StepOp<true>`, chosen once per batch): twice
//! the lines through the same kernels, penetrations from four slots and a normal per
//! lane ([`plane_penetrations`]), two dashpot dot products and four force axpys per
//! closed contact ([`plane_contact_forces`]), and the modal update on the x and the y
//! lines with their own base acceleration. The row's copy does none of it. With
//! [`Settings::threads`] > 1 the plane's step forks its level deflections, vector pass,
//! closed contacts and x/y updates ([`plane_step`]); on one thread it is this inlined
//! copy.
//!
//! The step is dispatched through `pulp` so that it is compiled for the SIMD level of
//! the running CPU (AVX2 + FMA on x86-64-v3) without unsafe code; see [`kernels`] for
//! what that means for reproducibility.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use pulp::Simd;

use super::exact::{self, ExactRun};
use super::kernels::{
    self, ContactState, ModalCoefficients, ModalState, UpdateSums, advance_positions, axpy, lanes,
    level_deflections, modal_update, penetration_rate, penetrations, plane_penetrations, row_axpy,
};
use super::layout::{ContactModel, Layout, LineKind, PlaneContacts};
use super::plane_step::{self, ClosedPass, Half, LaneOutputs, Loads};
use super::recorder::{Powers, Recorder, record_closed_contact};
use super::state::State;
use super::walls::{WallLayout, WallState};
use super::{Model, Settings, Simulation, SimulationError, StepSize, step_counts};
use crate::contact::{NormalForce, force_vector};
use crate::stability::Scheme;

/// Steps between two calls of the progress callback.
const PROGRESS_EVERY: u64 = 4096;
/// Looks for forked work (about 0.1 µs each) a worker of a shared step makes before it
/// yields its core to the system once.
const IDLE_LOOKS_BEFORE_YIELDING: u32 = 1024;
/// Steps between two divergence checks.
const DIVERGENCE_CHECK_EVERY: u64 = 32;

/// The time loop, with the step compiled for the SIMD level `arch`. The model and
/// settings must have been checked and the step resolved ([`super::Plan`]).
pub(super) fn integrate(
    arch: pulp::Arch,
    model: &Model<'_>,
    settings: &Settings,
    step: &StepSize,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let threads = settings.threads.clamp(1, rayon::current_num_threads().max(1));
    if threads == 1 || model.plane.is_none() {
        return time_loop(arch, model, settings, step, (threads, None), progress);
    }
    // The plane's step is shared: four forks a step, too close for a worker of the pool
    // to fall asleep and be woken between them (a wake-up costs about what a fork
    // saves: measured, 16 % of the second thread's time in the scheduler). One job of
    // this scope per other thread keeps a worker looking for the forks until the run
    // ends. A worker taken by other work (the step check beside the run) joins when it
    // is done; until one has joined, the run steps on its own thread with the step of
    // one thread (the shared step on one thread costs 30 % more: measured on hex217
    // beside its check, 5 600 against 8 200 steps/s).
    let stop = AtomicBool::new(false);
    let helping = AtomicUsize::new(0);
    rayon::in_place_scope(|scope| {
        for _ in 1..threads {
            scope.spawn(|_| {
                helping.fetch_add(1, Ordering::AcqRel);
                let mut idle = 0u32;
                while !stop.load(Ordering::Acquire) {
                    if rayon::yield_now() == Some(rayon::Yield::Executed) {
                        idle = 0;
                    } else if idle == IDLE_LOOKS_BEFORE_YIELDING {
                        // Long without work (the run records a sample, or the core is
                        // wanted elsewhere): let the system run something else.
                        std::thread::yield_now();
                        idle = 0;
                    } else {
                        idle += 1;
                        std::hint::spin_loop();
                    }
                }
            });
        }
        // Stops the workers however the run ends (an error, or a panic that the scope
        // carries out once its jobs are done).
        struct Stop<'a>(&'a AtomicBool);
        impl Drop for Stop<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Release);
            }
        }
        let _stop = Stop(&stop);
        time_loop(arch, model, settings, step, (threads, Some(&helping)), progress)
    })
}

/// [`integrate`]'s loop over the steps. With `helping` (the workers looking for the
/// run's forks), each batch of steps is shared by the run's thread and those that have
/// joined (at most `threads` in all: [`Settings::threads`] within the pool): the step
/// gives the same numbers whatever the count, so the count may change from one batch
/// to the next.
pub(super) fn time_loop(
    arch: pulp::Arch,
    model: &Model<'_>,
    settings: &Settings,
    step: &StepSize,
    (threads, helping): (usize, Option<&AtomicUsize>),
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<Simulation, SimulationError> {
    let sharing = || helping.map_or(1, |helping| (1 + helping.load(Ordering::Acquire)).min(threads));
    let mut run = Integrator::new(arch, model, settings, step, sharing());
    let (total_steps, output_every) = step_counts(settings.duration, step, settings.output_interval);
    let interval = step.output_interval(settings.output_interval);
    run.record_sample(0.0);
    let mut n = 0;
    while n < total_steps {
        // Steps run in batches up to the next check, sample or progress call, all in
        // one SIMD context.
        let next = [DIVERGENCE_CHECK_EVERY, output_every, PROGRESS_EVERY]
            .iter()
            .map(|every| (n / every + 1) * every)
            .fold(total_steps, u64::min);
        run.threads = sharing();
        run.steps(n + 1..=next)?;
        n = next;
        if n % DIVERGENCE_CHECK_EVERY == 0 || n == total_steps {
            run.check_divergence(n as f64 * step.time_step)?;
        }
        if n % output_every == 0 {
            // k × interval as the decimal it stands for, not a sum of steps.
            run.record_sample(super::step_size::sample_time(n / output_every, interval));
        }
        if n % PROGRESS_EVERY == 0 && progress(n as f64 / total_steps as f64).is_break() {
            return Err(SimulationError::Cancelled);
        }
    }
    Ok(run.finish(total_steps, interval))
}

/// One run: what does not change, what the step advances, what is recorded.
struct Integrator<'m> {
    arch: pulp::Arch,
    /// Threads the plane's step shares: the run's own and the workers that have joined
    /// it, within [`Settings::threads`] and the caller's pool (set for each batch).
    threads: usize,
    layout: Layout<'m>,
    state: State,
    recorder: Recorder,
    /// The exact modal scheme's own data (`None` for the explicit schemes).
    exact: Option<ExactRun>,
}

/// What [`StepOp`] does.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Operation {
    /// The contact and point forces at t = 0.
    Initial,
    /// The steps of this range (step n ends at t = n·Δt).
    Steps(std::ops::RangeInclusive<u64>),
}

/// An operation on the state as a [`pulp::WithSimd`] operation: everything it inlines
/// is compiled with the target features [`pulp::Arch`] detected at run time. `PLANE`
/// picks the plane's contacts and modal update at compile time, so that the row's step
/// is compiled alone, as if the plane did not exist.
struct StepOp<'a, 'm, const PLANE: bool> {
    integrator: &'a mut Integrator<'m>,
    operation: Operation,
}

impl<const PLANE: bool> pulp::WithSimd for StepOp<'_, '_, PLANE> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let integrator = self.integrator;
        let vectors = integrator.layout.row / lanes::<S>();
        debug_assert_eq!(integrator.layout.lanes, lanes::<S>());
        match self.operation {
            Operation::Initial => {
                integrator.contact_forces_and_statistics::<S, PLANE>(simd, 0, false, vectors);
                if PLANE && integrator.threads > 1 {
                    // The contact loads at t = 0 (the walls' transport load is added by
                    // the caller).
                    let (halves, loads) =
                        plane_split(&integrator.layout, &mut integrator.state, (0.0, 0.0), false);
                    plane_step::update_halves(simd, &loads, halves, None, integrator.threads);
                }
            }
            // The usual row lengths get a copy of the step where the row length is a
            // constant: every per-row loop is then unrolled, without bounds checks.
            Operation::Steps(steps) => match vectors {
                1 => integrator.steps_body::<S, PLANE>(simd, steps, 1),
                2 => integrator.steps_body::<S, PLANE>(simd, steps, 2),
                3 => integrator.steps_body::<S, PLANE>(simd, steps, 3),
                4 => integrator.steps_body::<S, PLANE>(simd, steps, 4),
                5 => integrator.steps_body::<S, PLANE>(simd, steps, 5),
                6 => integrator.steps_body::<S, PLANE>(simd, steps, 6),
                7 => integrator.steps_body::<S, PLANE>(simd, steps, 7),
                8 => integrator.steps_body::<S, PLANE>(simd, steps, 8),
                _ => integrator.steps_body::<S, PLANE>(simd, steps, vectors),
            },
        }
    }
}

impl<'m> Integrator<'m> {
    /// The run at t = 0, for the SIMD level `arch` (normally `pulp::Arch::new()`).
    fn new(
        arch: pulp::Arch,
        model: &'m Model<'m>,
        settings: &Settings,
        step: &StepSize,
        threads: usize,
    ) -> Self {
        let layout = Layout::new(arch, model, settings, step);
        let state = State::new(&layout);
        let recorder = Recorder::new(&layout, settings);
        let mut integrator = Self {
            arch,
            threads,
            layout,
            state,
            recorder,
            exact: None,
        };
        // The state at t = 0: contacts already closed count as impacts at t = 0; a₀ from
        // equilibrium (velocities are zero).
        integrator.dispatch(Operation::Initial);
        let Self {
            layout,
            state,
            recorder,
            exact,
            ..
        } = &mut integrator;
        recorder.record_initial_contacts(layout, state);
        recorder.resultants.track(layout, state, 0);
        let (base_x, base_y) = base_accelerations(model, 0.0);
        let (row, pins) = (layout.row, model.pins);
        if let (Some(walls), Some(wall)) = (&layout.walls, &state.wall) {
            wall.add_transport_loads(walls, &mut state.force, (row, pins));
        }
        if layout.scheme == Scheme::ExactModal {
            // The exact scheme starts from the loads at t = 0 (it takes loads linear
            // over each step).
            *exact = Some(ExactRun::new(layout, state.force.clone()));
        }
        let pin_kinds = model.pin_kinds();
        for (line, ((a, f), q)) in state
            .a
            .chunks_exact_mut(row)
            .zip(state.force.chunks_exact_mut(row))
            .zip(state.q.chunks_exact(row))
            .enumerate()
        {
            // The x lines come first; y lines only exist in the plane.
            let base = if line < pins { base_x } else { base_y };
            let kind = &layout.kinds[pin_kinds[line % pins]];
            for k in 0..row {
                a[k] =
                    f[k] * kind.inverse_mass - base * layout.participation[k] - kind.omega_squared[k] * q[k];
                f[k] = 0.0;
            }
        }
        recorder.energy.initial = state.mechanical_energy(arch, layout);
        integrator
    }

    /// Point loads at step n (t = nΔt) added to `force` (which holds no other load yet),
    /// contact forces from the current positions and the dashpot velocity v + lookahead · a
    /// added too; updates the per-step statistics and impacts when `record` and returns
    /// the contact dissipation power Σ (F − Kc δ) δ̇. `vectors`: the row length in vectors.
    #[inline(always)]
    fn contact_forces_and_statistics<S: Simd, const PLANE: bool>(
        &mut self,
        simd: S,
        n: u64,
        record: bool,
        vectors: usize,
    ) -> f64 {
        let Self {
            layout,
            state,
            recorder,
            threads,
            ..
        } = self;
        let threads = *threads;
        // The row length from `vectors`, so that it is a constant where `vectors` is.
        let (row, dt) = (vectors * lanes::<S>(), layout.dt);
        let t = n as f64 * dt;
        for (point, shape) in layout.model.point_forces.iter().zip(&layout.point_force_shapes) {
            let value = point.force.at(t);
            axpy(simd, value, shape, &mut state.force[point.line * row..][..row]);
        }
        let deflections = S::as_mut_simd_f64s(&mut state.level_deflections).0;
        let shapes = &layout.grouped_level_shapes;
        if PLANE && threads > 1 {
            plane_step::level_deflections(
                simd,
                shapes,
                (row, layout.stride),
                &state.q,
                deflections,
                (0..shapes.groups(), threads),
            );
        } else {
            level_deflections(simd, shapes, row, &state.q, deflections, layout.stride);
        }
        // Every contact, in vectors: penetration, its running maximum, a zero force
        // where open, and the list of closed contacts (about one in seven).
        std::mem::swap(&mut state.penetration, &mut state.previous_penetration);
        let gaps = state.wall.as_ref().map_or(&layout.gaps, |wall| &wall.gaps);
        let contact_state = ContactState {
            now: &mut state.penetration,
            max: &mut recorder.max_penetration,
            closed: &mut state.closed,
            closed_groups: &mut state.closed_groups,
        };
        if let (true, ContactModel::Plane(plane)) = (PLANE, &layout.contact_model) {
            let count = if threads > 1 {
                plane_step::penetrations(
                    simd,
                    (&layout.contacts, &plane.groups),
                    deflections,
                    gaps,
                    contact_state,
                    threads,
                )
            } else {
                plane_penetrations(
                    simd,
                    &layout.contacts,
                    &plane.groups,
                    deflections,
                    gaps,
                    contact_state,
                )
            };
            state.closed_count = count;
            if threads > 1 {
                return shared_plane_contact_forces(
                    simd,
                    (layout, plane),
                    state,
                    recorder,
                    count,
                    (n, record),
                    (vectors, threads),
                );
            }
            return plane_contact_forces(
                simd,
                (layout, plane),
                state,
                recorder,
                count,
                (n, record),
                vectors,
            );
        }
        let count = penetrations(simd, &layout.contacts, deflections, gaps, contact_state);
        state.closed_count = count;

        let (mut dissipation_power, mut wall_power) = (0.0, 0.0);
        let walls = layout.walls.as_ref().zip(state.wall.as_ref());
        let at = (n, recorder.impact_block, dt);
        let (lookahead, wall, n) = (layout.dashpot_lookahead, layout.wall_row, vectors);
        let shapes = S::as_simd_f64s(&layout.level_shapes).0;
        let (v, a) = (S::as_simd_f64s(&state.v).0, S::as_simd_f64s(&state.a).0);
        let loads = S::as_mut_simd_f64s(&mut state.force).0;
        // Per lane, all of one length (so that one bounds check covers them all).
        let lane_contacts = layout.lane_contacts.as_slice();
        let lanes = lane_contacts.len();
        let laws = &layout.lane_laws[..lanes];
        let (now, before) = (&state.penetration[..lanes], &state.previous_penetration[..lanes]);
        let (forces, statistics) = (
            &mut state.contact_force[..lanes],
            &mut recorder.statistics[..lanes],
        );
        let peaks = &mut recorder.force_peak[..lanes];
        let impacts = &mut recorder.impacts[..lanes];
        let (clock, log) = (&recorder.impact_clock, &mut recorder.impact_log);
        let closed = &state.closed[..count];
        // Two passes over the closed contacts: the forces first (their dot products are
        // independent of each other, so they overlap), then their projection on the
        // modes (whose only dependencies are through the rows they update).
        for &j in closed {
            let j = j as usize;
            let contact = lane_contacts[j];
            let (penetration, previous) = (now[j], before[j]);
            let mut rate = if contact.needs_rate {
                let rows = |offset: usize| (&v[offset..], &a[offset..]);
                let shape = &shapes[contact.shape..][..n];
                penetration_rate(simd, shape, rows(contact.left), rows(contact.right), lookahead)
            } else {
                0.0
            };
            let wall_rate = match walls {
                Some((layout, wall)) => wall.rate(layout, j),
                None => 0.0,
            };
            if walls.is_some() {
                rate += wall_rate;
            }
            // The penetration is positive: the contact's law.
            let NormalForce { force, elastic } = contact.force(laws, j, penetration, rate);
            forces[j] = force;
            let dissipation = (force - elastic) * rate;
            dissipation_power += dissipation;
            wall_power += force * wall_rate;
            if record && force > peaks[j] {
                peaks[j] = force;
            }
            if record && contact.active {
                record_closed_contact(
                    (&mut statistics[j], &mut impacts[j]),
                    (clock, &mut *log),
                    at,
                    (penetration, previous),
                    (force, dissipation),
                );
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
        if let Some(wall) = &mut state.wall {
            wall.power = wall_power;
        }
        dissipation_power
    }

    /// Takes the steps of `steps` (step n advances to t = n·Δt), compiled for the best
    /// SIMD level of this CPU.
    fn steps(&mut self, steps: std::ops::RangeInclusive<u64>) -> Result<(), SimulationError> {
        if self.exact.is_some() {
            return self.arch.dispatch(ExactSteps {
                integrator: self,
                steps,
            });
        }
        self.dispatch(Operation::Steps(steps));
        Ok(())
    }

    /// `operation` compiled for the best SIMD level of this CPU, with the row's or the
    /// plane's contacts.
    fn dispatch(&mut self, operation: Operation) {
        let arch = self.arch;
        match self.layout.contact_model {
            ContactModel::Row => arch.dispatch(StepOp::<false> {
                integrator: self,
                operation,
            }),
            ContactModel::Plane(_) => arch.dispatch(StepOp::<true> {
                integrator: self,
                operation,
            }),
        }
    }

    #[inline(always)]
    fn steps_body<S: Simd, const PLANE: bool>(
        &mut self,
        simd: S,
        steps: std::ops::RangeInclusive<u64>,
        vectors: usize,
    ) {
        let last = *steps.end();
        for n in steps {
            self.step_body::<S, PLANE>(simd, n, vectors, n < last);
        }
    }

    /// Step n (to t = nΔt); `vectors` is the row length in vectors (a constant in the
    /// usual cases). With `more` (step n + 1 follows in the same batch), a step shared
    /// between threads may take the first half of step n + 1 with its modal update
    /// ([`State::advanced`]).
    #[inline(always)]
    fn step_body<S: Simd, const PLANE: bool>(&mut self, simd: S, n: u64, vectors: usize, more: bool) {
        let dt = self.layout.dt;
        let t = n as f64 * dt;
        self.recorder.enter_step(n);
        let half = 0.5 * dt;
        // q ← qₙ₊₁ and v ← v½ (central difference), or vₙ₊₁ (Tchamwa).
        let first_half = match self.layout.scheme {
            Scheme::CentralDifference | Scheme::ExactModal => (dt, half, half * dt),
            Scheme::Tchamwa { phi } => (dt, dt, phi * dt * dt),
        };
        // The pins' rows (`v` and `a` have the walls' row of zeros after them).
        let state = &mut self.state;
        let pins_state = state.q.len();
        if !std::mem::take(&mut state.advanced) {
            advance_positions(
                simd,
                first_half,
                S::as_mut_simd_f64s(&mut state.q).0,
                S::as_mut_simd_f64s(&mut state.v[..pins_state]).0,
                S::as_simd_f64s(&state.a[..pins_state]).0,
            );
        }
        if let (Some(walls), Some(wall)) = (&self.layout.walls, &mut self.state.wall) {
            wall.advance(walls, self.layout.model, (t, dt));
        }
        let contact_damping = self.contact_forces_and_statistics::<S, PLANE>(simd, n, true, vectors);
        let Self {
            layout,
            state,
            recorder,
            threads,
            ..
        } = self;
        recorder.resultants.track(layout, state, n);
        if let (Some(walls), Some(wall)) = (&layout.walls, &state.wall) {
            transport_outputs(layout, walls, wall, &mut state.level_deflections);
        }
        recorder.track_deflection_peaks(layout, &state.level_deflections);
        let second_half = match layout.scheme {
            Scheme::CentralDifference | Scheme::ExactModal => half,
            Scheme::Tchamwa { .. } => 0.0,
        };
        // A step shared between threads adds the closed contacts' loads with the update.
        let shared = PLANE && *threads > 1;
        // The transport's inertial load −Γᴾ r joins the contact and point loads.
        if let (false, Some(walls), Some(wall)) = (shared, &layout.walls, &state.wall) {
            wall.add_transport_loads(walls, &mut state.force, (layout.row, layout.model.pins));
        }
        // The base excitation's power −a(t) Σ Γ v, per direction in the plane.
        let (modal_damping, mut external) = match (PLANE, &layout.contact_model) {
            (false, _) | (true, ContactModel::Row) => {
                let (q, v, a, f) = (
                    S::as_simd_f64s(&state.q).0,
                    S::as_mut_simd_f64s(&mut state.v[..pins_state]).0,
                    S::as_mut_simd_f64s(&mut state.a[..pins_state]).0,
                    S::as_mut_simd_f64s(&mut state.force).0,
                );
                let base = layout.model.base_acceleration.as_ref().map_or(0.0, |b| b.at(t));
                let sums = update_lines(simd, layout, 0, base, second_half, (q, v, a, f));
                (sums.damping_power, -base * sums.participation_velocity)
            }
            (true, ContactModel::Plane(_)) if !shared => {
                let (base_x, base_y) = base_accelerations(layout.model, t);
                let (q, v, a, f) = (
                    S::as_simd_f64s(&state.q).0,
                    S::as_mut_simd_f64s(&mut state.v[..pins_state]).0,
                    S::as_mut_simd_f64s(&mut state.a[..pins_state]).0,
                    S::as_mut_simd_f64s(&mut state.force).0,
                );
                let x_lines = q.len() / 2;
                let (q_x, q_y) = q.split_at(x_lines);
                let (v_x, v_y) = v.split_at_mut(x_lines);
                let (a_x, a_y) = a.split_at_mut(x_lines);
                let (f_x, f_y) = f.split_at_mut(x_lines);
                let pins = layout.model.pins;
                let x = update_lines(simd, layout, 0, base_x, second_half, (q_x, v_x, a_x, f_x));
                let y = update_lines(simd, layout, pins, base_y, second_half, (q_y, v_y, a_y, f_y));
                (
                    x.damping_power + y.damping_power,
                    -base_x * x.participation_velocity - base_y * y.participation_velocity,
                )
            }
            (true, ContactModel::Plane(_)) => {
                // The contact loads, the transport's inertial load −Γᴾ r, then the
                // update, of the x lines and of the y lines: the additions each row
                // receives, in the order the step on one thread makes them.
                let bases = base_accelerations(layout.model, t);
                // The next step's first half with the update, unless something reads
                // the velocities at the end of this step (point forces, moving walls).
                let advance = more && layout.model.point_forces.is_empty() && layout.walls.is_none();
                state.advanced = advance;
                let (halves, loads) = plane_split(layout, state, bases, true);
                let update = Some((second_half, advance.then_some(first_half)));
                let [x, y] = plane_step::update_halves(simd, &loads, halves, update, *threads)
                    .map(|sums| sums.expect("an update was asked"));
                (
                    x.damping_power + y.damping_power,
                    -bases.0 * x.participation_velocity - bases.1 * y.participation_velocity,
                )
            }
        };
        for (point, shape) in layout.model.point_forces.iter().zip(&layout.point_force_shapes) {
            let velocity = kernels::dot(simd, shape, &state.v[point.line * layout.row..][..layout.row]);
            external += point.force.at(t) * velocity;
        }
        if let (Some(walls), Some(wall)) = (&layout.walls, &state.wall) {
            external += wall.power + wall.transport_power(walls, &state.v, (layout.row, layout.model.pins));
        }
        recorder.add_powers(
            half,
            Powers {
                modal_damping,
                contact_damping,
                external,
            },
        );
    }

    /// An unstable scheme creates energy: mechanical + dissipated − work − initial grows
    /// like the unstable mode. A stable explicit scheme conserves a shadow energy instead
    /// of the plain one; the plain energy of a mode with ωΔt = r × limit exceeds it by
    /// at most a factor 1/(1 − r²), so the alarm rings when the created energy exceeds
    /// 2/(1 − r²) times the energy involved (r = Δt / critical step). Non-finite too.
    fn check_divergence(&self, t: f64) -> Result<(), SimulationError> {
        let (layout, state) = (&self.layout, &self.state);
        let energy = &self.recorder.energy;
        let mechanical = state.mechanical_energy(self.arch, layout);
        let diverged = |detail: String| SimulationError::Diverged {
            time: t,
            detail,
            time_step: layout.dt,
            critical_time_step: layout.step.critical_time_step,
        };
        if !mechanical.is_finite() || state.q.iter().any(|x| !x.is_finite()) {
            return Err(diverged("non-finite state".into()));
        }
        let dissipated = energy.dissipated_modal + energy.dissipated_contact;
        let created = mechanical + dissipated - energy.external_work - energy.initial;
        let scale = energy.initial + self.recorder.external_work_peak + dissipated;
        if created > layout.divergence_allowance * scale + f64::MIN_POSITIVE {
            return Err(diverged(format!(
                "the scheme created {created:e} J of energy from {scale:e} J supplied"
            )));
        }
        Ok(())
    }

    /// Records the samples at time `t` (the state is the one of the last step).
    fn record_sample(&mut self, t: f64) {
        self.recorder
            .record_sample(self.arch, &self.layout, &self.state, t);
    }

    fn finish(self, steps: u64, output_interval: f64) -> Simulation {
        self.recorder
            .finish(self.arch, &self.layout, &self.state, steps, output_interval)
    }
}

/// Steps of the exact modal scheme ([`exact::step`]) as a [`pulp::WithSimd`] operation.
struct ExactSteps<'a, 'm> {
    integrator: &'a mut Integrator<'m>,
    steps: std::ops::RangeInclusive<u64>,
}

impl pulp::WithSimd for ExactSteps<'_, '_> {
    type Output = Result<(), SimulationError>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Self::Output {
        let Integrator {
            layout,
            state,
            recorder,
            exact,
            ..
        } = self.integrator;
        let run = exact.as_mut().expect("an exact run has its data");
        let half = 0.5 * layout.dt;
        for n in self.steps {
            match exact::step(simd, (layout, state, recorder), run, n) {
                Ok(powers) => recorder.add_powers(half, powers),
                Err(failure) => {
                    return Err(SimulationError::ContactSolveFailed {
                        time: n as f64 * layout.dt,
                        sweeps: exact::MAX_SWEEPS,
                        contacts: failure.contacts,
                    });
                }
            }
        }
        Ok(())
    }
}

/// Adds the transport Ψ(z) d to every line's deflection at the output heights (after
/// the contacts read the level deflections: they see the modal part and the walls'
/// relative position through their gaps).
fn transport_outputs(layout: &Layout<'_>, walls: &WallLayout, wall: &WallState, deflections: &mut [f64]) {
    let (pins, lanes) = (layout.model.pins, layout.lanes);
    for (&offset, &psi) in layout.output_offsets.iter().zip(&walls.output_transport) {
        for line in 0..layout.lines {
            let d = wall.transport()[usize::from(line >= pins)];
            deflections[offset + line * lanes] += psi * d;
        }
    }
}

/// The modal update ([`modal_update`]) of the lines from `first` on that `q`, `v`, `a`
/// and `f` hold (whole rows, whole runs of [`Layout::runs`]), each run of one kind with
/// its coefficients and mass; the power sums weighted by each kind's mass (the basis's
/// alone: one update of every line, as without kinds).
#[inline(always)]
pub(super) fn update_lines<S: Simd>(
    simd: S,
    layout: &Layout<'_>,
    first: usize,
    base: f64,
    second_half: f64,
    (q, v, a, f): ModalState<'_, S::f64s>,
) -> UpdateSums {
    let n = layout.row / layout.lanes;
    let lines = q.len() / n;
    let participation = &S::as_simd_f64s(&layout.participation).0[..n];
    if let [kind] = &layout.kinds[..] {
        // Every line the basis's: one update, as without kinds.
        let coefficients = coefficients_of::<S>(kind, participation, n);
        return modal_update::<S, false>(simd, &coefficients, base, second_half, (q, v, a, f));
    }
    let mut sums = UpdateSums::default();
    for run in layout
        .runs
        .iter()
        .filter(|r| (first..first + lines).contains(&r.first))
    {
        let kind = &layout.kinds[run.kind];
        let coefficients = coefficients_of::<S>(kind, participation, n);
        let rows = (run.first - first) * n..(run.first - first + run.lines) * n;
        let state = (
            &q[rows.clone()],
            &mut v[rows.clone()],
            &mut a[rows.clone()],
            &mut f[rows],
        );
        let run_sums = if kind.inverse_mass == 1.0 {
            modal_update::<S, false>(simd, &coefficients, base, second_half, state)
        } else {
            modal_update::<S, true>(simd, &coefficients, base, second_half, state)
        };
        sums.damping_power += kind.mass * run_sums.damping_power;
        sums.participation_velocity += kind.mass * run_sums.participation_velocity;
    }
    sums
}

/// `kind`'s modal coefficients as vectors of rows of `n` vectors, with `participation`.
#[inline(always)]
fn coefficients_of<'a, S: Simd>(
    kind: &'a LineKind,
    participation: &'a [S::f64s],
    n: usize,
) -> ModalCoefficients<'a, S> {
    ModalCoefficients {
        stiffness: &S::as_simd_f64s(&kind.omega_squared).0[..n],
        damping: &S::as_simd_f64s(&kind.damping).0[..n],
        factor: &S::as_simd_f64s(&kind.implicit_damping_factor).0[..n],
        participation,
        inverse_mass: kind.inverse_mass,
    }
}

/// The plane's state as [`plane_step::update_halves`] takes it: the x and the y lines
/// (with the base acceleration along each), and the closed contacts' forces (and the
/// walls, for their transport load, with `walls`).
fn plane_split<'a>(
    layout: &'a Layout<'_>,
    state: &'a mut State,
    (base_x, base_y): (f64, f64),
    walls: bool,
) -> ([Half<'a>; 2], Loads<'a>) {
    let (contacts, lines) = match &layout.contact_model {
        ContactModel::Plane(plane) => (&plane.lanes[..], state.q.len()),
        ContactModel::Row => unreachable!("the plane's step runs on plane models"),
    };
    let x = lines / 2;
    let (q_x, q_y) = state.q.split_at_mut(x);
    let (v_x, v_y) = state.v[..lines].split_at_mut(x);
    let (a_x, a_y) = state.a[..lines].split_at_mut(x);
    let (f_x, f_y) = state.force.split_at_mut(x);
    let start = x / layout.lanes;
    let halves = [
        Half {
            y: false,
            start: 0,
            q: q_x,
            v: v_x,
            a: a_x,
            force: f_x,
            base: base_x,
        },
        Half {
            y: true,
            start,
            q: q_y,
            v: v_y,
            a: a_y,
            force: f_y,
            base: base_y,
        },
    ];
    let loads = Loads {
        layout,
        plane_lanes: contacts,
        closed: &state.closed[..state.closed_count],
        forces: &state.contact_force,
        tangentials: &state.tangential_force,
        walls: if walls {
            layout.walls.as_ref().zip(state.wall.as_ref())
        } else {
            None
        },
    };
    (halves, loads)
}

/// The base acceleration (m/s²) at `t` along x and along y (0 for the row).
fn base_accelerations(model: &Model<'_>, t: f64) -> (f64, f64) {
    let at = |base: Option<&crate::loads::BaseAcceleration>| base.map_or(0.0, |b| b.at(t));
    let y = model.plane.as_ref().and_then(|p| p.base_acceleration_y.as_ref());
    (at(model.base_acceleration.as_ref()), at(y))
}

/// The closed contacts of the plane, after [`plane_penetrations`]: with the dashpot
/// velocity of each body along x and y, rate_x = ψ·Δṽ_x and rate_y = ψ·Δṽ_y, the
/// penetration rate is δ̇ = n_x rate_x + n_y rate_y and the sliding velocity
/// v_t = −n_y rate_x + n_x rate_y (tangent t = (−n_y, n_x)); F from the contact's law
/// pushes the left body by −F n and the right one by +F n, and the wear work gains
/// F |v_t| Δt. Returns the contact dissipation power Σ (F − Kc δ) δ̇.
#[inline(always)]
fn plane_contact_forces<S: Simd>(
    simd: S,
    (layout, plane): (&Layout<'_>, &PlaneContacts),
    state: &mut State,
    recorder: &mut Recorder,
    count: usize,
    (step, record): (u64, bool),
    vectors: usize,
) -> f64 {
    let (mut dissipation_power, mut wall_power) = (0.0, 0.0);
    let walls = layout.walls.as_ref().zip(state.wall.as_ref());
    let (lookahead, wall, n, dt) = (layout.dashpot_lookahead, layout.wall_row, vectors, layout.dt);
    let shapes = S::as_simd_f64s(&layout.level_shapes).0;
    let (v, a) = (S::as_simd_f64s(&state.v).0, S::as_simd_f64s(&state.a).0);
    let loads = S::as_mut_simd_f64s(&mut state.force).0;
    let lane_contacts = layout.lane_contacts.as_slice();
    let lanes = lane_contacts.len();
    let laws = &layout.lane_laws[..lanes];
    let plane_lanes = &plane.lanes[..lanes];
    let (now, before) = (&state.penetration[..lanes], &state.previous_penetration[..lanes]);
    let (forces, statistics) = (
        &mut state.contact_force[..lanes],
        &mut recorder.statistics[..lanes],
    );
    let (peaks, wear) = (&mut recorder.force_peak[..lanes], &mut recorder.wear[..lanes]);
    let (tangentials, friction) = (
        &mut state.tangential_force[..lanes],
        &mut recorder.friction[..lanes],
    );
    let impacts = &mut recorder.impacts[..lanes];
    let (clock, log) = (&recorder.impact_clock, &mut recorder.impact_log);
    let at = (step, recorder.impact_block, dt);
    let closed = &state.closed[..count];
    for &j in closed {
        let j = j as usize;
        let (contact, lane) = (lane_contacts[j], plane_lanes[j]);
        let (penetration, previous) = (now[j], before[j]);
        let rows = |offset: usize| (&v[offset..], &a[offset..]);
        let shape = &shapes[contact.shape..][..n];
        let mut rate_x = penetration_rate(simd, shape, rows(contact.left), rows(contact.right), lookahead);
        let mut rate_y = penetration_rate(simd, shape, rows(lane.left_y), rows(lane.right_y), lookahead);
        let [normal_x, normal_y] = lane.normal;
        let (mut wall_rate, mut wall_sliding) = (0.0, 0.0);
        if let Some((layout, wall)) = walls {
            let [x, y] = wall.velocity_of(layout, j);
            (rate_x, rate_y) = (rate_x + x, rate_y + y);
            wall_rate = normal_x * x + normal_y * y;
            wall_sliding = normal_x * y - normal_y * x;
        }
        let rate = normal_x * rate_x + normal_y * rate_y;
        let sliding = normal_x * rate_y - normal_y * rate_x;
        let NormalForce { force, elastic } = contact.force(laws, j, penetration, rate);
        forces[j] = force;
        let mut dissipation = (force - elastic) * rate;
        let mut slipping = true;
        if contact.friction {
            let previous = if previous > 0.0 { tangentials[j] } else { 0.0 };
            let tangential = layout.lane_friction[j].step(previous, sliding, dt, force);
            tangentials[j] = tangential.force;
            dissipation += tangential.dissipation;
            wall_power += tangential.force * wall_sliding;
            slipping = tangential.slipping;
            if record {
                friction[j].record(&tangential, sliding, dt);
            }
        }
        dissipation_power += dissipation;
        wall_power += force * wall_rate;
        if record {
            if force > peaks[j] {
                peaks[j] = force;
            }
            if contact.active {
                record_closed_contact(
                    (&mut statistics[j], &mut impacts[j]),
                    (clock, &mut *log),
                    at,
                    (penetration, previous),
                    (force, dissipation),
                );
            }
            if slipping {
                wear[j] += force * sliding.abs() * dt;
            }
        }
    }
    for &j in closed {
        let j = j as usize;
        let (contact, lane, force) = (lane_contacts[j], plane_lanes[j], forces[j]);
        if force != 0.0 {
            let shape = &shapes[contact.shape..][..n];
            let tangential = if contact.friction { tangentials[j] } else { 0.0 };
            let [x, y] = force_vector(force, tangential, lane.normal);
            if contact.left != wall {
                row_axpy(simd, -x, shape, &mut loads[contact.left..]);
                row_axpy(simd, -y, shape, &mut loads[lane.left_y..]);
            }
            if contact.right != wall {
                row_axpy(simd, x, shape, &mut loads[contact.right..]);
                row_axpy(simd, y, shape, &mut loads[lane.right_y..]);
            }
        }
    }
    if let Some(wall) = &mut state.wall {
        wall.power = wall_power;
    }
    dissipation_power
}

/// [`plane_contact_forces`] shared by `threads` threads ([`ClosedPass`]), but for the
/// loads, which join the rows in the modal update ([`plane_step::update_halves`]).
/// Every lane's powers are stored, then summed in the order of the closed lanes, as
/// [`plane_contact_forces`] sums them.
fn shared_plane_contact_forces<S: Simd>(
    simd: S,
    (layout, plane): (&Layout<'_>, &PlaneContacts),
    state: &mut State,
    recorder: &mut Recorder,
    count: usize,
    (step, record): (u64, bool),
    (vectors, threads): (usize, usize),
) -> f64 {
    let lanes = layout.lane_contacts.len();
    let pass = ClosedPass {
        simd,
        lane_contacts: &layout.lane_contacts,
        lane_laws: &layout.lane_laws,
        lane_friction: &layout.lane_friction,
        plane_lanes: &plane.lanes[..lanes],
        shapes: S::as_simd_f64s(&layout.level_shapes).0,
        v: S::as_simd_f64s(&state.v).0,
        a: S::as_simd_f64s(&state.a).0,
        now: &state.penetration[..lanes],
        before: &state.previous_penetration[..lanes],
        walls: layout.walls.as_ref().zip(state.wall.as_ref()),
        clock: &recorder.impact_clock,
        at: (step, recorder.impact_block, layout.dt),
        record,
        lookahead: layout.dashpot_lookahead,
        vectors,
    };
    let out = LaneOutputs {
        first: 0,
        powers: &mut state.lane_powers[..lanes],
        forces: &mut state.contact_force[..lanes],
        tangentials: &mut state.tangential_force[..lanes],
        statistics: &mut recorder.statistics[..lanes],
        peaks: &mut recorder.force_peak[..lanes],
        wear: &mut recorder.wear[..lanes],
        friction: &mut recorder.friction[..lanes],
        impacts: &mut recorder.impacts[..lanes],
    };
    let closed = &state.closed[..count];
    pass.run(closed, out, &mut recorder.impact_log, threads);
    state.closed_count = count;
    let (mut dissipation_power, mut wall_power) = (0.0, 0.0);
    for &j in closed {
        let [dissipation, wall] = state.lane_powers[j as usize];
        dissipation_power += dissipation;
        wall_power += wall;
    }
    if let Some(wall) = &mut state.wall {
        wall.power = wall_power;
    }
    dissipation_power
}
