//! Inputs of `hex-bundle-dynamics`: the pin, the bundle's geometry (a dozen numbers),
//! contact laws, gap state, excitation in the transverse plane, solver and output
//! selection, with their mapping to the physics types (`physics::hex`).
//!
//! Angles are in degrees, counter-clockwise from +x seen from above (the physics works in
//! radians). Flats are numbered 0..6 counter-clockwise, flat k's outward normal at
//! k·60° + 30°; pins from the centre outward, ring by ring (docs/hex-bundle.md).

use crate::processes::contact_law::{Families, LawInput};
use crate::processes::margins::{AllowablesInput, Family, LawAllowable};
use serde::Deserialize;
use utoipa::ToSchema;

use super::loads::{HexInitialInput, HexPointForceInput};
use crate::physics::hex::{FlatOffset, Handedness, HexGapState, HexGaps, HexLayout, PinZone, ZoneClosure};
use crate::processes::common_inputs::{BeamInput, SectionInput, SolverInput};
use crate::processes::excitation::BaseAccelerationInput;
use crate::processes::impact_report::ImpactsInput;
use crate::processes::input_schema::NonNegativeNumber;
use crate::processes::random_gaps::DistributionInput;
use crate::processes::warnings::WarningsInput;

/// Inputs of `hex-bundle-dynamics`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexInputs {
    /// The pin shared by every pin of the bundle: one modal basis, used for the bending
    /// along x and along y. A tube section's outer diameter is the clad diameter D.
    pub pin: BeamInput,
    /// Pins of other kinds (an instrumented pin, an absorber pin): another material,
    /// section, added mass and damping on the pin's length, supports, mesh, modes and
    /// static correction, and the same clad diameter D (the wire-wrap geometry's)
    /// (docs/kinds.md); absent, every pin is `pin`.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub kinds: Vec<crate::processes::kinds::KindInput>,
    /// The bundle's geometry: rings, pitch, wires, wrapper.
    pub bundle: HexGeometryInput,
    /// Penalty laws of the wire contacts.
    pub contact: HexContactInput,
    /// Gap state: the nominal clearances from the geometry (or given ones), one gap per
    /// contact, or random draws.
    #[serde(default)]
    #[schema(default = json!({"type": "uniform"}))]
    pub gaps: HexGapsInput,
    /// Local gap changes (swelling), applied after `gaps`, in order.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub closures: Vec<HexClosureInput>,
    /// Every pin moved toward one flat (a bundle pressed against the wrapper), applied last.
    pub offset: Option<OffsetInput>,
    /// The state at t = 0: pins released from bent shapes; all at rest and straight when
    /// left out.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub initial: HexInitialInput,
    /// The feet's and the wrapper's acceleration in the transverse plane, and point
    /// forces on pins.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub excitation: HexExcitationInput,
    /// Explicit integration.
    #[serde(default)]
    #[schema(schema_with = crate::processes::input_schema::auto_solver_schema, default = json!({}))]
    pub solver: SolverInput,
    /// History sampling and selection, impact counting.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub output: HexOutputInput,
    /// Plausibility warnings (a unit slip, nothing exciting the model, ...): `on`
    /// (default) or `off`; never a refusal.
    #[serde(default)]
    #[schema(default = "on")]
    pub warnings: WarningsInput,
}

/// The wire-wrapped hexagonal bundle in its wrapper tube (lengths in m).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexGeometryInput {
    /// Rings of pins around the centre pin, 1 to 9: 3n(n + 1) + 1 pins (7 to 271).
    #[schema(minimum = 1, maximum = 9)]
    pub rings: usize,
    /// P, distance between neighbouring pin centres (m), ≥ D + d_w.
    #[schema(exclusive_minimum = 0.0)]
    pub pitch: f64,
    /// d_w, spacer wire diameter (m).
    #[schema(exclusive_minimum = 0.0)]
    pub wire_diameter: f64,
    /// H, axial length of one wire turn (m), ≥ 6 beam element lengths (and at most
    /// 100000 contact levels, one every H/12, over the pin).
    #[schema(exclusive_minimum = 0.0)]
    pub wire_lead: f64,
    /// F, inner flat-to-flat distance of the wrapper (m), ≥ √3·n·P + D + 2·d_w.
    #[schema(exclusive_minimum = 0.0)]
    pub wrapper_flat_to_flat: f64,
    /// D, clad outer diameter (m); the pin section's outer diameter when left out
    /// (required with an explicit section).
    #[schema(exclusive_minimum = 0.0)]
    pub pin_diameter: Option<f64>,
    /// Direction of every wire at the pin foot (degrees, counter-clockwise from +x).
    #[serde(default)]
    #[schema(default = 0.0)]
    pub wire_start_angle: f64,
    /// Sense in which the wires turn going up.
    #[serde(default)]
    #[schema(default = "right")]
    pub handedness: HandednessInput,
}

/// `right`: counter-clockwise seen from above as z rises; `left`: clockwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum HandednessInput {
    #[default]
    Right,
    Left,
}

/// Penalty laws of the contacts (wire on clad, wire on wrapper).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexContactInput {
    /// Kc of the pin–pin contacts (N/m).
    #[schema(minimum = 0.0)]
    pub stiffness: f64,
    /// cc of the pin–pin contacts (N·s/m), acting only while a contact is closed.
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0)]
    pub damping: f64,
    /// Kc of the pin–wrapper contacts (N/m); `stiffness` when left out.
    #[schema(minimum = 0.0)]
    pub wall_stiffness: Option<f64>,
    /// cc of the pin–wrapper contacts (N·s/m); `damping` when left out.
    #[schema(minimum = 0.0)]
    pub wall_damping: Option<f64>,
    /// The rest of the law of the pin–pin contacts (and of the pin–wrapper ones without
    /// `wall_law`): exponent, restitution, Hunt–Crossley damping, friction, allowable
    /// force (the linear spring–dashpot without friction when left out).
    #[serde(default)]
    #[schema(default = json!({}))]
    pub law: LawInput,
    /// The law of the pin–wrapper contacts, instead of `law`.
    pub wall_law: Option<LawInput>,
}

impl HexContactInput {
    /// The laws of the two families.
    pub fn families(&self) -> Families<'_> {
        Families {
            pins: &self.law,
            walls: self.wall_law.as_ref(),
            pins_pointer: "/inputs/contact/law",
            walls_pointer: "/inputs/contact/wall_law",
        }
    }

    /// The stiffness, dashpot and law of a pin–wrapper contact (`wall`) or a pin–pin
    /// one, and where its law was written.
    pub fn family(&self, wall: bool) -> (f64, f64, &LawInput, &str) {
        let (law, pointer) = self.families().of(wall);
        if wall {
            (
                self.wall_stiffness.unwrap_or(self.stiffness),
                self.wall_damping.unwrap_or(self.damping),
                law,
                pointer,
            )
        } else {
            (self.stiffness, self.damping, law, pointer)
        }
    }

    /// The allowable force (N) of the contacts of one family (pin–wrapper when `wall`,
    /// else pin–pin): the law's `allowable_force`, else the family's in `allowables`.
    pub fn allowable_force(&self, wall: bool, allowables: &AllowablesInput) -> Option<f64> {
        let family = if wall { Family::PinWall } else { Family::PinPin };
        self.family(wall).2.allowable().or(allowables.force_of(family))
    }

    /// The laws that give their own `allowable_force`, by family, for
    /// [`AllowablesInput::check`].
    pub fn law_allowables(&self) -> Vec<LawAllowable<'_>> {
        [(false, Family::PinPin), (true, Family::PinWall)]
            .into_iter()
            .filter_map(|(wall, family)| {
                let (_, _, law, pointer) = self.family(wall);
                law.allowable_force.map(|_| LawAllowable { family, pointer })
            })
            .collect()
    }

    /// Every problem of the two laws, at their pointers: the physics' own check of a
    /// law ([`crate::physics::contact::Law::validate`]) and the inputs' ([`Families::check`]).
    pub fn check_laws(&self, errors: &mut Vec<crate::processes::FieldError>, service_time: Option<f64>) {
        self.families().check(errors);
        match (self.families().wears(), service_time) {
            (true, None) => errors.push(crate::processes::FieldError::new(
                "/inputs/output/service_time",
                "a contact law has a `wear`: give the service time (s) it wears over",
            )),
            (false, Some(_)) => errors.push(crate::processes::FieldError::new(
                "/inputs/output/service_time",
                "is the time the contact laws' `wear` wears over, and no law has one",
            )),
            (_, Some(time)) if !(time.is_finite() && time > 0.0) => errors.push(
                crate::processes::FieldError::new("/inputs/output/service_time", "must be a time > 0 (s)"),
            ),
            _ => {}
        }
        let mut families = vec![false];
        if self.wall_law.is_some() || self.wall_damping.is_some() {
            families.push(true);
        }
        for wall in families {
            let (_, damping, law, pointer) = self.family(wall);
            let mut issues = Vec::new();
            law.law().validate(&mut issues, damping);
            errors.extend(crate::processes::common_inputs::at(pointer, issues));
        }
    }
}

/// Gap state of the bundle: `uniform`, `per_contact` or `random`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum HexGapsInput {
    /// One gap for every pin–pin contact and one for every wall contact.
    Uniform {
        /// Gap of every pin–pin contact (m); the nominal clearance P − D − d_w when
        /// left out.
        #[schema(minimum = 0.0)]
        pin_pin: Option<f64>,
        /// Gap of every pin–wrapper contact (m); the nominal clearance from the
        /// flat-to-flat when left out.
        #[schema(minimum = 0.0)]
        pin_wall: Option<f64>,
    },
    /// One gap per contact, in contact order (results `contacts`).
    PerContact {
        /// The gaps (m), one per contact.
        #[schema(value_type = Vec<NonNegativeNumber>)]
        values: Vec<f64>,
    },
    /// Independent draws in contact order, reproducible from the seed on every machine.
    Random {
        /// The law of the draws.
        distribution: DistributionInput,
        /// Seed of the draws (an integer from 0 to 2⁶⁴ − 1).
        seed: u64,
        /// Draws multiply the nominal clearances (dimensionless) instead of being gaps (m).
        #[serde(default)]
        #[schema(default = false)]
        relative: bool,
    },
}

impl Default for HexGapsInput {
    fn default() -> Self {
        Self::Uniform {
            pin_pin: None,
            pin_wall: None,
        }
    }
}

/// Gaps of the contacts on levels first_level..=last_level that involve a pin of the
/// zone (rings first_ring..=last_ring, or sectors first_sector..=last_sector: give one
/// pair) are multiplied by `factor` (0 closes them).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexClosureInput {
    /// First ring of the zone (0 = the centre pin), with `last_ring`.
    pub first_ring: Option<usize>,
    /// Last ring of the zone, at least `first_ring`, at most `bundle.rings`.
    pub last_ring: Option<usize>,
    /// First sector of the zone (sextants 0..5 of the centre angles [s·60°, (s+1)·60°)),
    /// with `last_sector`.
    #[schema(maximum = 5)]
    pub first_sector: Option<usize>,
    /// Last sector of the zone, at least `first_sector`.
    #[schema(maximum = 5)]
    pub last_sector: Option<usize>,
    /// First level of the zone (0 = the lowest; results `geometry.levels`).
    pub first_level: usize,
    /// Last level of the zone, at least `first_level`, below the level count.
    pub last_level: usize,
    /// Multiplier of the gaps (dimensionless).
    #[schema(minimum = 0.0)]
    pub factor: f64,
}

/// Every pin moved by `distance` (m) toward flat `flat` (0..6): the wall gaps change,
/// pin–pin gaps do not.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct OffsetInput {
    /// The flat the pins move toward (0..5, flat k's outward normal at k·60° + 30°).
    #[schema(maximum = 5)]
    pub flat: usize,
    /// How far (m): at most what keeps every wall gap ≥ 0.
    #[schema(minimum = 0.0)]
    pub distance: f64,
}

/// Acceleration of every pin foot in the transverse plane (one signal along `direction`,
/// or two components), and of the wrapper, which moves with the feet unless given its
/// own (`wrapper_acceleration…`); point forces on pins. Results are relative to the feet.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexExcitationInput {
    /// The pin feet's acceleration (m/s²), positive along `direction` (and the wrapper's,
    /// unless given its own). Deflections and contact forces are relative to the feet,
    /// in whose frame each pin feels the inertial load −m·a(t) per unit length
    /// (opposite to the acceleration).
    pub base_acceleration: Option<BaseAccelerationInput>,
    /// Direction of `base_acceleration` (degrees, counter-clockwise from +x; 30 is flat
    /// 0's normal); 0 when left out. Only with `base_acceleration`.
    pub direction: Option<f64>,
    /// Component along +x (m/s²), instead of `base_acceleration`.
    pub base_acceleration_x: Option<BaseAccelerationInput>,
    /// Component along +y (m/s²), instead of `base_acceleration`.
    pub base_acceleration_y: Option<BaseAccelerationInput>,
    /// The wrapper's own absolute acceleration (m/s²) along `wrapper_direction`, when it
    /// does not move with the pin feet (hitting its neighbour). Pins held at both ends
    /// have their top support on it and follow it quasi-statically. Results are relative
    /// to the feet.
    pub wrapper_acceleration: Option<BaseAccelerationInput>,
    /// Direction of `wrapper_acceleration` (degrees, counter-clockwise from +x); default
    /// `direction`.
    pub wrapper_direction: Option<f64>,
    /// The wrapper's own acceleration along x (m/s²), instead of `wrapper_acceleration`;
    /// a component not given follows the feet.
    pub wrapper_acceleration_x: Option<BaseAccelerationInput>,
    /// Along y (m/s²), instead of `wrapper_acceleration`.
    pub wrapper_acceleration_y: Option<BaseAccelerationInput>,
    /// Force histories at a height of a pin, each along its own direction (N).
    #[serde(default)]
    #[schema(default = json!([]))]
    pub point_forces: Vec<HexPointForceInput>,
}

impl HexExcitationInput {
    /// The stored signals referenced, with their pointers.
    /// The acceleration members (name, value), in the schema's order.
    pub fn accelerations(&self) -> [(&'static str, &Option<BaseAccelerationInput>); 6] {
        [
            ("base_acceleration", &self.base_acceleration),
            ("base_acceleration_x", &self.base_acceleration_x),
            ("base_acceleration_y", &self.base_acceleration_y),
            ("wrapper_acceleration", &self.wrapper_acceleration),
            ("wrapper_acceleration_x", &self.wrapper_acceleration_x),
            ("wrapper_acceleration_y", &self.wrapper_acceleration_y),
        ]
    }

    pub fn signal_references(&mut self) -> Vec<crate::processes::signal_input::SignalSlot<'_>> {
        crate::processes::excitation::signal_slots([
            ("base_acceleration", &mut self.base_acceleration),
            ("base_acceleration_x", &mut self.base_acceleration_x),
            ("base_acceleration_y", &mut self.base_acceleration_y),
            ("wrapper_acceleration", &mut self.wrapper_acceleration),
            ("wrapper_acceleration_x", &mut self.wrapper_acceleration_x),
            ("wrapper_acceleration_y", &mut self.wrapper_acceleration_y),
        ])
    }
}

/// History sampling and selection.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexOutputInput {
    /// Time between two history samples (s), a whole number of steps; 1e-4 s when left
    /// out (every step when the step is longer).
    #[schema(exclusive_minimum = 0.0)]
    pub interval: Option<f64>,
    /// Heights (m from the feet, within the pin) of the deflections (x and y) recorded
    /// for every pin; the tips when left out.
    #[schema(value_type = Option<Vec<NonNegativeNumber>>)]
    pub heights: Option<Vec<f64>>,
    /// Contacts whose force histories are recorded (statistics are kept for every
    /// contact); the wall contacts when left out.
    pub contacts: Option<ContactSelectionInput>,
    /// How impacts are counted and tabulated; default: every closure is an impact.
    pub impacts: Option<ImpactsInput>,
    /// Equal blocks of the run over which the impact statistics are also computed,
    /// reported as their mean and standard deviation (code_aster's NB_BLOC; 1…100).
    #[schema(minimum = 1, maximum = 100, default = 1)]
    pub blocks: Option<usize>,
    /// The service time (s) the contact laws' `wear` wears over: each contact's worn
    /// volume and depth after it, at the run's wear power. Required with a `wear`.
    #[schema(exclusive_minimum = 0.0)]
    pub service_time: Option<f64>,
    /// What the contacts and the clad may carry (docs/margins.md): each contact's peak
    /// force and each pin's largest stress over them, as utilisation ratios. Families:
    /// `pin_pin` (a wire on a neighbour's clad), `pin_wall` (a wire on the wrapper). None
    /// by default.
    #[serde(default)]
    #[schema(default = json!({}))]
    pub allowables: AllowablesInput,
}

/// A selection of contacts: `all`, `none`, `walls`, `list`, `levels` or `rings`.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContactSelectionInput {
    /// Every contact (thousands of columns for a large bundle).
    All {},
    /// None.
    None {},
    /// The pin–wrapper contacts.
    Walls {},
    /// These contacts.
    List {
        /// Contact indices (results `contacts` order), each once.
        contacts: Vec<usize>,
    },
    /// The contacts on some levels.
    Levels {
        /// First level (0 = the lowest).
        first: usize,
        /// Last level, at least `first`.
        last: usize,
    },
    /// The contacts involving a pin of some rings.
    Rings {
        /// First ring (0 = the centre pin).
        first: usize,
        /// Last ring, at least `first`, at most `bundle.rings`.
        last: usize,
    },
}

impl HexInputs {
    /// Where the user wrote (or the geometry set) the gap of `contact`, number `k` in
    /// contact order.
    pub fn gap_pointer(&self, contact: &crate::physics::contact::Contact, k: usize) -> String {
        let wall = contact.right == crate::physics::contact::Body::Wall;
        match &self.gaps {
            HexGapsInput::Uniform {
                pin_wall: Some(_), ..
            } if wall => "/inputs/gaps/pin_wall".to_owned(),
            HexGapsInput::Uniform { .. } if wall => "/inputs/bundle/wrapper_flat_to_flat".to_owned(),
            HexGapsInput::Uniform { pin_pin: Some(_), .. } => "/inputs/gaps/pin_pin".to_owned(),
            HexGapsInput::Uniform { .. } => "/inputs/bundle/pitch".to_owned(),
            HexGapsInput::PerContact { .. } => format!("/inputs/gaps/values/{k}"),
            HexGapsInput::Random { .. } => "/inputs/gaps".to_owned(),
        }
    }

    /// D: `bundle.pin_diameter`, else the tube's outer diameter; `None` when neither.
    pub fn pin_diameter(&self) -> Option<f64> {
        self.bundle.pin_diameter.or(match self.pin.section {
            SectionInput::Tube { outer_diameter, .. } => Some(outer_diameter),
            SectionInput::Explicit { .. } => None,
        })
    }

    /// The physics layout (angles in radians).
    pub fn layout(&self, pin_diameter: f64) -> HexLayout {
        let geometry = &self.bundle;
        HexLayout {
            rings: geometry.rings,
            pitch: geometry.pitch,
            pin_diameter,
            wire_diameter: geometry.wire_diameter,
            wire_lead: geometry.wire_lead,
            wrapper_flat_to_flat: geometry.wrapper_flat_to_flat,
            wire_start_angle: geometry.wire_start_angle.to_radians(),
            handedness: match geometry.handedness {
                HandednessInput::Right => Handedness::Right,
                HandednessInput::Left => Handedness::Left,
            },
        }
    }

    /// The physics gap description; closures with no zone or two are reported by
    /// [`Self::closure_issues`] and left out here.
    pub fn gaps(&self) -> HexGaps {
        HexGaps {
            state: match &self.gaps {
                HexGapsInput::Uniform { pin_pin, pin_wall } => HexGapState::Uniform {
                    pin_pin: *pin_pin,
                    pin_wall: *pin_wall,
                },
                HexGapsInput::PerContact { values } => HexGapState::PerContact(values.clone()),
                HexGapsInput::Random {
                    distribution,
                    seed,
                    relative,
                } => HexGapState::Random {
                    distribution: distribution.physics(),
                    seed: *seed,
                    relative: *relative,
                },
            },
            closures: self
                .closures
                .iter()
                .filter_map(|c| {
                    let zone = c.zone().ok()?;
                    Some(ZoneClosure {
                        zone,
                        first_level: c.first_level,
                        last_level: c.last_level,
                        factor: c.factor,
                    })
                })
                .collect(),
            offset: self.offset.map(|o| FlatOffset {
                flat: o.flat,
                distance: o.distance,
            }),
        }
    }

    /// `(pointer, reason)` for every closure whose zone is not exactly one of rings or
    /// sectors (both ends).
    pub fn closure_issues(&self) -> Vec<(String, String)> {
        self.closures
            .iter()
            .enumerate()
            .filter_map(|(k, c)| {
                c.zone()
                    .err()
                    .map(|reason| (format!("/inputs/closures/{k}"), reason))
            })
            .collect()
    }
}

impl HexClosureInput {
    fn zone(&self) -> Result<PinZone, String> {
        match (
            self.first_ring,
            self.last_ring,
            self.first_sector,
            self.last_sector,
        ) {
            (Some(first_ring), Some(last_ring), None, None) => Ok(PinZone::Rings {
                first_ring,
                last_ring,
            }),
            (None, None, Some(first_sector), Some(last_sector)) => Ok(PinZone::Sectors {
                first_sector,
                last_sector,
            }),
            _ => Err(
                "give the zone as first_ring and last_ring, or as first_sector and last_sector (one pair)"
                    .to_owned(),
            ),
        }
    }
}
