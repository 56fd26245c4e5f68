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
//! every loop) closes the system, each contact open, pushing or held at touch (where a
//! dashpot makes the law jump): an active-set Newton iteration ([`contact_forces`]),
//! one banded linear solve per change of sides for the linear law.
//!
//! **Order.** Loads linear over the step make the scheme second order (the trapezoidal
//! rule of the loads' effect), exact for free vibration and for loads that are linear
//! between steps. The step check proves a run as for central difference.
//!
//! **Energy.** The dissipated and external works are integrated by the trapezoidal rule
//! on the powers at the step ends, as in the other schemes; the balance holds to O(h²).
//!
//! **The plane.** A contact reads each pin's x and y lines along its normal n:
//! δ = n·(u_L − u_R) − gap, one term per line ([`Term`]); W couples two contacts through
//! the lines they share with the product of their normal components, and the sliding
//! velocity t·(u̇_L − u̇_R) (the wear work) comes from the same terms with t = (−n_y, n_x).
//!
//! What it does not do (refused up front at `scheme`, `Plan::new`): friction, walls
//! with their own motion.

use pulp::Simd;

use super::kernels;
use super::layout::{ContactModel, Layout};
use super::recorder::{Powers, Recorder, record_closed_contact};
use super::state::State;
use crate::contact::NormalLaw;

/// Newton iterations of the contact solve before it gives up.
pub(super) const MAX_ITERATIONS: usize = 400;
/// Iterations of the contact solve after which a contact caught in a cycle changes side
/// only when it is the first wrong one (`CYCLING_CHANGES`).
const SINGLE_CHANGES_AFTER: usize = 20;
/// Side changes in one step that mark a contact as cycling.
const CYCLING_CHANGES: u8 = 3;
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
    ///
    /// The response spectra's step (`response_spectrum::Step`, Nigam–Jennings) is the
    /// same solution in closed form, but it divides by ω² and loses digits as ωh → 0,
    /// which the slow modes of a run reach (ωh ~ 1e-5), and has no ω = 0; it is not
    /// reused here, and left as it is there (its spectra are pinned bit for bit).
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

/// One deflection line a contact reads: δ = Σ `normal` × w_line(z) − gap over its
/// terms, and the sliding velocity v_t = Σ `tangent` × ẇ_line(z). The row: +1 on the
/// left pin's line, −1 on the right one's; the plane: ±n_x on the x lines, ±n_y on the
/// y lines (t = (−n_y, n_x)). A force F on the contact loads the line by −`normal` F ψ.
#[derive(Debug, Clone, Copy, Default)]
struct Term {
    line: usize,
    normal: f64,
    tangent: f64,
}

/// A lane's contact: its level, the lines it reads (none for a wall) and its law.
#[derive(Debug, Clone, Copy)]
struct LaneBodies {
    lane: usize,
    /// The first pin it touches (its place in the banded Newton system).
    order: usize,
    level: usize,
    terms: [Term; 4],
    count: usize,
    law: NormalLaw,
}

impl LaneBodies {
    fn terms(&self) -> &[Term] {
        &self.terms[..self.count]
    }

    /// Σ over the lines both contacts read of the product of their normal coefficients.
    fn coupling(&self, other: &Self) -> f64 {
        let mut sum = 0.0;
        for a in self.terms() {
            for b in other.terms() {
                if a.line == b.line {
                    sum += a.normal * b.normal;
                }
            }
        }
        sum
    }
}

/// The exact scheme's data for one run: the propagators for the step, the flexibility
/// of the basis between contact levels over a step, and the loads the next step starts
/// from.
pub(super) struct ExactRun {
    /// Per entry of a row (padded modes have ω = 0 and ψ = 0, and stay 0), the
    /// propagator's coefficients one array each (`q[k][i]`: mode i's coefficient k of
    /// its position), so that the updates run in vectors.
    q_coefficients: [Vec<f64>; 4],
    v_coefficients: [Vec<f64>; 4],
    /// G(l, l') and G'(l, l') over one step (levels × levels).
    levels: usize,
    flexibility: Vec<f64>,
    rate_flexibility: Vec<f64>,
    /// Every contact, by lane (one that cannot push never does: its law gives 0).
    contacts: Vec<LaneBodies>,
    /// Contact and point loads on each line's modes at the current time (lines × row),
    /// the next step's, and the contact part of the next step's.
    loads: Vec<f64>,
    next_loads: Vec<f64>,
    contact_loads: Vec<f64>,
    /// Whether some law reads the penetration rate, and then the predicted velocities
    /// at the levels (laid out as the level deflections).
    rates: bool,
    level_velocities: Vec<f64>,
    /// Whether every law is linear (its Newton system then depends on the sides only).
    linear: bool,
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
        let pins = layout.model.pins;
        let line = |offset: usize| (offset != layout.wall_row).then_some(offset / vectors);
        let contacts: Vec<LaneBodies> = layout
            .lane_contacts
            .iter()
            .enumerate()
            .filter(|(lane, _)| layout.contacts.contact[*lane] != kernels::ContactLanes::EMPTY)
            .map(|(lane, contact)| {
                let (left, right) = (line(contact.left), line(contact.right));
                // The row reads the x lines along +x; the plane each pin's x and y lines
                // along its normal.
                let [n_x, n_y] = match &layout.contact_model {
                    ContactModel::Row => [1.0, 0.0],
                    ContactModel::Plane(plane) => plane.lanes[lane].normal,
                };
                let mut terms = [Term::default(); 4];
                let mut count = 0;
                for (pin, side) in [(left, 1.0), (right, -1.0)] {
                    let Some(pin) = pin else { continue };
                    for (line, normal, tangent) in [(pin, n_x, -n_y), (pins + pin, n_y, n_x)] {
                        if normal != 0.0 || (tangent != 0.0 && line < layout.lines) {
                            terms[count] = Term {
                                line,
                                normal: side * normal,
                                tangent: side * tangent,
                            };
                            count += 1;
                        }
                    }
                }
                LaneBodies {
                    lane,
                    order: left.into_iter().chain(right).min().unwrap_or(0),
                    level: contact.shape / vectors,
                    terms,
                    count,
                    law: layout.lane_laws[lane],
                }
            })
            .collect();
        let size = loads.len();
        let rates = contacts.iter().any(|c| c.law.needs_rate()) || layout.model.plane.is_some();
        let linear = contacts.iter().all(|c| c.law.is_linear());
        let column = |get: &dyn Fn(&Propagator) -> f64| propagators.iter().map(get).collect::<Vec<f64>>();
        Self {
            rates,
            linear,
            level_velocities: vec![0.0; layout.level_deflections_len()],
            q_coefficients: [0, 1, 2, 3].map(|k| column(&|p: &Propagator| p.q[k])),
            v_coefficients: [0, 1, 2, 3].map(|k| column(&|p: &Propagator| p.v[k])),
            levels,
            flexibility,
            rate_flexibility,
            solve: ContactSolve::new(contacts.len(), (layout.lines, levels)),
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

/// What a contact does in an iterate of the contact solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    /// No force.
    Open,
    /// Penetrating and pushing: F = law(δ, δ̇) > 0.
    Pushing,
    /// Just touching at the step's end (δ = 0) with 0 ≤ F ≤ law(0⁺, δ̇): where the
    /// dashpot makes the law jump at δ = 0 (c δ̇ at once), the step may end with the
    /// contact held exactly at touch by a force within that jump (the set-valued law's
    /// solution; no other exists there).
    Touching,
}

/// Scratch of the implicit contact solve, per contact of [`ExactRun::contacts`].
struct ContactSolve {
    /// Predicted penetration and rate (no contact force at the step's end; the rate 0
    /// where no law reads it).
    predicted: Vec<f64>,
    predicted_rate: Vec<f64>,
    /// Forces of the iterate, the penetrations and rates they give.
    force: Vec<f64>,
    penetration: Vec<f64>,
    rate: Vec<f64>,
    /// Each contact's side in the iterate, kept from one step to the next (the next
    /// step starts from it).
    side: Vec<Side>,
    /// The contacts with a force in the iterate, those not open in the next one, and
    /// the contacts whose side is wrong.
    loaded: Vec<usize>,
    active: Vec<usize>,
    wrong: Vec<(usize, Side)>,
    /// Per contact, how many times it changed side in this step, and those that did.
    changes: Vec<u8>,
    changed: Vec<usize>,
    /// Per contact, whether it is in the Newton system; the system, and a copy of it
    /// for the pivoted solve.
    in_system: Vec<bool>,
    matrix: Vec<f64>,
    right: Vec<f64>,
    backup: Vec<f64>,
    /// The contacts and sides of the system whose factors `matrix` holds (empty when
    /// it holds none), and its band.
    factored: Vec<(usize, Side)>,
    factored_band: usize,
    /// Per contact of the system, the law's tangent (∂F/∂δ, ∂F/∂δ̇) (K, 0 for a touching
    /// one); per line, the system's contacts on it and their sign.
    factors: Vec<(f64, f64)>,
    by_line: Vec<Vec<(usize, f64)>>,
    /// Per line and level: the deflection and velocity the iterate's forces add.
    shift: Vec<f64>,
    rate_shift: Vec<f64>,
}

impl ContactSolve {
    fn new(contacts: usize, (lines, levels): (usize, usize)) -> Self {
        let lines_by_levels = lines * levels;
        Self {
            predicted: vec![0.0; contacts],
            predicted_rate: vec![0.0; contacts],
            force: vec![0.0; contacts],
            penetration: vec![0.0; contacts],
            rate: vec![0.0; contacts],
            side: vec![Side::Open; contacts],
            loaded: Vec::with_capacity(contacts),
            active: Vec::with_capacity(contacts),
            wrong: Vec::with_capacity(contacts),
            changes: vec![0; contacts],
            changed: Vec::with_capacity(contacts),
            in_system: vec![false; contacts],
            matrix: Vec::new(),
            right: Vec::new(),
            backup: Vec::new(),
            factored: Vec::new(),
            factored_band: 0,
            factors: Vec::new(),
            by_line: vec![Vec::new(); lines],
            shift: vec![0.0; lines_by_levels],
            rate_shift: vec![0.0; lines_by_levels],
        }
    }
}

/// Why a step of the exact scheme failed.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct NotConverged {
    pub contacts: usize,
}

/// One step of the exact scheme (to t = n h), compiled for `simd`: the modes
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
    // The base acceleration along x, and along y in the plane (the y lines follow the x
    // lines).
    let base_y = model.plane.as_ref().and_then(|p| p.base_acceleration_y.as_ref());
    let at = |base: Option<&crate::loads::BaseAcceleration>, time: f64| base.map_or(0.0, |b| b.at(time));
    let bases = [
        (
            at(model.base_acceleration.as_ref(), t0),
            at(model.base_acceleration.as_ref(), t),
        ),
        (at(base_y, t0), at(base_y, t)),
    ];
    let pins = model.pins;
    // Every mode without contact force at the step's end.
    let ([q0, q1, q2, q3], [v0, v1, v2, v3]) = (&run.q_coefficients, &run.v_coefficients);
    // One length for every row, so that the loop runs in vectors without bounds checks.
    let (q0, q1, q2, q3) = (&q0[..row], &q1[..row], &q2[..row], &q3[..row]);
    let (v0, v1, v2, v3) = (&v0[..row], &v1[..row], &v2[..row], &v3[..row]);
    let gamma = &layout.participation[..row];
    for (((q, v), (f0, f1)), line) in state
        .q
        .chunks_exact_mut(row)
        .zip(state.v.chunks_exact_mut(row))
        .zip(run.loads.chunks_exact(row).zip(run.next_loads.chunks_exact(row)))
        .zip(0..layout.lines)
    {
        let (base0, base1) = bases[usize::from(line >= pins)];
        let (q, v, f0, f1) = (&mut q[..row], &mut v[..row], &f0[..row], &f1[..row]);
        for i in 0..row {
            let (load0, load1) = (f0[i] - gamma[i] * base0, f1[i] - gamma[i] * base1);
            let (qi, vi) = (q[i], v[i]);
            q[i] = q0[i] * qi + q1[i] * vi + q2[i] * load0 + q3[i] * load1;
            v[i] = v0[i] * qi + v1[i] * vi + v2[i] * load0 + v3[i] * load1;
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
    // The velocities at the levels too, where a law reads the rate.
    if run.rates {
        kernels::level_deflections(
            simd,
            &layout.grouped_level_shapes,
            row,
            &state.v[..layout.lines * row],
            S::as_mut_simd_f64s(&mut run.level_velocities).0,
            layout.stride,
        );
    }
    let (lanes, stride) = (layout.lanes, layout.stride);
    let (levels, velocities) = (&state.level_deflections, &run.level_velocities);
    let offset = |line: usize, level: usize| Layout::level_offset(lanes, stride, level) + line * lanes;
    let solve = &mut run.solve;
    for (c, contact) in run.contacts.iter().enumerate() {
        let read = |values: &[f64]| {
            contact
                .terms()
                .iter()
                .map(|t| t.normal * values[offset(t.line, contact.level)])
                .sum::<f64>()
        };
        solve.predicted[c] = read(levels) - layout.gaps[contact.lane];
        solve.predicted_rate[c] = if run.rates { read(velocities) } else { 0.0 };
    }
    contact_forces(run)?;
    // The contacts' loads, into the modes and the next step's loads.
    let run_contacts = &run.contacts;
    run.contact_loads.fill(0.0);
    for (c, contact) in run_contacts.iter().enumerate() {
        let force = run.solve.force[c];
        if force == 0.0 {
            continue;
        }
        let shape = &layout.level_shapes[contact.level * row..][..row];
        for term in contact.terms() {
            kernels::axpy(
                simd,
                -term.normal * force,
                shape,
                &mut run.contact_loads[term.line * row..][..row],
            );
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
        let ([.., q3], [.., v3]) = (&run.q_coefficients, &run.v_coefficients);
        let (q3, v3, q, v) = (&q3[..row], &v3[..row], &mut q[..row], &mut v[..row]);
        let (loads, next) = (&loads[..row], &mut next[..row]);
        for i in 0..row {
            q[i] += q3[i] * loads[i];
            v[i] += v3[i] * loads[i];
            next[i] += loads[i];
        }
    }
    std::mem::swap(&mut run.loads, &mut run.next_loads);
    // The step's end as the other schemes record it: the level deflections (the
    // predicted ones moved by the forces, as the solve found them), penetrations with
    // their running maxima and the closed lanes, forces, statistics, powers.
    let solve = &run.solve;
    let levels = run.levels;
    for (line, shift) in solve.shift.chunks_exact(levels).enumerate() {
        for (level, moved) in shift.iter().enumerate() {
            state.level_deflections[offset(line, level)] += moved;
        }
    }
    std::mem::swap(&mut state.penetration, &mut state.previous_penetration);
    let (mut count, mut contact_damping) = (0, 0.0);
    for (c, contact) in run.contacts.iter().enumerate() {
        let (lane, penetration, force) = (contact.lane, solve.penetration[c], solve.force[c]);
        state.penetration[lane] = penetration;
        state.contact_force[lane] = force;
        let max = &mut recorder.max_penetration[lane];
        *max = max.max(penetration);
        if penetration <= 0.0 && force == 0.0 {
            continue;
        }
        // The dashpots' and the force clamp's power (F − K δⁿ) δ̇, as the other schemes
        // count it, and the power of a force held at touch (δ = 0).
        let rate = solve.rate[c];
        let elastic = contact.law.force(penetration.max(0.0), 0.0).elastic;
        let dissipation = (force - elastic) * rate;
        contact_damping += dissipation;
        if penetration <= 0.0 {
            continue;
        }
        state.closed[count] = lane as u32;
        count += 1;
        if force > recorder.force_peak[lane] {
            recorder.force_peak[lane] = force;
        }
        if !recorder.wear.is_empty() {
            // The sliding velocity at the step's end: the predicted level velocities
            // moved by the forces (the plane's wear work ∫ F |v_t| dt).
            let sliding: f64 = contact
                .terms()
                .iter()
                .map(|term| {
                    let at = offset(term.line, contact.level);
                    term.tangent
                        * (run.level_velocities[at] + solve.rate_shift[term.line * levels + contact.level])
                })
                .sum();
            recorder.wear[lane] += force * sliding.abs() * h;
        }
        record_closed_contact(
            (&mut recorder.statistics[lane], &mut recorder.impacts[lane]),
            (&recorder.impact_clock, &mut recorder.impact_log),
            (n, recorder.impact_block, h),
            (penetration, state.previous_penetration[lane]),
            (force, dissipation),
        );
    }
    state.closed_count = count;
    recorder.resultants.track(layout, state, n);
    recorder.track_deflection_peaks(layout, &state.level_deflections);
    let (mut modal_damping, mut external) = (0.0, 0.0);
    for (line, v) in state.v[..layout.lines * row].chunks_exact(row).enumerate() {
        let mut participation_velocity = 0.0;
        for i in 0..row {
            modal_damping += layout.damping[i] * v[i] * v[i];
            participation_velocity += layout.participation[i] * v[i];
        }
        external -= bases[usize::from(line >= pins)].1 * participation_velocity;
    }
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
/// rates they give), with δ = δ̃ − W F and δ̇ = δ̃̇ − W' F: each contact open (F = 0),
/// pushing (F = law(δ, δ̇) > 0 with δ > 0) or touching (δ = 0, 0 ≤ F ≤ law(0⁺, δ̇)).
/// An active-set Newton iteration: each iterate puts every contact on the side its
/// penetration and force ask for, then takes a Newton step of the equations of those
/// sides (one linear solve per change of sides for the linear law); it stops when every
/// side holds and the residual is at rounding level. From [`SINGLE_CHANGES_AFTER`]
/// iterations on, a contact that has changed side [`CYCLING_CHANGES`] times in the step
/// changes again only as the first wrong one, which ends the cycles simultaneous
/// changes can fall into without slowing the many changes of a bundle's first touch. Each
/// step starts from the sides the last one ended with. Inlined into the step, so that
/// its loops (the banded elimination above all) are compiled for the step's SIMD level.
#[inline(always)]
fn contact_forces(run: &mut ExactRun) -> Result<(), NotConverged> {
    let levels = run.levels;
    let contacts = &run.contacts;
    let mut solve = std::mem::replace(&mut run.solve, ContactSolve::new(0, (0, 0)));
    for &d in &solve.loaded {
        solve.force[d] = 0.0;
    }
    solve.loaded.clear();
    for &c in &solve.changed {
        solve.changes[c] = 0;
    }
    solve.changed.clear();
    let mut converged = false;
    for iteration in 0..MAX_ITERATIONS {
        // The iterate's forces move each line at each level by Σ ∓F G(l, l_d) (and its
        // velocity by G'): every contact's penetration then reads those of its lines.
        solve.shift.fill(0.0);
        solve.rate_shift.fill(0.0);
        for &d in &solve.loaded {
            let (source, force) = (&contacts[d], solve.force[d]);
            let g = &run.flexibility[source.level * levels..][..levels];
            let g_rate = &run.rate_flexibility[source.level * levels..][..levels];
            for term in source.terms() {
                let sign = -term.normal * force;
                let shift = &mut solve.shift[term.line * levels..][..levels];
                let rate_shift = &mut solve.rate_shift[term.line * levels..][..levels];
                for l in 0..levels {
                    shift[l] += sign * g[l];
                    rate_shift[l] += sign * g_rate[l];
                }
            }
        }
        let moved = |shift: &[f64], contact: &LaneBodies| {
            contact
                .terms()
                .iter()
                .map(|t| t.normal * shift[t.line * levels + contact.level])
                .sum::<f64>()
        };
        // Each contact's side, and the residual of its equation. An open contact whose
        // predicted penetration is below −2 × the largest shift cannot close: skipped
        // (its penetration is read once the solve is done).
        let reach = -2.0 * solve.shift.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        let (mut scale, mut residual): (f64, f64) = (0.0, 0.0);
        solve.wrong.clear();
        for (c, contact) in contacts.iter().enumerate() {
            let side = solve.side[c];
            if side == Side::Open && solve.predicted[c] < reach {
                continue;
            }
            let penetration = solve.predicted[c] + moved(&solve.shift, contact);
            solve.penetration[c] = penetration;
            let force = solve.force[c];
            let rate = if contact.law.needs_rate() && (penetration > 0.0 || side != Side::Open) {
                solve.predicted_rate[c] + moved(&solve.rate_shift, contact)
            } else {
                0.0
            };
            solve.rate[c] = rate;
            let law = if penetration > 0.0 {
                contact.law.force(penetration, rate).force
            } else {
                0.0
            };
            let touch = contact.law.force(0.0, rate).force;
            let wanted = match side {
                Side::Open if penetration > 0.0 && law > 0.0 => Side::Pushing,
                Side::Open => Side::Open,
                Side::Pushing if penetration <= 0.0 && touch > 0.0 => Side::Touching,
                Side::Pushing if penetration <= 0.0 || law <= 0.0 => Side::Open,
                Side::Pushing => {
                    residual = residual.max((force - law).abs());
                    Side::Pushing
                }
                Side::Touching if touch <= 0.0 || force < 0.0 => Side::Open,
                Side::Touching if force > touch => Side::Pushing,
                Side::Touching => {
                    residual = residual.max((contact.law.stiffness * penetration).abs());
                    Side::Touching
                }
            };
            scale = scale.max(force.abs()).max(law);
            if wanted != side {
                solve.wrong.push((c, wanted));
            }
        }
        if solve.wrong.is_empty() && residual <= 1e-11 * scale {
            converged = true;
            for (c, contact) in contacts.iter().enumerate() {
                if solve.side[c] == Side::Open && solve.predicted[c] < reach {
                    solve.penetration[c] = solve.predicted[c] + moved(&solve.shift, contact);
                    solve.rate[c] = 0.0;
                }
            }
            break;
        }
        // Every wrong side changed; once simultaneous changes have had their chance,
        // a contact that has already changed `CYCLING_CHANGES` times in this step (a
        // cycle) changes only if it is the first wrong one.
        let mut first = true;
        for &(c, side) in &solve.wrong {
            let cycling = iteration >= SINGLE_CHANGES_AFTER && solve.changes[c] >= CYCLING_CHANGES;
            if !cycling || first {
                if solve.changes[c] == 0 {
                    solve.changed.push(c);
                }
                solve.changes[c] = solve.changes[c].saturating_add(1);
                solve.side[c] = side;
            }
            first = false;
        }
        // The Newton step on the contacts not open; the others drop to 0.
        // In the order of the pins they touch, so that the system is banded (contacts
        // couple only through a pin they share).
        solve.active.clear();
        solve
            .active
            .extend((0..contacts.len()).filter(|&c| solve.side[c] != Side::Open));
        solve.active.sort_by_key(|&c| contacts[c].order);
        for &c in &solve.active {
            solve.in_system[c] = true;
        }
        let m = solve.active.len();
        // With linear laws the system depends on the contacts and their sides only:
        // the factors of the last system serve again while they are the same (a
        // contact stays closed over many steps).
        let reuse = run.linear
            && solve.factored.len() == m
            && solve
                .factored
                .iter()
                .zip(&solve.active)
                .all(|(&(c, side), &a)| c == a && side == solve.side[a]);
        if !reuse {
            solve.matrix.clear();
            solve.matrix.resize(m * m, 0.0);
        }
        solve.right.clear();
        solve.factors.clear();
        // Per line, the system's contacts on it with their sign (+1 on the left pin).
        for list in &mut solve.by_line {
            list.clear();
        }
        for (a, &c) in solve.active.iter().enumerate() {
            for term in contacts[c].terms() {
                solve.by_line[term.line].push((a, term.normal));
            }
        }
        for (a, &c) in solve.active.iter().enumerate() {
            let contact = &contacts[c];
            let (penetration, rate, force) = (solve.penetration[c], solve.rate[c], solve.force[c]);
            // A pushing contact's row: F − law(δ(F), δ̇(F)) = 0, linearised; a touching
            // one's: K δ(F) = 0.
            let (stiffness, damping, mut right) = match solve.side[c] {
                Side::Pushing => {
                    let (k, g) = contact.law.tangent(penetration.max(0.0), rate);
                    let law = contact.law.force(penetration.max(0.0), rate).force;
                    (k, g, law - force)
                }
                _ => {
                    let k = if contact.law.stiffness > 0.0 {
                        contact.law.stiffness
                    } else {
                        1.0
                    };
                    (k, 0.0, k * penetration)
                }
            };
            let jacobian = |d: usize| {
                let other = &contacts[d];
                stiffness * run.coupling(contact, other, false)
                    + if damping != 0.0 {
                        damping * run.coupling(contact, other, true)
                    } else {
                        0.0
                    }
            };
            for &d in &solve.loaded {
                if !solve.in_system[d] {
                    right += jacobian(d) * solve.force[d];
                }
            }
            solve.right.push(right);
            solve.factors.push((stiffness, damping));
            if !reuse && solve.side[c] == Side::Pushing {
                solve.matrix[a * m + a] = 1.0;
            }
        }
        // J_ab += (k_a G(l_a, l_b) + γ_a G'(l_a, l_b)) s_a s_b over the lines both
        // touch: W = Σ_lines, assembled line by line (contacts couple only there).
        let mut band = if reuse { solve.factored_band } else { 0 };
        for list in solve.by_line.iter().filter(|_| !reuse) {
            for &(a, sign_a) in list {
                let (stiffness, damping) = solve.factors[a];
                let level = contacts[solve.active[a]].level * levels;
                let (g, g_rate) = (
                    &run.flexibility[level..][..levels],
                    &run.rate_flexibility[level..][..levels],
                );
                for &(b, sign_b) in list {
                    let other = contacts[solve.active[b]].level;
                    let value = stiffness * g[other] + damping * g_rate[other];
                    solve.matrix[a * m + b] += sign_a * sign_b * value;
                    band = band.max(a.abs_diff(b));
                }
            }
        }
        if reuse {
            substitute_banded(&solve.matrix, &mut solve.right, (m, band));
        } else {
            solve.backup.clear();
            solve.backup.extend_from_slice(&solve.matrix);
            solve.factored.clear();
            if factor_banded(&mut solve.matrix, (m, band)) {
                substitute_banded(&solve.matrix, &mut solve.right, (m, band));
                solve
                    .factored
                    .extend(solve.active.iter().map(|&c| (c, solve.side[c])));
                solve.factored_band = band;
            } else {
                solve.matrix.copy_from_slice(&solve.backup);
                solve_dense(&mut solve.matrix, &mut solve.right, m);
            }
        }
        for &d in &solve.loaded {
            if !solve.in_system[d] {
                solve.force[d] = 0.0;
            }
        }
        for &c in &solve.active {
            solve.in_system[c] = false;
        }
        for (a, &c) in solve.active.iter().enumerate() {
            solve.force[c] += solve.right[a];
        }
        std::mem::swap(&mut solve.loaded, &mut solve.active);
    }
    let count = contacts.len();
    run.solve = solve;
    if converged {
        Ok(())
    } else {
        Err(NotConverged { contacts: count })
    }
}

/// Factors the m × m system `matrix` in place as L U within its band (the multipliers
/// below the diagonal), without pivoting: the contacts are ordered by the pins they
/// touch and couple only through a shared pin, and the system (K⁻¹ + W scaled by K, W
/// the basis's flexibility between the contacts) needs no pivots. False, and `matrix`
/// spoilt, when a pivot is tiny against its row (the caller then solves with pivots).
#[inline(always)]
fn factor_banded(matrix: &mut [f64], (m, band): (usize, usize)) -> bool {
    for k in 0..m {
        let end = m.min(k + band + 1);
        let diagonal = matrix[k * m + k];
        let size = matrix[k * m..k * m + end]
            .iter()
            .fold(0.0_f64, |a, x| a.max(x.abs()));
        if diagonal.abs() <= 1e-10 * size || diagonal.is_nan() {
            return false;
        }
        let (pivot_row, rest) = matrix[k * m..].split_at_mut(m);
        let pivot_row = &pivot_row[..end];
        for i in k + 1..end {
            let row = &mut rest[(i - k - 1) * m..][..end];
            let factor = row[k] / diagonal;
            row[k] = factor;
            if factor != 0.0 {
                for j in k + 1..end {
                    row[j] -= factor * pivot_row[j];
                }
            }
        }
    }
    true
}

/// Solves L U x = `right` in place with the factors of [`factor_banded`].
#[inline(always)]
fn substitute_banded(factors: &[f64], right: &mut [f64], (m, band): (usize, usize)) {
    for i in 0..m {
        let mut value = right[i];
        for k in i.saturating_sub(band)..i {
            value -= factors[i * m + k] * right[k];
        }
        right[i] = value;
    }
    for k in (0..m).rev() {
        let end = m.min(k + band + 1);
        let mut value = right[k];
        for j in k + 1..end {
            value -= factors[k * m + j] * right[j];
        }
        right[k] = value / factors[k * m + k];
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
