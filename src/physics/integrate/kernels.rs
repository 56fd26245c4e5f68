//! The dense kernels of a step, written on `pulp`'s portable SIMD vectors so that they
//! vectorize whatever the optimizer decides (AVX2 + FMA on x86-64-v3, NEON on aarch64,
//! scalar elsewhere). Every slice handed to them is a whole number of [`BLOCK`]s, so on
//! AVX2 there is no scalar tail; other vector widths fall back to a tail loop.
//!
//! Products and sums use `mul_add_e`: fused where the CPU has FMA, plain otherwise.
//! A run is therefore bitwise reproducible on one machine, and agrees to rounding
//! across machines of different SIMD levels.

use pulp::Simd;

/// Values per block: every row is padded to a multiple of this (4 × f64 = 256 bits).
pub(super) const BLOCK: usize = 4;

/// Σ x·y.
#[inline(always)]
pub(super) fn dot<S: Simd>(simd: S, x: &[f64], y: &[f64]) -> f64 {
    let (x_head, x_tail) = S::as_simd_f64s(x);
    let (y_head, y_tail) = S::as_simd_f64s(y);
    let mut acc = simd.splat_f64s(0.0);
    for (a, b) in x_head.iter().zip(y_head) {
        acc = simd.mul_add_e_f64s(*a, *b, acc);
    }
    let mut sum = simd.reduce_sum_f64s(acc);
    for (a, b) in x_tail.iter().zip(y_tail) {
        sum += a * b;
    }
    sum
}

/// Σ ψ·(v + lookahead·a): the dashpot velocity of one pin at one height.
#[inline(always)]
pub(super) fn dot_ahead<S: Simd>(simd: S, shape: &[f64], v: &[f64], a: &[f64], lookahead: f64) -> f64 {
    let (s_head, s_tail) = S::as_simd_f64s(shape);
    let (v_head, v_tail) = S::as_simd_f64s(v);
    let (a_head, a_tail) = S::as_simd_f64s(a);
    let ahead = simd.splat_f64s(lookahead);
    let mut acc = simd.splat_f64s(0.0);
    for ((s, v), a) in s_head.iter().zip(v_head).zip(a_head) {
        acc = simd.mul_add_e_f64s(*s, simd.mul_add_e_f64s(ahead, *a, *v), acc);
    }
    let mut sum = simd.reduce_sum_f64s(acc);
    for ((s, v), a) in s_tail.iter().zip(v_tail).zip(a_tail) {
        sum += s * (v + lookahead * a);
    }
    sum
}

/// y += α x.
#[inline(always)]
pub(super) fn axpy<S: Simd>(simd: S, alpha: f64, x: &[f64], y: &mut [f64]) {
    let (x_head, x_tail) = S::as_simd_f64s(x);
    let (y_head, y_tail) = S::as_mut_simd_f64s(y);
    let scale = simd.splat_f64s(alpha);
    for (y, x) in y_head.iter_mut().zip(x_head) {
        *y = simd.mul_add_e_f64s(scale, *x, *y);
    }
    for (y, x) in y_tail.iter_mut().zip(x_tail) {
        *y += alpha * x;
    }
}

/// y = α x.
#[inline(always)]
pub(super) fn scale_into<S: Simd>(simd: S, alpha: f64, x: &[f64], y: &mut [f64]) {
    let (x_head, x_tail) = S::as_simd_f64s(x);
    let (y_head, y_tail) = S::as_mut_simd_f64s(y);
    let scale = simd.splat_f64s(alpha);
    for (y, x) in y_head.iter_mut().zip(x_head) {
        *y = simd.mul_f64s(scale, *x);
    }
    for (y, x) in y_tail.iter_mut().zip(x_tail) {
        *y = alpha * x;
    }
}

/// Most blocks of levels accumulated at once (registers held: this many, plus one).
const GROUP: usize = 4;

/// Ψ at the contact levels laid out for [`level_deflections`]: levels padded to whole
/// blocks, blocks gathered in groups of up to [`GROUP`], and within a group, mode after
/// mode, the group's blocks side by side:
/// `data[group_start + (i·G + j)·BLOCK + k] = ψᵢ(z_{(first_block + j)·BLOCK + k})`.
pub(super) struct LevelShapes {
    data: Vec<f64>,
    /// Levels rounded up to whole blocks.
    pub levels: usize,
    /// Levels.
    level_count: usize,
}

impl LevelShapes {
    /// From Ψ stored level by level (`level_shapes[l·row + i]`).
    pub fn new(level_shapes: &[f64], row: usize) -> Self {
        let level_count = level_shapes.len() / row;
        let blocks = level_count.div_ceil(BLOCK);
        let mut data = Vec::with_capacity(blocks * BLOCK * row);
        for first in (0..blocks).step_by(GROUP) {
            let group = GROUP.min(blocks - first);
            for i in 0..row {
                for j in 0..group {
                    for k in 0..BLOCK {
                        let level = (first + j) * BLOCK + k;
                        data.push(if level < level_count {
                            level_shapes[level * row + i]
                        } else {
                            0.0
                        });
                    }
                }
            }
        }
        Self {
            data,
            levels: blocks * BLOCK,
            level_count,
        }
    }
}

/// Deflection of every pin at every contact level:
/// `out[p·levels + l] = Σᵢ ψᵢ(zₗ) q[p·row + i]`. Each group of blocks of a pin's levels
/// is accumulated in registers, each coordinate broadcast once per group.
#[inline(always)]
pub(super) fn level_deflections<S: Simd>(
    simd: S,
    shapes: &LevelShapes,
    row: usize,
    q: &[f64],
    out: &mut [f64],
) {
    let levels = shapes.levels;
    if levels == 0 {
        return;
    }
    let (vectors, _) = S::as_simd_f64s(&shapes.data);
    let one_block_per_vector = vectors.len() * BLOCK == shapes.data.len();
    let stride = out.len() / levels;
    let mut pin_levels = [0.0; GROUP * BLOCK];
    for (p, coordinates) in q.chunks_exact(row).enumerate() {
        let (mut first, mut offset) = (0, 0);
        while first < levels / BLOCK {
            let group = GROUP.min(levels / BLOCK - first);
            let size = group * BLOCK * row;
            let data = &shapes.data[offset..offset + size];
            let out_group = &mut pin_levels[..group * BLOCK];
            if one_block_per_vector {
                let (group_vectors, _) = S::as_simd_f64s(data);
                match group {
                    1 => accumulate_group::<S, 1>(simd, coordinates, group_vectors, out_group),
                    2 => accumulate_group::<S, 2>(simd, coordinates, group_vectors, out_group),
                    3 => accumulate_group::<S, 3>(simd, coordinates, group_vectors, out_group),
                    _ => accumulate_group::<S, GROUP>(simd, coordinates, group_vectors, out_group),
                }
            } else {
                // The SIMD width is not one block (scalar fallback, wider vectors).
                out_group.fill(0.0);
                for (x, values) in coordinates.iter().zip(data.chunks_exact(group * BLOCK)) {
                    for (out, s) in out_group.iter_mut().zip(values) {
                        *out += x * s;
                    }
                }
            }
            // Real levels only: the padded ones stay 0.
            let mut slot = first * BLOCK * stride + 1 + p;
            for w in &out_group[..out_group.len().min(shapes.level_count - first * BLOCK)] {
                out[slot] = *w;
                slot += stride;
            }
            first += group;
            offset += size;
        }
    }
}

/// A run of consecutive contacts whose left and right sides are consecutive slots of
/// the level-major deflections (a row of pins between two walls is one run per level):
/// their penetrations are one vector subtraction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Run {
    pub first_contact: usize,
    pub len: usize,
    pub left_slot: usize,
    pub right_slot: usize,
}

impl Run {
    /// Contacts (left slot, right slot) cut into maximal runs.
    pub fn split(slots: impl IntoIterator<Item = (usize, usize)>) -> Vec<Run> {
        let mut runs: Vec<Run> = Vec::new();
        for (c, (left, right)) in slots.into_iter().enumerate() {
            match runs.last_mut() {
                Some(run) if run.left_slot + run.len == left && run.right_slot + run.len == right => {
                    run.len += 1
                }
                _ => runs.push(Run {
                    first_contact: c,
                    len: 1,
                    left_slot: left,
                    right_slot: right,
                }),
            }
        }
        runs
    }
}

/// Per-contact state that [`penetrations`] updates (all indexed by contact).
pub(super) struct ContactState<'a> {
    /// Penetration δ = w_left − w_right − gap (m) now.
    pub now: &'a mut [f64],
    /// Largest penetration so far.
    pub max: &'a mut [f64],
    /// Contact force, set to 0 where the contact is open.
    pub force: &'a mut [f64],
    /// Receives the contacts closed now, in order.
    pub closed: &'a mut [u32],
}

/// For every contact of every run: its penetration, running maximum, a zero force if it
/// is open; returns how many contacts are closed (listed first in `state.closed`).
#[inline(always)]
pub(super) fn penetrations<S: Simd>(
    simd: S,
    runs: &[Run],
    deflections: &[f64],
    gaps: &[f64],
    state: ContactState<'_>,
) -> usize {
    let zero = simd.splat_f64s(0.0);
    let lanes = std::mem::size_of::<S::f64s>() / std::mem::size_of::<f64>();
    let mut count = 0;
    for run in runs {
        let contacts = run.first_contact..run.first_contact + run.len;
        let left = &deflections[run.left_slot..run.left_slot + run.len];
        let right = &deflections[run.right_slot..run.right_slot + run.len];
        let (l_head, l_tail) = S::as_simd_f64s(left);
        let (r_head, r_tail) = S::as_simd_f64s(right);
        let (g_head, g_tail) = S::as_simd_f64s(&gaps[contacts.clone()]);
        let (n_head, n_tail) = S::as_mut_simd_f64s(&mut state.now[contacts.clone()]);
        let (m_head, m_tail) = S::as_mut_simd_f64s(&mut state.max[contacts.clone()]);
        let (f_head, f_tail) = S::as_mut_simd_f64s(&mut state.force[contacts.clone()]);
        for (((((l, r), g), n), m), f) in l_head
            .iter()
            .zip(r_head)
            .zip(g_head)
            .zip(n_head)
            .zip(m_head)
            .zip(f_head)
        {
            *n = simd.sub_f64s(simd.sub_f64s(*l, *r), *g);
            *m = simd.max_f64s(*m, *n);
            *f = simd.select_f64s(simd.greater_than_f64s(*n, zero), *f, zero);
        }
        for (((((l, r), g), n), m), f) in l_tail
            .iter()
            .zip(r_tail)
            .zip(g_tail)
            .zip(n_tail)
            .zip(m_tail)
            .zip(f_tail)
        {
            *n = l - r - g;
            *m = m.max(*n);
            if *n <= 0.0 {
                *f = 0.0;
            }
        }
        // Closed contacts: most vectors of a run hold none, one test each.
        let now = &state.now[contacts];
        let (n_head, _) = S::as_simd_f64s(now);
        for (j, n) in n_head.iter().enumerate() {
            if simd.reduce_max_f64s(*n) > 0.0 {
                for k in j * lanes..(j + 1) * lanes {
                    state.closed[count] = (run.first_contact + k) as u32;
                    count += usize::from(now[k] > 0.0);
                }
            }
        }
        for (k, n) in now.iter().enumerate().skip(n_head.len() * lanes) {
            state.closed[count] = (run.first_contact + k) as u32;
            count += usize::from(*n > 0.0);
        }
    }
    count
}

/// One group of `G` blocks of one pin's levels.
#[inline(always)]
fn accumulate_group<S: Simd, const G: usize>(
    simd: S,
    coordinates: &[f64],
    shapes: &[S::f64s],
    out: &mut [f64],
) {
    let mut acc = [simd.splat_f64s(0.0); G];
    for (x, vectors) in coordinates.iter().zip(shapes.chunks_exact(G)) {
        let x = simd.splat_f64s(*x);
        for j in 0..G {
            acc[j] = simd.mul_add_e_f64s(x, vectors[j], acc[j]);
        }
    }
    let (out_vectors, _) = S::as_mut_simd_f64s(out);
    out_vectors.copy_from_slice(&acc);
}

/// ½ Σ (v² + ωᵢ² q²) over every pin (`stiffness` = ωᵢ² per mode, one row).
#[inline(always)]
pub(super) fn modal_energy<S: Simd>(simd: S, stiffness: &[f64], q: &[f64], v: &[f64]) -> f64 {
    let row = stiffness.len();
    let (k_head, k_tail) = S::as_simd_f64s(stiffness);
    let mut acc = simd.splat_f64s(0.0);
    let mut tail = 0.0;
    for (q, v) in q.chunks_exact(row).zip(v.chunks_exact(row)) {
        let (q_head, q_tail) = S::as_simd_f64s(q);
        let (v_head, v_tail) = S::as_simd_f64s(v);
        for ((q, v), k) in q_head.iter().zip(v_head).zip(k_head) {
            acc = simd.mul_add_e_f64s(*v, *v, acc);
            acc = simd.mul_add_e_f64s(simd.mul_f64s(*k, *q), *q, acc);
        }
        for ((q, v), k) in q_tail.iter().zip(v_tail).zip(k_tail) {
            tail += v * v + k * q * q;
        }
    }
    0.5 * (simd.reduce_sum_f64s(acc) + tail)
}

/// Per-mode coefficients of the modal update (each padded to the row length).
pub(super) struct ModalCoefficients<'a> {
    /// ωᵢ².
    pub stiffness: &'a [f64],
    /// 2ξᵢωᵢ.
    pub damping: &'a [f64],
    /// Central difference: 1/(1 + ξᵢωᵢΔt); Tchamwa: 1.
    pub factor: &'a [f64],
    /// Γᵢ.
    pub participation: &'a [f64],
}

/// Sums the modal update accumulates: Σ 2ξω v² and Σ Γ v over every pin and mode.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct UpdateSums {
    pub damping_power: f64,
    pub participation_velocity: f64,
}

/// a = (f − ω² q − 2ξω v)·factor, then v += `half_step`·a (0 for Tchamwa, whose velocity
/// was advanced before the forces), row by row; returns the power sums at the new v.
#[inline(always)]
pub(super) fn modal_update<S: Simd>(
    simd: S,
    coefficients: &ModalCoefficients<'_>,
    half_step: f64,
    (q, v, a, f): (&[f64], &mut [f64], &mut [f64], &[f64]),
) -> UpdateSums {
    let row = coefficients.stiffness.len();
    let (k_head, k_tail) = S::as_simd_f64s(coefficients.stiffness);
    let (c_head, c_tail) = S::as_simd_f64s(coefficients.damping);
    let (x_head, x_tail) = S::as_simd_f64s(coefficients.factor);
    let (g_head, g_tail) = S::as_simd_f64s(coefficients.participation);
    let half = simd.splat_f64s(half_step);
    let mut damping_power = simd.splat_f64s(0.0);
    let mut participation_velocity = simd.splat_f64s(0.0);
    let mut tail_sums = UpdateSums::default();
    for (((q, v), a), f) in q
        .chunks_exact(row)
        .zip(v.chunks_exact_mut(row))
        .zip(a.chunks_exact_mut(row))
        .zip(f.chunks_exact(row))
    {
        let (q_head, q_tail) = S::as_simd_f64s(q);
        let (v_head, v_tail) = S::as_mut_simd_f64s(v);
        let (a_head, a_tail) = S::as_mut_simd_f64s(a);
        let (f_head, f_tail) = S::as_simd_f64s(f);
        for (((((q, v), a), f), (k, c)), (x, g)) in q_head
            .iter()
            .zip(v_head.iter_mut())
            .zip(a_head.iter_mut())
            .zip(f_head)
            .zip(k_head.iter().zip(c_head))
            .zip(x_head.iter().zip(g_head))
        {
            let elastic = simd.mul_f64s(*k, *q);
            let viscous = simd.mul_f64s(*c, *v);
            *a = simd.mul_f64s(simd.sub_f64s(simd.sub_f64s(*f, elastic), viscous), *x);
            *v = simd.mul_add_e_f64s(half, *a, *v);
            damping_power = simd.mul_add_e_f64s(simd.mul_f64s(*c, *v), *v, damping_power);
            participation_velocity = simd.mul_add_e_f64s(*g, *v, participation_velocity);
        }
        for (((((q, v), a), f), (k, c)), (x, g)) in q_tail
            .iter()
            .zip(v_tail.iter_mut())
            .zip(a_tail.iter_mut())
            .zip(f_tail)
            .zip(k_tail.iter().zip(c_tail))
            .zip(x_tail.iter().zip(g_tail))
        {
            *a = (f - k * q - c * *v) * x;
            *v += half_step * *a;
            tail_sums.damping_power += c * *v * *v;
            tail_sums.participation_velocity += g * *v;
        }
    }
    UpdateSums {
        damping_power: simd.reduce_sum_f64s(damping_power) + tail_sums.damping_power,
        participation_velocity: simd.reduce_sum_f64s(participation_velocity)
            + tail_sums.participation_velocity,
    }
}

/// First half of a step over the whole state. Central difference (`curvature` = 0):
/// v += ½Δt a, q += Δt v. Tchamwa (`half_step` = Δt, `curvature` = φΔt²):
/// q += Δt v + φΔt² a, then v += Δt a.
#[inline(always)]
pub(super) fn advance_positions<S: Simd>(
    simd: S,
    (dt, half_step, curvature): (f64, f64, f64),
    q: &mut [f64],
    v: &mut [f64],
    a: &[f64],
) {
    let (q_head, q_tail) = S::as_mut_simd_f64s(q);
    let (v_head, v_tail) = S::as_mut_simd_f64s(v);
    let (a_head, a_tail) = S::as_simd_f64s(a);
    let (step, half, curve) = (
        simd.splat_f64s(dt),
        simd.splat_f64s(half_step),
        simd.splat_f64s(curvature),
    );
    if curvature == 0.0 {
        for ((q, v), a) in q_head.iter_mut().zip(v_head.iter_mut()).zip(a_head) {
            *v = simd.mul_add_e_f64s(half, *a, *v);
            *q = simd.mul_add_e_f64s(step, *v, *q);
        }
        for ((q, v), a) in q_tail.iter_mut().zip(v_tail.iter_mut()).zip(a_tail) {
            *v += half_step * a;
            *q += dt * *v;
        }
    } else {
        for ((q, v), a) in q_head.iter_mut().zip(v_head.iter_mut()).zip(a_head) {
            *q = simd.mul_add_e_f64s(curve, *a, simd.mul_add_e_f64s(step, *v, *q));
            *v = simd.mul_add_e_f64s(half, *a, *v);
        }
        for ((q, v), a) in q_tail.iter_mut().zip(v_tail.iter_mut()).zip(a_tail) {
            *q += dt * *v + curvature * a;
            *v += half_step * a;
        }
    }
}

#[cfg(test)]
mod tests {
    //! Every kernel against its plain formula, on the SIMD level of this CPU and on the
    //! scalar fallback (which also covers the tail loops and the non-vector branch).

    use super::*;

    /// Deterministic values in (-1, 1) without a random-number dependency.
    fn values(n: usize, seed: f64) -> Vec<f64> {
        (0..n).map(|i| ((i as f64 + 1.0) * seed).sin()).collect()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
    }

    struct Check;

    impl pulp::WithSimd for Check {
        type Output = ();
        fn with_simd<S: Simd>(self, simd: S) {
            check(simd);
        }
    }

    fn check<S: Simd>(simd: S) {
        let (pins, row) = (3, 8);
        let (x, y, z) = (values(row, 0.7), values(row, 1.3), values(row, 2.9));
        let plain: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        assert!(close(dot(simd, &x, &y), plain));
        let ahead: f64 = (0..row).map(|i| x[i] * (y[i] + 0.25 * z[i])).sum();
        assert!(close(dot_ahead(simd, &x, &y, &z, 0.25), ahead));
        let mut w = z.clone();
        axpy(simd, -1.5, &x, &mut w);
        assert!((0..row).all(|i| close(w[i], z[i] - 1.5 * x[i])));
        scale_into(simd, 2.0, &x, &mut w);
        assert!((0..row).all(|i| close(w[i], 2.0 * x[i])));

        // 9 levels: three blocks, the last one padded.
        for level_count in [1, 4, 9, 21] {
            let shapes = values(level_count * row, 0.37);
            let q = values(pins * row, 0.53);
            let grouped = LevelShapes::new(&shapes, row);
            let stride = pins + 2;
            let mut out = vec![0.0; stride * grouped.levels];
            level_deflections(simd, &grouped, row, &q, &mut out);
            for l in 0..grouped.levels {
                assert!(
                    out[l * stride] == 0.0 && out[l * stride + pins + 1] == 0.0,
                    "wall slots stay 0"
                );
            }
            for p in 0..pins {
                for l in 0..grouped.levels {
                    let expected = if l < level_count {
                        (0..row).map(|i| shapes[l * row + i] * q[p * row + i]).sum()
                    } else {
                        0.0
                    };
                    assert!(close(out[l * stride + 1 + p], expected), "level {l} of pin {p}");
                }
            }
        }

        // Two runs (4 + 7 contacts, one run with a tail) and a lone contact.
        let slots: Vec<(usize, usize)> = (0..4)
            .map(|k| (k, k + 1))
            .chain((0..7).map(|k| (20 + k, 10 + k)))
            .chain([(3, 3)])
            .collect();
        let runs = Run::split(slots.iter().copied());
        assert_eq!(runs.len(), 3);
        let deflections = values(40, 0.61);
        let gaps = values(slots.len(), 0.67);
        let contacts = slots.len();
        let (mut now, mut max) = (vec![0.0; contacts], vec![0.2; contacts]);
        let (mut force, mut closed) = (vec![1.0; contacts], vec![0; contacts]);
        let count = penetrations(
            simd,
            &runs,
            &deflections,
            &gaps,
            ContactState {
                now: &mut now,
                max: &mut max,
                force: &mut force,
                closed: &mut closed,
            },
        );
        let mut expected_closed = Vec::new();
        for (c, (left, right)) in slots.iter().enumerate() {
            let expected = deflections[*left] - deflections[*right] - gaps[c];
            assert!(close(now[c], expected) && max[c] == expected.max(0.2));
            assert_eq!(force[c], if expected > 0.0 { 1.0 } else { 0.0 });
            if expected > 0.0 {
                expected_closed.push(c as u32);
            }
        }
        assert!(!expected_closed.is_empty() && expected_closed.len() < contacts);
        assert_eq!(closed[..count], expected_closed[..]);

        let (stiffness, damping, factor, participation) = (
            values(row, 0.11),
            values(row, 0.17),
            values(row, 0.19),
            values(row, 0.23),
        );
        let coefficients = ModalCoefficients {
            stiffness: &stiffness,
            damping: &damping,
            factor: &factor,
            participation: &participation,
        };
        let (q, f) = (values(pins * row, 0.29), values(pins * row, 0.31));
        let (mut v, mut a) = (values(pins * row, 0.41), vec![0.0; pins * row]);
        let v0 = v.clone();
        let sums = modal_update(simd, &coefficients, 0.5, (&q, &mut v, &mut a, &f));
        let (mut damping_power, mut participation_velocity) = (0.0, 0.0);
        for k in 0..pins * row {
            let i = k % row;
            let acceleration = (f[k] - stiffness[i] * q[k] - damping[i] * v0[k]) * factor[i];
            let velocity = v0[k] + 0.5 * acceleration;
            assert!(close(a[k], acceleration) && close(v[k], velocity));
            damping_power += damping[i] * velocity * velocity;
            participation_velocity += participation[i] * velocity;
        }
        assert!(close(sums.damping_power, damping_power));
        let energy: f64 = (0..pins * row)
            .map(|k| 0.5 * (v[k] * v[k] + stiffness[k % row] * q[k] * q[k]))
            .sum();
        assert!(close(modal_energy(simd, &stiffness, &q, &v), energy));
        assert!(close(sums.participation_velocity, participation_velocity));

        for (half, curvature) in [(0.5, 0.0), (1.0, 0.3)] {
            let (mut q, mut v, a) = (values(10, 0.43), values(10, 0.47), values(10, 0.59));
            let (q0, v0) = (q.clone(), v.clone());
            advance_positions(simd, (1.0, half, curvature), &mut q, &mut v, &a);
            for k in 0..10 {
                let (position, velocity) = if curvature == 0.0 {
                    let velocity = v0[k] + half * a[k];
                    (q0[k] + velocity, velocity)
                } else {
                    (q0[k] + v0[k] + curvature * a[k], v0[k] + half * a[k])
                };
                assert!(close(q[k], position) && close(v[k], velocity));
            }
        }
    }

    #[test]
    fn kernels_match_their_formulas_on_this_cpu_and_on_the_scalar_fallback() {
        pulp::Arch::new().dispatch(Check);
        check(pulp::Scalar::new());
    }
}
