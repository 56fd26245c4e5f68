//! Gap states of a hexagonal bundle: pure functions from the contact list
//! ([`super::contacts`]) to one gap per contact (m, same order), and [`HexGaps`], the
//! input that composes them.
//!
//! Steps, in order: a base state (uniform, per contact, or random), then local closures
//! by zone, then an offset of the whole bundle toward one flat.
//! - Random states draw once per contact in contact order from [`GapRng`] (bit-exact, see
//!   `random.rs`), like the row; with `relative` the draw multiplies the contact's
//!   nominal clearance (nominal pin–pin clearances are ≈ 0 in real designs: relative
//!   draws then leave them ≈ 0).
//! - A closure multiplies by `factor` the gaps of the contacts on its levels that involve
//!   a pin of its zone (either body), as the row's closures do: swelling closes the
//!   clearances around the swollen pins.
//! - An offset moves every pin by s along flat k's normal nₖ: the gap to flat j becomes
//!   g − s·(nₖ·nⱼ) (the flat itself: −s, its neighbours −s/2, the next ones +s/2, the
//!   opposite +s); pin–pin gaps do not change (all pins move together).

use super::contacts::{Body, HexContact};
use super::lattice::Lattice;
use super::layout::HexBundle;
use super::wrapper::Flat;
use crate::bundle::GapDistribution;
use crate::random::GapRng;
use crate::{InputIssue, number, require_non_negative};

/// Bad entries reported per list before summarizing the rest (as the row does).
const MAX_LIST_ISSUES: usize = 10;

/// How the bundle's gaps are set (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct HexGaps {
    pub state: HexGapState,
    /// Applied after the state, in order.
    pub closures: Vec<ZoneClosure>,
    /// Applied last.
    pub offset: Option<FlatOffset>,
}

/// The base gap state.
#[derive(Debug, Clone, PartialEq)]
pub enum HexGapState {
    /// One gap for every pin–pin contact and one for every wall contact (m, ≥ 0);
    /// `None` keeps the nominal clearance from geometry.
    Uniform {
        pin_pin: Option<f64>,
        pin_wall: Option<f64>,
    },
    /// One gap (m, ≥ 0) per contact, in contact order.
    PerContact(Vec<f64>),
    /// Independent draws in contact order; with `relative`, multipliers of the nominal
    /// clearance.
    Random {
        distribution: GapDistribution,
        seed: u64,
        relative: bool,
    },
}

/// The pins of a closure zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PinZone {
    /// Rings first_ring..=last_ring (0 = the centre pin, n = the outer ring).
    Rings { first_ring: usize, last_ring: usize },
    /// Sectors first_sector..=last_sector (sextants 0..6 of centre angles
    /// [s·60°, (s + 1)·60°), [`super::lattice`]); the centre pin is in none.
    Sectors { first_sector: usize, last_sector: usize },
}

impl PinZone {
    /// Whether `pin` lies in the zone.
    pub fn contains(&self, lattice: &Lattice, pin: usize) -> bool {
        match *self {
            Self::Rings {
                first_ring,
                last_ring,
            } => (first_ring..=last_ring).contains(&lattice.ring(pin)),
            Self::Sectors {
                first_sector,
                last_sector,
            } => lattice
                .sector(pin)
                .is_some_and(|sector| (first_sector..=last_sector).contains(&sector)),
        }
    }
}

/// Gaps of the contacts on levels first_level..=last_level (indices) involving a pin of
/// `zone` are multiplied by `factor` (≥ 0: 0 closes them, > 1 opens them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZoneClosure {
    pub zone: PinZone,
    pub first_level: usize,
    pub last_level: usize,
    pub factor: f64,
}

/// Every pin moved by `distance` (m, ≥ 0) toward flat `flat` (index 0..6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatOffset {
    pub flat: usize,
    pub distance: f64,
}

/// The nominal clearance of each contact (m).
pub fn nominal_gaps(contacts: &[HexContact]) -> Vec<f64> {
    contacts.iter().map(|contact| contact.clearance).collect()
}

/// `pin_pin` for every pin–pin contact, `pin_wall` for every wall contact (m).
pub fn uniform_gaps(contacts: &[HexContact], pin_pin: f64, pin_wall: f64) -> Vec<f64> {
    contacts
        .iter()
        .map(|contact| match contact.touched {
            Body::Pin(_) => pin_pin,
            Body::Flat(_) => pin_wall,
        })
        .collect()
}

/// One draw of `distribution` per contact in contact order (× the nominal clearance
/// when `relative`).
pub fn random_gaps(
    contacts: &[HexContact],
    distribution: &GapDistribution,
    seed: u64,
    relative: bool,
) -> Vec<f64> {
    let mut rng = GapRng::new(seed);
    contacts
        .iter()
        .map(|contact| {
            let draw = rng.sample(distribution);
            if relative { draw * contact.clearance } else { draw }
        })
        .collect()
}

/// Applies `closure` to `gaps` (module doc).
pub fn close_zone(gaps: &mut [f64], contacts: &[HexContact], lattice: &Lattice, closure: &ZoneClosure) {
    let in_zone = |pin| closure.zone.contains(lattice, pin);
    for (gap, contact) in gaps.iter_mut().zip(contacts) {
        let on_levels = (closure.first_level..=closure.last_level).contains(&contact.level);
        if on_levels && (in_zone(contact.wire_pin) || contact.touched_pin().is_some_and(in_zone)) {
            *gap *= closure.factor;
        }
    }
}

/// Moves every pin by `distance` (m) toward `flat`: wall gaps change by
/// −distance·(n_flat·n_touched), pin–pin gaps stay (module doc). May leave negative
/// gaps: [`HexGaps::gaps`] refuses those.
pub fn offset_toward_flat(gaps: &mut [f64], contacts: &[HexContact], flat: Flat, distance: f64) {
    for (gap, contact) in gaps.iter_mut().zip(contacts) {
        if let Body::Flat(touched) = contact.touched {
            *gap -= distance * flat.normal_cosine(touched);
        }
    }
}

impl HexGaps {
    /// Every problem with these gaps for `bundle`; field paths relative to the gaps
    /// input (`gaps/values/3`, `closures/0/last_ring`, `offset/flat`).
    pub fn validate(&self, bundle: &HexBundle) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        self.validate_state(bundle.contact_count(), &mut issues);
        let rings = bundle.layout().rings;
        let levels = bundle.levels().len();
        for (k, closure) in self.closures.iter().enumerate() {
            let (what, first, last, available) = match closure.zone {
                PinZone::Rings {
                    first_ring,
                    last_ring,
                } => ("ring", first_ring, last_ring, rings + 1),
                PinZone::Sectors {
                    first_sector,
                    last_sector,
                } => ("sector", first_sector, last_sector, 6),
            };
            for (what, first, last, available) in [
                (what, first, last, available),
                ("level", closure.first_level, closure.last_level, levels),
            ] {
                for (end, index) in [("first", first), ("last", last)] {
                    if index >= available {
                        issues.push(InputIssue::new(
                            format!("closures/{k}/{end}_{what}"),
                            format!(
                                "{what} {index} is outside the bundle: must be ≤ {} ({available} {what}s, from 0)",
                                available.saturating_sub(1)
                            ),
                        ));
                    }
                }
                if first > last {
                    issues.push(InputIssue::new(
                        format!("closures/{k}/last_{what}"),
                        format!("must be ≥ first_{what} ({first}), got {last}"),
                    ));
                }
            }
            require_non_negative(&mut issues, &format!("closures/{k}/factor"), closure.factor);
        }
        if let Some(offset) = self.offset {
            if offset.flat >= 6 {
                issues.push(InputIssue::new(
                    "offset/flat",
                    format!("flat {} does not exist: must be ≤ 5 (flats 0..6)", offset.flat),
                ));
            }
            require_non_negative(&mut issues, "offset/distance", offset.distance);
        }
        issues
    }

    /// One gap per contact (m) for `contacts` (= `bundle.contacts()`), or every problem.
    pub fn gaps(&self, bundle: &HexBundle, contacts: &[HexContact]) -> Result<Vec<f64>, Vec<InputIssue>> {
        debug_assert_eq!(
            contacts.len(),
            bundle.contact_count(),
            "contacts of another bundle"
        );
        let issues = self.validate(bundle);
        if !issues.is_empty() {
            return Err(issues);
        }
        let mut gaps = match &self.state {
            HexGapState::Uniform { pin_pin, pin_wall } => uniform_gaps(
                contacts,
                pin_pin.unwrap_or(bundle.pin_clearance()),
                pin_wall.unwrap_or(bundle.wall_clearance()),
            ),
            HexGapState::PerContact(values) => values.clone(),
            HexGapState::Random {
                distribution,
                seed,
                relative,
            } => random_gaps(contacts, distribution, *seed, *relative),
        };
        for closure in &self.closures {
            close_zone(&mut gaps, contacts, bundle.lattice(), closure);
        }
        if let Some(offset) = self.offset
            && let Some(flat) = Flat::new(offset.flat)
        {
            // The largest offset keeping every wall gap ≥ 0: min over the flats it
            // approaches (nₖ·nⱼ > 0) of g/(nₖ·nⱼ).
            let limit = gaps
                .iter()
                .zip(contacts)
                .filter_map(|(&gap, contact)| match contact.touched {
                    Body::Flat(touched) if flat.normal_cosine(touched) > 0.0 => {
                        Some(gap / flat.normal_cosine(touched))
                    }
                    _ => None,
                })
                .fold(f64::INFINITY, f64::min);
            if offset.distance > limit {
                return Err(vec![InputIssue::new(
                    "offset/distance",
                    format!(
                        "must be ≤ {limit} m (the pins would cross flat {} or its neighbours), got {} m",
                        offset.flat, offset.distance
                    ),
                )]);
            }
            offset_toward_flat(&mut gaps, contacts, flat, offset.distance);
            // A gap within rounding below 0 after moving by exactly the limit is a closed gap.
            for gap in &mut gaps {
                *gap = gap.max(0.0);
            }
        }
        // Only reachable by overflow (e.g. std ~ 1e308, or a huge factor × gap).
        if let Some(index) = gaps.iter().position(|gap| !gap.is_finite()) {
            return Err(vec![InputIssue::new(
                "gaps",
                format!("the gap of contact {index} overflows: parameters are too large"),
            )]);
        }
        Ok(gaps)
    }

    fn validate_state(&self, count: usize, issues: &mut Vec<InputIssue>) {
        match &self.state {
            HexGapState::Uniform { pin_pin, pin_wall } => {
                for (field, value) in [("gaps/pin_pin", pin_pin), ("gaps/pin_wall", pin_wall)] {
                    if let Some(value) = value {
                        require_non_negative(issues, field, *value);
                    }
                }
            }
            HexGapState::PerContact(values) => {
                if values.len() != count {
                    issues.push(InputIssue::new(
                        "gaps/values",
                        format!(
                            "expected {count} gaps (one per contact, in contact order), got {}",
                            values.len()
                        ),
                    ));
                }
                let bad: Vec<usize> = values
                    .iter()
                    .enumerate()
                    .filter(|(_, gap)| !gap.is_finite() || **gap < 0.0)
                    .map(|(k, _)| k)
                    .collect();
                for &k in bad.iter().take(MAX_LIST_ISSUES) {
                    issues.push(InputIssue::new(
                        format!("gaps/values/{k}"),
                        format!("must be a finite gap ≥ 0 m (got {})", number(values[k])),
                    ));
                }
                if bad.len() > MAX_LIST_ISSUES {
                    issues.push(InputIssue::new(
                        "gaps/values",
                        format!("{} more bad entries not listed", bad.len() - MAX_LIST_ISSUES),
                    ));
                }
            }
            HexGapState::Random { distribution, .. } => distribution.validate(issues),
        }
    }
}

#[cfg(test)]
#[path = "gap_tests.rs"]
mod tests;
