//! The resultant of the contact forces on each pin at each contact height, tracked at
//! every step: where two contacts act on one pin at one height (a wire pushing a
//! neighbour while another wire pushes it back, a pin squeezed between its two
//! neighbours in the row, friction beside the normal force), the clad carries their
//! vector sum, which neither contact's own peak gives.
//!
//! Each closed lane adds its force vector (−F n − T t on its left body, +F n + T t on
//! its right one, [`force_vector`]) to the slot of each pin it touches at its height; a
//! slot's sum is compared with its peak (squares: one root for a new peak) when a later
//! step first touches it, or at the end. The work is one cache line per side of a
//! closed contact, beside the closed contact's own dot products.

use super::layout::{ContactModel, Layout};
use super::state::State;
use super::{ResultantPeak, sample_time};
use crate::contact::{Body, force_vector};

/// No slot: a wall side or an empty lane.
const NONE: u32 = u32::MAX;

/// No step yet.
const NO_STEP: u64 = u64::MAX;

/// What a step touches of a slot, in one cache line: the sum of the step that last
/// touched it (folded into the peak at its next touch, or at the end) and the peak's
/// square.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
struct Slot {
    sum: [f64; 2],
    step: u64,
    peak_squared: f64,
}

/// The running peaks of every (pin, contact height) slot.
pub(super) struct Resultants {
    /// Per lane: the slots of its left and right bodies.
    sides: Vec<[u32; 2]>,
    slots: Vec<Slot>,
    /// Per slot: the step of its peak (its time is written once, at the end).
    peak_steps: Vec<u64>,
    peaks: Vec<ResultantPeak>,
}

impl Resultants {
    /// A slot for every pin and height where one of the model's contacts acts on it,
    /// by pin then height; every lane pointing at its bodies' slots.
    pub fn new(layout: &Layout<'_>) -> Self {
        let contacts = &layout.model.contacts;
        let mut keys: Vec<(usize, f64)> = contacts
            .iter()
            .flat_map(|c| [(c.left, c.height), (c.right, c.height)])
            .filter_map(|(body, height)| match body {
                Body::Pin(pin) => Some((pin, height)),
                Body::Wall => None,
            })
            .collect();
        keys.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        keys.dedup();
        let slot_of = |pin: usize, height: f64| {
            keys.binary_search_by(|k| k.0.cmp(&pin).then(k.1.total_cmp(&height)))
                .expect("every contact's pins have a slot") as u32
        };
        let side = |body: Body, height: f64| match body {
            Body::Pin(pin) => slot_of(pin, height),
            Body::Wall => NONE,
        };
        let mut sides = vec![[NONE; 2]; layout.lane_contacts.len()];
        let mut peaks: Vec<ResultantPeak> = keys
            .iter()
            .map(|&(pin, height)| ResultantPeak {
                pin,
                height,
                ..ResultantPeak::default()
            })
            .collect();
        for (contact, &lane) in contacts.iter().zip(&layout.contacts.lane) {
            let pair = [
                side(contact.left, contact.height),
                side(contact.right, contact.height),
            ];
            for slot in pair.into_iter().filter(|&s| s != NONE) {
                peaks[slot as usize].contacts += 1;
            }
            sides[lane as usize] = pair;
        }
        let slot = Slot {
            sum: [0.0; 2],
            step: NO_STEP,
            peak_squared: 0.0,
        };
        Self {
            sides,
            slots: vec![slot; keys.len()],
            peak_steps: vec![NO_STEP; keys.len()],
            peaks,
        }
    }

    /// Adds step n's closed lanes (their forces in `state`) to their slots; a slot's
    /// sum of an earlier step is first compared with its peak.
    #[inline(always)]
    pub fn track(&mut self, layout: &Layout<'_>, state: &State, n: u64) {
        for &lane in &state.closed[..state.closed_count] {
            let lane = lane as usize;
            let force = state.contact_force[lane];
            if force == 0.0 {
                continue;
            }
            let on_right = match &layout.contact_model {
                ContactModel::Row => [force, 0.0],
                ContactModel::Plane(plane) => {
                    let tangential = match layout.lane_contacts[lane].friction {
                        true => state.tangential_force[lane],
                        false => 0.0,
                    };
                    force_vector(force, tangential, plane.lanes[lane].normal)
                }
            };
            let [left, right] = self.sides[lane];
            for (slot, sign) in [(left, -1.0), (right, 1.0)] {
                if slot == NONE {
                    continue;
                }
                let at = slot as usize;
                let slot = &mut self.slots[at];
                if slot.step != n {
                    fold(slot, &mut self.peak_steps[at]);
                    (slot.sum, slot.step) = ([0.0; 2], n);
                }
                slot.sum[0] += sign * on_right[0];
                slot.sum[1] += sign * on_right[1];
            }
        }
    }

    /// The peaks, by pin then height (every slot's last sum folded in).
    pub fn finish(mut self, dt: f64) -> Vec<ResultantPeak> {
        for ((slot, step), peak) in self
            .slots
            .iter_mut()
            .zip(&mut self.peak_steps)
            .zip(&mut self.peaks)
        {
            fold(slot, step);
            if *step != NO_STEP {
                peak.force = slot.peak_squared.sqrt();
                peak.time = sample_time(*step, dt);
            }
        }
        self.peaks
    }
}

/// The sum a slot holds (of its step) against its peak: a new peak when larger (its
/// square, and its step in `peak_step`).
#[inline(always)]
fn fold(slot: &mut Slot, peak_step: &mut u64) {
    if slot.step == NO_STEP {
        return;
    }
    let [x, y] = slot.sum;
    let squared = x * x + y * y;
    if squared > slot.peak_squared {
        slot.peak_squared = squared;
        *peak_step = slot.step;
    }
}
