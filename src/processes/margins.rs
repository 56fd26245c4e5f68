//! Margins (docs/margins.md): the optional allowables of `output.allowables` (the force a
//! contact may carry, for every contact or per family of contacts, and the clad's
//! allowable outer-fibre bending stress) and the utilisation ratios they give, peak over
//! allowable, per contact, per pin and for the run. Reporting only: an allowable changes
//! nothing else in a results document, and without one every utilisation is null.
//!
//! A contact's allowable force comes from `output.allowables.contact_force` or from its
//! law's `allowable_force` (docs/contact-laws.md), never from both: a family given both
//! ways is refused at the `output` member.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::FieldError;
use super::bending::Bending;
use super::contact_law::Utilisation;

/// The utilisation bands the dashboard colours by: below [`AMBER`] green, from it to 1
/// amber, from 1 red (the allowable reached or exceeded).
pub const AMBER: f64 = 0.8;

/// A family of contacts: what a contact touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// Between two pins (in the hexagonal bundle, a wire on a neighbour's clad).
    PinPin,
    /// Between a pin and a wall (the wrapper; the cantilever's spring).
    PinWall,
}

impl Family {
    /// The family's member name in `output.allowables.contact_force`.
    pub fn member(self) -> &'static str {
        match self {
            Family::PinPin => "pin_pin",
            Family::PinWall => "pin_wall",
        }
    }
}

/// `output.allowables` of a bundle of pins (`bundle-dynamics`, `hex-bundle-dynamics`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(as = BundleAllowablesInput)]
pub struct AllowablesInput {
    /// The force a contact may carry (N): one force for every contact, or one per family
    /// of contacts (`{"pin_pin": …, "pin_wall": …}`; a family left out has none). Each
    /// contact reports its peak force over it (`utilisation`), each pin the largest of
    /// its contacts', the run the worst (`max_utilisation`). A family whose contact law
    /// already gives `allowable_force` is refused here.
    pub contact_force: Option<ContactForceAllowable>,
    /// The clad's allowable outer-fibre bending stress (Pa, > 0): each pin reports its
    /// largest stress over it (`stress_utilisation`), the run the worst with where and
    /// when (`max_stress_utilisation`). Needs the outer diameter (a tube section; or
    /// `bundle.pin_diameter` in `hex-bundle-dynamics`).
    #[schema(exclusive_minimum = 0.0)]
    pub stress: Option<f64>,
}

/// `output.allowables` of `cantilever-impact`: its one contact, the tip spring.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(as = TipAllowablesInput)]
pub struct TipAllowablesInput {
    /// The force the tip contact may carry (N, > 0): the results report the peak force
    /// over it (`numerical.utilisation`). Refused when `contact.law.allowable_force` is
    /// given.
    #[schema(exclusive_minimum = 0.0)]
    pub contact_force: Option<f64>,
    /// The beam's allowable outer-fibre bending stress (Pa, > 0): the results report the
    /// largest stress over it (`numerical.max_stress_utilisation`). Needs a tube section.
    #[schema(exclusive_minimum = 0.0)]
    pub stress: Option<f64>,
}

// Deserialized by hand rather than as an untagged enum (as `LevelsInput`): an object is
// read as the families, so that an unknown family or a wrong type inside it is reported
// at its own pointer, not as "matches no variant". The `serde` attribute only shapes the
// schema.
/// One force for every contact (N, > 0), or one per family.
#[derive(Debug, Clone, Copy, PartialEq, ToSchema)]
#[serde(untagged)]
pub enum ContactForceAllowable {
    #[schema(value_type = super::input_schema::PositiveNumber)]
    Every(f64),
    Families(FamilyForces),
}

/// The force a contact of each family may carry.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FamilyForces {
    /// Of the contacts between two pins (N, > 0): in the hexagonal bundle a wire on a
    /// neighbour's clad.
    #[schema(exclusive_minimum = 0.0)]
    pub pin_pin: Option<f64>,
    /// Of the contacts between a pin and a wall (N, > 0): the wrapper.
    #[schema(exclusive_minimum = 0.0)]
    pub pin_wall: Option<f64>,
}

impl<'de> Deserialize<'de> for ContactForceAllowable {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Allowable;
        impl<'de> serde::de::Visitor<'de> for Allowable {
            type Value = ContactForceAllowable;

            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a force (N) or {\"pin_pin\": N, \"pin_wall\": N}")
            }

            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<ContactForceAllowable, E> {
                Ok(ContactForceAllowable::Every(v))
            }

            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ContactForceAllowable, E> {
                Ok(ContactForceAllowable::Every(v as f64))
            }

            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<ContactForceAllowable, E> {
                Ok(ContactForceAllowable::Every(v as f64))
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                map: A,
            ) -> Result<ContactForceAllowable, A::Error> {
                FamilyForces::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(ContactForceAllowable::Families)
            }
        }
        deserializer.deserialize_any(Allowable)
    }
}

/// The problem of an allowable that is not a positive finite number, at `pointer`.
fn check_positive(value: Option<f64>, pointer: String, unit: &str, errors: &mut Vec<FieldError>) {
    if let Some(value) = value
        && !(value.is_finite() && value > 0.0)
    {
        errors.push(FieldError::new(
            pointer,
            format!("an allowable must be a finite number > 0 ({unit}), not {value}"),
        ));
    }
}

/// Where a contact's law gives its own `allowable_force`, for [`AllowablesInput::check`].
#[derive(Debug, Clone, Copy)]
pub struct LawAllowable<'a> {
    pub family: Family,
    /// The law's pointer (`/inputs/bundle/wall_law`, `/inputs/contacts/3/law`).
    pub pointer: &'a str,
}

impl AllowablesInput {
    /// The allowable force of a contact of `family` given here (N), if any.
    pub fn force_of(&self, family: Family) -> Option<f64> {
        match self.contact_force? {
            ContactForceAllowable::Every(force) => Some(force),
            ContactForceAllowable::Families(families) => match family {
                Family::PinPin => families.pin_pin,
                Family::PinWall => families.pin_wall,
            },
        }
    }

    /// The problems of `output.allowables` (at `pointer`): every allowable a finite
    /// number > 0; a stress allowable only where the outer fibre is known (`fibre`); no
    /// family given here whose contacts' laws (`laws`) give `allowable_force` too.
    pub fn check(&self, pointer: &str, fibre: bool, laws: &[LawAllowable<'_>], errors: &mut Vec<FieldError>) {
        let force_pointer = format!("{pointer}/contact_force");
        match self.contact_force {
            Some(ContactForceAllowable::Every(force)) => {
                check_positive(Some(force), force_pointer.clone(), "N", errors)
            }
            Some(ContactForceAllowable::Families(families)) => {
                for (family, force) in [
                    (Family::PinPin, families.pin_pin),
                    (Family::PinWall, families.pin_wall),
                ] {
                    check_positive(force, format!("{force_pointer}/{}", family.member()), "N", errors);
                }
            }
            None => {}
        }
        check_positive(self.stress, format!("{pointer}/stress"), "Pa", errors);
        if self.stress.is_some() && !fibre {
            errors.push(FieldError::new(
                format!("{pointer}/stress"),
                "the section is `explicit` without a diameter, so the clad's stress is unknown: give a \
                 `tube` section (or, in hex-bundle-dynamics, `bundle.pin_diameter`)",
            ));
        }
        for family in [Family::PinPin, Family::PinWall] {
            if self.force_of(family).is_none() {
                continue;
            }
            if let Some(law) = laws.iter().find(|law| law.family == family) {
                let at = match self.contact_force {
                    Some(ContactForceAllowable::Families(_)) => {
                        format!("{force_pointer}/{}", family.member())
                    }
                    _ => force_pointer.clone(),
                };
                errors.push(FieldError::new(
                    at,
                    format!(
                        "the {} contacts' law already gives `allowable_force` ({}/allowable_force): give \
                         their allowable in one place",
                        family.member(),
                        law.pointer
                    ),
                ));
            }
        }
    }
}

impl TipAllowablesInput {
    /// The problems of the cantilever's `output.allowables` (at `pointer`), as
    /// [`AllowablesInput::check`]; `law` the law's pointer when it gives `allowable_force`.
    pub fn check(&self, pointer: &str, fibre: bool, law: Option<&str>, errors: &mut Vec<FieldError>) {
        let bundle = AllowablesInput {
            contact_force: self.contact_force.map(ContactForceAllowable::Every),
            stress: self.stress,
        };
        let laws: Vec<LawAllowable<'_>> = law
            .map(|pointer| LawAllowable {
                family: Family::PinWall,
                pointer,
            })
            .into_iter()
            .collect();
        bundle.check(pointer, fibre, &laws, errors);
    }
}

/// A peak over its allowable, when there is one (dimensionless; ≥ 1: reached). Held
/// finite: an allowable so small that the ratio overflows gives the largest number, not
/// an infinity (which JSON cannot carry).
pub fn ratio(peak: f64, allowable: Option<f64>) -> Option<f64> {
    allowable.map(|allowable| over(peak, allowable))
}

/// [`ratio`] with an allowable given.
pub fn over(peak: f64, allowable: f64) -> f64 {
    (peak / allowable).min(f64::MAX)
}

/// The largest bending stress of a pin, or of the run, over the allowable stress.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct StressUtilisation {
    /// The pin.
    pub pin: usize,
    /// Height from the foot (m).
    pub height: f64,
    /// When (s): an output sample.
    pub time: f64,
    /// The outer-fibre bending stress there (Pa).
    pub stress: f64,
    /// The allowable stress (Pa).
    pub allowable_stress: f64,
    /// `stress` over `allowable_stress` (dimensionless; ≥ 1: reached).
    pub utilisation: f64,
}

impl StressUtilisation {
    /// The stress utilisation of `bending` against `allowable` (Pa), when both are known.
    pub fn of(bending: &Bending, allowable: Option<f64>) -> Option<Self> {
        let (stress, allowable_stress) = (bending.stress?, allowable?);
        Some(Self {
            pin: bending.pin,
            height: bending.height,
            time: bending.time,
            stress,
            allowable_stress,
            utilisation: over(stress, allowable_stress),
        })
    }
}

/// A pin's utilisations; each null without its allowable.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, ToSchema)]
pub struct PinUtilisation {
    /// The pin's largest bending stress over the allowable stress (dimensionless):
    /// `bending.stress` / `output.allowables.stress`.
    pub stress_utilisation: Option<f64>,
    /// The largest `utilisation` of the contacts the pin takes part in (dimensionless);
    /// null when none of them has an allowable force.
    pub contact_utilisation: Option<f64>,
    /// The larger of the two: the pin's governing utilisation (dimensionless).
    pub utilisation: Option<f64>,
}

impl PinUtilisation {
    /// Of a pin whose bending is `bending`, against the allowable stress `stress` (Pa),
    /// with the utilisations of its contacts.
    pub fn of(
        bending: &Bending,
        stress: Option<f64>,
        contacts: impl IntoIterator<Item = Option<f64>>,
    ) -> Self {
        let stress_utilisation = bending.stress.and_then(|s| ratio(s, stress));
        let contact_utilisation = largest(contacts);
        Self {
            stress_utilisation,
            contact_utilisation,
            utilisation: largest([stress_utilisation, contact_utilisation]),
        }
    }
}

/// The largest of the values given (`None` when none is).
pub fn largest(values: impl IntoIterator<Item = Option<f64>>) -> Option<f64> {
    values.into_iter().flatten().max_by(f64::total_cmp)
}

/// The run's margins: its worst contact, its worst stress, and the worse of the two.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, ToSchema)]
pub struct RunMargins {
    /// The contact of largest utilisation (peak force over allowable force); null when
    /// no contact has an allowable force.
    pub max_utilisation: Option<Utilisation>,
    /// The largest bending stress of the run over the allowable stress, where and when;
    /// null without `output.allowables.stress`.
    pub max_stress_utilisation: Option<StressUtilisation>,
    /// The run's worst utilisation, contact force or stress (dimensionless; ≥ 1: an
    /// allowable reached); null without allowables.
    pub worst_utilisation: Option<f64>,
}

impl RunMargins {
    /// Of a run whose worst contact is `contact` and largest bending `bending`, against
    /// the allowable stress `stress` (Pa).
    pub fn of(contact: Option<Utilisation>, bending: &Bending, stress: Option<f64>) -> Self {
        let max_stress_utilisation = StressUtilisation::of(bending, stress);
        Self {
            max_utilisation: contact,
            max_stress_utilisation,
            worst_utilisation: largest([
                contact.map(|c| c.utilisation),
                max_stress_utilisation.map(|s| s.utilisation),
            ]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bending(stress: Option<f64>) -> Bending {
        Bending {
            height: 0.0,
            pin: 3,
            time: 0.01,
            moment: 2.0,
            stress,
            strain: stress.map(|s| s / 2e11),
        }
    }

    #[test]
    fn a_ratio_is_the_peak_over_the_allowable_and_stays_finite() {
        assert_eq!(ratio(3.0, Some(4.0)), Some(0.75));
        assert_eq!(ratio(3.0, None), None);
        assert_eq!(ratio(1e10, Some(1e-300)), Some(f64::MAX));
    }

    #[test]
    fn a_pin_is_governed_by_the_larger_of_its_stress_and_its_contacts() {
        let pin = PinUtilisation::of(&bending(Some(150e6)), Some(300e6), [Some(0.2), None, Some(0.7)]);
        assert_eq!(pin.stress_utilisation, Some(0.5));
        assert_eq!(pin.contact_utilisation, Some(0.7));
        assert_eq!(pin.utilisation, Some(0.7));
        let bare = PinUtilisation::of(&bending(Some(150e6)), None, [None, None]);
        assert_eq!(bare, PinUtilisation::default());
        let no_fibre = PinUtilisation::of(&bending(None), Some(300e6), [Some(1.5)]);
        assert_eq!(
            (no_fibre.stress_utilisation, no_fibre.utilisation),
            (None, Some(1.5))
        );
    }

    #[test]
    fn the_run_reports_its_worst_utilisation_and_where() {
        let contact = Utilisation {
            contact: 4,
            utilisation: 0.9,
            force: 90.0,
            allowable_force: 100.0,
        };
        let run = RunMargins::of(Some(contact), &bending(Some(240e6)), Some(200e6));
        let stress = run.max_stress_utilisation.unwrap();
        assert_eq!((stress.pin, stress.utilisation), (3, 1.2));
        assert_eq!(run.worst_utilisation, Some(1.2));
        assert_eq!(
            RunMargins::of(None, &bending(Some(1.0)), None),
            RunMargins::default()
        );
    }

    #[test]
    fn allowables_are_refused_at_their_pointer_when_not_positive_or_given_twice() {
        let allowables = AllowablesInput {
            contact_force: Some(ContactForceAllowable::Families(FamilyForces {
                pin_pin: Some(0.0),
                pin_wall: Some(10.0),
            })),
            stress: Some(-1.0),
        };
        let mut errors = Vec::new();
        let laws = [LawAllowable {
            family: Family::PinWall,
            pointer: "/inputs/bundle/wall_law",
        }];
        allowables.check("/inputs/output/allowables", false, &laws, &mut errors);
        let pointers: Vec<&str> = errors.iter().map(|e| e.pointer.as_str()).collect();
        assert_eq!(
            pointers,
            [
                "/inputs/output/allowables/contact_force/pin_pin",
                "/inputs/output/allowables/stress",
                "/inputs/output/allowables/stress",
                "/inputs/output/allowables/contact_force/pin_wall",
            ],
            "{errors:?}"
        );
        assert!(
            errors[3]
                .detail
                .contains("/inputs/bundle/wall_law/allowable_force"),
            "{errors:?}"
        );
        let mut none = Vec::new();
        AllowablesInput::default().check("/inputs/output/allowables", false, &laws, &mut none);
        assert!(none.is_empty(), "{none:?}");
    }
}
