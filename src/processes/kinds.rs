//! `kinds`: pins of other kinds than the process's `pin` in one model (a guide tube in a
//! row of fuel rods, a stiffer tube), each with its own section, material, added mass
//! and damping, on the pin's length, supports, mesh, modes and static correction
//! (docs/kinds.md). The physics runs them on the pin's mode shapes, each kind with its
//! own frequencies and modal mass ([`crate::physics::integrate::BodyKind`]).

use serde::Deserialize;
use utoipa::ToSchema;

use super::FieldError;
use super::bending::{Flexure, Flexures};
use super::common_inputs::{BeamInput, DampingInput, SectionInput, StaticCorrectionInput};
use crate::physics::InputIssue;
use crate::physics::discretisation::auto;
use crate::physics::integrate::{BodyKind, pin_kinds_of, relative_mass};
use crate::physics::modal::ModalBasis;

/// Pins of another kind than `pin`: the pin's beam (length, supports, mesh, modes,
/// static correction, beam theory) with this section, material, added mass and
/// damping.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct KindInput {
    /// The kind's name, given with each of its pins in the results (e.g. `guide_tube`);
    /// one name per kind, not `pin`.
    pub name: String,
    /// The pins of this kind (numbers from 0); a pin is of one kind at most, and every
    /// pin of no kind is `pin`.
    #[schema(min_items = 1)]
    pub pins: Vec<usize>,
    /// Young's modulus E (Pa).
    #[schema(minimum = 1.0, maximum = 1e15)]
    pub young_modulus: f64,
    /// Density ρ of the material (kg/m³).
    #[schema(minimum = 1e-3, maximum = 1e9)]
    pub density: f64,
    /// Cross-section: a circular tube, or its area and second moment of area.
    pub section: SectionInput,
    /// Added mass per unit length (kg/m).
    #[serde(default)]
    #[schema(default = 0.0, minimum = 0.0, maximum = 1e9)]
    pub added_mass_per_length: f64,
    /// Modal damping ratio ξ (dimensionless, in [0, 1)), as `pin.damping_ratio`;
    /// absent: the pin's.
    #[serde(default)]
    pub damping_ratio: Option<DampingInput>,
}

impl KindInput {
    /// The pin's beam with this kind's section, material, mass and damping.
    pub fn beam(&self, pin: &BeamInput) -> BeamInput {
        BeamInput {
            young_modulus: self.young_modulus,
            density: self.density,
            section: self.section,
            added_mass_per_length: self.added_mass_per_length,
            damping_ratio: self
                .damping_ratio
                .clone()
                .unwrap_or_else(|| pin.damping_ratio.clone()),
            ..pin.clone()
        }
    }
}

/// Every problem with `kinds` of pins of `pin`, at `pointer` (`/inputs/kinds`): the
/// kind's own members (the pin's are refused at the pin), names that are distinct and
/// not `pin`. Which pins exist is the model's check ([`pointer`]).
pub fn check(kinds: &[KindInput], pin: &BeamInput, pointer: &str, errors: &mut Vec<FieldError>) {
    let own = |field: &str| {
        [
            "young_modulus",
            "density",
            "section",
            "added_mass_per_length",
            "damping_ratio",
        ]
        .iter()
        .any(|member| field == *member || field.starts_with(&format!("{member}/")))
    };
    for (k, kind) in kinds.iter().enumerate() {
        let at = format!("{pointer}/{k}");
        let issues: Vec<InputIssue> = kind
            .beam(pin)
            .validate()
            .into_iter()
            .filter(|issue| own(&issue.field))
            .filter(|issue| kind.damping_ratio.is_some() || !issue.field.starts_with("damping_ratio"))
            .collect();
        errors.extend(super::common_inputs::at(&at, issues));
        let name = kind.name.trim();
        if name.is_empty() || name == "pin" {
            errors.push(FieldError::new(
                format!("{at}/name"),
                "must name the kind (not empty, not `pin`: the pins of no kind)",
            ));
        } else if kinds[..k].iter().any(|other| other.name.trim() == name) {
            errors.push(FieldError::new(
                format!("{at}/name"),
                format!("`{name}` names an earlier kind too: one name per kind"),
            ));
        }
        if kind.pins.is_empty() {
            errors.push(FieldError::new(
                format!("{at}/pins"),
                "must list at least one pin",
            ));
        }
    }
}

/// Each kind's modal basis: its beam on the mesh of `basis` (the pin's, as chosen), with
/// as many eigenmodes and the same static correction at `correction_heights`; refused
/// at the kind when its modes are not the pin's scaled (its shapes differ: a Timoshenko
/// beam whose shear or rotary inertia is in another proportion).
pub fn bases(
    kinds: &[KindInput],
    pin: &BeamInput,
    basis: &ModalBasis,
    correction_heights: &[f64],
    pointer: &str,
) -> Result<Vec<ModalBasis>, Vec<FieldError>> {
    let correction = pin.static_correction == StaticCorrectionInput::Contacts;
    let mut errors = Vec::new();
    let mut bases = Vec::new();
    for (k, kind) in kinds.iter().enumerate() {
        let spec = crate::physics::beam::BeamSpec {
            elements: basis.model().elements,
            ..kind.beam(pin).spec()
        };
        let built = auto::basis_of(
            &spec,
            basis.eigenmodes(),
            correction.then_some(correction_heights),
        )
        .map_err(|e| e.to_string())
        .and_then(|own| relative_mass(basis, &own).map(|_| own));
        match built {
            Ok(own) => bases.push(own),
            Err(reason) => errors.push(FieldError::new(
                format!("{pointer}/{k}"),
                format!("the kind's beam {reason}"),
            )),
        }
    }
    if errors.is_empty() { Ok(bases) } else { Err(errors) }
}

/// The kinds as the physics takes them, on `bases` ([`bases`]; the pin's basis when
/// absent, so that the model's checks run before the bases are built), with
/// `diameter` the outer diameter of every pin where an explicit section does not give
/// it (a hexagonal bundle's D, which its kinds keep).
pub fn body_kinds<'a>(
    kinds: &[KindInput],
    pin: &BeamInput,
    bases: Option<&'a [ModalBasis]>,
    fallback: &'a ModalBasis,
    diameter: Option<f64>,
) -> Vec<BodyKind<'a>> {
    let reference = Flexure::of(pin, diameter);
    kinds
        .iter()
        .enumerate()
        .map(|(k, kind)| {
            let basis = bases.and_then(|b| b.get(k)).unwrap_or(fallback);
            let beam = kind.beam(pin);
            let own = Flexure::of(&beam, diameter);
            BodyKind {
                basis,
                damping_ratios: beam.damping_ratios_for(basis.modes()),
                pins: kind.pins.clone(),
                envelope_weight: stress_weight(&own, &reference),
            }
        })
        .collect()
}

/// A kind's stress per unit curvature E c against the pin's; its moment EI against the
/// pin's where either's outer fibre is unknown (an explicit section).
fn stress_weight(kind: &Flexure, pin: &Flexure) -> f64 {
    match (kind.fibre, pin.fibre) {
        (Some(c), Some(c_pin)) => kind.young_modulus * c / (pin.young_modulus * c_pin),
        _ => kind.bending_stiffness / pin.bending_stiffness,
    }
}

/// The flexure of every pin of a model of `pins` pins with `kinds` (`diameter` as in
/// [`body_kinds`]).
pub fn flexures(kinds: &[KindInput], pin: &BeamInput, pins: usize, diameter: Option<f64>) -> Flexures {
    if kinds.is_empty() {
        return Flexures::uniform(Flexure::of(pin, diameter));
    }
    Flexures::by_kind(
        std::iter::once(Flexure::of(pin, diameter))
            .chain(kinds.iter().map(|kind| Flexure::of(&kind.beam(pin), diameter)))
            .collect(),
        pin_kinds(kinds, pins),
    )
}

/// The kind of each of `pins` pins: 0 for `pin`, k + 1 for `kinds[k]`.
pub fn pin_kinds(kinds: &[KindInput], pins: usize) -> Vec<usize> {
    pin_kinds_of(kinds.iter().map(|k| &k.pins[..]), pins)
}

/// The name of pin `p`'s kind: `None` for `pin`.
pub fn name_of(kinds: &[KindInput], p: usize) -> Option<String> {
    kinds
        .iter()
        .find(|k| k.pins.contains(&p))
        .map(|k| k.name.trim().to_owned())
}

/// Where the user wrote what the model's path `kinds/<k>/…` names, under `pointer`
/// (`/inputs/kinds`): the kind's pins and damping as given, its basis at the kind; `None`
/// for the weight derived from its section.
pub fn pointer(pointer: &str, k: usize, rest: &str) -> Option<String> {
    let at = format!("{pointer}/{k}");
    Some(match rest {
        "" | "basis" => at,
        "envelope_weight" => return None,
        rest if rest.starts_with("damping_ratios") => format!("{at}/damping_ratio"),
        rest => format!("{at}/{rest}"),
    })
}
