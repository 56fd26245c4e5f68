//! Bundle generator (BRIEF §8, API.md "Generator form"): expands a compact description
//! of a row of identical pins between two wrapper walls (pin count, contact levels, gap
//! state, local closures) into the explicit contact list the integrator consumes.
//!
//! Expansion order: level by level from the lowest; at each level the contacts
//! `wall–0, 0–1, …, (n−2)–(n−1), (n−1)–wall` (`left`, `right`). Contact `i` therefore sits
//! at level `i / (pins + 1)`, slot `i % (pins + 1)`.
//!
//! Random gap states are drawn by [`GapRng`], whose module doc (`physics/random.rs`) defines the
//! algorithm bit for bit (SplitMix64-seeded xoshiro256**, polar-method normals,
//! Robert's tail sampler): same seed, same gaps, on every machine.
//!
//! With `relative`, the draw multiplies the contact's nominal gap (`wall_gap` or
//! `pin_gap`).

use super::contact::{Body, Contact, Law};
use super::{InputIssue, number, require_non_negative, require_positive};

pub use super::random::{GapRng, ln, splitmix64};

/// Hard ceiling on levels × (pins + 1); the service may configure a lower one.
pub const MAX_CONTACTS: usize = 100_000;
/// Levels within this relative distance of the pin top are snapped onto it, so that
/// `first + k·spacing` rounding (0.1 + 2 × 0.1 = 0.30000000000000004 on a 0.3 m pin) stays on the pin.
pub const HEIGHT_SNAP_TOLERANCE: f64 = 1e-9;
/// Truncating a normal law deeper than α = −mean/std > this leaves < 1e-197 of it.
pub const MAX_TRUNCATION: f64 = 30.0;
/// Bad entries reported per list before summarizing the rest.
const MAX_LIST_ISSUES: usize = 10;

/// Compact description of a row of `pins` identical pins between two walls.
#[derive(Debug, Clone, PartialEq)]
pub struct BundleLayout {
    /// Number of pins, ≥ 1 (numbered 0.. from the left wall).
    pub pins: usize,
    /// Contact heights (m from the pin feet).
    pub levels: Levels,
    /// Penalty stiffness of every contact (N/m), ≥ 0.
    pub stiffness: f64,
    /// Dashpot of every contact (N·s/m), ≥ 0.
    pub damping: f64,
    /// Nominal gap wall–pin (m), ≥ 0.
    pub wall_gap: f64,
    /// Nominal gap pin–pin (m), ≥ 0.
    pub pin_gap: f64,
    /// How the gaps are set from the nominal ones.
    pub gaps: GapState,
    /// Local gap changes applied after the gap state, in order.
    pub closures: Vec<LocalClosure>,
}

/// Contact heights (m), each within (0, pin length], strictly increasing.
#[derive(Debug, Clone, PartialEq)]
pub enum Levels {
    /// `first + k·spacing` for k = 0..count (computed by product, not accumulation).
    Regular { first: f64, spacing: f64, count: usize },
    /// Listed heights.
    Explicit(Vec<f64>),
}

/// Gap state of the bundle.
#[derive(Debug, Clone, PartialEq)]
pub enum GapState {
    /// Nominal gaps (`wall_gap`, `pin_gap`).
    Uniform,
    /// One gap (m) per contact, in expansion order.
    PerContact(Vec<f64>),
    /// Independent draws in expansion order (module doc: exact algorithm). With
    /// `relative`, the law's parameters are dimensionless multipliers of the nominal gap.
    Random {
        distribution: GapDistribution,
        seed: u64,
        relative: bool,
    },
}

/// Law of a random gap (m, or × nominal gap when relative).
#[derive(Debug, Clone, PartialEq)]
pub enum GapDistribution {
    /// Uniform on [low, high), 0 ≤ low ≤ high.
    Uniform { low: f64, high: f64 },
    /// Normal N(mean, std²) truncated at 0 (resampled, so the law is truly truncated).
    Normal { mean: f64, std: f64 },
}

impl GapDistribution {
    /// Checks the law's parameters, at `gaps/distribution/<field>` (the row's and the
    /// hexagonal bundle's gap states alike).
    pub fn validate(&self, issues: &mut Vec<InputIssue>) {
        match *self {
            GapDistribution::Uniform { low, high } => {
                require_non_negative(issues, "gaps/distribution/low", low);
                require_non_negative(issues, "gaps/distribution/high", high);
                if low > high {
                    issues.push(InputIssue::new(
                        "gaps/distribution/high",
                        format!("must be ≥ low ({low}), got {high}"),
                    ));
                }
            }
            GapDistribution::Normal { mean, std } => {
                let before = issues.len();
                if !mean.is_finite() {
                    issues.push(InputIssue::new(
                        "gaps/distribution/mean",
                        "must be a finite number",
                    ));
                }
                require_non_negative(issues, "gaps/distribution/std", std);
                if issues.len() == before && (std == 0.0 && mean < 0.0 || -mean > MAX_TRUNCATION * std) {
                    issues.push(InputIssue::new(
                        "gaps/distribution/mean",
                        format!(
                            "truncation at 0 would discard almost all of the law: need mean ≥ \
                         −{MAX_TRUNCATION}·std (and ≥ 0 when std = 0)"
                        ),
                    ));
                }
            }
        }
    }
}

/// Gaps of the contacts in levels [first_level, last_level] (indices, inclusive) that
/// touch a pin in [first_pin, last_pin] are multiplied by `factor` (≥ 0; 0 closes them,
/// e.g. after irradiation swelling; > 1 opens them).
#[derive(Debug, Clone, PartialEq)]
pub struct LocalClosure {
    pub first_level: usize,
    pub last_level: usize,
    pub first_pin: usize,
    pub last_pin: usize,
    pub factor: f64,
}

impl BundleLayout {
    /// levels × (pins + 1), saturating (so absurd inputs never overflow).
    pub fn contact_count(&self) -> usize {
        self.level_count().saturating_mul(self.pins.saturating_add(1))
    }

    fn level_count(&self) -> usize {
        match &self.levels {
            Levels::Regular { count, .. } => *count,
            Levels::Explicit(heights) => heights.len(),
        }
    }

    /// Every problem with the layout on a pin of `pin_length` m; field paths are relative
    /// to the layout (`levels/spacing`, `gaps/values/3`, `closures/0/last_pin`; `""` for
    /// the layout as a whole).
    pub fn validate(&self, pin_length: f64) -> Vec<InputIssue> {
        let mut issues = Vec::new();
        if self.pins == 0 {
            issues.push(InputIssue::new("pins", "a bundle needs at least one pin"));
        }
        self.validate_levels(pin_length, &mut issues);
        require_non_negative(&mut issues, "stiffness", self.stiffness);
        require_non_negative(&mut issues, "damping", self.damping);
        require_non_negative(&mut issues, "wall_gap", self.wall_gap);
        require_non_negative(&mut issues, "pin_gap", self.pin_gap);
        let count = self.contact_count();
        if count > MAX_CONTACTS {
            issues.push(InputIssue::new(
                "",
                format!(
                    "levels × (pins + 1) = {} contacts exceeds the limit of {MAX_CONTACTS}",
                    if count == usize::MAX {
                        "too many".to_owned()
                    } else {
                        count.to_string()
                    }
                ),
            ));
        }
        self.validate_gaps(count, &mut issues);
        self.validate_closures(&mut issues);
        issues
    }

    /// The explicit contacts, in expansion order, or every problem found.
    pub fn expand(&self, pin_length: f64) -> Result<Vec<Contact>, Vec<InputIssue>> {
        let issues = self.validate(pin_length);
        if !issues.is_empty() {
            return Err(issues);
        }
        let slots = self.pins + 1;
        let mut contacts = Vec::with_capacity(self.contact_count());
        for height in level_heights(&self.levels, pin_length) {
            for slot in 0..slots {
                let at_wall = slot == 0 || slot == self.pins;
                contacts.push(Contact {
                    left: if slot == 0 {
                        Body::Wall
                    } else {
                        Body::Pin(slot - 1)
                    },
                    right: if slot == self.pins {
                        Body::Wall
                    } else {
                        Body::Pin(slot)
                    },
                    height,
                    gap: if at_wall { self.wall_gap } else { self.pin_gap },
                    stiffness: self.stiffness,
                    damping: self.damping,
                    law: Law::LINEAR,
                });
            }
        }
        match &self.gaps {
            GapState::Uniform => {}
            GapState::PerContact(values) => {
                for (contact, &gap) in contacts.iter_mut().zip(values) {
                    contact.gap = gap;
                }
            }
            GapState::Random {
                distribution,
                seed,
                relative,
            } => {
                let mut rng = GapRng::new(*seed);
                for contact in &mut contacts {
                    let draw = rng.sample(distribution);
                    contact.gap = if *relative { draw * contact.gap } else { draw };
                }
            }
        }
        for closure in &self.closures {
            // Slot s holds pins s − 1 and s: it touches [first_pin, last_pin] iff
            // first_pin ≤ s ≤ last_pin + 1.
            for level in closure.first_level..=closure.last_level {
                for slot in closure.first_pin..=closure.last_pin + 1 {
                    contacts[level * slots + slot].gap *= closure.factor;
                }
            }
        }
        // Only reachable by overflow (e.g. std ~ 1e308, or a huge factor × gap).
        if let Some(index) = contacts.iter().position(|c| !c.gap.is_finite()) {
            return Err(vec![InputIssue::new(
                "gaps",
                format!("the gap of contact {index} overflows: parameters are too large"),
            )]);
        }
        Ok(contacts)
    }

    fn validate_levels(&self, pin_length: f64, issues: &mut Vec<InputIssue>) {
        let length_ok = pin_length.is_finite() && pin_length > 0.0;
        if !length_ok {
            issues.push(InputIssue::new(
                "levels",
                format!("cannot place levels on a pin of length {} m", number(pin_length)),
            ));
        }
        let too_many = || format!("more than {MAX_CONTACTS} levels");
        match &self.levels {
            Levels::Regular {
                first,
                spacing,
                count,
            } => {
                let before = issues.len();
                require_positive(issues, "levels/first", *first);
                require_positive(issues, "levels/spacing", *spacing);
                if *count == 0 {
                    issues.push(InputIssue::new("levels/count", "needs at least one level"));
                } else if *count > MAX_CONTACTS {
                    issues.push(InputIssue::new("levels/count", too_many()));
                }
                if issues.len() > before || !length_ok {
                    return;
                }
                let heights = level_heights(&self.levels, pin_length);
                if heights[0] > pin_length {
                    issues.push(InputIssue::new(
                        "levels/first",
                        format!(
                            "{} m lies above the pin top ({} m)",
                            number(*first),
                            number(pin_length)
                        ),
                    ));
                } else if heights[count - 1] > pin_length {
                    issues.push(InputIssue::new(
                        "levels/count",
                        format!(
                            "the last level, first + (count − 1)·spacing = {} m, lies above \
                             the pin top ({} m)",
                            number(heights[count - 1]),
                            number(pin_length)
                        ),
                    ));
                } else if heights.windows(2).any(|pair| pair[1] <= pair[0]) {
                    issues.push(InputIssue::new(
                        "levels/spacing",
                        "too small to separate the levels in floating point",
                    ));
                }
            }
            Levels::Explicit(listed) => {
                if listed.is_empty() {
                    issues.push(InputIssue::new("levels", "needs at least one level"));
                } else if listed.len() > MAX_CONTACTS {
                    issues.push(InputIssue::new("levels", too_many()));
                } else if length_ok {
                    let heights = level_heights(&self.levels, pin_length);
                    let mut bad = Vec::new();
                    for (k, &height) in heights.iter().enumerate() {
                        if !height.is_finite() {
                            bad.push((k, "must be a finite number".to_owned()));
                        } else if height <= 0.0 || height > pin_length {
                            bad.push((k, format!("{height} m is outside the pin (0, {pin_length}]")));
                        } else if k > 0 && heights[k - 1].is_finite() && height <= heights[k - 1] {
                            bad.push((k, format!("must lie strictly above level {}", k - 1)));
                        }
                    }
                    push_list_issues(issues, "levels", bad);
                }
            }
        }
    }

    fn validate_gaps(&self, count: usize, issues: &mut Vec<InputIssue>) {
        match &self.gaps {
            GapState::Uniform => {}
            GapState::PerContact(values) => {
                if values.len() != count {
                    issues.push(InputIssue::new(
                        "gaps/values",
                        format!(
                            "expected {count} gaps (levels × (pins + 1), in expansion order), \
                             got {}",
                            values.len()
                        ),
                    ));
                }
                let bad = values
                    .iter()
                    .enumerate()
                    .filter(|(_, gap)| !gap.is_finite() || **gap < 0.0)
                    .map(|(k, gap)| (k, format!("must be a finite gap ≥ 0 m (got {})", number(*gap))))
                    .collect();
                push_list_issues(issues, "gaps/values", bad);
            }
            GapState::Random { distribution, .. } => distribution.validate(issues),
        }
    }

    fn validate_closures(&self, issues: &mut Vec<InputIssue>) {
        let levels = self.level_count();
        if self.closures.len() > MAX_CONTACTS {
            issues.push(InputIssue::new(
                "closures",
                format!("more than {MAX_CONTACTS} closures"),
            ));
            return;
        }
        for (k, closure) in self.closures.iter().enumerate() {
            let ranges = [
                ("level", closure.first_level, closure.last_level, levels),
                ("pin", closure.first_pin, closure.last_pin, self.pins),
            ];
            for (what, first, last, available) in ranges {
                for (end, index) in [("first", first), ("last", last)] {
                    if index >= available {
                        issues.push(InputIssue::new(
                            format!("closures/{k}/{end}_{what}"),
                            format!("{what} {index} does not exist ({available} {what}s, from 0)"),
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
            require_non_negative(issues, &format!("closures/{k}/factor"), closure.factor);
        }
    }
}

/// Level heights (m), snapped onto the pin top when within rounding of it; regular
/// levels as the decimals they stand for (0.2 + 2 × 0.2 is 0.6, not
/// 0.6000000000000001). Callers bound the count first.
fn level_heights(levels: &Levels, pin_length: f64) -> Vec<f64> {
    let snap = |height: f64| {
        if (height - pin_length).abs() <= HEIGHT_SNAP_TOLERANCE * pin_length {
            pin_length
        } else {
            height
        }
    };
    match levels {
        Levels::Regular {
            first,
            spacing,
            count,
        } => (0..*count)
            .map(|k| snap(super::decimal(first + k as f64 * spacing)))
            .collect(),
        Levels::Explicit(heights) => heights.iter().map(|&h| snap(h)).collect(),
    }
}

fn push_list_issues(issues: &mut Vec<InputIssue>, list: &str, bad: Vec<(usize, String)>) {
    let total = bad.len();
    for (k, reason) in bad.into_iter().take(MAX_LIST_ISSUES) {
        issues.push(InputIssue::new(format!("{list}/{k}"), reason));
    }
    if total > MAX_LIST_ISSUES {
        issues.push(InputIssue::new(
            list,
            format!("{} more bad entries not listed", total - MAX_LIST_ISSUES),
        ));
    }
}

#[cfg(test)]
mod tests;
