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
//! dashpot makes the law jump). It is solved by nonlinear Gauss–Seidel
//! ([`contact_forces`]): each contact's force solved exactly against the others'
//! ([`implicit_force`]), sweep after sweep, from the last step's forces. W is symmetric
//! and positive, so the sweeps converge (projected Gauss–Seidel on K⁻¹ + W); where the
//! step resolves the contacts K W is small (about (ω_c h)², plus K times the static
//! correction's flexibility), and 3–6 sweeps settle a step (row17, 19 and 37 wire-wrapped
//! pins). A sweep costs O(contacts × levels); a direct solve of the contacts' system
//! (the first version: active-set Newton, banded LU) cost O(m³) on a bundle, whose
//! hundreds of pushing wire contacts couple within a band of hundreds.
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

/// A penetration within this share of the deflections and gap it is the difference of
/// is rounding (taken as none).
const ROUNDING: f64 = 1e-12;
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
    level: usize,
    terms: [Term; 4],
    count: usize,
    law: NormalLaw,
}

impl LaneBodies {
    fn terms(&self) -> &[Term] {
        &self.terms[..self.count]
    }

    /// Σ of its normal coefficients squared over the terms whose line `of` keeps (its
    /// terms read distinct lines): W_cc = this × G(l, l) for the lines of one kind.
    fn self_coupling(&self, of: impl Fn(usize) -> bool) -> f64 {
        self.terms()
            .iter()
            .filter(|t| of(t.line))
            .map(|t| t.normal * t.normal)
            .sum()
    }
}

/// The exact scheme's data for one run: the propagators for the step, the flexibility
/// of the basis between contact levels over a step, and the loads the next step starts
/// from.
pub(super) struct ExactRun {
    /// Per kind of body ([`Layout::kinds`]) and entry of a row (padded modes have ω = 0
    /// and ψ = 0, and stay 0), the propagator's coefficients one array each
    /// (`q[k][i]`: mode i's coefficient k of its position), so that the updates run in
    /// vectors.
    q_coefficients: Vec<[Vec<f64>; 4]>,
    v_coefficients: Vec<[Vec<f64>; 4]>,
    /// Per kind, G(l, l') and G'(l, l') over one step (levels × levels), its loads
    /// divided by its mass.
    levels: usize,
    flexibility: Vec<Vec<f64>>,
    rate_flexibility: Vec<Vec<f64>>,
    /// The kind of each line, and each kind's 1/μ.
    line_kinds: Vec<usize>,
    inverse_masses: Vec<f64>,
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
    /// Per contact, W_cc and W'_cc.
    own: Vec<(f64, f64)>,
    solve: ContactSolve,
}

impl ExactRun {
    /// For the layout's step; `loads` are the contact and point loads at t = 0.
    pub fn new(layout: &Layout<'_>, loads: Vec<f64>) -> Self {
        let (row, h) = (layout.row, layout.dt);
        let propagators: Vec<Vec<Propagator>> = layout
            .kinds
            .iter()
            .map(|kind| {
                (0..row)
                    .map(|i| {
                        let omega = kind.omega_squared[i].sqrt();
                        let xi = if omega > 0.0 {
                            kind.damping[i] / (2.0 * omega)
                        } else {
                            0.0
                        };
                        Propagator::new(omega, xi, h)
                    })
                    .collect()
            })
            .collect();
        let levels = layout.level_shapes.len() / row;
        let shape = |l: usize| &layout.level_shapes[l * row..][..row];
        let mut flexibility = vec![vec![0.0; levels * levels]; layout.kinds.len()];
        let mut rate_flexibility = flexibility.clone();
        for (k, kind) in layout.kinds.iter().enumerate() {
            for a in 0..levels {
                for b in 0..levels {
                    let (psi_a, psi_b) = (shape(a), shape(b));
                    for i in 0..row {
                        let product = psi_a[i] * psi_b[i] * kind.inverse_mass;
                        flexibility[k][a * levels + b] += product * propagators[k][i].q[3];
                        rate_flexibility[k][a * levels + b] += product * propagators[k][i].v[3];
                    }
                }
            }
        }
        let pin_kinds = layout.model.pin_kinds();
        let line_kinds: Vec<usize> = (0..layout.lines)
            .map(|line| pin_kinds[line % layout.model.pins])
            .collect();
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
                    level: contact.shape / vectors,
                    terms,
                    count,
                    law: layout.lane_laws[lane],
                }
            })
            .collect();
        let size = loads.len();
        let rates = contacts.iter().any(|c| c.law.needs_rate()) || layout.model.plane.is_some();
        let column = |kind: &[Propagator], get: &dyn Fn(&Propagator) -> f64| {
            kind.iter().map(get).collect::<Vec<f64>>()
        };
        let own = contacts
            .iter()
            .map(|c| {
                // W_cc = Σ over the kinds of its lines of (Σ normal²) G_kind(l, l).
                let g = c.level * levels + c.level;
                let mut kinds: Vec<usize> = c.terms().iter().map(|t| line_kinds[t.line]).collect();
                kinds.sort_unstable();
                kinds.dedup();
                kinds.iter().fold((0.0, 0.0), |(w, w_rate), &kind| {
                    let coupling = c.self_coupling(|line| line_kinds[line] == kind);
                    (
                        w + coupling * flexibility[kind][g],
                        w_rate + coupling * rate_flexibility[kind][g],
                    )
                })
            })
            .collect();
        Self {
            own,
            rates,
            level_velocities: vec![0.0; layout.level_deflections_len()],
            q_coefficients: propagators
                .iter()
                .map(|kind| [0, 1, 2, 3].map(|k| column(kind, &|p: &Propagator| p.q[k])))
                .collect(),
            v_coefficients: propagators
                .iter()
                .map(|kind| [0, 1, 2, 3].map(|k| column(kind, &|p: &Propagator| p.v[k])))
                .collect(),
            line_kinds,
            inverse_masses: layout.kinds.iter().map(|k| k.inverse_mass).collect(),
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
}

/// Scratch of the implicit contact solve, per contact of [`ExactRun::contacts`].
struct ContactSolve {
    /// Predicted penetration and rate (no contact force at the step's end; the rate 0
    /// where no law reads it).
    predicted: Vec<f64>,
    predicted_rate: Vec<f64>,
    /// Per contact, the penetration below which it is rounding: a relative 1e-12 of
    /// the deflections and gap it is the difference of. Pins that move together on
    /// contacts with no gap (the wire-wrapped bundle's wires at rest) predict
    /// penetrations of ±1e-20 m, which must not decide whether a contact pushes.
    floor: Vec<f64>,
    /// The forces, kept from one step to the next (the next solve starts from them),
    /// and the penetrations and rates they give.
    force: Vec<f64>,
    penetration: Vec<f64>,
    rate: Vec<f64>,
    /// The contacts with a force; those the sweeps visit, and whether each is one.
    loaded: Vec<usize>,
    swept: Vec<usize>,
    in_sweep: Vec<bool>,
    /// Per line and level: the deflection and velocity the forces add.
    shift: Vec<f64>,
    rate_shift: Vec<f64>,
}

impl ContactSolve {
    fn new(contacts: usize, (lines, levels): (usize, usize)) -> Self {
        let lines_by_levels = lines * levels;
        Self {
            predicted: vec![0.0; contacts],
            predicted_rate: vec![0.0; contacts],
            floor: vec![0.0; contacts],
            force: vec![0.0; contacts],
            penetration: vec![0.0; contacts],
            rate: vec![0.0; contacts],
            loaded: Vec::with_capacity(contacts),
            swept: Vec::with_capacity(contacts),
            in_sweep: vec![false; contacts],
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
    // Every mode without contact force at the step's end, each line with its kind's
    // propagator and its loads divided by its kind's mass.
    let gamma = &layout.participation[..row];
    for (((q, v), (f0, f1)), line) in state
        .q
        .chunks_exact_mut(row)
        .zip(state.v.chunks_exact_mut(row))
        .zip(run.loads.chunks_exact(row).zip(run.next_loads.chunks_exact(row)))
        .zip(0..layout.lines)
    {
        let (base0, base1) = bases[usize::from(line >= pins)];
        let kind = run.line_kinds[line];
        let ([q0, q1, q2, q3], [v0, v1, v2, v3]) = (&run.q_coefficients[kind], &run.v_coefficients[kind]);
        // One length for every row, so that the loop runs in vectors without bounds checks.
        let (q0, q1, q2, q3) = (&q0[..row], &q1[..row], &q2[..row], &q3[..row]);
        let (v0, v1, v2, v3) = (&v0[..row], &v1[..row], &v2[..row], &v3[..row]);
        let inverse_mass = run.inverse_masses[kind];
        let (q, v, f0, f1) = (&mut q[..row], &mut v[..row], &f0[..row], &f1[..row]);
        for i in 0..row {
            let (load0, load1) = (
                f0[i] * inverse_mass - gamma[i] * base0,
                f1[i] * inverse_mass - gamma[i] * base1,
            );
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
        // The penetration and the size of what it is the difference of, in one pass.
        let gap = layout.gaps[contact.lane];
        let (mut deflection, mut magnitude) = (0.0, gap.abs());
        for t in contact.terms() {
            let term = t.normal * levels[offset(t.line, contact.level)];
            deflection += term;
            magnitude += term.abs();
        }
        solve.predicted[c] = deflection - gap;
        solve.floor[c] = ROUNDING * magnitude;
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
    for (((q, v), (loads, next)), line) in state
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
        let kind = run.line_kinds[line];
        let ([.., q3], [.., v3]) = (&run.q_coefficients[kind], &run.v_coefficients[kind]);
        let inverse_mass = run.inverse_masses[kind];
        let (q3, v3, q, v) = (&q3[..row], &v3[..row], &mut q[..row], &mut v[..row]);
        let (loads, next) = (&loads[..row], &mut next[..row]);
        for i in 0..row {
            q[i] += q3[i] * (loads[i] * inverse_mass);
            v[i] += v3[i] * (loads[i] * inverse_mass);
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
        let kind = &layout.kinds[run.line_kinds[line]];
        let mut participation_velocity = 0.0;
        for i in 0..row {
            modal_damping += kind.mass * kind.damping[i] * v[i] * v[i];
            participation_velocity += layout.participation[i] * v[i];
        }
        external -= bases[usize::from(line >= pins)].1 * kind.mass * participation_velocity;
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

/// Sweeps of the contact solve before it gives up.
pub(super) const MAX_SWEEPS: usize = 2000;

/// The contact forces at the step's end (`run.solve.force`, with the penetrations and
/// rates they give), with δ = δ̃ − W F and δ̇ = δ̃̇ − W' F, by nonlinear Gauss–Seidel:
/// each contact's force solved exactly against the others' ([`implicit_force`]), sweep
/// after sweep, from the last step's forces, until no force moves by more than 1e-10 of
/// the largest. The sweeps visit the contacts with a force and those the forces may
/// close; the others are checked once the sweeps settle (any that penetrates joins and
/// the sweeps go on). Inlined into the step, so that its loops are compiled for the
/// step's SIMD level.
#[inline(always)]
fn contact_forces(run: &mut ExactRun) -> Result<(), NotConverged> {
    let levels = run.levels;
    let (contacts, own) = (&run.contacts, &run.own);
    let (flexibility, rate_flexibility) = (&run.flexibility, &run.rate_flexibility);
    let solve = &mut run.solve;
    // The shift of every line at every level by the forces: Σ ∓F G(l, l_d), and G' for
    // the velocities where they are read.
    // (Functions, not closures: a closure is not inlined into the step's SIMD context.)
    let rate_flexibility = run.rates.then_some(rate_flexibility.as_slice());
    let (flexibilities, moved) = (
        (flexibility.as_slice(), rate_flexibility, &run.line_kinds[..]),
        read_lines,
    );
    // The sweeps start from the last step's forces.
    solve.shift.fill(0.0);
    solve.rate_shift.fill(0.0);
    for &d in &solve.loaded {
        add(
            &mut solve.shift,
            &mut solve.rate_shift,
            flexibilities,
            levels,
            &contacts[d],
            solve.force[d],
        );
    }
    // The contacts that may push: those loaded, and those whose predicted penetration
    // the forces may close (checked again at the end).
    let reach = -3.0 * solve.shift.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    solve.swept.clear();
    for c in 0..contacts.len() {
        solve.in_sweep[c] = solve.force[c] != 0.0 || solve.predicted[c] >= reach;
        if solve.in_sweep[c] {
            solve.swept.push(c);
        }
    }
    let mut sweeps = 0;
    loop {
        let (mut change, mut scale): (f64, f64) = (0.0, 0.0);
        for &c in &solve.swept {
            let contact = &contacts[c];
            let old = solve.force[c];
            let (w, w_rate) = own[c];
            let penetration = solve.predicted[c] + moved(&solve.shift, levels, contact) + w * old;
            let rate = if contact.law.needs_rate() {
                solve.predicted_rate[c] + moved(&solve.rate_shift, levels, contact) + w_rate * old
            } else {
                0.0
            };
            let force = implicit_force(&contact.law, (penetration, rate), (w, w_rate), solve.floor[c]);
            scale = scale.max(force);
            if force != old {
                change = change.max((force - old).abs());
                solve.force[c] = force;
                add(
                    &mut solve.shift,
                    &mut solve.rate_shift,
                    flexibilities,
                    levels,
                    contact,
                    force - old,
                );
            }
        }
        sweeps += 1;
        if change <= 1e-10 * scale {
            // The penetrations and rates the forces give; every contact left out must
            // stay open.
            let mut more = false;
            for (c, contact) in contacts.iter().enumerate() {
                let penetration = solve.predicted[c] + moved(&solve.shift, levels, contact);
                solve.penetration[c] = penetration;
                solve.rate[c] = if contact.law.needs_rate() {
                    solve.predicted_rate[c] + moved(&solve.rate_shift, levels, contact)
                } else {
                    0.0
                };
                if !solve.in_sweep[c] && penetration > solve.floor[c] {
                    solve.in_sweep[c] = true;
                    solve.swept.push(c);
                    more = true;
                }
            }
            if !more {
                break;
            }
        }
        if sweeps >= MAX_SWEEPS {
            return Err(NotConverged {
                contacts: contacts.len(),
            });
        }
    }
    solve.loaded.clear();
    solve
        .loaded
        .extend(solve.swept.iter().copied().filter(|&c| solve.force[c] != 0.0));
    Ok(())
}

/// Per kind, the flexibilities G and G' (where velocities are read), and each line's
/// kind.
type Flexibilities<'a> = (&'a [Vec<f64>], Option<&'a [Vec<f64>]>, &'a [usize]);

/// Moves the lines by a contact's force: their deflections through G, their velocities
/// through G' where they are read.
#[inline(always)]
fn add(
    shift: &mut [f64],
    rate_shift: &mut [f64],
    (g, g_rate, kinds): Flexibilities<'_>,
    levels: usize,
    source: &LaneBodies,
    force: f64,
) {
    shift_lines(shift, (g, kinds), levels, source, force);
    if let Some(g_rate) = g_rate {
        shift_lines(rate_shift, (g_rate, kinds), levels, source, force);
    }
}

/// Moves every line a contact reads, at every level, by its force F through its kind's
/// flexibility `g` (levels × levels): shift(line, l) −= normal F g(l_c, l).
#[inline(always)]
fn shift_lines(
    shift: &mut [f64],
    (g, kinds): (&[Vec<f64>], &[usize]),
    levels: usize,
    source: &LaneBodies,
    force: f64,
) {
    // One kind (every model without `kinds`): its row of G read once for every term.
    let single = (g.len() == 1).then(|| &g[0][source.level * levels..][..levels]);
    for term in source.terms() {
        let g = single.unwrap_or_else(|| &g[kinds[term.line]][source.level * levels..][..levels]);
        let sign = -term.normal * force;
        let shift = &mut shift[term.line * levels..][..levels];
        for (s, g) in shift.iter_mut().zip(g) {
            *s += sign * g;
        }
    }
}

/// What a contact reads of the lines' shifts at its level: Σ normal × shift(line, l_c).
#[inline(always)]
fn read_lines(shift: &[f64], levels: usize, contact: &LaneBodies) -> f64 {
    contact
        .terms()
        .iter()
        .map(|t| t.normal * shift[t.line * levels + contact.level])
        .sum()
}

/// The force F ≥ 0 of one contact whose penetration and rate, `a` and `b` without a
/// force of its own, fall by w F and w' F under it: open (F = 0: δ = a at most
/// `floor`, or a law that gives nothing), held at touch (δ = 0 with F ≤ law(0⁺, δ̇),
/// where the dashpot makes the law jump) or pushing (F = law(δ, δ̇), δ > 0). The
/// solution is unique: F − law(a − w F, b − w' F) grows with F.
#[inline(always)]
fn implicit_force(law: &NormalLaw, (a, b): (f64, f64), (w, w_rate): (f64, f64), floor: f64) -> f64 {
    if a <= floor {
        return 0.0;
    }
    if w <= 0.0 {
        // No mode moves the contact: its force does not move it either.
        return law.force(a, b).force;
    }
    let touch = a / w;
    if law.force(0.0, b - w_rate * touch).force >= touch {
        return touch;
    }
    if law.force(a, b).force <= 0.0 {
        return 0.0;
    }
    if law.is_linear() {
        let force = (law.stiffness * a + law.damping * b) / (1.0 + law.stiffness * w + law.damping * w_rate);
        return force.clamp(0.0, touch);
    }
    // Newton within the bracket [0, touch) where F − law changes sign.
    let (mut low, mut high) = (0.0, touch);
    let mut force = 0.5 * touch;
    for _ in 0..100 {
        let (penetration, rate) = ((a - w * force).max(0.0), b - w_rate * force);
        let residual = force - law.force(penetration, rate).force;
        if residual > 0.0 {
            high = force;
        } else {
            low = force;
        }
        let (spring, damper) = law.tangent(penetration, rate);
        let next = force - residual / (1.0 + spring * w + damper * w_rate);
        let next = if next > low && next < high {
            next
        } else {
            0.5 * (low + high)
        };
        if (next - force).abs() <= 1e-15 * touch {
            return next;
        }
        force = next;
    }
    force
}
