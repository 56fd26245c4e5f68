//! What a run records: the sampled histories and their peaks between samples (the
//! deflections of every line, the forces of the recorded contacts), the per-contact
//! statistics (and wear work in the plane) and per-line extremes accumulated at every
//! step, and the energy accounting (dissipated and external work by the trapezoidal
//! rule on the powers of each step). It reads the [`State`] and never changes it.

use pulp::Simd;

use super::kernels::level_deflections;
use super::layout::{ContactModel, Layout};
use super::resultants::Resultants;
use super::state::State;
use super::{
    ContactStatistics, CurvaturePeak, EnergyBalance, FrictionStatistics, PeakDeflection, PinExtreme,
    Settings, Simulation,
};
use crate::impacts::{ContactImpacts, ImpactClock, ImpactLog, ImpactSink, ImpactStatistics};

/// Powers of a step (W), integrated over time by the trapezoidal rule.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Powers {
    /// Σ 2ξᵢωᵢ q̇ᵢ²: modal damping.
    pub modal_damping: f64,
    /// Σ (F − Kc δ) δ̇ over closed contacts: dashpots and the force clamp.
    pub contact_damping: f64,
    /// Base excitation and point forces.
    pub external: f64,
}

/// Histories, peaks, statistics and energy of one run.
pub(super) struct Recorder {
    /// Per lane: statistics, largest penetration so far, largest force since the last
    /// sample.
    pub statistics: Vec<ContactStatistics>,
    pub max_penetration: Vec<f64>,
    pub force_peak: Vec<f64>,
    /// Per lane in the plane (empty for the row): ∫ F |v_t| dt (J), while slipping
    /// for a contact with friction, and its friction.
    pub wear: Vec<f64>,
    pub friction: Vec<FrictionStatistics>,
    /// Per lane: impacts as counted by `Settings::impacts`, the run's clock for them,
    /// their table and the current step's block.
    pub impacts: Vec<ContactImpacts>,
    pub impact_clock: ImpactClock,
    pub impact_log: ImpactLog,
    /// The block of the current step, and its last step.
    pub impact_block: usize,
    impact_block_end: u64,
    /// The lanes of the recorded contacts, in the order of their histories.
    recorded: Vec<usize>,
    /// Per output height and line, the highest and lowest deflection since the last
    /// sample, and the deflection of largest magnitude over the run.
    deflection_high: Vec<f64>,
    deflection_low: Vec<f64>,
    peak_deflections: Vec<PeakDeflection>,
    /// Scratch: the nodal deflections of every pin at the last sample (laid out as the
    /// level deflections).
    node_deflections: Vec<f64>,
    pub energy: EnergyBalance,
    previous_power: Powers,
    /// Largest |net external work| so far (J).
    pub external_work_peak: f64,
    time: Vec<f64>,
    deflections: Vec<Vec<Vec<f64>>>,
    deflection_peaks: Vec<Vec<Vec<f64>>>,
    /// Per recorded contact (not by lane).
    contact_forces: Vec<Vec<f64>>,
    contact_force_peaks: Vec<Vec<f64>>,
    mechanical_energy: Vec<f64>,
    pin_extremes: Vec<PinExtreme>,
    /// Per pin in the plane (empty for the row): the largest resultant deflection.
    resultant_extremes: Vec<PinExtreme>,
    /// Scratch: every line's curvature at every node and output height at the last
    /// sample (laid out as the level deflections).
    node_curvatures: Vec<f64>,
    output_curvatures: Vec<f64>,
    curvatures: Vec<Vec<Vec<f64>>>,
    curvature_envelope: Vec<CurvaturePeak>,
    /// The square of each node's envelope curvature (the comparisons' operand).
    envelope_squares: Vec<f64>,
    /// Per pin, the square of its kind's [`super::BodyKind::envelope_weight`] (1 for the
    /// basis's beam): what the envelope compares is the weighted curvature.
    envelope_weights: Vec<f64>,
    pin_curvatures: Vec<CurvaturePeak>,
    /// Scratch: every line's deflection or curvature at every node, line after line.
    node_columns: Vec<f64>,
    /// The height of every mesh node (m), as the decimal it stands for: computed once,
    /// not at every sample.
    node_heights: Vec<f64>,
    /// The resultant contact force on every pin at every contact height (every step).
    pub resultants: Resultants,
}

impl Recorder {
    /// Nothing recorded yet.
    pub fn new(layout: &Layout<'_>, settings: &Settings) -> Self {
        let lines = layout.lines;
        let lanes = layout.contact_lanes();
        let outputs = layout.output_offsets.len() * lines;
        let lane_of = |c: &usize| layout.contacts.lane[*c] as usize;
        let recorded: Vec<usize> = match &settings.recorded_contacts {
            Some(contacts) => contacts.iter().map(lane_of).collect(),
            None => (0..layout.model.contacts.len()).map(|c| lane_of(&c)).collect(),
        };
        let contacts = recorded.len();
        let counting = &settings.impacts;
        let steps = layout.step.steps(settings.duration);
        let mesh = layout.model.basis.model();
        let node_heights: Vec<f64> = (0..=mesh.elements)
            .map(|node| crate::decimal(node as f64 * mesh.element_length))
            .collect();
        Self {
            statistics: vec![ContactStatistics::default(); lanes],
            impacts: impacts_by_lane(layout, counting.blocks),
            impact_clock: ImpactClock::new(counting, layout.dt, steps),
            impact_log: ImpactLog::new(layout.model.contacts.len(), counting),
            impact_block: 0,
            impact_block_end: 0,
            max_penetration: vec![f64::NEG_INFINITY; lanes],
            force_peak: vec![0.0; lanes],
            wear: match layout.contact_model {
                ContactModel::Row => Vec::new(),
                ContactModel::Plane(_) => vec![0.0; lanes],
            },
            friction: match layout.contact_model {
                ContactModel::Row => Vec::new(),
                ContactModel::Plane(_) => vec![FrictionStatistics::default(); lanes],
            },
            recorded,
            deflection_high: vec![0.0; outputs],
            deflection_low: vec![0.0; outputs],
            peak_deflections: vec![PeakDeflection::default(); outputs],
            node_deflections: vec![0.0; layout.node_deflections_len()],
            energy: EnergyBalance::default(),
            previous_power: Powers::default(),
            external_work_peak: 0.0,
            time: Vec::new(),
            deflections: vec![vec![Vec::new(); lines]; settings.output_heights.len()],
            deflection_peaks: vec![vec![Vec::new(); lines]; settings.output_heights.len()],
            contact_forces: vec![Vec::new(); contacts],
            contact_force_peaks: vec![Vec::new(); contacts],
            mechanical_energy: Vec::new(),
            pin_extremes: vec![PinExtreme::default(); lines],
            resultant_extremes: match layout.contact_model {
                ContactModel::Row => Vec::new(),
                ContactModel::Plane(_) => vec![PinExtreme::default(); layout.model.pins],
            },
            node_curvatures: vec![0.0; layout.node_curvatures_len()],
            output_curvatures: vec![0.0; layout.output_curvatures_len()],
            curvatures: vec![vec![Vec::new(); lines]; settings.output_heights.len()],
            curvature_envelope: node_heights
                .iter()
                .map(|&height| CurvaturePeak {
                    height,
                    ..CurvaturePeak::default()
                })
                .collect(),
            envelope_squares: vec![0.0; node_heights.len()],
            envelope_weights: {
                let weights: Vec<f64> = std::iter::once(1.0)
                    .chain(
                        layout
                            .model
                            .kinds
                            .iter()
                            .map(|k| k.envelope_weight * k.envelope_weight),
                    )
                    .collect();
                layout.model.pin_kinds().iter().map(|k| weights[*k]).collect()
            },
            node_columns: vec![0.0; lines * node_heights.len()],
            node_heights,
            resultants: Resultants::new(layout),
            pin_curvatures: (0..layout.model.pins)
                .map(|pin| CurvaturePeak {
                    pin,
                    ..CurvaturePeak::default()
                })
                .collect(),
        }
    }

    /// Contacts already closed at t = 0 count as impacts at t = 0, with their force then.
    pub fn record_initial_contacts(&mut self, layout: &Layout<'_>, state: &State) {
        for (contact, lane) in layout.model.contacts.iter().zip(&layout.contacts.lane) {
            let lane = *lane as usize;
            let penetration = state.penetration[lane];
            if penetration > 0.0 && contact.normal_law().is_active() {
                let force = state.contact_force[lane];
                self.impacts[lane].record_initial(&self.impact_clock, force);
                let stats = &mut self.statistics[lane];
                stats.first_impact_time = Some(0.0);
                // The force at t = 0 counts for the peak, as it does in the samples.
                stats.max_force = state.contact_force[lane];
                stats.max_force_time = 0.0;
            }
        }
    }

    /// Step n's block for the impacts (a comparison, and a division when it changes).
    #[inline(always)]
    pub fn enter_step(&mut self, n: u64) {
        if n > self.impact_block_end {
            let block = self.impact_clock.block(n);
            if block != self.impact_block {
                for contact in &mut self.impacts {
                    contact.enter_block(block, &self.impact_clock);
                }
            }
            self.impact_block = block;
            self.impact_block_end = self.impact_clock.last_step(block);
        }
    }

    /// Accumulates the powers of the step just taken (step length 2 × `half`).
    #[inline(always)]
    pub fn add_powers(&mut self, half: f64, powers: Powers) {
        let (energy, previous) = (&mut self.energy, self.previous_power);
        energy.dissipated_modal += half * (previous.modal_damping + powers.modal_damping);
        energy.dissipated_contact += half * (previous.contact_damping + powers.contact_damping);
        energy.external_work += half * (previous.external + powers.external);
        self.external_work_peak = self.external_work_peak.max(energy.external_work.abs());
        self.previous_power = powers;
    }

    /// Keeps, per output height and line, the highest and the lowest deflection since the
    /// last sample (branch-free: this runs at every step).
    #[inline(always)]
    pub fn track_deflection_peaks(&mut self, layout: &Layout<'_>, level_deflections: &[f64]) {
        let (lines, lanes) = (layout.lines, layout.lanes);
        for (h, &offset) in layout.output_offsets.iter().enumerate() {
            let column = &level_deflections[offset..][..(lines - 1) * lanes + 1];
            let highs = &mut self.deflection_high[h * lines..][..lines];
            let lows = &mut self.deflection_low[h * lines..][..lines];
            for (p, (high, low)) in highs.iter_mut().zip(lows.iter_mut()).enumerate() {
                let w = column[p * lanes];
                *high = if w > *high { w } else { *high };
                *low = if w < *low { w } else { *low };
            }
        }
    }

    /// Records the samples at time `t` (the state is the one of the last step) and the
    /// peaks since the previous sample, then starts new peaks.
    pub fn record_sample(&mut self, arch: pulp::Arch, layout: &Layout<'_>, state: &State, t: f64) {
        self.time.push(t);
        let (lines, lanes) = (layout.lines, layout.lanes);
        for (h, &offset) in layout.output_offsets.iter().enumerate() {
            for p in 0..lines {
                // From the same values as the peaks, so that no sample exceeds its peak.
                let w = state.level_deflections[offset + p * lanes];
                let k = h * lines + p;
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
        for ((history, peaks), &lane) in self
            .contact_forces
            .iter_mut()
            .zip(&mut self.contact_force_peaks)
            .zip(&self.recorded)
        {
            let force = state.contact_force_of(lane);
            history.push(force);
            peaks.push(self.force_peak[lane].max(force));
        }
        // Every lane's peak restarts, recorded or not (the step tracks them all).
        self.force_peak.fill(0.0);
        self.mechanical_energy.push(state.mechanical_energy(arch, layout));
        self.record_pin_extremes(arch, layout, state, t);
        self.record_bending(arch, layout, state, t);
    }

    /// The curvature of every line at the output heights (the moment histories), and
    /// the largest at every node and of every pin so far (the bending envelope).
    fn record_bending(&mut self, arch: pulp::Arch, layout: &Layout<'_>, state: &State, t: f64) {
        for (shapes, out) in [
            (&layout.node_curvature_shapes, &mut self.node_curvatures),
            (&layout.output_curvature_shapes, &mut self.output_curvatures),
        ] {
            arch.dispatch(LevelsOp {
                layout,
                shapes,
                q: &state.q,
                out,
            });
        }
        let (lanes, stride, pins, lines) = (layout.lanes, layout.stride, layout.model.pins, layout.lines);
        // The transport's curvature by a moving top support (per output height or node),
        // and the support's displacement per channel of the line (x, y): once a sample.
        fn transport_of(curvature: &[f64], moving: Option<[f64; 2]>) -> Option<(&[f64], [f64; 2])> {
            moving.filter(|_| !curvature.is_empty()).map(|by| (curvature, by))
        }
        let moving = state.wall.as_ref().map(|wall| wall.transport());
        let (output_transport, node_transport) = match &layout.walls {
            Some(walls) => (
                transport_of(&walls.output_transport_curvature, moving),
                transport_of(&walls.node_transport_curvature, moving),
            ),
            None => (None, None),
        };
        let moved = |transport: Option<(&[f64], [f64; 2])>, at: usize, line: usize| {
            transport.map_or(0.0, |(curvature, by)| {
                curvature[at] * by[usize::from(line >= pins)]
            })
        };
        // Level `level` of `line` in a block-of-lanes layout ([`LevelsOp`]).
        let index = |level: usize, line: usize| {
            let (block, lane) = (level / lanes, level % lanes);
            (block * stride + 1 + line) * lanes + lane
        };
        for (h, per_line) in self.curvatures.iter_mut().enumerate() {
            for (line, history) in per_line.iter_mut().enumerate() {
                history.push(self.output_curvatures[index(h, line)] + moved(output_transport, h, line));
            }
        }
        // Every line's curvature at every node, line after line, then each pin's (its
        // resultant in the plane) node by node: squares compared, one root for a new
        // extreme.
        let nodes = self.curvature_envelope.len();
        gather_columns(
            &self.node_curvatures,
            (lanes, stride),
            lines,
            &mut self.node_columns,
        );
        if let Some((curvature, by)) = node_transport {
            add_transport(&mut self.node_columns, curvature, by, pins);
        }
        for (pin, extreme) in self.pin_curvatures.iter_mut().enumerate() {
            let weight = self.envelope_weights[pin];
            let x = &self.node_columns[pin * nodes..(pin + 1) * nodes];
            let y =
                (lines > pins).then(|| &self.node_columns[(pins + pin) * nodes..(pins + pin + 1) * nodes]);
            let mut largest = (extreme.curvature * extreme.curvature, None);
            for node in 0..nodes {
                let squared = x[node] * x[node] + y.map_or(0.0, |y| y[node] * y[node]);
                if squared > largest.0 {
                    largest = (squared, Some(node));
                }
                let weighted = squared * weight;
                if weighted > self.envelope_squares[node] {
                    self.envelope_squares[node] = weighted;
                    self.curvature_envelope[node] = CurvaturePeak {
                        curvature: squared.sqrt(),
                        pin,
                        time: t,
                        ..self.curvature_envelope[node]
                    };
                }
            }
            if let (squared, Some(node)) = largest {
                *extreme = CurvaturePeak {
                    curvature: squared.sqrt(),
                    height: self.node_heights[node],
                    pin,
                    time: t,
                };
            }
        }
    }

    /// The largest |w| of each line over the mesh nodes, if above the one so far.
    fn record_pin_extremes(&mut self, arch: pulp::Arch, layout: &Layout<'_>, state: &State, t: f64) {
        arch.dispatch(LevelsOp {
            layout,
            shapes: &layout.node_shapes,
            q: &state.q,
            out: &mut self.node_deflections,
        });
        let (lanes, stride, pins, lines) = (layout.lanes, layout.stride, layout.model.pins, layout.lines);
        let nodes = self.node_heights.len();
        gather_columns(
            &self.node_deflections,
            (lanes, stride),
            lines,
            &mut self.node_columns,
        );
        // The transport by the top support, with walls that move (0 without).
        if let (Some(walls), Some(wall)) = (&layout.walls, &state.wall)
            && !walls.node_transport.is_empty()
        {
            add_transport(
                &mut self.node_columns,
                &walls.node_transport,
                wall.transport(),
                pins,
            );
        }
        let columns = &self.node_columns;
        let column = |line: usize| &columns[line * nodes..(line + 1) * nodes];
        for (line, extreme) in self.pin_extremes.iter_mut().enumerate() {
            let mut largest = (extreme.max_abs_deflection, None);
            for (node, w) in column(line).iter().enumerate() {
                if w.abs() > largest.0 {
                    largest = (w.abs(), Some(node));
                }
            }
            if let (max_abs_deflection, Some(node)) = largest {
                *extreme = PinExtreme {
                    max_abs_deflection,
                    height: self.node_heights[node],
                    time: t,
                };
            }
        }
        // In the plane, each pin's resultant √(wx² + wy²).
        for (p, extreme) in self.resultant_extremes.iter_mut().enumerate() {
            let (x, y) = (column(p), column(pins + p));
            let mut largest = (extreme.max_abs_deflection.powi(2), None);
            for node in 0..nodes {
                let squared = x[node] * x[node] + y[node] * y[node];
                if squared > largest.0 {
                    largest = (squared, Some(node));
                }
            }
            if let (squared, Some(node)) = largest {
                *extreme = PinExtreme {
                    max_abs_deflection: squared.sqrt(),
                    height: self.node_heights[node],
                    time: t,
                };
            }
        }
    }

    /// The results, with the energy balance of the final state.
    pub fn finish(
        mut self,
        arch: pulp::Arch,
        layout: &Layout<'_>,
        state: &State,
        steps: u64,
        output_interval: f64,
    ) -> Simulation {
        self.energy.kinetic = state.kinetic_energy(layout);
        self.energy.contact = state.contact_energy(layout);
        self.energy.strain =
            state.mechanical_energy(arch, layout) - self.energy.kinetic - self.energy.contact;
        for (stats, max) in self.statistics.iter_mut().zip(&self.max_penetration) {
            stats.max_penetration = *max;
        }
        // Every lane's impacts ended, in contact order; `impacts` counts them as set.
        let (clock, mut log) = (self.impact_clock, self.impact_log);
        let mut impacts: Vec<Option<ContactImpacts>> = self.impacts.into_iter().map(Some).collect();
        let impact_statistics: Vec<ImpactStatistics> = layout
            .contacts
            .lane
            .iter()
            .map(|&lane| {
                let contact = impacts[lane as usize].take().expect("one contact per lane");
                let stats = &mut self.statistics[lane as usize];
                if clock.loads_every_closed_step() {
                    let closed = contact.closed_steps(layout.dt);
                    stats.contact_time = closed.contact_time;
                    stats.impulse = closed.impulse;
                    stats.max_force = closed.max_force;
                    stats.max_force_time = closed.max_force_time;
                }
                let statistics = contact.finish(&clock, &mut log);
                stats.impacts = statistics.summary.impacts;
                statistics
            })
            .collect();
        let (impact_table, impact_histogram) = log.finish();
        Simulation {
            step: layout.step,
            steps,
            output_interval,
            time: self.time,
            deflections: self.deflections,
            deflection_peaks: self.deflection_peaks,
            peak_deflections: self
                .peak_deflections
                .chunks(layout.lines.max(1))
                .map(<[_]>::to_vec)
                .collect(),
            contact_forces: self.contact_forces,
            contact_force_peaks: self.contact_force_peaks,
            contact_statistics: layout.contacts.by_contact(&self.statistics),
            wear_work: match layout.contact_model {
                ContactModel::Row => Vec::new(),
                ContactModel::Plane(_) => layout.contacts.by_contact(&self.wear),
            },
            friction_statistics: match layout.contact_model {
                ContactModel::Row => Vec::new(),
                ContactModel::Plane(_) => layout.contacts.by_contact(&self.friction),
            },
            impact_statistics,
            impact_table,
            impact_histogram,
            pin_extremes: self.pin_extremes,
            resultant_extremes: self.resultant_extremes,
            curvatures: self.curvatures,
            curvature_envelope: self.curvature_envelope,
            pin_curvatures: self.pin_curvatures,
            resultant_forces: self.resultants.finish(layout.dt),
            energy: self.energy,
            mechanical_energy: self.mechanical_energy,
        }
    }
}

/// A closed contact's step n (of `dt`, in impact block `block`) in its statistics and
/// impacts: the first closure (`previous` ≤ 0, timed by linear interpolation of the
/// penetration), contact time, impulse, the largest force, and the impact counting.
/// With a threshold of 0 every closed step is loaded, and the impacts' sums are the
/// contact's: they are summed once, and [`Recorder::finish`] reads them.
#[inline(always)]
pub(super) fn record_closed_contact(
    (stats, impacts): (&mut ContactStatistics, &mut ContactImpacts),
    (clock, log): (&ImpactClock, &mut impl ImpactSink),
    (n, block, dt): (u64, usize, f64),
    (penetration, previous): (f64, f64),
    (force, dissipation): (f64, f64),
) {
    if previous <= 0.0 && stats.first_impact_time.is_none() {
        let t = n as f64 * dt;
        stats.first_impact_time = Some(t - dt * penetration / (penetration - previous));
    }
    let at = (n, block);
    if clock.loads_every_closed_step() {
        impacts.record(clock, log, at, force, (penetration, previous), dissipation);
        return;
    }
    stats.contact_time += dt;
    stats.impulse += force * dt;
    if force > stats.max_force {
        stats.max_force = force;
        // On the grid of the step (the times of an every-step history).
        stats.max_force_time = super::step_size::sample_time(n, dt);
    }
    if clock.loads(force) {
        impacts.record(clock, log, at, force, (penetration, previous), dissipation);
    }
}

/// Per lane, the impacts of its contact (of none in empty lanes), each with the inverse
/// of its effective mass: with unit modal masses a force F along the contact's normal
/// changes the relative normal acceleration by F Σᵢ ψᵢ(z)² per pin it touches (the
/// normal is a unit vector and x and y share the basis).
fn impacts_by_lane(layout: &Layout<'_>, blocks: usize) -> Vec<ContactImpacts> {
    let mut contact_of_lane = vec![usize::MAX; layout.lane_contacts.len()];
    for (contact, &lane) in layout.contacts.lane.iter().enumerate() {
        contact_of_lane[lane as usize] = contact;
    }
    let (lanes, row, wall) = (layout.lanes, layout.row, layout.wall_row);
    layout
        .lane_contacts
        .iter()
        .zip(contact_of_lane)
        .map(|(lane, contact)| {
            let shape = &layout.level_shapes[lane.shape * lanes..][..row];
            let pins = usize::from(lane.left != wall) + usize::from(lane.right != wall);
            let inverse_mass = pins as f64 * shape.iter().map(|psi| psi * psi).sum::<f64>();
            ContactImpacts::new(contact, inverse_mass, blocks)
        })
        .collect()
}

/// Every line's value at every level of `shapes` (deflections or curvatures at the nodes,
/// curvatures at the output heights), as a [`pulp::WithSimd`] operation.
struct LevelsOp<'a> {
    layout: &'a Layout<'a>,
    shapes: &'a super::kernels::LevelShapes,
    q: &'a [f64],
    out: &'a mut [f64],
}

impl pulp::WithSimd for LevelsOp<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let layout = self.layout;
        level_deflections(
            simd,
            self.shapes,
            layout.row,
            self.q,
            S::as_mut_simd_f64s(self.out).0,
            layout.stride,
        );
    }
}

/// Every line's values at the mesh nodes of a block-of-lanes layout ([`LevelsOp`]:
/// level n of line l at `(n / lanes · stride + 1 + l) · lanes + n % lanes`), gathered
/// line after line into `columns` (lines × nodes).
fn gather_columns(values: &[f64], (lanes, stride): (usize, usize), lines: usize, columns: &mut [f64]) {
    let nodes = columns.len() / lines.max(1);
    for (line, column) in columns.chunks_mut(nodes.max(1)).enumerate().take(lines) {
        for (block, chunk) in column.chunks_mut(lanes).enumerate() {
            let at = (block * stride + 1 + line) * lanes;
            chunk.copy_from_slice(&values[at..at + chunk.len()]);
        }
    }
}

/// Adds a moving top support's transport to gathered node columns: `shape` at every
/// node times the support's displacement `by` along x (the first `pins` lines) or y.
fn add_transport(columns: &mut [f64], shape: &[f64], by: [f64; 2], pins: usize) {
    let nodes = shape.len();
    for (line, column) in columns.chunks_mut(nodes.max(1)).enumerate() {
        let factor = by[usize::from(line >= pins)];
        for (value, s) in column.iter_mut().zip(shape) {
            *value += s * factor;
        }
    }
}
