//! What does not change during a run: the modal coefficients for the step, the shapes at
//! the contact levels, output heights, point forces and nodes, and how the contacts are
//! indexed (by lanes of the block-major level deflections, [`ContactLanes`]).
//!
//! Layout of the arrays the step runs on: pin-major. Each pin's modal coordinates are one
//! contiguous row of `row` values (the modes rounded up to whole SIMD vectors; padded
//! modes have ω = 0, Γ = 0, ψ = 0 and stay 0). A closed contact then reads and writes
//! whole rows: its dashpot velocity ψ·ṽ is one contiguous dot product and its force
//! projection one contiguous axpy. The deflections at the contact levels are block-major
//! (a vector holds one pin's deflections at `lanes` consecutive levels, with a wall slot
//! on each side: `[wall, pin 0, …, pin n−1, wall]`), and every per-contact array of the
//! step is stored by lane and mapped back to contact order for samples and results.
//!
//! The rows are deflection *lines*: one per pin in the row; in the plane the x lines of
//! every pin, then their y lines (line `pins + p` is pin p along y), each line a row of
//! modal coordinates on the same basis. The level deflections then hold every line
//! (`[wall, x lines, y lines, wall]`), and the contacts pick their kernel here
//! ([`ContactModel`]): the row keeps its one-slot-per-side penetrations, the plane reads
//! four slots and a normal per lane.

use super::kernels::{ContactLanes, Lanes, LevelShapes, PlaneGroups};
use super::walls::WallLayout;
use super::{Model, Settings, StepSize};
use crate::contact::{Body, Contact, Friction, NormalForce, NormalLaw};
use crate::stability::Scheme;

/// The fixed data of one run at one step, for one SIMD level.
pub(super) struct Layout<'m> {
    pub model: &'m Model<'m>,
    pub scheme: Scheme,
    /// Δt (s), and the step it comes from (its critical step for the messages).
    pub dt: f64,
    pub step: StepSize,
    /// f64 values per SIMD vector of the run's `pulp::Arch`.
    pub lanes: usize,
    /// Length of one line's row: the modes rounded up to whole vectors.
    pub row: usize,
    /// Deflection lines: `pins` in the row, `2 × pins` in the plane (x lines, then y).
    pub lines: usize,
    /// Slots per block of the block-major deflections: `[wall, line 0, …, line n−1, wall]`.
    pub stride: usize,
    /// Γᵢ, padded to `row`.
    pub participation: Vec<f64>,
    /// Per kind of body (the basis's first, [`super::BodyKind`]): its modal
    /// coefficients and its mass.
    pub kinds: Vec<LineKind>,
    /// The lines as runs of consecutive lines of one kind (the x lines' runs, then the
    /// y lines'): one run over each direction's lines when every pin is the basis's.
    pub runs: Vec<LineRun>,
    /// The same with the runs of one kind on either side of the x/y boundary merged (what
    /// the energies sum over: one run over every line when every pin is the basis's).
    pub energy_runs: Vec<LineRun>,
    /// The dashpots see ṽ = v + `dashpot_lookahead` · a right after the first half of
    /// the update: ½Δt for central difference (ṽ = v½ + ½Δt aₙ), 0 for Tchamwa.
    pub dashpot_lookahead: f64,
    /// ψ at each distinct contact height (`levels × row`), and by blocks of levels for
    /// [`super::kernels::level_deflections`].
    pub level_shapes: Vec<f64>,
    pub grouped_level_shapes: LevelShapes,
    /// The contacts by lanes of the level deflections.
    pub contacts: ContactLanes,
    /// Per lane: what a closed contact needs (its x rows in the plane), and the gap (∞
    /// in empty lanes).
    pub lane_contacts: Vec<LaneContact>,
    /// Per lane, the normal law with its damping resolved, and friction.
    pub lane_laws: Vec<NormalLaw>,
    pub lane_friction: Vec<Friction>,
    pub gaps: Vec<f64>,
    /// The row's contacts (normal +x) or the plane's.
    pub contact_model: ContactModel,
    /// Offset (in vectors) of the row of zeros after the lines' rows in `v` and `a`,
    /// read for a wall.
    pub wall_row: usize,
    /// ψ at each point force's height (padded to `row`).
    pub point_force_shapes: Vec<Vec<f64>>,
    /// Where pin 0's deflection at each output height is in the level deflections
    /// (output heights that are no contact level are levels with no contact).
    pub output_offsets: Vec<usize>,
    /// Nodal deflection of each mode, for the pin extremes.
    pub node_shapes: LevelShapes,
    /// Bending curvature of each mode at every node and at every output height
    /// ([`crate::modal::ModalBasis::curvature_at`]), for the bending envelope and the
    /// moment histories.
    pub node_curvature_shapes: LevelShapes,
    pub output_curvature_shapes: LevelShapes,
    /// Created energy allowed per joule involved before declaring divergence
    /// (see [`super::stepper`]'s divergence check).
    pub divergence_allowance: f64,
    /// The walls' own motion; `None` when they move with the feet.
    pub walls: Option<WallLayout>,
}

/// A contact as its lane needs it; offsets are in SIMD vectors. The record stays as
/// small as the linear law needs (the closed contacts' pass waits on these scattered
/// records): a power law, Hunt–Crossley damping and friction live in
/// [`Layout::lane_laws`] and [`Layout::lane_friction`], read only by the lanes whose
/// flags say so.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct LaneContact {
    /// K and c of the linear spring–dashpot, its damping resolved (a restitution turned
    /// into a dashpot on the model's basis).
    pub stiffness: f64,
    pub dashpot: f64,
    /// Offset of ψ at the contact's level in `level_shapes`.
    pub shape: usize,
    /// Offsets of the left and right body's rows in the state (`wall_row` for a wall).
    pub left: usize,
    pub right: usize,
    /// Whether it can push at all (stiffness or dashpot > 0): only those count impacts.
    pub active: bool,
    /// Whether its law is a power law or has Hunt–Crossley damping (then it is
    /// `lane_laws[lane]`), whether its force depends on the penetration rate, and
    /// whether it has friction (`lane_friction[lane]`).
    pub nonlinear: bool,
    pub needs_rate: bool,
    pub friction: bool,
}

impl LaneContact {
    /// The force of the contact in `lane`, penetrating by δ > 0 at the rate δ̇: its law
    /// ([`NormalLaw::force`], the one law of every loop), the linear one inlined from
    /// this record.
    #[inline(always)]
    pub fn force(&self, laws: &[NormalLaw], lane: usize, penetration: f64, rate: f64) -> NormalForce {
        if self.nonlinear {
            laws[lane].force(penetration, rate)
        } else {
            NormalLaw::linear(self.stiffness, self.dashpot).force(penetration, rate)
        }
    }
}

/// One kind of body's modal coefficients (padded to `row`): ωᵢ², 2ξᵢωᵢ and the implicit
/// damping factor, and its mass μ relative to the basis's beam (its lines' loads are
/// divided by it, their energies multiplied: [`super::kinds`]).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct LineKind {
    pub omega_squared: Vec<f64>,
    pub damping: Vec<f64>,
    pub implicit_damping_factor: Vec<f64>,
    pub mass: f64,
    pub inverse_mass: f64,
}

/// Consecutive lines `first..first + lines` of one kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LineRun {
    pub first: usize,
    pub lines: usize,
    pub kind: usize,
}

impl LineKind {
    fn new(scale: &super::KindScale<'_>, row: usize, scheme: Scheme, dt: f64) -> Self {
        let damping: Vec<f64> = scale
            .frequencies
            .iter()
            .zip(scale.damping_ratios)
            .map(|(w, xi)| 2.0 * xi * w)
            .collect();
        Self {
            omega_squared: padded(
                &scale.frequencies.iter().map(|w| w * w).collect::<Vec<_>>(),
                row,
                0.0,
            ),
            implicit_damping_factor: padded(
                &damping
                    .iter()
                    .map(|c| match scheme {
                        Scheme::CentralDifference => 1.0 / (1.0 + 0.5 * c * dt),
                        Scheme::Tchamwa { .. } | Scheme::ExactModal => 1.0,
                    })
                    .collect::<Vec<_>>(),
                row,
                1.0,
            ),
            damping: padded(&damping, row, 0.0),
            mass: scale.mass,
            inverse_mass: 1.0 / scale.mass,
        }
    }
}

/// The runs of consecutive lines of one kind, `kinds` giving each pin's: the x lines,
/// then in the plane the y lines.
fn line_runs(kinds: &[usize], plane: bool) -> Vec<LineRun> {
    let pins = kinds.len();
    let mut runs: Vec<LineRun> = Vec::new();
    for direction in 0..(if plane { 2 } else { 1 }) {
        for (pin, kind) in kinds.iter().enumerate() {
            let line = direction * pins + pin;
            match runs.last_mut() {
                Some(run) if run.kind == *kind && run.first + run.lines == line && pin > 0 => run.lines += 1,
                _ => runs.push(LineRun {
                    first: line,
                    lines: 1,
                    kind: *kind,
                }),
            }
        }
    }
    runs
}

/// What the contacts need besides [`LaneContact`]: nothing for the row, where every
/// normal is +x (δ = w_L − w_R − gap), the y slots and rows and the normals in the plane.
pub(super) enum ContactModel {
    Row,
    Plane(PlaneContacts),
}

/// The plane's contacts: per group the y deflection vectors and per lane the normal
/// ([`super::kernels::plane_penetrations`]), per lane the y rows.
pub(super) struct PlaneContacts {
    pub groups: PlaneGroups,
    pub lanes: Vec<PlaneLane>,
}

/// A plane contact's y rows and normal, as its lane needs them (offsets in vectors).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct PlaneLane {
    /// Offsets of the left and right body's y rows in the state (`wall_row` for a wall).
    pub left_y: usize,
    pub right_y: usize,
    /// Unit normal (x, y) from left to right; (0, 0) in empty lanes.
    pub normal: [f64; 2],
}

/// `values` followed by `fill` up to `row`.
fn padded(values: &[f64], row: usize, fill: f64) -> Vec<f64> {
    let mut out = values.to_vec();
    out.resize(row, fill);
    out
}

/// The contact levels reordered so that levels where the same pairs of bodies touch
/// are consecutive: `(heights, contact_level)` in the new order. A group of lanes holds
/// one pair at `lanes` consecutive levels; in a wire-wrapped bundle the pattern of
/// touching pairs turns by 60° from one level to the next and comes back every wire
/// lead, so in the order of the heights a group would hold one contact in `lanes`,
/// and in this order it is full. (The row's levels all hold the same pairs.)
fn by_contact_pattern(
    heights: &[f64],
    contact_level: &[usize],
    contacts: &[Contact],
) -> (Vec<f64>, Vec<usize>) {
    let side = |body: Body| match body {
        Body::Wall => None,
        Body::Pin(pin) => Some(pin),
    };
    let mut patterns = vec![Vec::new(); heights.len()];
    for (contact, level) in contacts.iter().zip(contact_level) {
        patterns[*level].push((side(contact.left), side(contact.right)));
    }
    for pattern in &mut patterns {
        pattern.sort_unstable();
    }
    // Equal patterns side by side (then by height order), similar ones close.
    let mut order: Vec<usize> = (0..heights.len()).collect();
    order.sort_by(|a, b| patterns[*a].cmp(&patterns[*b]).then(a.cmp(b)));
    let mut new_level = vec![0; heights.len()];
    for (new, old) in order.iter().enumerate() {
        new_level[*old] = new;
    }
    (
        order.iter().map(|old| heights[*old]).collect(),
        contact_level.iter().map(|old| new_level[*old]).collect(),
    )
}

/// Index of `value` in `levels`, appended if new.
fn level_of(levels: &mut Vec<f64>, value: f64) -> usize {
    match levels.iter().position(|h| *h == value) {
        Some(level) => level,
        None => {
            levels.push(value);
            levels.len() - 1
        }
    }
}

impl<'m> Layout<'m> {
    /// The layout of `model` run with `settings` at `step`, for the SIMD level `arch`.
    pub fn new(arch: pulp::Arch, model: &'m Model<'m>, settings: &Settings, step: &StepSize) -> Self {
        let (dt, critical) = (step.time_step, step.critical_time_step);
        let lanes = arch.dispatch(Lanes);
        let basis = model.basis;
        let (pins, modes) = (model.pins, basis.modes());
        let row = modes.div_ceil(lanes) * lanes;
        let kinds: Vec<LineKind> = model
            .kind_scales()
            .iter()
            .map(|scale| LineKind::new(scale, row, settings.scheme, dt))
            .collect();
        let pin_kinds = model.pin_kinds();
        let runs = line_runs(&pin_kinds, model.plane.is_some());
        let mut energy_runs: Vec<LineRun> = Vec::new();
        for run in &runs {
            match energy_runs.last_mut() {
                Some(last) if last.kind == run.kind => last.lines += run.lines,
                _ => energy_runs.push(*run),
            }
        }

        let mut heights: Vec<f64> = Vec::new();
        let mut contact_level: Vec<usize> = model
            .contacts
            .iter()
            .map(|c| level_of(&mut heights, c.height))
            .collect();
        if model.plane.is_some() {
            (heights, contact_level) = by_contact_pattern(&heights, &contact_level, &model.contacts);
        }
        // The output heights are levels too (with no contact unless one is there).
        let output_levels: Vec<usize> = settings
            .output_heights
            .iter()
            .map(|h| level_of(&mut heights, *h))
            .collect();
        let shape_at = |height: f64| padded(&basis.deflection_at(height), row, 0.0);
        let nodes = basis.model().elements + 1;
        let contacts = &model.contacts;
        let lines = model.lines();
        // Offsets in vectors of one row of `row` values; a wall reads the row of zeros
        // after the lines' rows. A pin's x line is its number, its y line `pins` further.
        let vectors = row / lanes;
        let state_row = |body: Body| match body {
            Body::Wall => vectors * lines,
            Body::Pin(pin) => vectors * pin,
        };
        let state_row_y = |body: Body| match body {
            Body::Wall => vectors * lines,
            Body::Pin(pin) => vectors * (pins + pin),
        };
        // A wall on the left reads the zero slot before the first line, on the right the
        // one after the last.
        let stride = lines + 2;
        let slot = |body: Body, wall: usize| match body {
            Body::Wall => wall,
            Body::Pin(pin) => 1 + pin,
        };
        let contact_lanes = ContactLanes::new(
            contacts.iter().enumerate().map(|(c, contact)| {
                (
                    contact_level[c],
                    slot(contact.left, 0),
                    slot(contact.right, lines + 1),
                )
            }),
            lanes,
            stride,
        );
        let contact_model = match &model.plane {
            None => ContactModel::Row,
            Some(plane) => {
                // The y slot of a pin's x slot (a wall's slot reads zeros either way).
                let y_vector = |vector: &u32| {
                    let slot = *vector as usize % stride;
                    if (1..=pins).contains(&slot) {
                        vector + pins as u32
                    } else {
                        *vector
                    }
                };
                let lane_normals = contact_lanes.by_lane(&plane.normals, [0.0, 0.0]);
                ContactModel::Plane(PlaneContacts {
                    groups: PlaneGroups {
                        left_y: contact_lanes.left.iter().map(y_vector).collect(),
                        right_y: contact_lanes.right.iter().map(y_vector).collect(),
                        normal_x: lane_normals.iter().map(|n| n[0]).collect(),
                        normal_y: lane_normals.iter().map(|n| n[1]).collect(),
                    },
                    lanes: contact_lanes.by_lane(
                        &contacts
                            .iter()
                            .zip(&plane.normals)
                            .map(|(contact, normal)| PlaneLane {
                                left_y: state_row_y(contact.left),
                                right_y: state_row_y(contact.right),
                                normal: *normal,
                            })
                            .collect::<Vec<_>>(),
                        PlaneLane::default(),
                    ),
                })
            }
        };
        let level_shapes: Vec<f64> = heights.iter().flat_map(|h| shape_at(*h)).collect();
        let grouped_level_shapes = LevelShapes::new(&level_shapes, row, lanes);
        let node_shapes = LevelShapes::new(
            &(0..nodes)
                .flat_map(|n| (0..row).map(move |i| if i < modes { basis.shape(i)[2 * n] } else { 0.0 }))
                .collect::<Vec<_>>(),
            row,
            lanes,
        );
        let curvatures = |heights: &mut dyn Iterator<Item = f64>| {
            let values: Vec<f64> = heights
                .flat_map(|h| padded(&basis.curvature_at(h), row, 0.0))
                .collect();
            LevelShapes::new(&values, row, lanes)
        };
        let element_length = basis.model().element_length;
        let node_curvature_shapes = curvatures(&mut (0..nodes).map(|n| n as f64 * element_length));
        let output_curvature_shapes = curvatures(&mut settings.output_heights.iter().copied());
        let r2 = (dt / critical).powi(2);
        let gaps = contact_lanes.by_lane(&contacts.iter().map(|c| c.gap).collect::<Vec<_>>(), f64::INFINITY);
        let walls = model.walls.as_ref().map(|_| {
            let normals = model
                .plane
                .as_ref()
                .map(|p| contact_lanes.by_lane(&p.normals, [0.0, 0.0]));
            WallLayout::new(
                model,
                &contact_lanes,
                normals.as_deref(),
                &gaps,
                (row, &settings.output_heights),
            )
        });
        let laws: Vec<NormalLaw> = contacts
            .iter()
            .map(|contact| contact.resolved_law(|| model.reduced_mass(contact)))
            .collect();
        Self {
            model,
            scheme: settings.scheme,
            dt,
            step: *step,
            lanes,
            row,
            lines,
            stride,
            participation: padded(basis.participation(), row, 0.0),
            kinds,
            runs,
            energy_runs,
            dashpot_lookahead: match settings.scheme {
                Scheme::CentralDifference => 0.5 * dt,
                Scheme::Tchamwa { .. } | Scheme::ExactModal => 0.0,
            },
            level_shapes,
            grouped_level_shapes,
            lane_contacts: contact_lanes.by_lane(
                &contacts
                    .iter()
                    .enumerate()
                    .zip(&laws)
                    .map(|((c, contact), law)| LaneContact {
                        stiffness: law.stiffness,
                        dashpot: law.damping,
                        shape: vectors * contact_level[c],
                        left: state_row(contact.left),
                        right: state_row(contact.right),
                        active: law.is_active(),
                        nonlinear: !law.is_linear(),
                        needs_rate: law.needs_rate(),
                        friction: contact.law.friction.is_on(),
                    })
                    .collect::<Vec<_>>(),
                LaneContact::default(),
            ),
            lane_laws: contact_lanes.by_lane(&laws, NormalLaw::default()),
            lane_friction: contact_lanes.by_lane(
                &contacts.iter().map(|c| c.law.friction).collect::<Vec<_>>(),
                Friction::NONE,
            ),
            contact_model,
            wall_row: state_row(Body::Wall),
            gaps,
            contacts: contact_lanes,
            point_force_shapes: model.point_forces.iter().map(|f| shape_at(f.height)).collect(),
            output_offsets: output_levels
                .iter()
                .map(|level| Self::level_offset(lanes, stride, *level))
                .collect(),
            node_shapes,
            node_curvature_shapes,
            output_curvature_shapes,
            divergence_allowance: if r2 < 1.0 { 2.0 / (1.0 - r2) } else { 1.0 },
            walls,
        }
    }

    /// Index in the level deflections of line 0 at `level` (block-major, the walls in
    /// slots 0 and lines + 1); line r is `lanes` × r further.
    pub fn level_offset(lanes: usize, stride: usize, level: usize) -> usize {
        ((level / lanes) * stride + 1) * lanes + level % lanes
    }

    /// Number of lanes of the per-lane contact arrays.
    pub fn contact_lanes(&self) -> usize {
        self.contacts.len()
    }

    /// Length of a block-major array of the lines' deflections at every level.
    pub fn level_deflections_len(&self) -> usize {
        self.grouped_level_shapes.blocks * self.stride * self.lanes
    }

    /// Length of a block-major array of the lines' deflections at every node.
    pub fn node_deflections_len(&self) -> usize {
        self.node_shapes.blocks * self.stride * self.lanes
    }

    /// Length of a block-major array of the lines' curvatures at every node, and at every
    /// output height.
    pub fn node_curvatures_len(&self) -> usize {
        self.node_curvature_shapes.blocks * self.stride * self.lanes
    }
    pub fn output_curvatures_len(&self) -> usize {
        self.output_curvature_shapes.blocks * self.stride * self.lanes
    }
}
