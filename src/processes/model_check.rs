//! The physics' own checks of what a process will integrate ([`Model::validate`],
//! [`Settings::validate`]), run with the inputs' other checks and reported at the
//! pointers the user wrote, so that a process checks its model once, in physics, and
//! every problem of a request still comes in one 422.
//!
//! The checks need a [`ModalBasis`], which a process can compute only from a valid pin
//! and, with a static correction, valid contact heights. Of a basis they read its
//! length, its mode count and whether its top is free to be released from; so they run
//! on a [`StandIn`] with the pin's length and top support, before and whatever else is
//! wrong with the pin. The real model is checked once more when its step is resolved
//! ([`super::common_inputs::resolve_step`]).

use super::FieldError;
use super::common_inputs::{BeamInput, DampingInput};
use crate::physics::InputIssue;
use crate::physics::beam::{BeamSpec, Section, Support};
use crate::physics::integrate::{Model, Settings};
use crate::physics::modal::ModalBasis;

/// A two-element beam of unit material and section, clamped at its foot, with the pin's
/// length and top support and one mode: the same length and tip release as the pin's
/// own basis, at no cost.
#[derive(Debug)]
pub struct StandIn {
    pub basis: ModalBasis,
    /// Whether the stand-in has the pin's length. It has not when that length is not a
    /// positive finite number, or one so far from a metre that the element matrices
    /// overflow (the pin's own basis fails then too): the stand-in is then 1 m long and
    /// issues about heights within the pin are left out, the length being the problem.
    pub length_known: bool,
}

impl StandIn {
    pub fn of(pin: &BeamInput) -> Self {
        let top: Support = pin.supports.top.into();
        let basis = |length: f64| {
            let spec = BeamSpec {
                length,
                young_modulus: 1.0,
                density: 1.0,
                section: Section::Explicit {
                    area: 1.0,
                    inertia: 1.0,
                },
                added_mass_per_length: 0.0,
                elements: 2,
                foot: Support::Clamped,
                top,
                shear: None,
            };
            ModalBasis::compute(&spec, 1)
        };
        let given = (pin.length.is_finite() && pin.length > 0.0)
            .then(|| basis(pin.length).ok())
            .flatten();
        match given {
            Some(basis) => Self {
                basis,
                length_known: true,
            },
            None => Self {
                basis: basis(1.0).expect("a clamped two-element beam of unit properties has a mode"),
                length_known: false,
            },
        }
    }
}

/// Adds the problems of `model` and `settings` to `errors`, each at the pointer
/// `pointer_of` gives its path (`contacts/3/right`, `output_heights/1`); `None` means
/// the issue only restates one reported at its cause (a derived value of an invalid
/// input) and is left out. A pointer already in `errors` is not repeated: the inputs'
/// own check of a field speaks first.
pub fn check(
    stand_in: &StandIn,
    model: &Model<'_>,
    settings: &Settings,
    pointer_of: impl Fn(&str) -> Option<String>,
    errors: &mut Vec<FieldError>,
) {
    let issues = model
        .validate()
        .into_iter()
        .chain(settings.validate(stand_in.basis.length(), model.contacts.len()));
    for InputIssue { field, reason } in issues {
        let about_a_height = field.ends_with("/height") || field.starts_with("output_heights");
        if about_a_height && !stand_in.length_known {
            continue;
        }
        let Some(pointer) = pointer_of(&field) else {
            continue;
        };
        if errors.iter().all(|e| e.pointer != pointer) {
            errors.push(FieldError::new(pointer, reason));
        }
    }
}

/// The pointer of a solver or output setting of [`Settings::validate`] (`time_step`,
/// `scheme/phi`, `output_interval`, …); `output_heights` is the caller's.
pub fn settings_pointer(path: &str) -> Option<String> {
    let pointer = match path {
        "scheme/phi" => "/inputs/solver/phi",
        "time_step" => "/inputs/solver/time_step",
        "tolerance" => "/inputs/solver/tolerance",
        "duration" => "/inputs/solver/duration",
        "output_interval" => "/inputs/output/interval",
        _ => return super::impact_report::settings_pointer(path).map(str::to_owned),
    };
    Some(pointer.to_owned())
}

/// The pointer of the ratio of mode `mode` (all modes when `None`) in the pin's
/// `damping_ratio` at `pin_pointer`: a number for every mode, or a list whose last value
/// repeats.
pub fn damping_ratio_pointer(pin: &BeamInput, pin_pointer: &str, mode: Option<usize>) -> String {
    match (&pin.damping_ratio, mode) {
        (DampingInput::PerMode(list), Some(mode)) if !list.is_empty() => {
            format!("{pin_pointer}/damping_ratio/{}", mode.min(list.len() - 1))
        }
        _ => format!("{pin_pointer}/damping_ratio"),
    }
}

/// A path's first segment, its index (when the second segment is one) and the rest:
/// `contacts/3/right` → (`contacts`, Some(3), `right`).
pub fn split(path: &str) -> (&str, Option<usize>, &str) {
    let (head, tail) = path.split_once('/').unwrap_or((path, ""));
    let (index, rest) = tail.split_once('/').unwrap_or((tail, ""));
    match index.parse() {
        Ok(index) => (head, Some(index), rest),
        Err(_) => (head, None, tail),
    }
}

/// `prefix/rest`, or `prefix` alone when `rest` is empty.
pub fn join(prefix: &str, rest: &str) -> String {
    if rest.is_empty() {
        prefix.to_owned()
    } else {
        format!("{prefix}/{rest}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::integrate::DEFAULT_TOLERANCE;
    use crate::processes::common_inputs::{SupportInput, SupportsInput};

    fn pin(foot: SupportInput, top: SupportInput) -> BeamInput {
        serde_json::from_value(serde_json::json!({
            "length": 1.8, "young_modulus": 2.1e11, "density": 7800.0,
            "section": {"type": "tube", "outer_diameter": 0.0097, "inner_diameter": 0.0085},
            "elements": 12, "modes": 6,
            "supports": {"foot": foot.name(), "top": top.name()},
        }))
        .expect("a valid pin")
    }

    /// What the checks read of a basis is the same on the stand-in as on the pin's own
    /// basis, for every support pair that holds a beam: its length and whether it has a
    /// tip-load shape to release from.
    #[test]
    fn the_stand_in_has_the_length_and_tip_release_of_the_real_basis() {
        use SupportInput::{Clamped, Free, Pinned};
        for (foot, top) in [
            (Clamped, Free),
            (Clamped, Pinned),
            (Clamped, Clamped),
            (Pinned, Pinned),
            (Pinned, Clamped),
            (Free, Clamped),
        ] {
            let pin = pin(foot, top);
            assert_eq!(pin.supports, SupportsInput { foot, top });
            let (real, _) = pin
                .basis(&[], &[], DEFAULT_TOLERANCE, 0, "/inputs/pin")
                .expect("a valid pin has a basis");
            let stand_in = StandIn::of(&pin);
            assert!(stand_in.length_known);
            assert_eq!(stand_in.basis.length(), real.length(), "{foot:?}-{top:?}");
            assert_eq!(
                stand_in.basis.unit_tip_release().is_some(),
                real.unit_tip_release().is_some(),
                "tip release of a {foot:?}-{top:?} pin"
            );
        }
    }

    /// A length that is no number of metres, or that overflows the element matrices,
    /// gives a 1 m stand-in that says so, never a panic.
    #[test]
    fn an_unusable_length_leaves_the_heights_unchecked() {
        for length in [f64::INFINITY, f64::NAN, -1.0, 0.0, 1e300, 1e-300] {
            let mut pin = pin(SupportInput::Clamped, SupportInput::Free);
            pin.length = length;
            let stand_in = StandIn::of(&pin);
            if stand_in.length_known {
                assert_eq!(stand_in.basis.length(), length);
            } else {
                assert_eq!(stand_in.basis.length(), 1.0, "length {length}");
            }
            assert!(
                length.is_finite() && length > 0.0 || !stand_in.length_known,
                "length {length}"
            );
        }
    }

    #[test]
    fn paths_split_into_list_index_and_rest() {
        assert_eq!(split("contacts/3/right"), ("contacts", Some(3), "right"));
        assert_eq!(
            split("initial_tip_displacements/2"),
            ("initial_tip_displacements", Some(2), "")
        );
        assert_eq!(
            split("initial_tip_displacements"),
            ("initial_tip_displacements", None, "")
        );
        assert_eq!(
            split("base_acceleration/time/1"),
            ("base_acceleration", None, "time/1")
        );
        assert_eq!(split("scheme/phi"), ("scheme", None, "phi"));
    }
}
