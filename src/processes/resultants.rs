//! The resultant contact force on each pin at each of its contact heights: the vector
//! sum of the forces of every contact acting on the pin there (normal and friction
//! forces; a wire pushing a neighbour while another wire pushes it back; a pin squeezed
//! between its two neighbours), largest over every step. It is the load a local model of
//! the clad at that height takes; a contact's own `max_force` is one side of it.

use serde::Serialize;
use utoipa::ToSchema;

use crate::physics::integrate::{ResultantPeak, Simulation};

/// The largest resultant contact force on a pin at one contact height.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct ContactResultant {
    /// Contact height (m).
    pub height: f64,
    /// How many of the model's contacts act on the pin at this height.
    pub contacts: usize,
    /// max |Σ F| (N) over every step; 0 when none of them ever closed.
    pub max_force: f64,
    /// When (s): the step's time; 0 when none closed.
    pub time: f64,
}

/// A pin's resultant contact forces.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct PinResultants {
    /// The largest over its contact heights (the lowest height on a tie); null for a pin
    /// no contact acts on.
    pub max_resultant_force: Option<ContactResultant>,
    /// At every height where a contact acts on the pin, from the foot.
    pub resultant_forces: Vec<ContactResultant>,
}

/// The largest resultant contact force of the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct RunResultant {
    /// The pin.
    pub pin: usize,
    #[serde(flatten)]
    pub resultant: ContactResultant,
}

impl ContactResultant {
    fn of(peak: &ResultantPeak) -> Self {
        Self {
            height: peak.height,
            contacts: peak.contacts,
            max_force: peak.force,
            time: peak.time,
        }
    }
}

/// The largest of `resultants` (the first on a tie).
fn largest<'a>(resultants: impl Iterator<Item = &'a ResultantPeak>) -> Option<&'a ResultantPeak> {
    resultants.fold(None, |best: Option<&ResultantPeak>, r| match best {
        Some(b) if b.force >= r.force => Some(b),
        _ => Some(r),
    })
}

impl PinResultants {
    /// Per pin (0..`pins`), its resultants in `run`.
    pub fn by_pin(run: &Simulation, pins: usize) -> Vec<Self> {
        let mut out = vec![
            Self {
                max_resultant_force: None,
                resultant_forces: Vec::new(),
            };
            pins
        ];
        // The run gives them by pin, then height.
        for peak in &run.resultant_forces {
            out[peak.pin].resultant_forces.push(ContactResultant::of(peak));
        }
        for report in &mut out {
            report.max_resultant_force = (report.resultant_forces.iter().copied())
                .reduce(|best, r| if r.max_force > best.max_force { r } else { best });
        }
        out
    }
}

impl RunResultant {
    /// The largest resultant of `run`; null without contacts on pins.
    pub fn of(run: &Simulation) -> Option<Self> {
        largest(run.resultant_forces.iter()).map(|peak| Self {
            pin: peak.pin,
            resultant: ContactResultant::of(peak),
        })
    }
}
