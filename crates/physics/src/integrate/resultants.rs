//! The resultant of the contact forces on each pin at each contact height, tracked at
//! every step: where two contacts act on one pin at one height (a wire pushing a
//! neighbour while another wire pushes it back, a pin squeezed between its two
//! neighbours in the row, friction beside the normal force), the clad carries their
//! vector sum, which neither contact's own peak gives.
//!
//! Each closed lane adds its force vector (−F n − T t on its left body, +F n + T t on
//! its right one, [`force_vector`]) to the slot of each pin it touches at its height;
//! the slots touched this step are then compared with their peaks (squares: one root
//! for a new peak) and cleared. The work is a few additions per closed contact, beside
//! the closed contact's own dot products.

use super::layout::{ContactModel, Layout};
use super::state::State;
use super::{ResultantPeak, sample_time};
use crate::contact::{Body, force_vector};

/// No slot: a wall side or an empty lane.
const NONE: u32 = u32::MAX;

/// The running peaks of every (pin, contact height) slot, and the sums of the step.
pub(super) struct Resultants {
    /// Per lane: the slots of its left and right bodies.
    slots: Vec<[u32; 2]>,
    /// Per slot: the force (x, y) summed over the step's closed contacts so far.
    sums: Vec<[f64; 2]>,
    /// Per slot: the last step that touched it (`u64::MAX`: none yet).
    touched_at: Vec<u64>,
    /// The slots touched this step.
    touched: Vec<u32>,
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
        let mut slots = vec![[NONE; 2]; layout.lane_contacts.len()];
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
            slots[lane as usize] = pair;
        }
        Self {
            slots,
            sums: vec![[0.0; 2]; keys.len()],
            touched_at: vec![u64::MAX; keys.len()],
            touched: Vec::new(),
            peaks,
        }
    }

    /// The resultants of step n (its closed lanes and their forces in `state`) against
    /// their peaks.
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
            let [left, right] = self.slots[lane];
            for (slot, sign) in [(left, -1.0), (right, 1.0)] {
                if slot == NONE {
                    continue;
                }
                let slot = slot as usize;
                if self.touched_at[slot] != n {
                    self.touched_at[slot] = n;
                    self.touched.push(slot as u32);
                }
                let sum = &mut self.sums[slot];
                sum[0] += sign * on_right[0];
                sum[1] += sign * on_right[1];
            }
        }
        for &slot in &self.touched {
            let slot = slot as usize;
            let [x, y] = std::mem::take(&mut self.sums[slot]);
            let squared = x * x + y * y;
            let peak = &mut self.peaks[slot];
            if squared > peak.force * peak.force {
                peak.force = squared.sqrt();
                peak.time = sample_time(n, layout.dt);
            }
        }
        self.touched.clear();
    }

    /// The peaks, by pin then height.
    pub fn finish(self) -> Vec<ResultantPeak> {
        self.peaks
    }
}
