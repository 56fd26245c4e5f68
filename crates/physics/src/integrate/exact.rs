//! The `exact_modal` scheme: every mode propagated exactly over the step, the contact
//! forces solved implicitly at the end of it. Its step follows the contacts, not the top
//! of the basis.
//!
//! **Why.** Central difference is stable for ω_max Δt ≤ 2, ω_max the highest frequency
//! of the basis with every contact closed. A basis rich enough to get an impact right on
//! a slender pin (more modes, or the static correction's stiff pseudo-modes) raises
//! ω_max, and the step shrinks with it: more modal DOFs cost quadratically. Here the free
//! motion of every mode is integrated exactly, whatever ω Δt, and the contacts, which
//! couple the modes, are implicit: there is no stability limit, and the step only has to
//! resolve what the results need (the contact durations and the excitation). This is the
//! idea of code_aster's `ITMI` (Antunes, Axisa et al., tube bundles with impacts), here
//! with a fixed step that the step check proves.
//!
//! **The step.** Between tₙ and tₙ₊₁ = tₙ + h every load on a mode (contacts, point
//! forces, base excitation −Γ a(t)) is taken linear in time, from its value at tₙ to its
//! value at tₙ₊₁. Each modal equation q̈ + 2ξω q̇ + ω² q = f(t) then has an exact
//! solution, linear in (qₙ, vₙ, fₙ, fₙ₊₁) ([`Propagator`]). The contact forces at tₙ₊₁
//! depend on the positions at tₙ₊₁, which depend on those forces through the last
//! coefficient: with δ̃ the penetrations predicted with no contact force at tₙ₊₁,
//!   δ = δ̃ − W F,   δ̇ = δ̃̇ − W' F,
//! where W_cc' = G(z_c, z_c') Σ_b s_c(b) s_c'(b), G(z, z') = Σᵢ ψᵢ(z) ψᵢ(z') c₁ᵢ (W' with
//! the velocity's coefficient d₁ᵢ), the sum over the pins b that both contacts touch and
//! s = +1 on a contact's left pin, −1 on its right one. Each contact's law
//! F = max(0, law(δ, δ̇)) while δ > 0 ([`crate::contact::NormalLaw`], the one law of
//! every loop) closes the system; it is solved by a semismooth Newton iteration on the
//! set of contacts that push ([`ContactSolve`]): one linear solve per change of that
//! set for the linear law.
//!
//! **Order.** Loads linear over the step make the scheme second order (the trapezoidal
//! rule of the loads' effect), exact for free vibration and for loads that are linear
//! between steps. The step check proves a run as for central difference.
//!
//! **Energy.** The dissipated and external works are integrated by the trapezoidal rule
//! on the powers at the step ends, as in the other schemes; the balance holds to O(h²).
//!
//! What it does not do (refused up front, [`super::Settings::validate`] and
//! [`super::Model::validate`]): the plane (the hexagonal bundle), walls with their own
//! motion, friction.

use pulp::Simd;

use super::kernels::{self, ContactState};
use super::layout::Layout;
use super::recorder::{Powers, Recorder, record_closed_contact};
use super::state::State;
use crate::contact::NormalLaw;

/// Newton iterations of the contact solve before it gives up.
pub(super) const MAX_ITERATIONS: usize = 60;
/// Terms of the Taylor series of the scaled exponential (its norm is at most 1/4).
const TAYLOR_TERMS: usize = 20;

/// One mode's exact step of length h under a load linear in time: with (q, v) at tₙ and
/// the loads f₀ at tₙ and f₁ at tₙ₊₁,
/// qₙ₊₁ = q·(q, v, f₀, f₁) and vₙ₊₁ = v·(q, v, f₀, f₁).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Propagator {
    pub q: [f64; 4],
    pub v: [f64; 4],
}

impl Propagator {
    /// The exact step of q̈ + 2ξω q̇ + ω² q = f(t), f linear over [0, h], for any ω ≥ 0
    /// and ξ ≥ 0 (ω = 0 included: q + h v + h²(f₀/3 + f₁/6)).
    ///
    /// The state (q, h v, h² f, h³ ḟ) obeys y' = B y in the time τ = t/h, with
    /// B = [[0, 1, 0, 0], [−w², −2ξw, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0]], w = ωh; the
    /// step is exp(B). The exponential is taken on D B D⁻¹, D = diag(s, 1, 1/s, 1/s²),
    /// s = max(w, 1), whose entries are all of order w (a rotation at rate w plus the
    /// load's terms), by scaling and squaring a Taylor series: the entries of a fast
    /// mode stay as accurate as those of a slow one.
    pub(crate) fn new(omega: f64, xi: f64, h: f64) -> Self {
        let w = omega * h;
        let s = w.max(1.0);
        let d = [s, 1.0, 1.0 / s, 1.0 / (s * s)];
        let mut b = [[0.0; 4]; 4];
        b[0][1] = s;
        b[1][0] = -w * w / s;
        b[1][1] = -2.0 * xi * w;
        b[1][2] = s;
        b[2][3] = s;
        let e = exponential(b);
        // E = D⁻¹ exp(D B D⁻¹) D.
        let entry = |i: usize, j: usize| e[i][j] * d[j] / d[i];
        Self {
            q: [
                entry(0, 0),
                h * entry(0, 1),
                h * h * (entry(0, 2) - entry(0, 3)),
                h * h * entry(0, 3),
            ],
            v: [
                entry(1, 0) / h,
                entry(1, 1),
                h * (entry(1, 2) - entry(1, 3)),
                h * entry(1, 3),
            ],
        }
    }
}

/// exp(b) of a 4 × 4 matrix by scaling and squaring a Taylor series.
fn exponential(b: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let norm = b
        .iter()
        .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > 0.25 {
        (norm / 0.25).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    let x = b.map(|row| row.map(|v| v * scale));
    let mut sum = identity();
    let mut term = identity();
    for k in 1..=TAYLOR_TERMS {
        term = product(&term, &x).map(|row| row.map(|v| v / k as f64));
        for (s, t) in sum.iter_mut().zip(&term) {
            for (s, t) in s.iter_mut().zip(t) {
                *s += t;
            }
        }
    }
    for _ in 0..squarings {
        sum = product(&sum, &sum);
    }
    sum
}

fn identity() -> [[f64; 4]; 4] {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

fn product(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            c[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// Where a lane's contact acts: its level and the lines of its left and right pins
/// (`None` for a wall), and its law. Empty lanes and contacts that cannot push are left
/// out of the solve.
#[derive(Debug, Clone, Copy)]
struct LaneBodies {
    lane: usize,
    level: usize,
    left: Option<usize>,
    right: Option<usize>,
    law: NormalLaw,
}

impl LaneBodies {
    /// Σ_b s_c(b) s_c'(b) over the pins both contacts touch.
    fn coupling(&self, other: &Self) -> f64 {
        let sign = |line: Option<usize>, contact: &Self| match line {
            None => 0.0,
            Some(line) if contact.left == Some(line) => 1.0,
            Some(line) if contact.right == Some(line) => -1.0,
            Some(_) => 0.0,
        };
        sign(self.left, other) - sign(self.right, other)
    }
}

/// The exact scheme's data for one run: the propagators for the step, the flexibility
/// of the basis between contact levels over a step, and the loads the next step starts
/// from.
pub(super) struct ExactRun {
    /// Per entry of a row (padded modes have ω = 0 and ψ = 0, and stay 0).
    propagators: Vec<Propagator>,
    /// G(l, l') and G'(l, l') over one step (levels × levels).
    levels: usize,
    flexibility: Vec<f64>,
    rate_flexibility: Vec<f64>,
    /// The contacts that can push, by lane.
    contacts: Vec<LaneBodies>,
    /// Contact and point loads on each line's modes at the current time (lines × row),
    /// the next step's, and the contact part of the next step's.
    loads: Vec<f64>,
    next_loads: Vec<f64>,
    contact_loads: Vec<f64>,
    solve: ContactSolve,
}

impl ExactRun {
    /// For the layout's step; `loads` are the contact and point loads at t = 0.
    pub fn new(layout: &Layout<'_>, loads: Vec<f64>) -> Self {
        let (row, h) = (layout.row, layout.dt);
        let propagators: Vec<Propagator> = (0..row)
            .map(|i| {
                let omega = layout.omega_squared[i].sqrt();
                let xi = if omega > 0.0 {
                    layout.damping[i] / (2.0 * omega)
                } else {
                    0.0
                };
                Propagator::new(omega, xi, h)
            })
            .collect();
        let levels = layout.level_shapes.len() / row;
        let shape = |l: usize| &layout.level_shapes[l * row..][..row];
        let mut flexibility = vec![0.0; levels * levels];
        let mut rate_flexibility = vec![0.0; levels * levels];
        for a in 0..levels {
            for b in 0..levels {
                let (psi_a, psi_b) = (shape(a), shape(b));
                for i in 0..row {
                    let product = psi_a[i] * psi_b[i];
                    flexibility[a * levels + b] += product * propagators[i].q[3];
                    rate_flexibility[a * levels + b] += product * propagators[i].v[3];
                }
            }
        }
        let vectors = row / layout.lanes;
        let line = |offset: usize| (offset != layout.wall_row).then_some(offset / vectors);
        let contacts: Vec<LaneBodies> = layout
            .lane_contacts
            .iter()
            .enumerate()
            .filter(|(lane, contact)| {
                layout.contacts.contact[*lane] != kernels::ContactLanes::EMPTY && contact.active
            })
            .map(|(lane, contact)| LaneBodies {
                lane,
                level: contact.shape / vectors,
                left: line(contact.left),
                right: line(contact.right),
                law: layout.lane_laws[lane],
            })
            .collect();
        let size = loads.len();
        Self {
            propagators,
            levels,
            flexibility,
            rate_flexibility,
            solve: ContactSolve::new(contacts.len(), layout.lines * levels),
            contacts,
            loads,
            next_loads: vec![0.0; size],
            contact_loads: vec![0.0; size],
        }
    }

    /// W_cc' (or W'_cc' with `rate`).
    fn coupling(&self, c: &LaneBodies, other: &LaneBodies, rate: bool) -> f64 {
        let g = if rate {
            &self.rate_flexibility
        } else {
            &self.flexibility
        };
        let coupling = c.coupling(other);
        if coupling == 0.0 {
            0.0
        } else {
            coupling * g[c.level * self.levels + other.level]
        }
    }
}

/// Scratch of the implicit contact solve, per contact of [`ExactRun::contacts`].
struct ContactSolve {
    /// Predicted penetration and rate (no contact force at the step's end).
    predicted: Vec<f64>,
    predicted_rate: Vec<f64>,
    /// Forces of the iterate, the penetrations and rates they give.
    force: Vec<f64>,
    penetration: Vec<f64>,
    rate: Vec<f64>,
    /// The contacts that push in the iterate, the previous iterate's, and the Newton
    /// system on them.
    pushing: Vec<usize>,
    previous: Vec<usize>,
    matrix: Vec<f64>,
    right: Vec<f64>,
    /// Per line and level: the deflection and velocity the iterate's forces add.
    shift: Vec<f64>,
    rate_shift: Vec<f64>,
}

impl ContactSolve {
    fn new(contacts: usize, lines_by_levels: usize) -> Self {
        Self {
            shift: vec![0.0; lines_by_levels],
            rate_shift: vec![0.0; lines_by_levels],
            predicted: vec![0.0; contacts],
            predicted_rate: vec![0.0; contacts],
            force: vec![0.0; contacts],
            penetration: vec![0.0; contacts],
            rate: vec![0.0; contacts],
            pushing: Vec::with_capacity(contacts),
            previous: Vec::with_capacity(contacts),
            matrix: Vec::new(),
            right: Vec::new(),
        }
    }
}

/// Why a step of the exact scheme failed.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct NotConverged {
    pub contacts: usize,
}

/// One step of the exact scheme (to t = n h) on the row, compiled for `simd`: the modes
/// propagated with no contact force at the step's end, the contact forces solved, the
/// modes corrected, then the step's records. Returns the step's powers.
#[inline(always)]
pub(super) fn step<S: Simd>(
    simd: S,
    (layout, state, recorder): (&Layout<'_>, &mut State, &mut Recorder),
    run: &mut ExactRun,
    n: u64,
) -> Result<Powers, NotConverged> {
    let (row, h) = (layout.row, layout.dt);
    let model = layout.model;
    let t = n as f64 * h;
    let t0 = t - h;
    recorder.enter_step(n);
    // The known loads at the step's end: the point forces.
    run.next_loads.fill(0.0);
    for (point, shape) in model.point_forces.iter().zip(&layout.point_force_shapes) {
        kernels::axpy(
            simd,
            point.force.at(t),
            shape,
            &mut run.next_loads[point.line * row..][..row],
        );
    }
    let base = |time: f64| model.base_acceleration.as_ref().map_or(0.0, |b| b.at(time));
    let (base0, base1) = (base(t0), base(t));
    // Every mode without contact force at the step's end.
    for (((q, v), (f0, f1)), _) in state
        .q
        .chunks_exact_mut(row)
        .zip(state.v.chunks_exact_mut(row))
        .zip(run.loads.chunks_exact(row).zip(run.next_loads.chunks_exact(row)))
        .zip(0..layout.lines)
    {
        for i in 0..row {
            let p = &run.propagators[i];
            let gamma = layout.participation[i];
            let (load0, load1) = (f0[i] - gamma * base0, f1[i] - gamma * base1);
            let (qi, vi) = (q[i], v[i]);
            q[i] = p.q[0] * qi + p.q[1] * vi + p.q[2] * load0 + p.q[3] * load1;
            v[i] = p.v[0] * qi + p.v[1] * vi + p.v[2] * load0 + p.v[3] * load1;
        }
    }
    // The predicted penetrations and rates of the contacts that can push.
    let deflections = S::as_mut_simd_f64s(&mut state.level_deflections).0;
    kernels::level_deflections(
        simd,
        &layout.grouped_level_shapes,
        row,
        &state.q,
        deflections,
        layout.stride,
    );
    let lanes = layout.lanes;
    let levels = &state.level_deflections;
    let at = |vector: u32, k: usize| levels[vector as usize * lanes + k];
    let solve = &mut run.solve;
    for (c, contact) in run.contacts.iter().enumerate() {
        let (group, k) = (contact.lane / lanes, contact.lane % lanes);
        let (left, right) = (layout.contacts.left[group], layout.contacts.right[group]);
        solve.predicted[c] = at(left, k) - at(right, k) - layout.gaps[contact.lane];
        solve.predicted_rate[c] = f64::NAN;
    }
    contact_forces(simd, layout, state, run)?;
    // The contacts' loads, into the modes and the next step's loads.
    let run_contacts = &run.contacts;
    run.contact_loads.fill(0.0);
    for (c, contact) in run_contacts.iter().enumerate() {
        let force = run.solve.force[c];
        if force == 0.0 {
            continue;
        }
        let shape = &layout.level_shapes[contact.level * row..][..row];
        if let Some(line) = contact.left {
            kernels::axpy(simd, -force, shape, &mut run.contact_loads[line * row..][..row]);
        }
        if let Some(line) = contact.right {
            kernels::axpy(simd, force, shape, &mut run.contact_loads[line * row..][..row]);
        }
    }
    for (((q, v), (loads, next)), _) in state
        .q
        .chunks_exact_mut(row)
        .zip(state.v.chunks_exact_mut(row))
        .zip(
            run.contact_loads
                .chunks_exact(row)
                .zip(run.next_loads.chunks_exact_mut(row)),
        )
        .zip(0..layout.lines)
    {
        for i in 0..row {
            let p = &run.propagators[i];
            q[i] += p.q[3] * loads[i];
            v[i] += p.v[3] * loads[i];
            next[i] += loads[i];
        }
    }
    std::mem::swap(&mut run.loads, &mut run.next_loads);
    // The step's end as the other schemes record it: level deflections, penetrations
    // (with their running maxima and the closed lanes), forces, statistics, powers.
    let deflections = S::as_mut_simd_f64s(&mut state.level_deflections).0;
    kernels::level_deflections(
        simd,
        &layout.grouped_level_shapes,
        row,
        &state.q,
        deflections,
        layout.stride,
    );
    std::mem::swap(&mut state.penetration, &mut state.previous_penetration);
    let count = kernels::penetrations(
        simd,
        &layout.contacts,
        S::as_simd_f64s(&state.level_deflections).0,
        &layout.gaps,
        ContactState {
            now: &mut state.penetration,
            max: &mut recorder.max_penetration,
            closed: &mut state.closed,
            closed_groups: &mut state.closed_groups,
        },
    );
    state.closed_count = count;
    let solve = &run.solve;
    let mut contact_damping = 0.0;
    for (c, contact) in run.contacts.iter().enumerate() {
        let lane = contact.lane;
        let force = solve.force[c];
        state.contact_force[lane] = force;
        let penetration = state.penetration[lane];
        if penetration <= 0.0 {
            continue;
        }
        // The rate the solve found (the predicted one where the contact closed by
        // rounding alone), and the dashpots' and the force clamp's power (F − K δⁿ) δ̇,
        // as the other schemes count it.
        let rate = match solve.rate[c] {
            rate if rate.is_nan() => 0.0,
            rate => rate,
        };
        let elastic = contact.law.force(penetration, 0.0).elastic;
        let dissipation = (force - elastic) * rate;
        contact_damping += dissipation;
        if force > recorder.force_peak[lane] {
            recorder.force_peak[lane] = force;
        }
        record_closed_contact(
            (&mut recorder.statistics[lane], &mut recorder.impacts[lane]),
            (&recorder.impact_clock, &mut recorder.impact_log),
            (n, recorder.impact_block, h),
            (penetration, state.previous_penetration[lane]),
            (force, dissipation),
        );
    }
    recorder.resultants.track(layout, state, n);
    recorder.track_deflection_peaks(layout, &state.level_deflections);
    let (mut modal_damping, mut participation_velocity) = (0.0, 0.0);
    for v in state.v[..layout.lines * row].chunks_exact(row) {
        for i in 0..row {
            modal_damping += layout.damping[i] * v[i] * v[i];
            participation_velocity += layout.participation[i] * v[i];
        }
    }
    let mut external = -base1 * participation_velocity;
    for (point, shape) in model.point_forces.iter().zip(&layout.point_force_shapes) {
        let velocity = kernels::dot(simd, shape, &state.v[point.line * row..][..row]);
        external += point.force.at(t) * velocity;
    }
    Ok(Powers {
        modal_damping,
        contact_damping,
        external,
    })
}

/// The contact forces at the step's end (`run.solve.force`, with the penetrations and
/// rates they give): F_c = law_c(δ_c, δ̇_c) where that pushes, 0 elsewhere, with
/// δ = δ̃ − W F and δ̇ = δ̃̇ − W' F. Semismooth Newton: at each iterate, the contacts
/// that push get a Newton step of F − law(δ(F), δ̇(F)) = 0 and the others F = 0; it
/// stops when the residual is at rounding level (for the linear law, one solve per
/// change of the set that pushes).
#[inline(always)]
fn contact_forces<S: Simd>(
    simd: S,
    layout: &Layout<'_>,
    state: &State,
    run: &mut ExactRun,
) -> Result<(), NotConverged> {
    let row = layout.row;
    let contacts = &run.contacts;
    let mut solve = std::mem::replace(&mut run.solve, ContactSolve::new(0, 0));
    let rows = |line: Option<usize>| line.map(|line| &state.v[line * row..][..row]);
    let predicted_rate = |contact: &LaneBodies| {
        let shape = &layout.level_shapes[contact.level * row..][..row];
        let side = |line| rows(line).map_or(0.0, |v| kernels::dot(simd, shape, v));
        side(contact.left) - side(contact.right)
    };
    solve.force.fill(0.0);
    solve.previous.clear();
    let mut converged = false;
    for _ in 0..MAX_ITERATIONS {
        // δ and δ̇ of the iterate (only the pushing contacts of the last iterate have a
        // force), and the contacts that push.
        let mut largest: f64 = 0.0;
        let mut residual: f64 = 0.0;
        solve.pushing.clear();
        // The iterate's forces move each pin at each level by Σ ∓F G(l, l_d) (and its
        // velocity by G'): every contact's penetration then reads two of these.
        solve.shift.fill(0.0);
        solve.rate_shift.fill(0.0);
        let levels = run.levels;
        for &d in &solve.previous {
            let (source, force) = (&contacts[d], solve.force[d]);
            let g = &run.flexibility[source.level * levels..][..levels];
            let g_rate = &run.rate_flexibility[source.level * levels..][..levels];
            for (line, sign) in [(source.left, -force), (source.right, force)] {
                if let Some(line) = line {
                    let shift = &mut solve.shift[line * levels..][..levels];
                    let rate_shift = &mut solve.rate_shift[line * levels..][..levels];
                    for l in 0..levels {
                        shift[l] += sign * g[l];
                        rate_shift[l] += sign * g_rate[l];
                    }
                }
            }
        }
        let moved = |shift: &[f64], contact: &LaneBodies| {
            let at = |line: Option<usize>| line.map_or(0.0, |line| shift[line * levels + contact.level]);
            at(contact.left) - at(contact.right)
        };
        for (c, contact) in contacts.iter().enumerate() {
            let penetration = solve.predicted[c] + moved(&solve.shift, contact);
            solve.penetration[c] = penetration;
            let mut target = 0.0;
            if penetration > 0.0 {
                let rate = if contact.law.needs_rate() {
                    if solve.predicted_rate[c].is_nan() {
                        solve.predicted_rate[c] = predicted_rate(contact);
                    }
                    solve.predicted_rate[c] + moved(&solve.rate_shift, contact)
                } else {
                    0.0
                };
                solve.rate[c] = rate;
                target = contact.law.force(penetration, rate).force.max(0.0);
                if target > 0.0 {
                    solve.pushing.push(c);
                }
            } else {
                solve.rate[c] = f64::NAN;
            }
            largest = largest.max(target).max(solve.force[c]);
            residual = residual.max((solve.force[c] - target).abs());
        }
        if residual <= 1e-11 * largest {
            converged = true;
            break;
        }
        // The Newton step on the pushing contacts; the others drop to 0.
        let m = solve.pushing.len();
        solve.matrix.clear();
        solve.matrix.resize(m * m, 0.0);
        solve.right.clear();
        for (a, &c) in solve.pushing.iter().enumerate() {
            let contact = &contacts[c];
            let (stiffness, damping) = contact.law.tangent(solve.penetration[c], solve.rate[c]);
            let jacobian = |d: usize| {
                let other = &contacts[d];
                stiffness * run.coupling(contact, other, false)
                    + if damping != 0.0 {
                        damping * run.coupling(contact, other, true)
                    } else {
                        0.0
                    }
            };
            let target = contact.law.force(solve.penetration[c], solve.rate[c]).force;
            let mut right = target - solve.force[c];
            for &d in &solve.previous {
                if solve.pushing.binary_search(&d).is_err() {
                    right += jacobian(d) * solve.force[d];
                }
            }
            solve.right.push(right);
            for (b, &d) in solve.pushing.iter().enumerate() {
                solve.matrix[a * m + b] = jacobian(d) + if a == b { 1.0 } else { 0.0 };
            }
        }
        solve_dense(&mut solve.matrix, &mut solve.right, m);
        for &d in &solve.previous {
            if solve.pushing.binary_search(&d).is_err() {
                solve.force[d] = 0.0;
            }
        }
        for (a, &c) in solve.pushing.iter().enumerate() {
            solve.force[c] += solve.right[a];
        }
        std::mem::swap(&mut solve.previous, &mut solve.pushing);
    }
    let count = contacts.len();
    run.solve = solve;
    if converged {
        Ok(())
    } else {
        Err(NotConverged { contacts: count })
    }
}

/// Solves the m × m system `matrix` x = `right` in place (x in `right`) by Gaussian
/// elimination with partial pivoting (the Newton systems are small: the contacts that
/// push at one step).
fn solve_dense(matrix: &mut [f64], right: &mut [f64], m: usize) {
    for k in 0..m {
        let pivot = (k..m)
            .max_by(|&a, &b| matrix[a * m + k].abs().total_cmp(&matrix[b * m + k].abs()))
            .unwrap_or(k);
        if pivot != k {
            for j in 0..m {
                matrix.swap(k * m + j, pivot * m + j);
            }
            right.swap(k, pivot);
        }
        let diagonal = matrix[k * m + k];
        for i in k + 1..m {
            let factor = matrix[i * m + k] / diagonal;
            if factor != 0.0 {
                for j in k..m {
                    matrix[i * m + j] -= factor * matrix[k * m + j];
                }
                right[i] -= factor * right[k];
            }
        }
    }
    for k in (0..m).rev() {
        let mut value = right[k];
        for j in k + 1..m {
            value -= matrix[k * m + j] * right[j];
        }
        right[k] = value / matrix[k * m + k];
    }
}
