//! Walls with their own motion ([`super::WallMotion`]), in the frame of the feet.
//!
//! A wall sits at d(t) = ∬ r dt, r = a_wall − a_base, integrated exactly for r linear
//! over each step, on three channels: the left walls and the right walls along x, every
//! wall along y. The pins' deflections in the state are their modal part Σ φᵢ qᵢ; a
//! pin held at both ends is also carried by Ψ(z) d(t) (the transport), the same for
//! every pin, so that it cancels between two pins and a wall at height z is seen at
//! (1 − Ψ(z)) d(t). A contact with a wall on its `side` (+1 left, −1 right) then has
//! δ = n·(u_L − u_R) − gap + side (1 − Ψ) n·d: its gap is gap − side (1 − Ψ) n·d, its
//! rate gets side (1 − Ψ) n·ḋ, and the walls do work F × side (1 − Ψ) n·ḋ on it.

use super::Model;
use super::kernels::ContactLanes;
use crate::contact::Body;

/// What does not change.
pub(super) struct WallLayout {
    /// Per lane: side (1 − Ψ(z)) for a wall contact, 0 between pins (and empty lanes).
    pub side: Vec<f64>,
    /// Per lane: `side` × the normal's x and y components (the row's normal is +x), and
    /// the x channel of its wall (0 left, 1 right).
    pub along_x: Vec<f64>,
    pub along_y: Vec<f64>,
    pub channel: Vec<usize>,
    /// Per lane: the gap at rest (∞ in empty lanes).
    pub gaps: Vec<f64>,
    /// Γᴾ padded to the row (`None` without a transport: a free top).
    pub transport_participation: Option<Vec<f64>>,
    /// Ψ at each output height and at each mesh node, and Ψ'' there (empty without a
    /// transport).
    pub output_transport: Vec<f64>,
    pub node_transport: Vec<f64>,
    pub output_transport_curvature: Vec<f64>,
    pub node_transport_curvature: Vec<f64>,
}

impl WallLayout {
    /// For the model's walls, with the contacts by lanes, their lane normals (`None`
    /// for the row) and the gaps by lane.
    pub fn new(
        model: &Model<'_>,
        contacts: &ContactLanes,
        normals: Option<&[[f64; 2]]>,
        gaps: &[f64],
        (row, output_heights): (usize, &[f64]),
    ) -> Self {
        let basis = model.basis;
        let transport = basis.support_transport();
        let side_of = |c: usize| {
            let contact = &model.contacts[c];
            let side = match (contact.left, contact.right) {
                (Body::Wall, Body::Pin(_)) => 1.0,
                (Body::Pin(_), Body::Wall) => -1.0,
                _ => 0.0,
            };
            side * (1.0 - basis.transport_at(contact.height))
        };
        let sides: Vec<f64> = (0..model.contacts.len()).map(side_of).collect();
        let side = contacts.by_lane(&sides, 0.0);
        let channels: Vec<usize> = model
            .contacts
            .iter()
            .map(|c| usize::from(c.right == Body::Wall))
            .collect();
        let normal = |j: usize| normals.map_or([1.0, 0.0], |n| n[j]);
        let nodes = basis.model().elements + 1;
        let element_length = basis.model().element_length;
        Self {
            along_x: side.iter().enumerate().map(|(j, s)| s * normal(j)[0]).collect(),
            along_y: side.iter().enumerate().map(|(j, s)| s * normal(j)[1]).collect(),
            side,
            channel: contacts.by_lane(&channels, 0),
            gaps: gaps.to_vec(),
            transport_participation: transport.map(|t| {
                let mut padded = t.participation.clone();
                padded.resize(row, 0.0);
                padded
            }),
            output_transport: match transport {
                Some(_) => output_heights.iter().map(|h| basis.transport_at(*h)).collect(),
                None => Vec::new(),
            },
            node_transport: match transport {
                Some(_) => (0..nodes)
                    .map(|n| basis.transport_at(n as f64 * element_length))
                    .collect(),
                None => Vec::new(),
            },
            output_transport_curvature: match transport {
                Some(_) => (output_heights.iter())
                    .map(|h| basis.transport_curvature_at(*h))
                    .collect(),
                None => Vec::new(),
            },
            node_transport_curvature: match transport {
                Some(_) => (0..nodes)
                    .map(|n| basis.transport_curvature_at(n as f64 * element_length))
                    .collect(),
                None => Vec::new(),
            },
        }
    }
}

/// Where the walls are.
pub(super) struct WallState {
    /// Their displacement, velocity and acceleration relative to the feet at the last
    /// step, per channel (left walls along x, right walls along x, along y).
    pub displacement: [f64; 3],
    pub velocity: [f64; 3],
    pub acceleration: [f64; 3],
    /// Per lane, the gap now.
    pub gaps: Vec<f64>,
    /// The walls' power on the contacts over the last step's contact pass (W).
    pub power: f64,
}

impl WallState {
    /// At rest at t = 0.
    pub fn new(layout: &WallLayout, model: &Model<'_>) -> Self {
        let walls = model.walls.as_ref().expect("walls that move");
        Self {
            displacement: [0.0; 3],
            velocity: [0.0; 3],
            acceleration: walls.relative(model, 0.0),
            gaps: layout.gaps.clone(),
            power: 0.0,
        }
    }

    /// Advances to `t`, a step `dt` after the last, with the relative acceleration
    /// linear over the step.
    pub fn advance(&mut self, layout: &WallLayout, model: &Model<'_>, (t, dt): (f64, f64)) {
        let walls = model.walls.as_ref().expect("walls that move");
        let now = walls.relative(model, t);
        for k in 0..3 {
            let (before, v) = (self.acceleration[k], self.velocity[k]);
            self.displacement[k] += dt * v + dt * dt * (2.0 * before + now[k]) / 6.0;
            self.velocity[k] = v + 0.5 * dt * (before + now[k]);
        }
        self.acceleration = now;
        self.update_gaps(layout);
    }

    /// gap − side (1 − Ψ) n·d per lane.
    fn update_gaps(&mut self, layout: &WallLayout) {
        let d = self.displacement;
        for ((((gap, rest), x), y), &channel) in self
            .gaps
            .iter_mut()
            .zip(&layout.gaps)
            .zip(&layout.along_x)
            .zip(&layout.along_y)
            .zip(&layout.channel)
        {
            *gap = rest - (x * d[channel] + y * d[2]);
        }
    }

    /// The transport's displacement along x and y: the walls share one motion when
    /// there is a transport ([`super::Model::validate`]).
    pub fn transport(&self) -> [f64; 2] {
        self.transport_of(self.displacement)
    }

    /// Adds the transport's inertial load −Γᴾ r to every line's loads (`force`, lines of
    /// `row`, the x lines of the `pins` first), with a transport.
    pub fn add_transport_loads(&self, layout: &WallLayout, force: &mut [f64], (row, pins): (usize, usize)) {
        let (x, y) = force.split_at_mut((pins * row).min(force.len()));
        self.add_transport_load(layout, x, row, 0);
        self.add_transport_load(layout, y, row, 1);
    }

    /// [`WallState::add_transport_loads`] of the lines `force` (all x lines, `direction`
    /// 0, or all y lines, 1).
    pub fn add_transport_load(&self, layout: &WallLayout, force: &mut [f64], row: usize, direction: usize) {
        let Some(transport) = &layout.transport_participation else {
            return;
        };
        let r = self.transport_of(self.acceleration)[direction];
        for loads in force.chunks_exact_mut(row) {
            for (f, psi) in loads.iter_mut().zip(transport) {
                *f -= psi * r;
            }
        }
    }

    /// The transport's inertial load's power −r Σ Γᴾ q̇ over the lines (W).
    pub fn transport_power(&self, layout: &WallLayout, v: &[f64], (row, pins): (usize, usize)) -> f64 {
        let Some(transport) = &layout.transport_participation else {
            return 0.0;
        };
        let [rx, ry] = self.transport_of(self.acceleration);
        let lines = v.len() / row - 1;
        (0..lines)
            .map(|line| {
                let r = if line < pins { rx } else { ry };
                let velocity: f64 = v[line * row..][..row]
                    .iter()
                    .zip(transport)
                    .map(|(v, p)| v * p)
                    .sum();
                -r * velocity
            })
            .sum()
    }

    /// A channel triple's x (left walls: they share the motion with a transport) and y.
    fn transport_of(&self, channels: [f64; 3]) -> [f64; 2] {
        [channels[0], channels[2]]
    }

    /// δ̇'s part from the walls for lane j, and the walls' power on it per newton.
    #[inline(always)]
    pub fn rate(&self, layout: &WallLayout, j: usize) -> f64 {
        layout.along_x[j] * self.velocity[layout.channel[j]] + layout.along_y[j] * self.velocity[2]
    }

    /// The walls' tangential velocity in lane j seen by the plane's sliding, side ×
    /// (1 − Ψ) (ḋ_x, ḋ_y).
    #[inline(always)]
    pub fn velocity_of(&self, layout: &WallLayout, j: usize) -> [f64; 2] {
        let s = layout.side[j];
        [s * self.velocity[layout.channel[j]], s * self.velocity[2]]
    }
}
