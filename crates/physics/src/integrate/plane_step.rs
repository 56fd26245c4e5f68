//! The plane's step shared between threads ([`super::Settings::threads`] > 1); on one
//! thread the stepper runs its own inlined copy. Four parts of the step are split, each
//! so that every number is computed by the same operations in the same order as on one
//! thread, so the results are the same, bit for bit, for every thread count.
//!
//! 1. The level deflections ([`level_deflections`]): the groups of blocks of levels are
//!    split; each deflection is its own dot product.
//! 2. The vector pass over the contact groups ([`penetrations`]): the words of 64 groups
//!    are split; the closed lanes are then listed from the words on one thread.
//! 3. The closed contacts ([`ClosedPass`]): the list of closed lanes is split into
//!    chunks of [`CLOSED_CHUNK`]; threads write disjoint lanes, each lane's powers
//!    included, which the stepper then sums in the order of the list, as on one thread.
//!    The impacts a thread ends wait in a list and join the log in lane order.
//! 4. The loads and the modal update ([`update_halves`]): the x lines and the y lines.
//!    Each half adds its share of every closed contact's force (so each row receives
//!    the same additions in the same order as on one thread), the walls' transport load,
//!    then updates its modes, and may take the next step's first half with it.
//!
//! The work is forked on the rayon pool the run is called in (`rayon::join`), at most
//! `threads` ways; each piece re-enters the SIMD context of the step
//! (`Simd::vectorize`), as a closure run on another thread is compiled without it. The
//! stepper keeps the pool's other workers looking for these forks for the whole run
//! (`stepper::integrate`).

use pulp::Simd;

use super::kernels::{
    ContactLanes, ContactState, LevelShapes, PlaneGroups, UpdateSums, advance_positions,
    level_deflections_of_groups, list_closed, penetration_rate, plane_penetrations_of_words, row_axpy,
};
use super::layout::{LaneContact, Layout, PlaneLane};
use super::recorder::record_closed_contact;
use super::walls::{WallLayout, WallState};
use super::{ContactStatistics, FrictionStatistics};
use crate::contact::{Friction, NormalForce, NormalLaw, force_vector};
use crate::impacts::{ContactImpacts, Impact, ImpactClock, ImpactSink};

/// Closed contacts per chunk of the contact pass: each chunk has its own sums.
pub(super) const CLOSED_CHUNK: usize = 64;

/// The deflection of every line at every level ([`super::kernels::level_deflections`]),
/// the groups of blocks shared by up to `threads` threads.
pub(super) fn level_deflections<S: Simd>(
    simd: S,
    shapes: &LevelShapes,
    (row, stride): (usize, usize),
    q: &[f64],
    out: &mut [S::f64s],
    (groups, threads): (std::ops::Range<usize>, usize),
) {
    if threads <= 1 || groups.len() <= 1 {
        simd.vectorize(
            #[inline(always)]
            || level_deflections_of_groups(simd, shapes, (row, stride), q, out, groups),
        );
        return;
    }
    let middle = groups.start + groups.len() / 2;
    let (first, second) = out.split_at_mut((middle - groups.start) * LevelShapes::GROUP_BLOCKS * stride);
    let shares = (threads / 2, threads - threads / 2);
    rayon::join(
        || {
            level_deflections(
                simd,
                shapes,
                (row, stride),
                q,
                first,
                (groups.start..middle, shares.0),
            )
        },
        || {
            level_deflections(
                simd,
                shapes,
                (row, stride),
                q,
                second,
                (middle..groups.end, shares.1),
            )
        },
    );
}

/// The plane's penetrations ([`super::kernels::plane_penetrations`]), the words of
/// groups (64 groups a word) shared by up to `threads` threads; then the closed lanes,
/// listed in lane order as on one thread. Returns how many are closed.
pub(super) fn penetrations<S: Simd>(
    simd: S,
    contacts: (&ContactLanes, &PlaneGroups),
    deflections: &[S::f64s],
    gaps: &[f64],
    state: ContactState<'_>,
    threads: usize,
) -> usize {
    let lanes = contacts.0.len();
    let words = &mut state.closed_groups[..contacts.0.left.len().div_ceil(64)];
    {
        let (now, _) = S::as_mut_simd_f64s(&mut state.now[..lanes]);
        let (max, _) = S::as_mut_simd_f64s(&mut state.max[..lanes]);
        penetrations_of_words(
            simd,
            contacts,
            (deflections, gaps),
            (now, max, &mut *words),
            (0, threads),
        );
    }
    list_closed(contacts.0.lanes(), words, state.now, state.closed)
}

/// [`penetrations`]' vector pass over `words` from word `first_word` on, split in two
/// halves of words while `threads` > 1.
fn penetrations_of_words<S: Simd>(
    simd: S,
    contacts: (&ContactLanes, &PlaneGroups),
    (deflections, gaps): (&[S::f64s], &[f64]),
    (now, max, words): (&mut [S::f64s], &mut [S::f64s], &mut [u64]),
    (first_word, threads): (usize, usize),
) {
    if threads <= 1 || words.len() <= 1 {
        simd.vectorize(
            #[inline(always)]
            || plane_penetrations_of_words(simd, contacts, deflections, gaps, (now, max, words), first_word),
        );
        return;
    }
    let middle = words.len() / 2;
    let (words_first, words_second) = words.split_at_mut(middle);
    let (now_first, now_second) = now.split_at_mut(middle * 64);
    let (max_first, max_second) = max.split_at_mut(middle * 64);
    let shares = (threads / 2, threads - threads / 2);
    rayon::join(
        || {
            penetrations_of_words(
                simd,
                contacts,
                (deflections, gaps),
                (now_first, max_first, words_first),
                (first_word, shares.0),
            )
        },
        || {
            penetrations_of_words(
                simd,
                contacts,
                (deflections, gaps),
                (now_second, max_second, words_second),
                (first_word + middle, shares.1),
            )
        },
    );
}

/// What every closed contact of the plane reads.
pub(super) struct ClosedPass<'a, S: Simd> {
    pub simd: S,
    pub lane_contacts: &'a [LaneContact],
    pub lane_laws: &'a [NormalLaw],
    pub lane_friction: &'a [Friction],
    pub plane_lanes: &'a [PlaneLane],
    /// ψ at every level, and the dashpot rows v and a of every line (walls' row last).
    pub shapes: &'a [S::f64s],
    pub v: &'a [S::f64s],
    pub a: &'a [S::f64s],
    /// Per lane, the penetration now and a step ago.
    pub now: &'a [f64],
    pub before: &'a [f64],
    pub walls: Option<(&'a WallLayout, &'a WallState)>,
    pub clock: &'a ImpactClock,
    /// Step, impact block, Δt.
    pub at: (u64, usize, f64),
    pub record: bool,
    pub lookahead: f64,
    /// The row length in vectors.
    pub vectors: usize,
}

/// What the pass writes per lane, for the lanes from `first` on.
pub(super) struct LaneOutputs<'a> {
    pub first: usize,
    /// Dissipation power (F − Kc δ) δ̇ and walls' power F n·ḋ_wall.
    pub powers: &'a mut [[f64; 2]],
    pub forces: &'a mut [f64],
    /// The tangential force T of friction (read as a step ago, then written).
    pub tangentials: &'a mut [f64],
    pub statistics: &'a mut [ContactStatistics],
    pub peaks: &'a mut [f64],
    pub wear: &'a mut [f64],
    pub friction: &'a mut [FrictionStatistics],
    pub impacts: &'a mut [ContactImpacts],
}

impl<'a> LaneOutputs<'a> {
    /// The lanes before `lane`, and those from it on.
    fn split_at(self, lane: usize) -> (Self, Self) {
        let at = lane - self.first;
        let (powers, powers_after) = self.powers.split_at_mut(at);
        let (forces, forces_after) = self.forces.split_at_mut(at);
        let (tangentials, tangentials_after) = self.tangentials.split_at_mut(at);
        let (statistics, statistics_after) = self.statistics.split_at_mut(at);
        let (peaks, peaks_after) = self.peaks.split_at_mut(at);
        let (wear, wear_after) = self.wear.split_at_mut(at);
        let (friction, friction_after) = self.friction.split_at_mut(at);
        let (impacts, impacts_after) = self.impacts.split_at_mut(at);
        (
            Self {
                first: self.first,
                powers,
                forces,
                tangentials,
                statistics,
                peaks,
                wear,
                friction,
                impacts,
            },
            Self {
                first: lane,
                powers: powers_after,
                forces: forces_after,
                tangentials: tangentials_after,
                statistics: statistics_after,
                peaks: peaks_after,
                wear: wear_after,
                friction: friction_after,
                impacts: impacts_after,
            },
        )
    }
}

impl<S: Simd> ClosedPass<'_, S> {
    /// The closed lanes `closed` (ascending), split into chunks of [`CLOSED_CHUNK`]
    /// shared by up to `threads` threads (each writes its own lanes); the impacts they
    /// end go to `log`, in lane order.
    pub fn run(
        &self,
        closed: &[u32],
        mut out: LaneOutputs<'_>,
        log: &mut (impl ImpactSink + Send),
        threads: usize,
    ) {
        let chunks = closed.len().div_ceil(CLOSED_CHUNK);
        if threads <= 1 || chunks <= 1 {
            // The row length as a constant in the usual cases, as in the stepper's own
            // copies of the step: every per-row loop unrolled (measured, 5 % off the
            // shared hex217 run). One `vectorize` per length: a closure holding them all
            // is too large to be inlined into the SIMD context, and ran 2× slower.
            let simd = self.simd;
            match self.vectors {
                1 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<1>(closed, &mut out, log),
                ),
                2 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<2>(closed, &mut out, log),
                ),
                3 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<3>(closed, &mut out, log),
                ),
                4 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<4>(closed, &mut out, log),
                ),
                5 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<5>(closed, &mut out, log),
                ),
                6 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<6>(closed, &mut out, log),
                ),
                7 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<7>(closed, &mut out, log),
                ),
                8 => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<8>(closed, &mut out, log),
                ),
                _ => simd.vectorize(
                    #[inline(always)]
                    || self.lanes::<0>(closed, &mut out, log),
                ),
            }
            return;
        }
        let (closed_first, closed_second) = closed.split_at(chunks / 2 * CLOSED_CHUNK);
        let (out_first, out_second) = out.split_at(closed_second[0] as usize);
        let mut later: Vec<Impact> = Vec::new();
        let shares = (threads / 2, threads - threads / 2);
        rayon::join(
            || self.run(closed_first, out_first, log, shares.0),
            || self.run(closed_second, out_second, &mut later, shares.1),
        );
        for impact in later {
            log.push(impact);
        }
    }

    /// The lanes `closed`, as `plane_contact_forces` in the stepper computes them: with
    /// the dashpot velocity of each body along x and y, rate_x = ψ·Δṽ_x and
    /// rate_y = ψ·Δṽ_y, the penetration rate is δ̇ = n_x rate_x + n_y rate_y and the
    /// sliding velocity v_t = −n_y rate_x + n_x rate_y (tangent t = (−n_y, n_x));
    /// F from the contact's law ([`crate::contact::NormalLaw::force`]), and the wear work gains F |v_t| Δt; each lane's
    /// dissipation power (F − Kc δ) δ̇ and walls' power F n·ḋ_wall are stored.
    #[inline(always)]
    fn lanes<const VECTORS: usize>(
        &self,
        closed: &[u32],
        out: &mut LaneOutputs<'_>,
        log: &mut impl ImpactSink,
    ) {
        // `VECTORS`: the row length in vectors where it is known at compile time, 0
        // where it is not.
        let n = if VECTORS == 0 { self.vectors } else { VECTORS };
        let (simd, lookahead) = (self.simd, self.lookahead);
        let (v, a, shapes) = (self.v, self.a, self.shapes);
        let first = out.first;
        for &j in closed {
            let j = j as usize;
            let (contact, lane) = (self.lane_contacts[j], self.plane_lanes[j]);
            let (penetration, previous) = (self.now[j], self.before[j]);
            let rows = |offset: usize| (&v[offset..], &a[offset..]);
            let shape = &shapes[contact.shape..][..n];
            let mut rate_x =
                penetration_rate(simd, shape, rows(contact.left), rows(contact.right), lookahead);
            let mut rate_y = penetration_rate(simd, shape, rows(lane.left_y), rows(lane.right_y), lookahead);
            let [normal_x, normal_y] = lane.normal;
            let (mut wall_rate, mut wall_sliding) = (0.0, 0.0);
            if let Some((layout, wall)) = self.walls {
                let [x, y] = wall.velocity_of(layout, j);
                (rate_x, rate_y) = (rate_x + x, rate_y + y);
                wall_rate = normal_x * x + normal_y * y;
                wall_sliding = normal_x * y - normal_y * x;
            }
            let rate = normal_x * rate_x + normal_y * rate_y;
            let sliding = normal_x * rate_y - normal_y * rate_x;
            let NormalForce { force, elastic } = contact.force(self.lane_laws, j, penetration, rate);
            let k = j - first;
            out.forces[k] = force;
            let mut dissipation = (force - elastic) * rate;
            let mut wall_power = force * wall_rate;
            let mut slipping = true;
            if contact.friction {
                let dt = self.at.2;
                let previous = if previous > 0.0 { out.tangentials[k] } else { 0.0 };
                let tangential = self.lane_friction[j].step(previous, sliding, dt, force);
                out.tangentials[k] = tangential.force;
                dissipation += tangential.dissipation;
                wall_power += tangential.force * wall_sliding;
                slipping = tangential.slipping;
                if self.record {
                    out.friction[k].record(&tangential, sliding, dt);
                }
            }
            out.powers[k] = [dissipation, wall_power];
            if self.record {
                if force > out.peaks[k] {
                    out.peaks[k] = force;
                }
                if contact.active {
                    record_closed_contact(
                        (&mut out.statistics[k], &mut out.impacts[k]),
                        (self.clock, &mut *log),
                        self.at,
                        (penetration, previous),
                        (force, dissipation),
                    );
                }
                if slipping {
                    out.wear[k] += force * sliding.abs() * self.at.2;
                }
            }
        }
    }
}

/// The x lines (`y` false) or the y lines of the state, from vector `start` on.
pub(super) struct Half<'a> {
    pub y: bool,
    /// Offset (in vectors) of the half's first row in the whole state.
    pub start: usize,
    pub q: &'a mut [f64],
    pub v: &'a mut [f64],
    pub a: &'a mut [f64],
    pub force: &'a mut [f64],
    /// The base acceleration along the half's direction (m/s²).
    pub base: f64,
}

/// What both halves read: the closed contacts and their forces, the walls.
pub(super) struct Loads<'a> {
    pub layout: &'a Layout<'a>,
    pub plane_lanes: &'a [PlaneLane],
    pub closed: &'a [u32],
    pub forces: &'a [f64],
    pub tangentials: &'a [f64],
    pub walls: Option<(&'a WallLayout, &'a WallState)>,
}

/// The modal update of a half: the second half of the step (Δt/2, or 0 for Tchamwa)
/// and, if the next step's first half is taken with it, that first half's (Δt, half
/// step, curvature) ([`advance_positions`]).
pub(super) type Update = (f64, Option<(f64, f64, f64)>);

/// Both halves' contact loads (and the walls' transport loads); with `update`, their
/// modal update with `second_half` too (and with a first half, the first half of the
/// next step after it: [`advance_positions`], the same operations the next step would
/// make), returning the x and the y sums. Up to `threads` threads (two at most: one per
/// half).
pub(super) fn update_halves<S: Simd>(
    simd: S,
    loads: &Loads<'_>,
    halves: [Half<'_>; 2],
    update: Option<Update>,
    threads: usize,
) -> [Option<UpdateSums>; 2] {
    let [x, y] = halves;
    if threads <= 1 {
        return [
            update_half(simd, loads, x, update),
            update_half(simd, loads, y, update),
        ];
    }
    let (x, y) = rayon::join(
        || update_half(simd, loads, x, update),
        || update_half(simd, loads, y, update),
    );
    [x, y]
}

/// One half: every closed contact's force along the half's direction added to the rows
/// of its bodies (−F n to the left one, +F n to the right one), the walls' transport
/// load, and the modal update.
fn update_half<S: Simd>(
    simd: S,
    loads: &Loads<'_>,
    half: Half<'_>,
    update: Option<Update>,
) -> Option<UpdateSums> {
    simd.vectorize(
        #[inline(always)]
        || {
            let layout = loads.layout;
            let (n, wall) = (layout.row / super::kernels::lanes::<S>(), layout.wall_row);
            let shapes = S::as_simd_f64s(&layout.level_shapes).0;
            let rows = S::as_mut_simd_f64s(half.force).0;
            for &j in loads.closed {
                let j = j as usize;
                let force = loads.forces[j];
                if force == 0.0 {
                    continue;
                }
                let (contact, lane) = (layout.lane_contacts[j], loads.plane_lanes[j]);
                let shape = &shapes[contact.shape..][..n];
                let tangential = if contact.friction {
                    loads.tangentials[j]
                } else {
                    0.0
                };
                let [x, y] = force_vector(force, tangential, lane.normal);
                let (left, right, along) = if half.y {
                    (lane.left_y, lane.right_y, y)
                } else {
                    (contact.left, contact.right, x)
                };
                if contact.left != wall {
                    row_axpy(simd, -along, shape, &mut rows[left - half.start..]);
                }
                if contact.right != wall {
                    row_axpy(simd, along, shape, &mut rows[right - half.start..]);
                }
            }
            if let Some((walls, wall)) = loads.walls {
                wall.add_transport_load(walls, half.force, layout.row, usize::from(half.y));
            }
            update.map(|(second_half, next)| {
                let (q, v, a) = (
                    S::as_mut_simd_f64s(half.q).0,
                    S::as_mut_simd_f64s(half.v).0,
                    S::as_mut_simd_f64s(half.a).0,
                );
                let first = if half.y { layout.model.pins } else { 0 };
                let sums = super::stepper::update_lines(
                    simd,
                    layout,
                    first,
                    half.base,
                    second_half,
                    (q, v, a, S::as_mut_simd_f64s(half.force).0),
                );
                if let Some(first_half) = next {
                    advance_positions(simd, first_half, q, v, a);
                }
                sums
            })
        },
    )
}
