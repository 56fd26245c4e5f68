//! What a run integrates ([`Model`]) and how ([`Settings`]), and every check on them that
//! must pass before the time loop may start: an invalid model is refused with the
//! offending fields named, never integrated into NaN or an index out of bounds.
//!
//! Field paths are slash paths relative to the checked struct (`contacts/3/right`,
//! `point_forces/0/height`, `output_heights/1`), as everywhere in this crate.

use crate::contact::{Body, Contact};
use crate::impacts::ImpactCounting;
use crate::loads::{BaseAcceleration, PointForce};
use crate::modal::ModalBasis;
use crate::stability::Scheme;
use crate::{InputIssue, require_non_negative, require_positive};

use super::kinds::{self, BodyKind, KindScale};
use super::quality::Check;

/// The pins being integrated: a row (every pin bends along x, every contact normal is
/// +x), or pins bending in the transverse plane ([`Plane`]).
#[derive(Debug, Clone)]
pub struct Model<'a> {
    /// Modal basis shared by every pin.
    pub basis: &'a ModalBasis,
    /// Number of pins (≥ 1).
    pub pins: usize,
    /// Modal damping ratio ξᵢ of each mode (length = modes).
    pub damping_ratios: Vec<f64>,
    pub contacts: Vec<Contact>,
    /// Release of each deflection line ([`Model::lines`]: one per pin in a row; in the
    /// plane the x lines, then the y lines) from its static tip-load shape with this tip
    /// deflection (m); empty means all at rest.
    pub initial_tip_displacements: Vec<f64>,
    /// Initial velocity of each deflection line (as `initial_tip_displacements`): the
    /// static tip-load shape moving with this tip velocity (m/s) at t = 0; empty means
    /// all at rest. A pin thrown, or cut loose from a support moving at this speed.
    pub initial_tip_velocities: Vec<f64>,
    /// Base acceleration (m/s²); along x in the plane.
    pub base_acceleration: Option<BaseAcceleration>,
    /// Point forces, each on one deflection line (along x or y in the plane).
    pub point_forces: Vec<PointForce>,
    /// `None`: the row (every pin bends along x only, every contact normal is +x).
    /// `Some`: every pin bends along x and y with the same modal basis.
    pub plane: Option<Plane>,
    /// `None`: the walls (the wrapper in the plane) and the pins' top supports move with
    /// the feet. `Some`: they have their own motion ([`WallMotion`]).
    pub walls: Option<WallMotion>,
    /// Pins of other kinds than the basis's beam (another section, material, mass or
    /// damping: [`BodyKind`]); empty when every pin is the basis's.
    pub kinds: Vec<BodyKind<'a>>,
}

/// The walls' own motion (and the wrapper's in the plane), distinct from the feet's.
///
/// Every result stays in the frame of the feet: a deflection is relative to the feet,
/// and a wall sits at d(t) = ∬ (a_wall − a_base) dt in it (starting at rest). Pins held
/// at both ends have their top support on the walls: they are carried by the
/// quasi-static transport Ψ(z) d(t) ([`crate::modal::SupportTransport`]), the modes
/// loaded by −Γᴾ d̈ besides the base's −Γ a_base. Walls given the feet's acceleration
/// give the results of walls moving with the feet, exactly. An acceleration left out is
/// zero: that wall stands still in space along it.
#[derive(Debug, Clone, PartialEq)]
pub struct WallMotion {
    /// Absolute acceleration along x (m/s²) of the walls on the left of their contacts
    /// (the row's left wall), and of those on the right. The plane's wrapper is one
    /// body: the two are the same there.
    pub left_x: Option<BaseAcceleration>,
    pub right_x: Option<BaseAcceleration>,
    /// Along y, in the plane only.
    pub y: Option<BaseAcceleration>,
}

impl WallMotion {
    /// One motion for every wall, along x and y.
    pub fn rigid(x: Option<BaseAcceleration>, y: Option<BaseAcceleration>) -> Self {
        Self {
            left_x: x.clone(),
            right_x: x,
            y,
        }
    }

    /// The walls' accelerations relative to the feet at `t` (m/s²): left walls and
    /// right walls along x, all walls along y.
    pub fn relative(&self, model: &Model<'_>, t: f64) -> [f64; 3] {
        let at = |a: Option<&BaseAcceleration>| a.map_or(0.0, |a| a.at(t));
        let base_x = at(model.base_acceleration.as_ref());
        let base_y = at(model.plane.as_ref().and_then(|p| p.base_acceleration_y.as_ref()));
        [
            at(self.left_x.as_ref()) - base_x,
            at(self.right_x.as_ref()) - base_x,
            at(self.y.as_ref()) - base_y,
        ]
    }
}

/// Pins bending in the transverse plane (x, y), each direction on the same basis.
///
/// Initial tip displacements and point forces act on a line each: pin p's along x is line
/// p, along y line pins + p (a release or a force along an angle is its two
/// components); the base acceleration has an x component (`Model::base_acceleration`)
/// and a y component (`base_acceleration_y`).
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// Per contact (same order as `Model::contacts`): unit normal (x, y) pointing from
    /// `left` toward `right`: δ = n·(u_left − u_right) − gap; the force pushes left by −F n
    /// and right by +F n. A wall's displacement is zero (wrapper frame).
    pub normals: Vec<[f64; 2]>,
    /// Base acceleration along y; `Model::base_acceleration` is the x component.
    pub base_acceleration_y: Option<BaseAcceleration>,
}

/// How far from 1 the length of a contact normal may be.
pub const NORMAL_LENGTH_TOLERANCE: f64 = 1e-9;

impl Plane {
    /// Every problem with the plane data of a model with `contacts` contacts: one
    /// finite unit normal per contact (length within [`NORMAL_LENGTH_TOLERANCE`] of 1),
    /// a valid y excitation.
    pub fn validate(&self, contacts: usize) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if self.normals.len() != contacts {
            issues.push(InputIssue::new(
                "normals",
                format!(
                    "needs one normal per contact ({contacts}), got {}",
                    self.normals.len()
                ),
            ));
        }
        for (c, [x, y]) in self.normals.iter().enumerate() {
            let field = format!("normals/{c}");
            if !(x.is_finite() && y.is_finite()) {
                issues.push(InputIssue::new(field, "must be two finite numbers"));
            } else if ((x * x + y * y).sqrt() - 1.0).abs() > NORMAL_LENGTH_TOLERANCE {
                issues.push(InputIssue::new(
                    field,
                    format!("must be a unit vector (length {})", (x * x + y * y).sqrt()),
                ));
            }
        }
        if let Some(base) = &self.base_acceleration_y {
            issues.extend(
                base.validate()
                    .into_iter()
                    .map(|i| i.within("base_acceleration_y")),
            );
        }
        issues
    }
}

impl Model<'_> {
    /// Every problem that keeps this model from being integrated (empty when it can run):
    /// at least one pin; one finite, non-negative damping ratio per mode of the basis;
    /// contacts between existing, different bodies, within the pin, with valid gap,
    /// stiffness and damping ([`Contact::validate`]); one finite initial tip deflection
    /// per deflection line or none, and none but zeros without a free top (no tip-load
    /// shape to release from); a valid excitation; point forces on existing lines,
    /// within the pin, with valid tables; in the plane, [`Plane::validate`].
    pub fn validate(&self) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        let (pins, modes, length) = (self.pins, self.basis.modes(), self.basis.length());
        let lines = self.lines();
        if pins == 0 {
            issues.push(InputIssue::new("pins", "a row needs at least one pin"));
        }
        if self.damping_ratios.len() != modes {
            issues.push(InputIssue::new(
                "damping_ratios",
                format!(
                    "needs one ratio per mode of the basis ({modes}), got {}",
                    self.damping_ratios.len()
                ),
            ));
        }
        for (i, xi) in self.damping_ratios.iter().enumerate() {
            require_non_negative(&mut issues, &format!("damping_ratios/{i}"), *xi);
        }
        for (k, contact) in self.contacts.iter().enumerate() {
            let prefix = format!("contacts/{k}");
            issues.extend(
                contact
                    .validate(pins, length)
                    .into_iter()
                    .map(|i| i.within(&prefix)),
            );
        }
        issues.extend(kinds::validate(&self.kinds, self.basis, pins));
        self.validate_laws(&mut issues);
        self.validate_release(&mut issues);
        if let Some(base) = &self.base_acceleration {
            issues.extend(base.validate().into_iter().map(|i| i.within("base_acceleration")));
        }
        for (k, point) in self.point_forces.iter().enumerate() {
            let prefix = format!("point_forces/{k}");
            if point.line >= lines {
                issues.push(InputIssue::new(
                    format!("{prefix}/line"),
                    format!(
                        "line {} does not exist: the model has {lines} deflection lines ({})",
                        point.line,
                        self.lines_per_pin()
                    ),
                ));
            }
            if !(point.height.is_finite() && (0.0..=length).contains(&point.height)) {
                issues.push(InputIssue::new(
                    format!("{prefix}/height"),
                    format!("must be within the pin, 0 to {length} m"),
                ));
            }
            issues.extend(
                point
                    .force
                    .validate("force")
                    .into_iter()
                    .map(|i| i.within(&prefix)),
            );
        }
        if let Some(plane) = &self.plane {
            issues.extend(
                plane
                    .validate(self.contacts.len())
                    .into_iter()
                    .map(|i| i.within("plane")),
            );
        }
        if let Some(walls) = &self.walls {
            self.validate_walls(walls, &mut issues);
        }
        issues
    }

    /// The reduced mass m₁m₂/(m₁ + m₂) (kg) of `contact`'s two bodies as a restitution
    /// sees them: each pin's apparent mass at the contact height on its modal basis,
    /// 1/Σᵢ φᵢ(z)² with mass-normalised modes (an impulse J there changes the pin's
    /// velocity at z by J Σᵢ φᵢ(z)²), a wall's infinite. Infinite at a pin's clamped
    /// foot, where no mode moves.
    pub fn reduced_mass(&self, contact: &Contact) -> f64 {
        let shape = self.basis.deflection_at(contact.height);
        let apparent = 1.0 / shape.iter().map(|phi| phi * phi).sum::<f64>();
        // A pin's kind's μ (1 for the basis's), computed only for the two pins here.
        let mass = |pin: usize| match self.kinds.iter().find(|k| k.pins.contains(&pin)) {
            Some(kind) => apparent * kinds::relative_mass(self.basis, kind.basis).unwrap_or(1.0),
            None => apparent,
        };
        match (contact.left, contact.right) {
            (Body::Pin(left), Body::Pin(right)) => {
                let (a, b) = (mass(left), mass(right));
                if a == b {
                    0.5 * a
                } else if a.is_finite() && b.is_finite() {
                    a * b / (a + b)
                } else {
                    a.min(b)
                }
            }
            (Body::Pin(pin), Body::Wall) | (Body::Wall, Body::Pin(pin)) => mass(pin),
            (Body::Wall, Body::Wall) => f64::INFINITY,
        }
    }

    /// The kind of every pin: 0 for the basis's beam, k + 1 for `kinds[k]`.
    pub fn pin_kinds(&self) -> Vec<usize> {
        kinds::pin_kinds(&self.kinds, self.pins)
    }

    /// Per kind (the basis's first, then `kinds`): its mass relative to the basis's beam,
    /// its frequencies and damping ratios. A kind refused by [`Model::validate`] counts
    /// as the basis's.
    pub fn kind_scales(&self) -> Vec<KindScale<'_>> {
        std::iter::once(KindScale {
            mass: 1.0,
            frequencies: self.basis.angular_frequencies(),
            damping_ratios: &self.damping_ratios,
        })
        .chain(
            self.kinds
                .iter()
                .map(|kind| match kinds::relative_mass(self.basis, kind.basis) {
                    Ok(mass) => KindScale {
                        mass,
                        frequencies: kind.basis.angular_frequencies(),
                        damping_ratios: &kind.damping_ratios,
                    },
                    Err(_) => KindScale {
                        mass: 1.0,
                        frequencies: self.basis.angular_frequencies(),
                        damping_ratios: &self.damping_ratios,
                    },
                }),
        )
        .collect()
    }

    /// Laws the model can carry: a restitution whose bodies have a finite mass (or one
    /// given), friction only in the plane (the row's contacts have no tangent), and
    /// preloads that balance at rest on every pin at every height (a preloaded contact
    /// alone would set the pin moving at t = 0).
    fn validate_laws(&self, issues: &mut Vec<InputIssue>) {
        for (k, contact) in self.contacts.iter().enumerate() {
            if let Some(restitution) = &contact.law.restitution
                && contact.law.exponent == 1.0
                && restitution.mass.is_none()
                && !self.reduced_mass(contact).is_finite()
            {
                issues.push(InputIssue::new(
                    format!("contacts/{k}/law/restitution"),
                    "no mode moves at this height (a clamped foot): give the \
                     impact's mass (`restitution_mass`) or a damping",
                ));
            }
            if contact.law.friction.is_on() && self.plane.is_none() {
                issues.push(InputIssue::new(
                    format!("contacts/{k}/law/friction/coefficient"),
                    "the pins of a row bend in one plane and their contacts have no tangent: \
                     friction needs pins in the transverse plane (hex-bundle-dynamics)",
                ));
            }
        }
        // Preloads, summed per pin and height (m, rounded to the µm).
        let mut nets: std::collections::BTreeMap<(usize, i64), ([f64; 2], f64, usize)> = Default::default();
        for (k, contact) in self.contacts.iter().enumerate() {
            let preload = contact.preload();
            if preload == 0.0 {
                continue;
            }
            let [nx, ny] = self
                .plane
                .as_ref()
                .and_then(|p| p.normals.get(k))
                .copied()
                .unwrap_or([1.0, 0.0]);
            let level = (contact.height * 1e6).round() as i64;
            for (body, sign) in [(contact.left, -1.0), (contact.right, 1.0)] {
                if let Body::Pin(pin) = body {
                    let entry = nets.entry((pin, level)).or_insert(([0.0, 0.0], 0.0, k));
                    entry.0[0] += sign * preload * nx;
                    entry.0[1] += sign * preload * ny;
                    entry.1 += preload;
                }
            }
        }
        for ((pin, _), ([x, y], total, k)) in nets {
            let net = x.hypot(y);
            if net > 1e-9 * total {
                let height = self.contacts[k].height;
                issues.push(InputIssue::new(
                    format!("contacts/{k}/gap"),
                    format!(
                        "the preloads at {height} m push pin {pin} with a net {} N at rest: a \
                         preloaded contact needs others at the same height that balance it \
                         (a spring and its dimples), or the pin would start moving at t = 0",
                        crate::number(net)
                    ),
                ));
            }
        }
    }

    fn validate_walls(&self, walls: &WallMotion, issues: &mut Vec<InputIssue>) {
        for (field, acceleration) in [
            ("left_x", &walls.left_x),
            ("right_x", &walls.right_x),
            ("y", &walls.y),
        ] {
            if let Some(a) = acceleration {
                issues.extend(
                    a.validate()
                        .into_iter()
                        .map(|i| i.within(&format!("walls/{field}"))),
                );
            }
        }
        if self.plane.is_none() && walls.y.is_some() {
            issues.push(InputIssue::new(
                "walls/y",
                "a row moves along x only: its walls have no y motion",
            ));
        }
        if self.plane.is_some() && walls.left_x != walls.right_x {
            issues.push(InputIssue::new(
                "walls/right_x",
                "the wrapper is one body: its walls share one motion",
            ));
        }
        let model = self.basis.model();
        let top_dof = 2 * model.elements;
        if !model.free_dofs.contains(&top_dof) {
            if !self.kinds.is_empty() {
                issues.push(InputIssue::new(
                    "kinds",
                    "pins held at both ends have their top support on walls with their own \
                     motion: that transport is not available with bodies of several kinds; \
                     let the walls move with the feet",
                ));
            } else if self.basis.support_transport().is_none() {
                issues.push(InputIssue::new(
                    "walls",
                    "the pins' top support cannot follow the walls: held by the top alone, \
                     they have no static shape for it",
                ));
            } else if walls.left_x != walls.right_x {
                issues.push(InputIssue::new(
                    "walls/right_x",
                    "pins held at both ends have their top support on the walls: the walls \
                     need one motion",
                ));
            }
        }
    }

    /// Deflection lines of the model: one per pin in the row, two (x then y) in the
    /// plane. Every per-pin output is indexed by line.
    pub fn lines(&self) -> usize {
        match self.plane {
            None => self.pins,
            Some(_) => 2 * self.pins,
        }
    }

    /// How the lines follow from the pins, in words (for messages).
    fn lines_per_pin(&self) -> &'static str {
        match self.plane {
            None => "one per pin",
            Some(_) => "two per pin: the x lines, then the y lines",
        }
    }

    fn validate_release(&self, issues: &mut Vec<InputIssue>) {
        let lines = self.lines();
        for (field, values, what) in [
            (
                "initial_tip_displacements",
                &self.initial_tip_displacements,
                "a tip release",
            ),
            (
                "initial_tip_velocities",
                &self.initial_tip_velocities,
                "an initial tip velocity",
            ),
        ] {
            if !values.is_empty() && values.len() != lines {
                issues.push(InputIssue::new(
                    field,
                    format!(
                        "needs one value per deflection line ({lines}, {}) or none, got {}",
                        self.lines_per_pin(),
                        values.len()
                    ),
                ));
            }
            for (line, value) in values.iter().enumerate() {
                if !value.is_finite() {
                    issues.push(InputIssue::new(
                        format!("{field}/{line}"),
                        "must be a finite number",
                    ));
                }
            }
            if values.iter().any(|v| *v != 0.0) && self.basis.unit_tip_release().is_none() {
                issues.push(InputIssue::new(
                    field,
                    format!("{what} needs a free top (the basis has no tip-load shape)"),
                ));
            }
        }
    }
}

/// Time step choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStep {
    /// This step (s); refused when above the critical step.
    Fixed(f64),
    /// Chosen for accuracy within stability ([`super::step_size`]).
    Auto,
}

/// Integration settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub scheme: Scheme,
    pub time_step: TimeStep,
    /// Relative accuracy target of `auto` and of the quality verdict, in (0, 1)
    /// ([`super::DEFAULT_TOLERANCE`]).
    pub tolerance: f64,
    /// The accuracy check [`super::Plan::run`] performs after the run.
    pub check: Check,
    /// Simulated duration (s).
    pub duration: f64,
    /// Time between two history samples (s), rounded to a whole number of steps (which
    /// `auto` makes exact); `None` samples every step. Samples are at t = k·interval ≤
    /// duration.
    pub output_interval: Option<f64>,
    /// Heights (m) where every line's deflection is recorded (every pin's, along x and y
    /// in the plane).
    pub output_heights: Vec<f64>,
    /// Contacts whose force histories are recorded, in this order; `None`: every contact.
    /// Statistics are accumulated for every contact regardless.
    pub recorded_contacts: Option<Vec<usize>>,
    /// How impacts are counted, summarised and tabulated.
    pub impacts: ImpactCounting,
    /// Threads the run may use (at least 1), within the threads of the rayon pool the
    /// run is called in: with two or more, the run and its step check's repetition
    /// compute at once ([`super::Plan::run`]), and the plane's step shares its level
    /// deflections, its vector pass over the contacts, its closed contacts and its x and
    /// y modal updates between the run's threads, whose other workers keep looking for
    /// its forks until the run ends (they spin: the run holds its cores); a row's step
    /// runs on one. Every result is the same, bit for bit, for every count. Call the run
    /// from inside the pool (`ThreadPool::install`): a thread outside it hands every
    /// fork to the pool and waits, four forks a step.
    pub threads: usize,
}

impl Settings {
    /// Every problem with these settings for pins of `length` (m) and a model of
    /// `contacts` contacts: φ ≥ 1 for Tchamwa–Wielgosz, a positive step, duration and
    /// output interval, a tolerance in (0, 1), output heights within the pin, recorded
    /// contacts that exist, each once.
    pub fn validate(&self, length: f64, contacts: usize) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if let Scheme::Tchamwa { phi } = self.scheme
            && !(phi.is_finite() && phi >= 1.0)
        {
            issues.push(InputIssue::new(
                "scheme/phi",
                format!("must be at least 1 (got {phi})"),
            ));
        }
        if let TimeStep::Fixed(dt) = self.time_step {
            require_positive(&mut issues, "time_step", dt);
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            issues.push(InputIssue::new(
                "tolerance",
                format!("must be between 0 and 1, both excluded (got {})", self.tolerance),
            ));
        }
        require_positive(&mut issues, "duration", self.duration);
        if self.threads == 0 {
            issues.push(InputIssue::new("threads", "must be at least 1"));
        }
        if let Some(interval) = self.output_interval {
            require_positive(&mut issues, "output_interval", interval);
        }
        for (k, h) in self.output_heights.iter().enumerate() {
            if !(h.is_finite() && (0.0..=length).contains(h)) {
                issues.push(InputIssue::new(
                    format!("output_heights/{k}"),
                    format!("must be within the pin, 0 to {length} m"),
                ));
            }
        }
        issues.extend(self.impacts.validate().into_iter().map(|i| i.within("impacts")));
        let mut listed = vec![false; contacts];
        for (k, &c) in self.recorded_contacts.iter().flatten().enumerate() {
            let field = format!("recorded_contacts/{k}");
            match listed.get_mut(c) {
                None => issues.push(InputIssue::new(
                    field,
                    format!("contact {c} does not exist (the model has {contacts})"),
                )),
                Some(true) => issues.push(InputIssue::new(field, format!("contact {c} is listed twice"))),
                Some(seen) => *seen = true,
            }
        }
        issues
    }
}

#[cfg(test)]
mod tests {
    use std::ops::ControlFlow;

    use super::*;
    use crate::beam::tests::default_tube;
    use crate::beam::{BeamSpec, Support};
    use crate::contact::{Body, Law};
    use crate::integrate::{DEFAULT_TOLERANCE, Plan, SimulationError, StepSize};
    use crate::loads::Table;

    fn basis() -> ModalBasis {
        ModalBasis::compute(&default_tube(10), 4).expect("valid beam")
    }

    /// Two pins of 1 m between the walls, a contact at each level, every field valid.
    fn row(basis: &ModalBasis) -> Model<'_> {
        let contact = |left, right, height| Contact {
            left,
            right,
            height,
            gap: 1e-4,
            stiffness: 1e4,
            damping: 0.5,
            law: Law::LINEAR,
        };
        Model {
            basis,
            pins: 2,
            damping_ratios: vec![0.01; basis.modes()],
            contacts: vec![
                contact(Body::Wall, Body::Pin(0), 1.0),
                contact(Body::Pin(0), Body::Pin(1), 1.0),
                contact(Body::Pin(1), Body::Wall, 0.5),
            ],
            initial_tip_displacements: vec![1e-3, 0.0],
            initial_tip_velocities: vec![],
            base_acceleration: Some(BaseAcceleration::HalfSine {
                amplitude: 5.0,
                duration: 0.01,
            }),
            point_forces: vec![PointForce {
                line: 1,
                height: 0.7,
                force: Table {
                    time: vec![0.0, 0.01],
                    values: vec![0.0, 1.0],
                },
            }],
            walls: None,
            plane: None,
            kinds: Vec::new(),
        }
    }

    fn settings() -> Settings {
        Settings {
            scheme: Scheme::CentralDifference,
            time_step: TimeStep::Auto,
            tolerance: DEFAULT_TOLERANCE,
            check: Check::None,
            duration: 0.02,
            output_interval: Some(1e-3),
            output_heights: vec![1.0, 0.5],
            recorded_contacts: None,
            impacts: Default::default(),
            threads: 1,
        }
    }

    fn fields(issues: Vec<InputIssue>) -> Vec<String> {
        issues.into_iter().map(|i| i.field).collect()
    }

    #[test]
    fn a_valid_model_and_settings_have_no_issue() {
        let basis = basis();
        assert_eq!(row(&basis).validate(), vec![]);
        assert_eq!(settings().validate(basis.length(), 3), vec![]);
    }

    /// Every check names its field relative to the model, in the model's order.
    #[test]
    fn every_problem_of_a_model_is_named_by_its_path() {
        let basis = basis();
        let mut model = row(&basis);
        model.damping_ratios = vec![0.01, f64::NAN, -0.1];
        model.contacts[0].right = Body::Pin(2);
        model.contacts[1].height = 1.5;
        model.contacts[2].stiffness = -1.0;
        model.initial_tip_displacements = vec![f64::INFINITY, 0.0, 1e-3];
        model.base_acceleration = Some(BaseAcceleration::HalfSine {
            amplitude: 5.0,
            duration: 0.0,
        });
        model.point_forces[0].line = 2;
        model.point_forces[0].height = -0.1;
        model.point_forces[0].force.time = vec![0.0, 0.0];
        assert_eq!(
            fields(model.validate()),
            [
                "damping_ratios",
                "damping_ratios/1",
                "damping_ratios/2",
                "contacts/0/right",
                "contacts/1/height",
                "contacts/2/stiffness",
                "initial_tip_displacements",
                "initial_tip_displacements/0",
                "base_acceleration/duration",
                "point_forces/0/line",
                "point_forces/0/height",
                "point_forces/0/time/1",
            ]
        );
    }

    #[test]
    fn a_row_without_pins_is_refused_without_underflow() {
        let basis = basis();
        let mut model = row(&basis);
        model.pins = 0;
        model.initial_tip_displacements.clear();
        let fields = fields(model.validate());
        assert_eq!(fields[0], "pins", "{fields:?}");
        assert!(fields.contains(&"contacts/0/right".to_owned()), "{fields:?}");
    }

    /// A clamped top has no tip-load shape: a release from it would be silently dropped.
    #[test]
    fn a_tip_release_needs_a_free_top() {
        let clamped = BeamSpec {
            top: Support::Clamped,
            ..default_tube(10)
        };
        let basis = ModalBasis::compute(&clamped, 3).expect("valid beam");
        let mut model = row(&basis);
        assert_eq!(fields(model.validate()), ["initial_tip_displacements"]);
        model.initial_tip_displacements = vec![0.0, 0.0];
        assert_eq!(model.validate(), vec![]);
    }

    #[test]
    fn every_problem_of_the_settings_is_named_by_its_path() {
        let settings = Settings {
            scheme: Scheme::Tchamwa { phi: 0.9 },
            time_step: TimeStep::Fixed(0.0),
            tolerance: 1.0,
            check: Check::None,
            duration: f64::NAN,
            output_interval: Some(-1.0),
            output_heights: vec![0.5, 1.2],
            recorded_contacts: Some(vec![1, 2, 1]),
            impacts: Default::default(),
            threads: 1,
        };
        assert_eq!(
            fields(settings.validate(1.0, 2)),
            [
                "scheme/phi",
                "time_step",
                "tolerance",
                "duration",
                "output_interval",
                "output_heights/1",
                "recorded_contacts/1",
                "recorded_contacts/2",
            ]
        );
    }

    /// The entry point refuses an invalid model before anything indexes a pin that does
    /// not exist (the stability analysis would panic) or integrates a NaN.
    #[test]
    fn an_invalid_model_is_refused_by_the_plan_not_integrated() {
        let basis = basis();
        let settings = settings();
        let mut model = row(&basis);
        model.contacts[1].right = Body::Pin(7);
        let Err(SimulationError::InvalidModel(issues)) = Plan::new(&model, &settings) else {
            panic!("a contact with pin 7 of 2 must be refused");
        };
        assert_eq!(fields(issues), ["contacts/1/right"]);

        let mut model = row(&basis);
        model.initial_tip_displacements[1] = f64::NAN;
        let step = *Plan::new(&row(&basis), &settings).expect("valid").step();
        let refused = Plan::with_step(&model, &settings, step).map(|plan| *plan.step());
        assert!(
            matches!(&refused, Err(SimulationError::InvalidModel(issues)) if issues[0].field == "initial_tip_displacements/1"),
            "{refused:?}"
        );
        assert!(
            refused
                .unwrap_err()
                .to_string()
                .contains("initial_tip_displacements/1: must be a finite number"),
            "the message names the field"
        );

        let bad_settings = Settings {
            duration: -1.0,
            ..settings.clone()
        };
        let refused = Plan::new(&row(&basis), &bad_settings).map(|plan| *plan.step());
        assert!(
            matches!(&refused, Err(SimulationError::InvalidSettings(issues)) if issues[0].field == "duration"),
            "{refused:?}"
        );
    }

    /// A step resolved earlier is refused above its critical step, and runs below it.
    #[test]
    fn a_plan_with_a_given_step_checks_it_against_its_critical_step() {
        let basis = basis();
        let (model, settings) = (row(&basis), settings());
        let step = *Plan::new(&model, &settings).expect("valid").step();
        let above = StepSize {
            time_step: 1.5 * step.critical_time_step,
            ..step
        };
        assert!(matches!(
            Plan::with_step(&model, &settings, above),
            Err(SimulationError::TimeStepAboveCritical { .. })
        ));
        let zero = StepSize {
            time_step: 0.0,
            ..step
        };
        assert!(matches!(
            Plan::with_step(&model, &settings, zero),
            Err(SimulationError::InvalidSettings(_))
        ));
        let run = Plan::with_step(&model, &settings, step)
            .and_then(|plan| plan.run(&mut |_| ControlFlow::Continue(())))
            .expect("runs");
        assert_eq!(run.simulation.step, step);
    }
}
