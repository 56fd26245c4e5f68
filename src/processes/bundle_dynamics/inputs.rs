//! Inputs of `bundle-dynamics`: the explicit form (pins + contacts) and the generator
//! form (`bundle`), excitation, initial state, solver and output, with their mapping to
//! the physics types.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::physics::bundle::{BundleLayout, GapState, Levels, LocalClosure};
use crate::physics::contact::{Body, Contact};
use crate::physics::loads::{PointForce, Table};
use crate::processes::common_inputs::{BeamInput, SolverInput};
use crate::processes::contact_law::{Families, LawInput};
use crate::processes::excitation::BaseAccelerationInput;
use crate::processes::impact_report::ImpactsInput;
use crate::processes::input_schema::{NonNegativeNumber, PositiveNumber};
use crate::processes::kinds::KindInput;
use crate::processes::margins::{AllowablesInput, Family, LawAllowable};
use crate::processes::random_gaps::DistributionInput;
use crate::processes::warnings::WarningsInput;

/// Inputs of `bundle-dynamics`: give either `pins` and `contacts`, or `bundle`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct BundleInputs {
    /// The pin of the row: every pin of no kind in `kinds`.
    pub pin: BeamInput,
    /// Pins of other kinds (a guide tube, a stiffer tube): another section, material,
    /// added mass and damping on the pin's length, supports, mesh, modes and static
    /// correction (docs/kinds.md); absent, every pin is `pin`.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub kinds: Vec<KindInput>,
    /// Explicit form: number of pins, numbered 0.. from the left wall.
    #[schema(minimum = 1, maximum = 2000)]
    pub pins: Option<usize>,
    /// Explicit form: every potential contact.
    pub contacts: Option<Vec<ContactInput>>,
    /// Generator form, instead of `pins` and `contacts`.
    pub bundle: Option<BundleGenerator>,
    /// The initial state: at rest, or released from bent shapes.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub initial: InitialInput,
    /// The loads: the wrapper's acceleration, forces on the pins.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub excitation: ExcitationInput,
    /// Explicit integration.
    #[serde(default)]
    #[schema(schema_with = crate::processes::input_schema::auto_solver_schema, default = json!({}))]
    pub solver: SolverInput,
    /// History sampling and impact counting.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub output: OutputInput,
    /// Plausibility warnings (a unit slip, nothing exciting the model, ...): `on`
    /// (default) or `off`; never a refusal.
    #[serde(default)]
    #[schema(default = "on")]
    pub warnings: WarningsInput,
}

/// A potential point contact between `left` and `right` ("wall" or a pin number): at
/// height z, penetration δ = w_left(z) − w_right(z) − gap (a wall's w is 0), force
/// F = max(0, stiffness·δ + damping·δ̇) while δ > 0, pushing `left` toward the left wall
/// and `right` toward the right wall.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactInput {
    /// The body on the left: "wall" (the left wall) or a pin number (0 … pins − 1).
    pub left: BodyInput,
    /// The body on the right: "wall" (the right wall) or a pin number, another body
    /// than `left`.
    pub right: BodyInput,
    /// Height from the pin feet (m), at most the pin length.
    #[schema(minimum = 0.0)]
    pub height: f64,
    /// Gap at rest (m); negative: an interference, the contact pushes at rest with
    /// its preload (which other contacts at the same height must balance).
    #[serde(default)]
    #[schema(default = 0.0)]
    pub gap: f64,
    /// Penalty stiffness K (N/m; N/mⁿ for a power law).
    #[schema(minimum = 0.0)]
    pub stiffness: f64,
    /// Dashpot cc (N·s/m), acting only while the contact is closed.
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0)]
    pub damping: f64,
    /// The rest of the law: power-law exponent, restitution, Hunt–Crossley damping,
    /// allowable force (the linear spring–dashpot when left out).
    #[serde(default, skip_serializing_if = "LawInput::is_default")]
    #[schema(schema_with = crate::processes::contact_law::row_law_schema, default = json!({}))]
    pub law: LawInput,
}

/// "wall" or a pin number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(untagged, expecting = "\"wall\" or a pin number")]
pub enum BodyInput {
    Pin(usize),
    Wall(WallKeyword),
}

/// The keyword `wall`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum WallKeyword {
    Wall,
}

impl From<BodyInput> for Body {
    fn from(value: BodyInput) -> Self {
        match value {
            BodyInput::Pin(p) => Body::Pin(p),
            BodyInput::Wall(_) => Body::Wall,
        }
    }
}

/// A body in results: "wall" or the pin number, as in the inputs.
impl From<Body> for BodyInput {
    fn from(value: Body) -> Self {
        match value {
            Body::Pin(p) => BodyInput::Pin(p),
            Body::Wall => BodyInput::Wall(WallKeyword::Wall),
        }
    }
}

impl BundleInputs {
    /// Where the user wrote the gap of `contact`, number `k` of the explicit list or of
    /// the generator's expansion.
    pub fn gap_pointer(&self, contact: &Contact, k: usize) -> String {
        let Some(generator) = &self.bundle else {
            return format!("/inputs/contacts/{k}/gap");
        };
        let wall = contact.left == Body::Wall || contact.right == Body::Wall;
        match &generator.gaps {
            GapsInput::Uniform {} if wall => "/inputs/bundle/wall_gap".to_owned(),
            GapsInput::Uniform {} => "/inputs/bundle/pin_gap".to_owned(),
            GapsInput::PerContact { .. } => format!("/inputs/bundle/gaps/values/{k}"),
            GapsInput::Random { .. } => "/inputs/bundle/gaps".to_owned(),
        }
    }
}

impl BundleGenerator {
    /// The laws of its two families of contacts.
    pub fn families(&self) -> Families<'_> {
        Families {
            pins: &self.law,
            walls: self.wall_law.as_ref(),
            pins_pointer: "/inputs/bundle/law",
            walls_pointer: "/inputs/bundle/wall_law",
        }
    }
}

impl BundleInputs {
    /// Each contact's law input (the generator's family laws for an expansion) and
    /// where the user wrote it.
    pub fn law_of(&self, contact: &Contact, k: usize) -> (LawInput, String) {
        match (&self.bundle, &self.contacts) {
            (Some(generator), _) => {
                let wall = contact.left == Body::Wall || contact.right == Body::Wall;
                let (law, pointer) = generator.families().of(wall);
                (*law, pointer.to_owned())
            }
            (None, Some(contacts)) => (
                contacts.get(k).map(|c| c.law).unwrap_or_default(),
                format!("/inputs/contacts/{k}/law"),
            ),
            (None, None) => (LawInput::default(), "/inputs".to_owned()),
        }
    }
}

impl BundleInputs {
    /// The family of a contact: against a wall or between two pins.
    pub fn family_of(contact: &Contact) -> Family {
        match contact.left == Body::Wall || contact.right == Body::Wall {
            true => Family::PinWall,
            false => Family::PinPin,
        }
    }

    /// The allowable force of each contact (N): its law's `allowable_force`, else its
    /// family's in `output.allowables`.
    pub fn allowable_forces(&self, contacts: &[Contact], laws: &[LawInput]) -> Vec<Option<f64>> {
        (contacts.iter().zip(laws))
            .map(|(c, law)| {
                law.allowable()
                    .or(self.output.allowables.force_of(Self::family_of(c)))
            })
            .collect()
    }

    /// The problems of `output.allowables` ([`AllowablesInput::check`]) for `contacts`.
    pub fn check_allowables(
        &self,
        contacts: &[Contact],
        fibre: bool,
        errors: &mut Vec<crate::processes::FieldError>,
    ) {
        let laws: Vec<(Family, String)> = (contacts.iter().enumerate())
            .filter_map(|(k, c)| {
                let (law, pointer) = self.law_of(c, k);
                law.allowable_force.map(|_| (Self::family_of(c), pointer))
            })
            .collect();
        let laws: Vec<LawAllowable<'_>> = (laws.iter())
            .map(|(family, pointer)| LawAllowable {
                family: *family,
                pointer,
            })
            .collect();
        self.output
            .allowables
            .check("/inputs/output/allowables", fibre, &laws, errors);
    }
}

impl ContactInput {
    pub fn contact(&self) -> Contact {
        Contact {
            left: self.left.into(),
            right: self.right.into(),
            height: self.height,
            gap: self.gap,
            stiffness: self.stiffness,
            damping: self.damping,
            law: self.law.law(),
        }
    }
}

/// Generator form of a row of pins between two walls: at each level, one contact
/// between the left wall and pin 0, between each pin and the next, and between the last
/// pin and the right wall (levels × (pins + 1) contacts, at most 100000).
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct BundleGenerator {
    /// Number of pins, numbered 0.. from the left wall.
    #[schema(minimum = 1, maximum = 2000)]
    pub pins: usize,
    /// Contact levels (m from the pin feet): `{first, spacing, count}` or a list of
    /// heights.
    pub levels: LevelsInput,
    /// Penalty stiffness Kc of every contact (N/m).
    #[schema(minimum = 0.0)]
    pub stiffness: f64,
    /// Dashpot cc of every contact (N·s/m), acting only while it is closed.
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0)]
    pub damping: f64,
    /// The rest of the law of every contact (of the pin–pin contacts when `wall_law`
    /// is given): exponent, restitution, Hunt–Crossley damping, allowable force.
    #[serde(default)]
    #[schema(schema_with = crate::processes::contact_law::row_law_schema, default = json!({}))]
    pub law: LawInput,
    /// The law of the wall contacts, instead of `law`.
    #[schema(schema_with = crate::processes::contact_law::row_law_schema)]
    pub wall_law: Option<LawInput>,
    /// Nominal wall–pin gap (m).
    #[schema(minimum = 0.0)]
    pub wall_gap: f64,
    /// Nominal pin–pin gap (m).
    #[schema(minimum = 0.0)]
    pub pin_gap: f64,
    /// Gap state: the nominal gaps, one per contact, or random draws.
    #[serde(default)]
    #[schema(default = json!({"type": "uniform"}))]
    pub gaps: GapsInput,
    /// Local gap changes (irradiation swelling), applied after `gaps`, in order.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub closures: Vec<ClosureInput>,
}

// Deserialized by hand rather than as an untagged enum: an object is parsed as
// `RegularLevels` and a list as heights, so that a mistake inside either (an unknown
// member, a wrong type) is reported at its own pointer, not as "matches no variant".
// The `serde` attribute only shapes the schema.
/// Contact levels: `{first, spacing, count}`, or a list of heights (m from the pin feet,
/// strictly increasing, within (0, pin length]).
#[derive(Debug, Clone, PartialEq, ToSchema)]
#[serde(untagged)]
pub enum LevelsInput {
    Regular(RegularLevels),
    #[schema(value_type = Vec<PositiveNumber>)]
    Explicit(Vec<f64>),
}

impl<'de> Deserialize<'de> for LevelsInput {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Levels;
        impl<'de> serde::de::Visitor<'de> for Levels {
            type Value = LevelsInput;

            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("{first, spacing, count} or a list of heights")
            }

            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<LevelsInput, A::Error> {
                Vec::<f64>::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))
                    .map(LevelsInput::Explicit)
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<LevelsInput, A::Error> {
                RegularLevels::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(LevelsInput::Regular)
            }
        }
        deserializer.deserialize_any(Levels)
    }
}

/// Levels first + k·spacing, k = 0..count (m), the last at most the pin length.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RegularLevels {
    /// Height of the lowest level (m from the pin feet).
    #[schema(exclusive_minimum = 0.0)]
    pub first: f64,
    /// Distance between two levels (m), enough to tell the levels apart in floating
    /// point.
    #[schema(exclusive_minimum = 0.0)]
    pub spacing: f64,
    /// Number of levels.
    #[schema(minimum = 1)]
    pub count: usize,
}

/// Gap state: `uniform`, `per_contact` or `random`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum GapsInput {
    // A struct variant: serde ignores `deny_unknown_fields` on the unit variants of
    // internally tagged enums, and a typo must not pass.
    /// The nominal gaps everywhere.
    Uniform {},
    /// One gap per contact, in expansion order (level by level: wall–0, 0–1, …, n−1–wall).
    PerContact {
        /// The gaps (m), levels × (pins + 1) of them.
        #[schema(value_type = Vec<NonNegativeNumber>)]
        values: Vec<f64>,
    },
    /// Independent draws in expansion order, reproducible from the seed on every machine.
    Random {
        /// The law of the draws.
        distribution: DistributionInput,
        /// Seed of the draws (an integer from 0 to 2⁶⁴ − 1).
        seed: u64,
        /// Draws multiply the nominal gaps (dimensionless) instead of being gaps (m).
        #[serde(default)]
        #[schema(default = false)]
        relative: bool,
    },
}

impl Default for GapsInput {
    fn default() -> Self {
        GapsInput::Uniform {}
    }
}

/// Gaps of the contacts in levels first_level..=last_level touching a pin in
/// first_pin..=last_pin are multiplied by `factor` (0 closes them).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ClosureInput {
    /// First level of the zone (0 = the lowest).
    pub first_level: usize,
    /// Last level of the zone, at least `first_level`, below the level count.
    pub last_level: usize,
    /// First pin of the zone.
    pub first_pin: usize,
    /// Last pin of the zone, at least `first_pin`, below the pin count.
    pub last_pin: usize,
    /// Multiplier of the gaps (dimensionless).
    #[schema(minimum = 0.0)]
    pub factor: f64,
}

impl BundleGenerator {
    pub fn layout(&self) -> BundleLayout {
        BundleLayout {
            pins: self.pins,
            levels: match &self.levels {
                LevelsInput::Regular(r) => Levels::Regular {
                    first: r.first,
                    spacing: r.spacing,
                    count: r.count,
                },
                LevelsInput::Explicit(list) => Levels::Explicit(list.clone()),
            },
            stiffness: self.stiffness,
            damping: self.damping,
            wall_gap: self.wall_gap,
            pin_gap: self.pin_gap,
            gaps: match &self.gaps {
                GapsInput::Uniform {} => GapState::Uniform,
                GapsInput::PerContact { values } => GapState::PerContact(values.clone()),
                GapsInput::Random {
                    distribution,
                    seed,
                    relative,
                } => GapState::Random {
                    distribution: distribution.physics(),
                    seed: *seed,
                    relative: *relative,
                },
            },
            closures: self
                .closures
                .iter()
                .map(|c| LocalClosure {
                    first_level: c.first_level,
                    last_level: c.last_level,
                    first_pin: c.first_pin,
                    last_pin: c.last_pin,
                    factor: c.factor,
                })
                .collect(),
        }
    }
}

/// Initial state.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialInput {
    /// Release of each pin, at rest, from its static tip-load shape with this tip
    /// deflection (m, positive toward the right wall); one per pin, or empty for all at
    /// rest and straight. A release needs a free top.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub tip_displacements: Vec<f64>,
    /// Initial velocity of each pin in its static tip-load shape, given by its tip
    /// velocity (m/s, positive toward the right wall): a pin thrown, or cut loose from a
    /// support moving at that speed; one per pin, or empty for all at rest. Combines with
    /// `tip_displacements`. Needs a free top.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub tip_velocities: Vec<f64>,
}

/// Loads.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ExcitationInput {
    /// Absolute acceleration a(t) of the pin feet (m/s²), positive toward the right
    /// wall; the walls (and the top supports of pins held at both ends) move with the
    /// feet unless given their own. Deflections and contact forces are relative to the
    /// feet, in whose frame each pin feels the inertial load −m·a(t) per unit length:
    /// a > 0 pushes the pins toward the left wall.
    pub base_acceleration: Option<BaseAccelerationInput>,
    /// Absolute acceleration of both walls (m/s²), positive toward the right wall, when
    /// they do not move with the feet (a wrapper hitting its neighbour). Pins held at
    /// both ends have their top support on the walls and follow them quasi-statically.
    /// A signal of amplitude 0 holds the walls still while the feet shake.
    pub wall_acceleration: Option<BaseAccelerationInput>,
    /// The left wall's own absolute acceleration (m/s²), instead of `wall_acceleration`;
    /// the other wall follows the feet unless given too.
    pub left_wall_acceleration: Option<BaseAccelerationInput>,
    /// The right wall's own absolute acceleration (m/s²), instead of `wall_acceleration`.
    pub right_wall_acceleration: Option<BaseAccelerationInput>,
    /// Force histories at a height of a pin, positive toward the right wall (N).
    #[serde(default)]
    #[schema(default = json!([]))]
    pub point_forces: Vec<PointForceInput>,
}

impl ExcitationInput {
    /// The stored signals referenced, with their pointers.
    /// The acceleration members (name, value), in the schema's order.
    pub fn accelerations(&self) -> [(&'static str, &Option<BaseAccelerationInput>); 4] {
        [
            ("base_acceleration", &self.base_acceleration),
            ("wall_acceleration", &self.wall_acceleration),
            ("left_wall_acceleration", &self.left_wall_acceleration),
            ("right_wall_acceleration", &self.right_wall_acceleration),
        ]
    }

    pub fn signal_references(&mut self) -> Vec<crate::processes::signal_input::SignalSlot<'_>> {
        crate::processes::excitation::signal_slots([
            ("base_acceleration", &mut self.base_acceleration),
            ("wall_acceleration", &mut self.wall_acceleration),
            ("left_wall_acceleration", &mut self.left_wall_acceleration),
            ("right_wall_acceleration", &mut self.right_wall_acceleration),
        ])
    }

    /// The member that gives the left (`right` false) or right wall's motion, if any.
    pub fn wall_member(&self, right: bool) -> Option<(&'static str, &BaseAccelerationInput)> {
        let own = if right {
            ("right_wall_acceleration", &self.right_wall_acceleration)
        } else {
            ("left_wall_acceleration", &self.left_wall_acceleration)
        };
        match (own, &self.wall_acceleration) {
            ((member, Some(signal)), _) => Some((member, signal)),
            (_, Some(signal)) => Some(("wall_acceleration", signal)),
            _ => None,
        }
    }

    /// The walls' motion for the integrator: `None` when both follow the feet; a wall
    /// not given follows the feet.
    pub fn walls(&self) -> Option<crate::physics::integrate::WallMotion> {
        let base = self
            .base_acceleration
            .as_ref()
            .map(BaseAccelerationInput::physics);
        let wall = |right| match self.wall_member(right) {
            Some((_, signal)) => Some(signal.physics()),
            None => base.clone(),
        };
        (self.wall_member(false).is_some() || self.wall_member(true).is_some()).then(|| {
            crate::physics::integrate::WallMotion {
                left_x: wall(false),
                right_x: wall(true),
                y: None,
            }
        })
    }
}

/// A force table applied at a height of one pin, positive toward the right wall.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PointForceInput {
    /// The loaded pin (0 … pins − 1).
    pub pin: usize,
    /// Height from the foot (m), at most the pin length.
    #[schema(minimum = 0.0)]
    pub height: f64,
    /// Sample times (s), at least two, ≥ 0 and strictly increasing.
    #[schema(value_type = Vec<NonNegativeNumber>)]
    pub time: Vec<f64>,
    /// Force at those times (N), linear between them, 0 after the last.
    pub force: Vec<f64>,
}

impl PointForceInput {
    /// The force on the pin's line (a row has one line per pin, line p for pin p).
    pub fn physics(&self) -> PointForce {
        PointForce {
            line: self.pin,
            height: self.height,
            force: Table {
                time: self.time.clone(),
                values: self.force.clone(),
            },
        }
    }
}

/// History sampling.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputInput {
    /// Time between two history samples (s), a whole number of steps; 1e-4 s when left
    /// out (every step when the step is longer).
    #[schema(exclusive_minimum = 0.0)]
    pub interval: Option<f64>,
    /// Heights (m from the feet, within the pin) of the deflections recorded for every
    /// pin; the pin tips when left out.
    #[schema(value_type = Option<Vec<NonNegativeNumber>>)]
    pub heights: Option<Vec<f64>>,
    /// How impacts are counted and tabulated; default: every closure is an impact.
    pub impacts: Option<ImpactsInput>,
    /// Equal blocks of the run over which the impact statistics are also computed,
    /// reported as their mean and standard deviation (code_aster's NB_BLOC; 1…100).
    #[schema(minimum = 1, maximum = 100, default = 1)]
    pub blocks: Option<usize>,
    /// What the contacts and the clad may carry (docs/margins.md): each contact's peak
    /// force and each pin's largest stress over them, as utilisation ratios. Families:
    /// `pin_pin` (between two pins), `pin_wall` (a pin and a wall). None by default.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub allowables: AllowablesInput,
}
