//! Point forces and tip releases of `hex-bundle-dynamics`: their inputs (per pin, in the
//! transverse plane), their checks at the pointers the user wrote, and the loads the
//! integrator takes, one per deflection line (pin p along x is line p, along y line
//! pins + p: `physics::integrate::Model::lines`).
//!
//! A force along θ (degrees, counter-clockwise from +x, as the base acceleration's
//! `direction`) is two line forces, cos θ·F on the x line and sin θ·F on the y line; a
//! component whose factor is exactly 0 is left out. The factors are exact at multiples
//! of 90° (0 and ±1, not cos 90° = 6e-17), so a force along an axis loads that axis
//! alone, bit for bit as the row's force along x.

use std::collections::BTreeMap;

use serde::Deserialize;
use utoipa::ToSchema;

use super::inputs::HexInputs;
use crate::physics::hex::{MAX_RINGS, pin_count};
use crate::physics::loads::{PointForce, Table};
use crate::processes::FieldError;
use crate::processes::common_inputs::at;
use crate::processes::input_schema::NonNegativeNumber;
use crate::processes::model_check::StandIn;

/// The state at t = 0.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexInitialInput {
    /// Pins released, at rest, from their static tip-load shape with these tip
    /// deflections; each pin at most once, the pins not listed at rest and straight. A
    /// release needs a free top.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub tip_displacements: Vec<TipReleaseInput>,
    /// Pins moving at t = 0 in their static tip-load shape with these tip velocities
    /// (thrown, or cut loose from a support moving at that speed); each pin at most once,
    /// the pins not listed at rest. Combines with `tip_displacements`. Needs a free top.
    #[serde(default)]
    #[schema(default = json!([]))]
    pub tip_velocities: Vec<TipVelocityInput>,
}

/// One pin's initial velocity: its tip velocity (x, y) at t = 0.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TipVelocityInput {
    /// The moving pin (0 … pins − 1, numbered from the centre, ring by ring).
    pub pin: usize,
    /// Tip velocity along +x (m/s).
    pub x: f64,
    /// Tip velocity along +y (m/s).
    pub y: f64,
}

/// One pin's release: its tip deflection (x, y) at t = 0.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct TipReleaseInput {
    /// The released pin (0 … pins − 1, numbered from the centre, ring by ring).
    pub pin: usize,
    /// Tip deflection along +x (m).
    pub x: f64,
    /// Tip deflection along +y (m).
    pub y: f64,
}

/// A force history at a height of one pin, along a direction of the transverse plane.
#[derive(Debug, Clone, PartialEq, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct HexPointForceInput {
    /// The loaded pin (0 … pins − 1, numbered from the centre, ring by ring).
    pub pin: usize,
    /// Height from the foot (m), at most the pin length.
    #[schema(minimum = 0.0)]
    pub height: f64,
    /// Direction of the force (degrees, counter-clockwise from +x, as the base
    /// acceleration's `direction`); 0 (along +x) when left out.
    #[serde(default)]
    #[schema(default = 0.0)]
    pub direction: f64,
    /// Sample times (s), at least two, ≥ 0 and strictly increasing.
    #[schema(value_type = Vec<NonNegativeNumber>)]
    pub time: Vec<f64>,
    /// Force along `direction` at those times (N), linear between them, 0 after the last.
    pub force: Vec<f64>,
}

/// The point loads of a bundle as the integrator takes them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PlaneLoads {
    /// One tip deflection (m) per line, the x lines then the y lines; empty when no pin
    /// is released.
    pub initial_tip_displacements: Vec<f64>,
    /// One tip velocity (m/s) per line, likewise; empty when no pin moves at t = 0.
    pub initial_tip_velocities: Vec<f64>,
    /// One or two per point force of the inputs (its x and y components).
    pub point_forces: Vec<PointForce>,
}

/// (cos θ, sin θ) of θ in degrees, exactly (0, ±1) at the multiples of 90°: θ is
/// reduced to [0°, 360°) first (exactly: a floating-point remainder is exact).
pub fn direction_factors(degrees: f64) -> (f64, f64) {
    let reduced = degrees.rem_euclid(360.0);
    if reduced == 0.0 || reduced == 360.0 {
        (1.0, 0.0)
    } else if reduced == 90.0 {
        (0.0, 1.0)
    } else if reduced == 180.0 {
        (-1.0, 0.0)
    } else if reduced == 270.0 {
        (0.0, -1.0)
    } else {
        let radians = reduced.to_radians();
        (radians.cos(), radians.sin())
    }
}

/// The releases and point forces of `inputs` per line, every problem added to `errors`
/// at its pointer: a pin outside the bundle (not checked when the ring count is itself
/// refused), a pin released twice, a release that is not finite or whose pin has no free
/// top, a height outside the pin, a direction that is not finite, a bad force table.
pub fn plane_loads(inputs: &HexInputs, errors: &mut Vec<FieldError>) -> PlaneLoads {
    let rings = inputs.bundle.rings;
    let pins = (1..=MAX_RINGS).contains(&rings).then(|| pin_count(rings));
    PlaneLoads {
        initial_tip_displacements: releases(inputs, pins, Initial::Displacements, errors),
        initial_tip_velocities: releases(inputs, pins, Initial::Velocities, errors),
        point_forces: point_forces(inputs, pins, errors),
    }
}

/// `Some(pin)` when `pin` is in the bundle, else the error at `pointer` (`None` without
/// an error when the pin count is unknown).
fn existing_pin(
    pin: usize,
    pins: Option<usize>,
    pointer: &str,
    errors: &mut Vec<FieldError>,
) -> Option<usize> {
    let pins = pins?;
    if pin < pins {
        return Some(pin);
    }
    errors.push(FieldError::new(
        pointer,
        format!(
            "pin {pin} does not exist: the bundle has {pins} pins (0 to {})",
            pins - 1
        ),
    ));
    None
}

/// Which list of `initial` a release is in.
#[derive(Debug, Clone, Copy)]
enum Initial {
    Displacements,
    Velocities,
}

impl Initial {
    /// (member, unit, what it is, what a pin listed is, in messages).
    fn names(self) -> (&'static str, &'static str, &'static str, &'static str) {
        match self {
            Initial::Displacements => ("tip_displacements", "m", "a tip release", "released"),
            Initial::Velocities => (
                "tip_velocities",
                "m/s",
                "an initial tip velocity",
                "given a velocity",
            ),
        }
    }

    /// Its entries as (pin, x, y).
    fn entries(self, inputs: &HexInputs) -> Vec<(usize, f64, f64)> {
        match self {
            Initial::Displacements => (inputs.initial.tip_displacements.iter())
                .map(|r| (r.pin, r.x, r.y))
                .collect(),
            Initial::Velocities => (inputs.initial.tip_velocities.iter())
                .map(|r| (r.pin, r.x, r.y))
                .collect(),
        }
    }
}

/// One value per line of the `initial` list `which` (empty without entries).
fn releases(
    inputs: &HexInputs,
    pins: Option<usize>,
    which: Initial,
    errors: &mut Vec<FieldError>,
) -> Vec<f64> {
    let list = which.entries(inputs);
    let (member, unit, what, listed) = which.names();
    let pointer = format!("/inputs/initial/{member}");
    let mut tips = match (pins, list.is_empty()) {
        (Some(pins), false) => vec![0.0; 2 * pins],
        _ => Vec::new(),
    };
    let mut released: BTreeMap<usize, usize> = BTreeMap::new();
    for (i, &(pin, x, y)) in list.iter().enumerate() {
        let at = format!("{pointer}/{i}");
        let mut finite = true;
        for (axis, value) in [("x", x), ("y", y)] {
            if !value.is_finite() {
                errors.push(FieldError::new(
                    format!("{at}/{axis}"),
                    format!("must be a finite number ({unit})"),
                ));
                finite = false;
            }
        }
        if let Some(first) = released.insert(pin, i) {
            errors.push(FieldError::new(
                format!("{at}/pin"),
                format!("pin {pin} is {listed} twice (also by {member}/{first}): each pin at most once"),
            ));
            continue;
        }
        if let (Some(pin), Some(pins), true) = (
            existing_pin(pin, pins, &format!("{at}/pin"), errors),
            pins,
            finite,
        ) {
            tips[pin] = x;
            tips[pins + pin] = y;
        }
    }
    let moved = list.iter().any(|&(_, x, y)| x != 0.0 || y != 0.0);
    if moved && StandIn::of(&inputs.pin).basis.unit_tip_release().is_none() {
        errors.push(FieldError::new(
            pointer,
            format!(
                "{what} needs a free top: the pins' top is {} (no tip-load shape to move in)",
                inputs.pin.supports.top.name()
            ),
        ));
    }
    tips
}

fn point_forces(inputs: &HexInputs, pins: Option<usize>, errors: &mut Vec<FieldError>) -> Vec<PointForce> {
    let length = inputs.pin.length;
    let mut forces = Vec::new();
    for (k, input) in inputs.excitation.point_forces.iter().enumerate() {
        let at_force = format!("/inputs/excitation/point_forces/{k}");
        let pin = existing_pin(input.pin, pins, &format!("{at_force}/pin"), errors);
        // An invalid length is refused at the pin: heights cannot be judged against it.
        let length_known = length.is_finite() && length > 0.0;
        if length_known && !(input.height.is_finite() && (0.0..=length).contains(&input.height)) {
            errors.push(FieldError::new(
                format!("{at_force}/height"),
                format!("must be within the pin, 0 to {length} m (got {})", input.height),
            ));
        }
        let direction_finite = input.direction.is_finite();
        if !direction_finite {
            errors.push(FieldError::new(
                format!("{at_force}/direction"),
                "must be a finite angle in degrees",
            ));
        }
        let table = Table {
            time: input.time.clone(),
            values: input.force.clone(),
        };
        errors.extend(at(&at_force, table.validate("force")));
        let (Some(pin), Some(pins), true) = (pin, pins, direction_finite) else {
            continue;
        };
        let (cos, sin) = direction_factors(input.direction);
        for (line, factor) in [(pin, cos), (pins + pin, sin)] {
            if factor != 0.0 {
                forces.push(PointForce {
                    line,
                    height: input.height,
                    force: Table {
                        time: table.time.clone(),
                        values: table.values.iter().map(|f| factor * f).collect(),
                    },
                });
            }
        }
    }
    forces
}

#[cfg(test)]
mod tests;
