//! The contact law beyond stiffness and damping, as every process takes it: the member
//! `law` of a contact (or of a family of contacts), and its mapping to the physics'
//! [`Law`] (docs/contact-laws.md).

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::physics::contact::{Friction, Law, Restitution};
use crate::physics::wear::{Wear, WearGeometry};

/// How a contact's force grows and what it loses, beside its `stiffness` K and
/// `damping` c: F = max(0, K δⁿ (1 + α δ̇) + c δ̇) while the penetration δ > 0. Every
/// member is optional: `{}` is the linear spring–dashpot without friction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LawInput {
    /// n in F = K δⁿ (dimensionless; K in N/mⁿ): 1 (default) is linear, 1.5 Hertz (a
    /// sphere or crossed cylinders).
    #[schema(minimum = 1.0)]
    pub exponent: Option<f64>,
    /// Hunt–Crossley α (s/m): the force K δⁿ (1 + α δ̇), damped in proportion to the
    /// spring, with no jump at first touch; e ≈ 1 − α v₀ at slow approach.
    #[schema(minimum = 0.0)]
    pub hunt_crossley: Option<f64>,
    /// A coefficient of restitution e (dimensionless), in (0, 1], instead of `damping` (and of
    /// `hunt_crossley`): the impact of two free bodies rebounds with e exactly. Linear
    /// law: sets the dashpot c = 2 ζ(e) √(K m), m the reduced mass (`restitution_mass`,
    /// or from each pin's modal basis at the contact). Power law: sets α for
    /// `restitution_speed`.
    #[schema(exclusive_minimum = 0.0, maximum = 1.0)]
    pub restitution: Option<f64>,
    /// The approach speed (m/s) at which a power law rebounds with `restitution`
    /// (required with n > 1; faster impacts rebound less).
    #[schema(exclusive_minimum = 0.0)]
    pub restitution_speed: Option<f64>,
    /// The reduced mass m₁m₂/(m₁ + m₂) (kg) of the linear law's restitution; by default
    /// each pin's apparent mass 1/Σᵢ φᵢ(z)² on its modal basis at the contact (a wall's
    /// infinite).
    #[schema(exclusive_minimum = 0.0)]
    pub restitution_mass: Option<f64>,
    /// The largest force (N) a power law (n > 1) is expected to carry: its tangent
    /// stiffness n K δⁿ⁻¹ there sizes the time step; `allowable_force` when left out. A
    /// run whose peak exceeds it is judged `doubtful` or `poor`.
    #[schema(exclusive_minimum = 0.0)]
    pub force_scale: Option<f64>,
    /// Coulomb friction on the contact's tangent (pins in the transverse plane only).
    pub friction: Option<FrictionInput>,
    /// The force (N) this contact may carry: results report each contact's peak over it
    /// (`utilisation`) and the worst in the run. Reporting only; `output.allowables`
    /// gives it per family of contacts instead.
    #[schema(exclusive_minimum = 0.0)]
    pub allowable_force: Option<f64>,
    /// Archard wear of the tube: the volume K P t and the depth it makes, P the wear
    /// power (normal force × sliding speed while slipping), t `output.service_time`
    /// (pins in the transverse plane only).
    pub wear: Option<WearInput>,
}

/// Archard's law of a contact (code_aster's POST_USURE, law ARCHARD).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WearInput {
    /// K (m³/(N·m), i.e. Pa⁻¹): volume worn per newton and metre slid (e.g. 1.2e-13
    /// for Inconel 600 on itself in a flat contact, code_aster's material bank).
    #[schema(minimum = 0.0)]
    pub coefficient: f64,
    /// The geometry the depth is worn into.
    pub geometry: WearGeometryInput,
}

/// The contact's geometry, seen from the worn tube.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum WearGeometryInput {
    /// A tube on a flat (clad on a wrapper flat, rod on a grid spring or dimple;
    /// TUBE_BAV): V = (4/3) L √(2R) d^{3/2}.
    Flat {
        /// The tube's outer radius R (m).
        #[schema(exclusive_minimum = 0.0)]
        radius: f64,
        /// The flat's width L across the tube (m).
        #[schema(exclusive_minimum = 0.0)]
        width: f64,
    },
    /// Two tubes crossing at an angle (wire on clad, tube on tube; TUBE_TUBE):
    /// V = (8/15) √(2R) d^{5/2}/θ.
    CrossedTubes {
        /// The worn tube's outer radius R (m).
        #[schema(exclusive_minimum = 0.0)]
        radius: f64,
        /// The crossing angle θ (degrees, in (0, 90]).
        #[schema(exclusive_minimum = 0.0, maximum = 90.0)]
        angle: f64,
    },
    /// A tube in a bore, worn evenly around (TUBE_ALESAGE): V = 2π R L d.
    Bore {
        /// The tube's outer radius R (m).
        #[schema(exclusive_minimum = 0.0)]
        radius: f64,
        /// The bore's length L (m).
        #[schema(exclusive_minimum = 0.0)]
        length: f64,
    },
}

impl WearInput {
    /// The physics law.
    pub fn wear(&self) -> Wear {
        Wear {
            coefficient: self.coefficient,
            geometry: match self.geometry {
                WearGeometryInput::Flat { radius, width } => WearGeometry::Flat { radius, width },
                WearGeometryInput::CrossedTubes { radius, angle } => WearGeometry::CrossedTubes {
                    radius,
                    angle_degrees: angle,
                },
                WearGeometryInput::Bore { radius, length } => WearGeometry::Bore { radius, length },
            },
        }
    }
}

/// The contact worn deepest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct WearDepth {
    /// Contact index.
    pub contact: usize,
    /// Its depth (m).
    pub depth: f64,
}

/// The worn volume and depth of a contact after the service time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct WearReport {
    /// The wear power P (W): F_n |v_t| averaged over the run while slipping.
    pub power: f64,
    /// V = K P t (m³).
    pub volume: f64,
    /// The depth worn into the tube (m).
    pub depth: f64,
}

impl WearReport {
    pub fn of(wear: &WearInput, power: f64, service_time: f64) -> Self {
        let wear = wear.wear();
        let volume = wear.volume(power, service_time);
        Self {
            power,
            volume,
            depth: wear.depth(volume),
        }
    }
}

/// Coulomb friction with a stick stiffness (as code_aster's DIS_CHOC): while the
/// tangential force stays below μ F_n the contact sticks on a spring k_t; beyond, it
/// slides with the force μ F_n against the sliding.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FrictionInput {
    /// μ (dimensionless), ≥ 0.
    #[schema(minimum = 0.0)]
    pub coefficient: f64,
    /// k_t (N/m) of the stick phase, > 0.
    #[schema(exclusive_minimum = 0.0)]
    pub tangential_stiffness: f64,
}

/// The schema of `law` where contacts do not slide (pins bending in one plane:
/// `bundle-dynamics`, `cantilever-impact`): [`LawInput`]'s without `friction` and
/// `wear`, which those processes refuse with the reason.
pub fn row_law_schema() -> utoipa::openapi::RefOr<utoipa::openapi::Schema> {
    use utoipa::PartialSchema;
    let mut schema = <LawInput as PartialSchema>::schema();
    if let utoipa::openapi::RefOr::T(utoipa::openapi::Schema::Object(object)) = &mut schema {
        object.properties.remove("friction");
        object.properties.remove("wear");
        object.description = Some(
            "How a contact's force grows and what it loses, beside its `stiffness` K and `damping` c: \
             F = max(0, K δⁿ (1 + α δ̇) + c δ̇) while the penetration δ > 0. Every member is optional: \
             `{}` is the linear spring–dashpot. (Friction and wear need pins bending in the transverse \
             plane: hex-bundle-dynamics.)"
                .to_owned(),
        );
    }
    schema
}

impl LawInput {
    /// The physics law (every value as given: the physics checks them, at `law/…`).
    pub fn law(&self) -> Law {
        Law {
            exponent: self.exponent.unwrap_or(1.0),
            hunt_crossley: self.hunt_crossley.unwrap_or(0.0),
            restitution: self.restitution.map(|coefficient| Restitution {
                coefficient,
                speed: self.restitution_speed.unwrap_or(f64::NAN),
                mass: self.restitution_mass,
            }),
            force_scale: self.force_scale.or(self.allowable_force).unwrap_or(f64::NAN),
            friction: self.friction.map_or(Friction::NONE, |f| Friction {
                coefficient: f.coefficient,
                tangential_stiffness: f.tangential_stiffness,
            }),
        }
    }

    /// `allowable_force` when it is a force (the physics does not check it).
    pub fn allowable(&self) -> Option<f64> {
        self.allowable_force.filter(|f| f.is_finite() && *f > 0.0)
    }

    /// The problems the physics does not see, at `pointer` (the `law` member):
    /// `allowable_force` a force > 0, `restitution_speed` and `restitution_mass` only
    /// with a `restitution`, a valid wear law.
    pub fn check(&self, pointer: &str, errors: &mut Vec<super::FieldError>) {
        if let Some(wear) = &self.wear {
            errors.extend(super::common_inputs::at(
                &format!("{pointer}/wear"),
                wear.wear().validate(),
            ));
        }
        if let Some(force) = self.allowable_force
            && !(force.is_finite() && force > 0.0)
        {
            errors.push(super::FieldError::new(
                format!("{pointer}/allowable_force"),
                "must be a force > 0 (N)",
            ));
        }
        if self.restitution.is_none() {
            for (member, given) in [
                ("restitution_speed", self.restitution_speed.is_some()),
                ("restitution_mass", self.restitution_mass.is_some()),
            ] {
                if given {
                    errors.push(super::FieldError::new(
                        format!("{pointer}/{member}"),
                        "belongs to a `restitution`, which is not given",
                    ));
                }
            }
        }
    }
}

impl LawInput {
    /// Refuses `wear` (at `pointer`, the law) in a model whose contacts do not slide:
    /// the pins of a row bend in one plane.
    pub fn refuse_wear_in_a_row(&self, pointer: &str, errors: &mut Vec<super::FieldError>) {
        if self.wear.is_some() {
            errors.push(super::FieldError::new(
                format!("{pointer}/wear"),
                "the contacts of pins bending in one plane do not slide, so nothing wears: wear needs \
                 pins in the transverse plane (hex-bundle-dynamics)",
            ));
        }
    }

    /// Whether every member is left out (the linear law): not echoed in results.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// The laws of the two families of a generated model: `law` for the contacts between
/// two pins, `wall_law` (or `law` when left out) for those against a wall.
#[derive(Debug, Clone, Copy)]
pub struct Families<'a> {
    pub pins: &'a LawInput,
    pub walls: Option<&'a LawInput>,
    /// The members' pointers (`/inputs/bundle/law`, `/inputs/bundle/wall_law`).
    pub pins_pointer: &'a str,
    pub walls_pointer: &'a str,
}

impl<'a> Families<'a> {
    /// The law of a contact against a wall (`wall`) or between two pins, and where the
    /// user wrote it.
    pub fn of(&self, wall: bool) -> (&'a LawInput, &'a str) {
        match (wall, self.walls) {
            (true, Some(law)) => (law, self.walls_pointer),
            _ => (self.pins, self.pins_pointer),
        }
    }

    /// The problems of both laws the physics does not see ([`LawInput::check`]).
    pub fn check(&self, errors: &mut Vec<super::FieldError>) {
        self.pins.check(self.pins_pointer, errors);
        if let Some(walls) = self.walls {
            walls.check(self.walls_pointer, errors);
        }
    }

    /// [`LawInput::refuse_wear_in_a_row`] for both laws.
    pub fn refuse_wear_in_a_row(&self, errors: &mut Vec<super::FieldError>) {
        self.pins.refuse_wear_in_a_row(self.pins_pointer, errors);
        if let Some(walls) = self.walls {
            walls.refuse_wear_in_a_row(self.walls_pointer, errors);
        }
    }

    /// Whether either law wears.
    pub fn wears(&self) -> bool {
        self.pins.wear.is_some() || self.walls.is_some_and(|w| w.wear.is_some())
    }
}

/// The contact most loaded against its allowable force.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct Utilisation {
    /// Contact index.
    pub contact: usize,
    /// Its peak force over its allowable force (dimensionless; > 1: exceeded).
    pub utilisation: f64,
    /// Its peak force (N).
    pub force: f64,
    /// Its allowable force (N).
    pub allowable_force: f64,
}

/// The contact of largest utilisation among those with an allowable force.
pub fn worst(peaks: &[f64], allowables: &[Option<f64>]) -> Option<Utilisation> {
    peaks
        .iter()
        .zip(allowables)
        .enumerate()
        .filter_map(|(contact, (force, allowable))| {
            allowable.map(|allowable_force| Utilisation {
                contact,
                utilisation: super::margins::over(*force, allowable_force),
                force: *force,
                allowable_force,
            })
        })
        .max_by(|a, b| a.utilisation.total_cmp(&b.utilisation))
}

/// Friction at one contact over the run (contacts whose law has friction).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct FrictionReport {
    /// Mean and RMS of |T| over the time closed (N), and its largest value.
    pub mean_tangential_force: f64,
    pub rms_tangential_force: f64,
    pub max_tangential_force: f64,
    /// Distance slid (m): ∫ |v_t| dt while slipping.
    pub slip_distance: f64,
    /// Share of the time closed spent sticking (0–1).
    pub stick_fraction: f64,
    /// Friction's wear power (W): (1/T) ∫ |T| |v_t| dt while slipping, T the duration.
    pub wear_power: f64,
}

impl FrictionReport {
    /// The report of `friction` for a contact closed `contact_time` (s) in a run of
    /// `duration` (s).
    pub fn of(
        friction: &crate::physics::integrate::FrictionStatistics,
        contact_time: f64,
        duration: f64,
    ) -> Self {
        let per_contact_time = |x: f64| if contact_time > 0.0 { x / contact_time } else { 0.0 };
        Self {
            mean_tangential_force: per_contact_time(friction.tangential_impulse),
            rms_tangential_force: per_contact_time(friction.tangential_square).sqrt(),
            max_tangential_force: friction.max_tangential_force,
            slip_distance: friction.slip_distance,
            stick_fraction: per_contact_time(friction.stick_time),
            wear_power: friction.tangential_wear_work / duration,
        }
    }
}
