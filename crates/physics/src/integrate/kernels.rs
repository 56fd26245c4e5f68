//! The dense kernels of a step, written on `pulp`'s portable SIMD vectors so that they
//! vectorize whatever the optimizer decides (AVX2 + FMA on x86-64-v3, NEON on aarch64,
//! scalar elsewhere).
//!
//! Every row of the state is padded to a whole number of vectors, so the kernels of the
//! hot loop have no scalar tail. They take the row length in vectors as a plain
//! argument: the stepper calls them with a constant for the usual row lengths, so that
//! every per-row loop is unrolled with no bounds checks (see `stepper`).
//!
//! Products and sums use `mul_add_e`: fused where the CPU has FMA, plain otherwise.
//! A run is therefore bitwise reproducible on one machine, and agrees to rounding
//! across machines of different SIMD levels.

use std::collections::HashMap;

use pulp::Simd;

/// f64 values per SIMD vector of `S`.
#[inline(always)]
pub(super) fn lanes<S: Simd>() -> usize {
    std::mem::size_of::<S::f64s>() / std::mem::size_of::<f64>()
}

/// [`lanes`] of the SIMD level an [`pulp::Arch`] dispatches to.
pub(super) struct Lanes;

impl pulp::WithSimd for Lanes {
    type Output = usize;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> usize {
        lanes::<S>()
    }
}

/// Σ x·y (any length).
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

/// y += α x (any length).
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

/// Σ ψ·((v_L + h·a_L) − (v_R + h·a_R)) over one row of vectors, h = `lookahead`: the
/// rate of a contact's penetration between the pins of rows L and R (a wall reads a row
/// of zeros). Two accumulators halve the dependency chain.
#[inline(always)]
pub(super) fn penetration_rate<S: Simd>(
    simd: S,
    shape: &[S::f64s],
    (v_left, a_left): (&[S::f64s], &[S::f64s]),
    (v_right, a_right): (&[S::f64s], &[S::f64s]),
    lookahead: f64,
) -> f64 {
    let n = shape.len();
    let (v_left, a_left, v_right, a_right) = (&v_left[..n], &a_left[..n], &v_right[..n], &a_right[..n]);
    let ahead = simd.splat_f64s(lookahead);
    let mut acc = [simd.splat_f64s(0.0); 2];
    for k in 0..n {
        let dv = simd.sub_f64s(v_left[k], v_right[k]);
        let da = simd.sub_f64s(a_left[k], a_right[k]);
        acc[k % 2] = simd.mul_add_e_f64s(shape[k], simd.mul_add_e_f64s(ahead, da, dv), acc[k % 2]);
    }
    simd.reduce_sum_f64s(simd.add_f64s(acc[0], acc[1]))
}

/// y += α x over one row of vectors.
#[inline(always)]
pub(super) fn row_axpy<S: Simd>(simd: S, alpha: f64, x: &[S::f64s], y: &mut [S::f64s]) {
    let n = x.len();
    let y = &mut y[..n];
    let scale = simd.splat_f64s(alpha);
    for k in 0..n {
        y[k] = simd.mul_add_e_f64s(scale, x[k], y[k]);
    }
}

/// Most blocks of heights accumulated at once (registers held: this many, plus one).
const GROUP: usize = 4;

/// Ψ at a set of heights, laid out for [`level_deflections`]. Heights are cut into
/// blocks of one vector (`lanes` heights, the last block padded with ψ = 0); blocks are
/// gathered in groups of up to [`GROUP`], and within a group, mode after mode, the
/// group's blocks side by side:
/// `data[group_start + (i·G + j)·lanes + k] = ψᵢ(z_{(first_block + j)·lanes + k})`.
pub(super) struct LevelShapes {
    data: Vec<f64>,
    /// Blocks of `lanes` heights.
    pub blocks: usize,
}

impl LevelShapes {
    /// From Ψ stored height by height (`shapes[l·row + i]`), for vectors of `lanes`.
    pub fn new(shapes: &[f64], row: usize, lanes: usize) -> Self {
        let count = shapes.len() / row;
        let blocks = count.div_ceil(lanes);
        let mut data = Vec::with_capacity(blocks * lanes * row);
        for first in (0..blocks).step_by(GROUP) {
            let group = GROUP.min(blocks - first);
            for i in 0..row {
                for j in 0..group {
                    for k in 0..lanes {
                        let level = (first + j) * lanes + k;
                        data.push(if level < count {
                            shapes[level * row + i]
                        } else {
                            0.0
                        });
                    }
                }
            }
        }
        Self { data, blocks }
    }

    /// Groups of up to [`GROUP`] blocks.
    pub fn groups(&self) -> usize {
        self.blocks.div_ceil(GROUP)
    }

    /// Blocks per group.
    pub const GROUP_BLOCKS: usize = GROUP;
}

/// Deflection of every pin at every height of `shapes`, block-major: the vector
/// `out[b·stride + 1 + p]` holds pin p's deflections at the heights of block b,
/// `w(z_l) = Σᵢ ψᵢ(z_l) q[p·row + i]`. Slots 0 and `pins + 1` of each block (the walls)
/// are left alone. Two pins and a group of blocks are accumulated at once in registers:
/// each shape vector is loaded once for both pins, and the independent accumulators
/// hide the latency of the FMAs.
#[inline(always)]
pub(super) fn level_deflections<S: Simd>(
    simd: S,
    shapes: &LevelShapes,
    row: usize,
    q: &[f64],
    out: &mut [S::f64s],
    stride: usize,
) {
    level_deflections_of_groups(simd, shapes, (row, stride), q, out, 0..shapes.groups());
}

/// [`level_deflections`] of the blocks of the groups `groups` only (groups of
/// [`GROUP`] blocks), `out` starting at the first of them. Each value is the same dot
/// product, in the same order, whatever the groups: threads that share the groups
/// compute the deflections a single thread computes, bit for bit.
#[inline(always)]
pub(super) fn level_deflections_of_groups<S: Simd>(
    simd: S,
    shapes: &LevelShapes,
    (row, stride): (usize, usize),
    q: &[f64],
    out: &mut [S::f64s],
    groups: std::ops::Range<usize>,
) {
    let (data, _) = S::as_simd_f64s(&shapes.data);
    let blocks = shapes.blocks.min(groups.end * GROUP);
    let start = groups.start * GROUP;
    let pins = q.len() / row;
    assert!(
        data.len() == shapes.blocks * row
            && start <= blocks
            && out.len() >= (blocks - start) * stride
            && pins < stride
    );
    let mut p = 0;
    while p < pins {
        let pair = pins - p >= 2;
        let rows = &q[p * row..];
        let (mut first, mut offset) = (start, start * row);
        while first < blocks {
            let group = GROUP.min(blocks - first);
            let (shapes, slot) = (&data[offset..], (first - start) * stride + 1 + p);
            let at = Destination { out, slot, stride };
            match (group, pair) {
                (1, false) => accumulate::<S, 1, 1>(simd, rows, row, shapes, at),
                (2, false) => accumulate::<S, 2, 1>(simd, rows, row, shapes, at),
                (3, false) => accumulate::<S, 3, 1>(simd, rows, row, shapes, at),
                (_, false) => accumulate::<S, GROUP, 1>(simd, rows, row, shapes, at),
                (1, true) => accumulate::<S, 1, 2>(simd, rows, row, shapes, at),
                (2, true) => accumulate::<S, 2, 2>(simd, rows, row, shapes, at),
                (3, true) => accumulate::<S, 3, 2>(simd, rows, row, shapes, at),
                (_, true) => accumulate::<S, GROUP, 2>(simd, rows, row, shapes, at),
            }
            first += group;
            offset += group * row;
        }
        p += if pair { 2 } else { 1 };
    }
}

/// Where [`accumulate`] stores: `out[slot + r + j·stride]` for pin r of the set and
/// block j of the group.
struct Destination<'a, V> {
    out: &'a mut [V],
    slot: usize,
    stride: usize,
}

/// One group of `G` blocks of `P` consecutive pins' heights (`rows`: their coordinates,
/// `row` each).
#[inline(always)]
fn accumulate<S: Simd, const G: usize, const P: usize>(
    simd: S,
    rows: &[f64],
    row: usize,
    shapes: &[S::f64s],
    at: Destination<'_, S::f64s>,
) {
    let rows = &rows[..P * row];
    let shapes = &shapes[..G * row];
    let mut acc = [[simd.splat_f64s(0.0); G]; P];
    for i in 0..row {
        let x: [S::f64s; P] = std::array::from_fn(|r| simd.splat_f64s(rows[r * row + i]));
        for j in 0..G {
            let shape = shapes[i * G + j];
            for r in 0..P {
                acc[r][j] = simd.mul_add_e_f64s(x[r], shape, acc[r][j]);
            }
        }
    }
    for (r, blocks) in acc.into_iter().enumerate() {
        for (j, value) in blocks.into_iter().enumerate() {
            at.out[at.slot + r + j * at.stride] = value;
        }
    }
}

/// The contacts laid out by lanes of the block-major deflections of
/// [`level_deflections`]: contacts at the heights of one block between the same two
/// slots share one vector (a group), one lane per height. In a regular bundle a group is
/// a pair of neighbours at `lanes` consecutive levels, so the penetrations of every
/// contact are one vector subtraction per group. Lanes without a contact get an
/// infinite gap and never close.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct ContactLanes {
    lanes: usize,
    /// Per group: the deflection vector (block·stride + slot) of its left and right body.
    pub left: Vec<u32>,
    pub right: Vec<u32>,
    /// Per lane (group·lanes + k): the contact there, or [`ContactLanes::EMPTY`].
    pub contact: Vec<u32>,
    /// Per contact: its lane.
    pub lane: Vec<u32>,
}

impl ContactLanes {
    pub const EMPTY: u32 = u32::MAX;

    /// From each contact's (level, left slot, right slot) in a block-major layout of
    /// `stride` slots per block.
    pub fn new(
        contacts: impl IntoIterator<Item = (usize, usize, usize)>,
        lanes: usize,
        stride: usize,
    ) -> Self {
        let mut layout = Self {
            lanes,
            left: Vec::new(),
            right: Vec::new(),
            contact: Vec::new(),
            lane: Vec::new(),
        };
        let mut groups: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (c, (level, left, right)) in contacts.into_iter().enumerate() {
            let (block, k) = (level / lanes, level % lanes);
            let vectors = (block * stride + left, block * stride + right);
            let candidates = groups.entry(vectors).or_default();
            let group = match candidates
                .iter()
                .find(|g| layout.contact[**g * lanes + k] == Self::EMPTY)
            {
                Some(g) => *g,
                None => {
                    let g = layout.left.len();
                    layout
                        .left
                        .push(u32::try_from(vectors.0).expect("deflection index fits u32"));
                    layout
                        .right
                        .push(u32::try_from(vectors.1).expect("deflection index fits u32"));
                    layout.contact.resize((g + 1) * lanes, Self::EMPTY);
                    candidates.push(g);
                    g
                }
            };
            let lane = group * lanes + k;
            layout.contact[lane] = u32::try_from(c).expect("contact index fits u32");
            layout.lane.push(lane as u32);
        }
        layout
    }

    /// Lanes per group (the SIMD width).
    pub fn lanes(&self) -> usize {
        self.lanes
    }

    /// Number of lanes (groups × lanes).
    pub fn len(&self) -> usize {
        self.contact.len()
    }

    /// Per-contact values laid out by lane, `fill` in the empty lanes.
    pub fn by_lane<T: Copy>(&self, per_contact: &[T], fill: T) -> Vec<T> {
        self.contact
            .iter()
            .map(|c| {
                if *c == Self::EMPTY {
                    fill
                } else {
                    per_contact[*c as usize]
                }
            })
            .collect()
    }

    /// Lane-ordered values back in contact order.
    pub fn by_contact<T: Clone>(&self, per_lane: &[T]) -> Vec<T> {
        self.lane.iter().map(|l| per_lane[*l as usize].clone()).collect()
    }
}

/// Per-lane contact state that [`penetrations`] updates.
pub(super) struct ContactState<'a> {
    /// Penetration δ = w_left − w_right − gap (m) now.
    pub now: &'a mut [f64],
    /// Largest penetration so far.
    pub max: &'a mut [f64],
    /// Receives the closed lanes, in order.
    pub closed: &'a mut [u32],
    /// Scratch: the groups with a closed lane, as bits (one word per 64 groups).
    pub closed_groups: &'a mut [u64],
}

/// For every group: penetrations δ = w_left − w_right − gap and running maxima; returns
/// how many lanes are closed (listed first in `state.closed`). `gaps` are per lane.
/// Forces are left alone: a masked store of zeros where open would cost more
/// (microcoded on some CPUs) than reading a force only where the penetration is positive.
#[inline(always)]
pub(super) fn penetrations<S: Simd>(
    simd: S,
    layout: &ContactLanes,
    deflections: &[S::f64s],
    gaps: &[f64],
    state: ContactState<'_>,
) -> usize {
    let groups = layout.left.len();
    let (gaps, _) = S::as_simd_f64s(gaps);
    let (now, _) = S::as_mut_simd_f64s(state.now);
    let (max, _) = S::as_mut_simd_f64s(state.max);
    let (left, right) = (&layout.left[..groups], &layout.right[..groups]);
    let (gaps, now, max) = (&gaps[..groups], &mut now[..groups], &mut max[..groups]);
    // The groups holding a closed lane, as bits: most groups hold none, one test each
    // and no branch, no store at a data-dependent address.
    let words = &mut state.closed_groups[..groups.div_ceil(64)];
    for (w, word) in words.iter_mut().enumerate() {
        let mut bits = 0u64;
        for g in w * 64..groups.min(w * 64 + 64) {
            let n = simd.sub_f64s(
                simd.sub_f64s(deflections[left[g] as usize], deflections[right[g] as usize]),
                gaps[g],
            );
            now[g] = n;
            max[g] = simd.max_f64s(max[g], n);
            bits |= u64::from(simd.reduce_max_f64s(n) > 0.0) << (g % 64);
        }
        *word = bits;
    }
    list_closed(layout.lanes, words, state.now, state.closed)
}

/// The lanes of the groups marked in `words` whose penetration `now` is positive,
/// listed first in `closed`; returns how many.
#[inline(always)]
pub(super) fn list_closed(lanes: usize, words: &[u64], now: &[f64], closed: &mut [u32]) -> usize {
    let mut count = 0;
    for (w, word) in words.iter().enumerate() {
        let mut bits = *word;
        while bits != 0 {
            let g = w * 64 + bits.trailing_zeros() as usize;
            bits &= bits - 1;
            for lane in g * lanes..(g + 1) * lanes {
                closed[count] = lane as u32;
                count += usize::from(now[lane] > 0.0);
            }
        }
    }
    count
}

/// The y side of the plane's contact groups ([`plane_penetrations`]): the x side is the
/// [`ContactLanes`] of the same contacts.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PlaneGroups {
    /// Per group: the deflection vector of its left and right body along y.
    pub left_y: Vec<u32>,
    pub right_y: Vec<u32>,
    /// Per lane: the normal's components (0 in empty lanes).
    pub normal_x: Vec<f64>,
    pub normal_y: Vec<f64>,
}

/// [`penetrations`] in the plane: δ = n_x (L_x − R_x) + n_y (L_y − R_y) − gap per lane,
/// the x deflections at the vectors of `layout`, the y ones at those of `plane`.
#[inline(always)]
pub(super) fn plane_penetrations<S: Simd>(
    simd: S,
    layout: &ContactLanes,
    plane: &PlaneGroups,
    deflections: &[S::f64s],
    gaps: &[f64],
    state: ContactState<'_>,
) -> usize {
    let groups = layout.left.len();
    let words = &mut state.closed_groups[..groups.div_ceil(64)];
    let (now, _) = S::as_mut_simd_f64s(state.now);
    let (max, _) = S::as_mut_simd_f64s(state.max);
    plane_penetrations_of_words(simd, (layout, plane), deflections, gaps, (now, max, words), 0);
    list_closed(layout.lanes, words, state.now, state.closed)
}

/// The vector pass of [`plane_penetrations`] over the groups of the words `words`
/// (64 groups a word) from word `first_word` on: `now` and `max` start at its first
/// group. Each group's values are computed alone, so any split of the words gives the
/// values of the whole pass.
#[inline(always)]
pub(super) fn plane_penetrations_of_words<S: Simd>(
    simd: S,
    (layout, plane): (&ContactLanes, &PlaneGroups),
    deflections: &[S::f64s],
    gaps: &[f64],
    (now, max, words): (&mut [S::f64s], &mut [S::f64s], &mut [u64]),
    first_word: usize,
) {
    let start = first_word * 64;
    let groups = layout.left.len().min((first_word + words.len()) * 64);
    let (left, right) = (&layout.left[..groups], &layout.right[..groups]);
    let (left_y, right_y) = (&plane.left_y[..groups], &plane.right_y[..groups]);
    let (normal_x, _) = S::as_simd_f64s(&plane.normal_x);
    let (normal_y, _) = S::as_simd_f64s(&plane.normal_y);
    let (normal_x, normal_y) = (&normal_x[..groups], &normal_y[..groups]);
    let (gaps, _) = S::as_simd_f64s(gaps);
    let gaps = &gaps[..groups];
    let (now, max) = (&mut now[..groups - start], &mut max[..groups - start]);
    for (w, word) in words.iter_mut().enumerate() {
        let mut bits = 0u64;
        let first = start + w * 64;
        for g in first..groups.min(first + 64) {
            let along_x = simd.sub_f64s(deflections[left[g] as usize], deflections[right[g] as usize]);
            let along_y = simd.sub_f64s(deflections[left_y[g] as usize], deflections[right_y[g] as usize]);
            let approach = simd.mul_add_e_f64s(normal_x[g], along_x, simd.mul_f64s(normal_y[g], along_y));
            let n = simd.sub_f64s(approach, gaps[g]);
            now[g - start] = n;
            max[g - start] = simd.max_f64s(max[g - start], n);
            bits |= u64::from(simd.reduce_max_f64s(n) > 0.0) << (g % 64);
        }
        *word = bits;
    }
}

/// ½ Σ (v² + ωᵢ² q²) over every pin (`stiffness` = ωᵢ² per mode: one row of vectors).
#[inline(always)]
pub(super) fn modal_energy<S: Simd>(simd: S, stiffness: &[S::f64s], q: &[S::f64s], v: &[S::f64s]) -> f64 {
    let n = stiffness.len();
    let mut acc = simd.splat_f64s(0.0);
    for (q, v) in q.chunks_exact(n).zip(v.chunks_exact(n)) {
        for k in 0..n {
            acc = simd.mul_add_e_f64s(v[k], v[k], acc);
            acc = simd.mul_add_e_f64s(simd.mul_f64s(stiffness[k], q[k]), q[k], acc);
        }
    }
    0.5 * simd.reduce_sum_f64s(acc)
}

/// Per-mode coefficients of the modal update (each one row of vectors).
pub(super) struct ModalCoefficients<'a, S: Simd> {
    /// ωᵢ².
    pub stiffness: &'a [S::f64s],
    /// 2ξᵢωᵢ.
    pub damping: &'a [S::f64s],
    /// Central difference: 1/(1 + ξᵢωᵢΔt); Tchamwa: 1.
    pub factor: &'a [S::f64s],
    /// Γᵢ.
    pub participation: &'a [S::f64s],
    /// 1/μ of the lines' kind ([`super::kinds`]): their loads are divided by their mass
    /// relative to the basis's beam (1 for the basis's).
    pub inverse_mass: f64,
}

/// Sums the modal update accumulates: Σ 2ξω v² and Σ Γ v over every pin and mode.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct UpdateSums {
    pub damping_power: f64,
    pub participation_velocity: f64,
}

/// q, v, a and the loads f of every pin, as [`modal_update`] reads and writes them.
pub(super) type ModalState<'a, V> = (&'a [V], &'a mut [V], &'a mut [V], &'a mut [V]);

/// Accumulators of the power sums (independent dependency chains).
const SUMS: usize = 4;

/// With f the contact and point loads: a = (f/μ − Γ·base − ω² q − 2ξω v)·factor, then
/// v += `half_step`·a (0 for Tchamwa, whose velocity was advanced before the forces),
/// and f is zeroed for the next step; returns the power sums at the new v. `SCALED`:
/// whether μ ≠ 1 (the basis's own lines skip the multiply).
#[inline(always)]
pub(super) fn modal_update<S: Simd, const SCALED: bool>(
    simd: S,
    coefficients: &ModalCoefficients<'_, S>,
    base: f64,
    half_step: f64,
    (q, v, a, f): ModalState<'_, S::f64s>,
) -> UpdateSums {
    let n = coefficients.stiffness.len();
    let (k, c) = (coefficients.stiffness, &coefficients.damping[..n]);
    let (x, g) = (&coefficients.factor[..n], &coefficients.participation[..n]);
    let (half, load, zero, inverse_mass) = (
        simd.splat_f64s(half_step),
        simd.splat_f64s(-base),
        simd.splat_f64s(0.0),
        simd.splat_f64s(coefficients.inverse_mass),
    );
    let mut damping_power = [zero; SUMS];
    let mut participation_velocity = [zero; SUMS];
    for (((q, v), a), f) in q
        .chunks_exact(n)
        .zip(v.chunks_exact_mut(n))
        .zip(a.chunks_exact_mut(n))
        .zip(f.chunks_exact_mut(n))
    {
        for i in 0..n {
            let loads = if SCALED {
                simd.mul_f64s(f[i], inverse_mass)
            } else {
                f[i]
            };
            let force = simd.mul_add_e_f64s(load, g[i], loads);
            f[i] = zero;
            let elastic = simd.mul_f64s(k[i], q[i]);
            let viscous = simd.mul_f64s(c[i], v[i]);
            a[i] = simd.mul_f64s(simd.sub_f64s(simd.sub_f64s(force, elastic), viscous), x[i]);
            v[i] = simd.mul_add_e_f64s(half, a[i], v[i]);
            let s = i % SUMS;
            damping_power[s] = simd.mul_add_e_f64s(simd.mul_f64s(c[i], v[i]), v[i], damping_power[s]);
            participation_velocity[s] = simd.mul_add_e_f64s(g[i], v[i], participation_velocity[s]);
        }
    }
    UpdateSums {
        damping_power: total(simd, damping_power),
        participation_velocity: total(simd, participation_velocity),
    }
}

/// Σ of the lanes of [`SUMS`] accumulators, pairwise.
#[inline(always)]
fn total<S: Simd>(simd: S, sums: [S::f64s; SUMS]) -> f64 {
    let pairs = [simd.add_f64s(sums[0], sums[1]), simd.add_f64s(sums[2], sums[3])];
    simd.reduce_sum_f64s(simd.add_f64s(pairs[0], pairs[1]))
}

/// First half of a step over the whole state: q += Δt v + `curvature`·a, then
/// v += `half_step`·a. Central difference: half_step = ½Δt and curvature = ½Δt², so
/// that q ends at qₙ + Δt v½; Tchamwa: half_step = Δt, curvature = φΔt².
#[inline(always)]
pub(super) fn advance_positions<S: Simd>(
    simd: S,
    (dt, half_step, curvature): (f64, f64, f64),
    q: &mut [S::f64s],
    v: &mut [S::f64s],
    a: &[S::f64s],
) {
    let (step, half, curve) = (
        simd.splat_f64s(dt),
        simd.splat_f64s(half_step),
        simd.splat_f64s(curvature),
    );
    for ((q, v), a) in q.iter_mut().zip(v.iter_mut()).zip(a) {
        *q = simd.mul_add_e_f64s(curve, *a, simd.mul_add_e_f64s(step, *v, *q));
        *v = simd.mul_add_e_f64s(half, *a, *v);
    }
}

#[cfg(test)]
mod tests {
    //! Every kernel against its plain formula, on the SIMD level of this CPU and on the
    //! scalar fallback (one lane per vector, so other layouts of the same contacts).

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

    /// `values` as SIMD vectors (its length is a whole number of vectors).
    fn vectors<S: Simd>(values: &[f64]) -> &[S::f64s] {
        let (head, tail) = S::as_simd_f64s(values);
        assert!(tail.is_empty());
        head
    }

    fn check<S: Simd>(simd: S) {
        let lanes = lanes::<S>();
        let (pins, row) = (3, 2 * lanes.max(4));
        let (x, y, z) = (values(row, 0.7), values(row, 1.3), values(row, 2.9));
        let plain: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        assert!(close(
            dot(simd, &x[..row - 1], &y[..row - 1]),
            plain - x[row - 1] * y[row - 1]
        ));
        let u = values(row, 3.1);
        let rate: f64 = (0..row)
            .map(|i| x[i] * ((y[i] - u[i]) + 0.25 * (z[i] - x[i])))
            .sum();
        let (left, right) = (
            (vectors::<S>(&y), vectors::<S>(&z)),
            (vectors::<S>(&u), vectors::<S>(&x)),
        );
        assert!(close(
            penetration_rate(simd, vectors::<S>(&x), left, right, 0.25),
            rate
        ));
        let mut w = z.clone();
        axpy(simd, -1.5, &x[..row - 1], &mut w[..row - 1]);
        assert!((0..row - 1).all(|i| close(w[i], z[i] - 1.5 * x[i])) && w[row - 1] == z[row - 1]);
        let mut w = z.clone();
        row_axpy(simd, 2.0, vectors::<S>(&x), S::as_mut_simd_f64s(&mut w).0);
        assert!((0..row).all(|i| close(w[i], z[i] + 2.0 * x[i])));

        // Heights in 1 to 6 blocks: groups of every size, the last block padded.
        for count in [1, 4, 9, 21] {
            let shapes = values(count * row, 0.37);
            let q = values(pins * row, 0.53);
            let grouped = LevelShapes::new(&shapes, row, lanes);
            let stride = pins + 2;
            let mut out = vec![7.0; stride * grouped.blocks * lanes];
            level_deflections(simd, &grouped, row, &q, S::as_mut_simd_f64s(&mut out).0, stride);
            for l in 0..grouped.blocks * lanes {
                let at = |slot: usize| out[((l / lanes) * stride + slot) * lanes + l % lanes];
                assert!(at(0) == 7.0 && at(pins + 1) == 7.0, "wall slots are left alone");
                for p in 0..pins {
                    let expected = if l < count {
                        (0..row).map(|i| shapes[l * row + i] * q[p * row + i]).sum()
                    } else {
                        0.0
                    };
                    assert!(close(at(1 + p), expected), "level {l} of pin {p}");
                }
            }
        }

        // Contacts (level, left slot, right slot) in 3 blocks of a 5-slot layout: a row of
        // neighbours at 6 levels, a lone wall contact, and two contacts on the same slots
        // and level (they cannot share a lane).
        let stride = 5;
        let contacts: Vec<(usize, usize, usize)> = (0..6)
            .flat_map(|level| (0..4).map(move |s| (level, s, s + 1)))
            .chain([(9, 0, 2), (1, 1, 2)])
            .collect();
        let layout = ContactLanes::new(contacts.iter().copied(), lanes, stride);
        assert_eq!(
            layout.by_contact(&layout.contact),
            (0..contacts.len() as u32).collect::<Vec<_>>()
        );
        let groups = layout.left.len();
        assert_eq!(layout.len(), groups * lanes);
        if lanes == 4 {
            // 4 pairs in the blocks of levels 0–3 and 4–5, the lone one, the duplicate.
            assert_eq!(groups, 10);
        }
        let blocks = 10usize.div_ceil(lanes);
        let deflections = values(blocks * stride * lanes, 0.61);
        let gaps_by_contact = values(contacts.len(), 0.67);
        let gaps = layout.by_lane(&gaps_by_contact, f64::INFINITY);
        let lanes_total = layout.len();
        let (mut now, mut max) = (vec![0.0; lanes_total], vec![0.2; lanes_total]);
        let mut closed = vec![0; lanes_total];
        let mut closed_groups = vec![0; groups.div_ceil(64)];
        let count = penetrations(
            simd,
            &layout,
            vectors::<S>(&deflections),
            &gaps,
            ContactState {
                now: &mut now,
                max: &mut max,
                closed: &mut closed,
                closed_groups: &mut closed_groups,
            },
        );
        let mut expected_closed = Vec::new();
        for (c, (level, left, right)) in contacts.iter().enumerate() {
            let w = |slot: usize| deflections[((level / lanes) * stride + slot) * lanes + level % lanes];
            let expected = w(*left) - w(*right) - gaps_by_contact[c];
            let lane = layout.lane[c] as usize;
            assert!(close(now[lane], expected) && max[lane] == expected.max(0.2));
            if expected > 0.0 {
                expected_closed.push(lane as u32);
            }
        }
        expected_closed.sort_unstable();
        assert!(!expected_closed.is_empty() && expected_closed.len() < contacts.len());
        assert_eq!(closed[..count], expected_closed[..]);

        let (stiffness, damping, factor, participation) = (
            values(row, 0.11),
            values(row, 0.17),
            values(row, 0.19),
            values(row, 0.23),
        );
        let coefficients = ModalCoefficients::<S> {
            stiffness: vectors::<S>(&stiffness),
            damping: vectors::<S>(&damping),
            factor: vectors::<S>(&factor),
            participation: vectors::<S>(&participation),
            inverse_mass: 0.8,
        };
        let (q, f0) = (values(pins * row, 0.29), values(pins * row, 0.31));
        let (mut v, mut a, mut f) = (values(pins * row, 0.41), vec![0.0; pins * row], f0.clone());
        let v0 = v.clone();
        let sums = modal_update::<S, true>(
            simd,
            &coefficients,
            0.7,
            0.5,
            (
                vectors::<S>(&q),
                S::as_mut_simd_f64s(&mut v).0,
                S::as_mut_simd_f64s(&mut a).0,
                S::as_mut_simd_f64s(&mut f).0,
            ),
        );
        let (mut damping_power, mut participation_velocity) = (0.0, 0.0);
        for k in 0..pins * row {
            let i = k % row;
            let load = f0[k] * 0.8 - 0.7 * participation[i];
            let acceleration = (load - stiffness[i] * q[k] - damping[i] * v0[k]) * factor[i];
            let velocity = v0[k] + 0.5 * acceleration;
            assert!(close(a[k], acceleration) && close(v[k], velocity) && f[k] == 0.0);
            damping_power += damping[i] * velocity * velocity;
            participation_velocity += participation[i] * velocity;
        }
        assert!(close(sums.damping_power, damping_power));
        assert!(close(sums.participation_velocity, participation_velocity));
        let energy: f64 = (0..pins * row)
            .map(|k| 0.5 * (v[k] * v[k] + stiffness[k % row] * q[k] * q[k]))
            .sum();
        assert!(close(
            modal_energy(simd, vectors::<S>(&stiffness), vectors::<S>(&q), vectors::<S>(&v)),
            energy
        ));

        for (half, curvature) in [(0.5, 0.25), (1.0, 0.3)] {
            let (mut q, mut v, a) = (values(row, 0.43), values(row, 0.47), values(row, 0.59));
            let (q0, v0) = (q.clone(), v.clone());
            advance_positions(
                simd,
                (0.9, half, curvature),
                S::as_mut_simd_f64s(&mut q).0,
                S::as_mut_simd_f64s(&mut v).0,
                vectors::<S>(&a),
            );
            for k in 0..row {
                assert!(close(q[k], q0[k] + 0.9 * v0[k] + curvature * a[k]));
                assert!(close(v[k], v0[k] + half * a[k]));
            }
        }
    }

    #[test]
    fn kernels_match_their_formulas_on_this_cpu_and_on_the_scalar_fallback() {
        pulp::Arch::new().dispatch(Check);
        check(pulp::Scalar::new());
    }
}
