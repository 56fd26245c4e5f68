//! The per-impact table of a run, and the rule that keeps it within `max_rows` rows.
//!
//! Every impact is tabulated while the run's impacts number at most `max_rows` (N).
//! Past that, the table keeps the **largest impacts by peak force, with a fair share per
//! contact**. With C the contacts of the model, the fair share is q = ⌊N / C⌋ and:
//!
//! 1. each contact keeps its q largest impacts (all of them if it has fewer);
//! 2. the rows left, N minus those, go to the largest of all the other impacts, whatever
//!    their contact.
//!
//! "Larger" is a larger peak force; equal peaks rank the earlier start first, then the
//! lower contact index, so the table is one set whatever order the impacts end in (and
//! whichever thread ends them). What follows, and what the tests check:
//!
//! - the table holds min(N, impacts) rows, and its rows of a contact are exactly that
//!   contact's largest impacts (a kept impact never ranks below a dropped one of its own
//!   contact);
//! - an impact is dropped while a smaller one of another contact is kept only when that
//!   smaller one is among its contact's q largest: a contact never loses rows to another
//!   beyond the other's fair share;
//! - the run's largest impact is always in the table (N ≥ 1), and so is every contact's
//!   largest when N ≥ C;
//! - every impact with a peak above [`ImpactTable::untabulated_max_peak`] is in it.
//!
//! The rule keeps no more than N impacts in memory however long the run: a min-heap of
//! its q largest per contact, and a min-heap of the others sized to the rows left. An
//! impact that leaves a contact's q largest never returns to them (impacts are only
//! added), and the rows left for the others only shrink, so an impact once dropped could
//! never have been kept.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use super::Impact;

/// Rows every contact is guaranteed in a table of `max_rows` rows over `contacts`
/// contacts: ⌊max_rows / contacts⌋ (all of them for a model without contacts).
pub fn fair_share(max_rows: usize, contacts: usize) -> usize {
    max_rows.checked_div(contacts).unwrap_or(max_rows)
}

/// An impact ordered by how much it matters to the table: larger peak force first, then
/// earlier start, then lower contact index (a total order: two impacts of one contact
/// never share a start).
#[derive(Debug, Clone, Copy)]
struct ByForce(Impact);

impl Ord for ByForce {
    fn cmp(&self, other: &Self) -> Ordering {
        let (a, b) = (&self.0, &other.0);
        a.peak_force
            .total_cmp(&b.peak_force)
            .then(b.start.total_cmp(&a.start))
            .then(b.contact.cmp(&a.contact))
    }
}

impl PartialOrd for ByForce {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for ByForce {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for ByForce {}

/// Builds the table as impacts end, by the rule of the module doc.
#[derive(Debug, Clone, Default)]
pub struct TableKeeper {
    max_rows: usize,
    fair_share: usize,
    /// Per contact, its largest impacts so far (at most `fair_share`), smallest on top.
    shares: Vec<BinaryHeap<Reverse<ByForce>>>,
    /// Impacts in `shares`.
    share_rows: usize,
    /// The largest of the other impacts, smallest on top: at most `max_rows − share_rows`.
    others: BinaryHeap<Reverse<ByForce>>,
    /// Per contact, every impact that ended.
    contact_impacts: Vec<u64>,
    untabulated: u64,
    untabulated_max_peak: Option<f64>,
}

impl TableKeeper {
    /// For `contacts` contacts and a table of at most `max_rows` rows.
    pub fn new(contacts: usize, max_rows: usize) -> Self {
        let fair_share = fair_share(max_rows, contacts);
        Self {
            max_rows,
            fair_share,
            shares: vec![BinaryHeap::new(); if fair_share > 0 { contacts } else { 0 }],
            share_rows: 0,
            others: BinaryHeap::new(),
            contact_impacts: vec![0; contacts],
            untabulated: 0,
            untabulated_max_peak: None,
        }
    }

    /// An impact ended.
    pub fn push(&mut self, impact: Impact) {
        let contact = impact.contact;
        if contact >= self.contact_impacts.len() {
            self.contact_impacts.resize(contact + 1, 0);
        }
        self.contact_impacts[contact] += 1;
        let mut candidate = ByForce(impact);
        if let Some(share) = self.shares.get_mut(contact) {
            if share.len() < self.fair_share {
                share.push(Reverse(candidate));
                self.share_rows += 1;
                self.trim_others();
                return;
            }
            // The share is full: the smaller of the new impact and the share's smallest
            // competes with the other contacts' impacts.
            if let Some(mut smallest) = share.peek_mut()
                && candidate > smallest.0
            {
                candidate = std::mem::replace(&mut smallest.0, candidate);
            }
        }
        self.others.push(Reverse(candidate));
        self.trim_others();
    }

    /// Drops the smallest of the other impacts until they fit the rows left.
    fn trim_others(&mut self) {
        let room = self.max_rows - self.share_rows;
        while self.others.len() > room {
            let Some(Reverse(ByForce(dropped))) = self.others.pop() else {
                break;
            };
            self.untabulated += 1;
            let peak = self.untabulated_max_peak.unwrap_or(f64::NEG_INFINITY);
            self.untabulated_max_peak = Some(peak.max(dropped.peak_force));
        }
    }

    /// The table, its rows sorted by start time then contact.
    pub fn finish(self) -> ImpactTable {
        let mut rows: Vec<Impact> = self
            .shares
            .into_iter()
            .flat_map(BinaryHeap::into_vec)
            .chain(self.others.into_vec())
            .map(|Reverse(ByForce(impact))| impact)
            .collect();
        rows.sort_by(|a, b| a.start.total_cmp(&b.start).then(a.contact.cmp(&b.contact)));
        let mut contact_tabulated = vec![0; self.contact_impacts.len()];
        for row in &rows {
            contact_tabulated[row.contact] += 1;
        }
        ImpactTable {
            rows,
            impacts: self.contact_impacts.iter().sum(),
            untabulated: self.untabulated,
            max_rows: self.max_rows,
            fair_share: self.fair_share,
            contact_impacts: self.contact_impacts,
            contact_tabulated,
            untabulated_max_peak: self.untabulated_max_peak,
        }
    }
}

/// The per-impact table of a run, and what it left out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ImpactTable {
    /// Sorted by start time, then contact.
    pub rows: Vec<Impact>,
    /// Every impact of the run, tabulated or not (the statistics' count).
    pub impacts: u64,
    /// Impacts left out: `impacts − rows.len()`.
    pub untabulated: u64,
    /// The cap on rows, and the rows each contact is guaranteed ([`fair_share`]).
    pub max_rows: usize,
    pub fair_share: usize,
    /// Per contact: its impacts, and its rows in the table.
    pub contact_impacts: Vec<u64>,
    pub contact_tabulated: Vec<u64>,
    /// The largest peak force of an impact left out (N); `None` when none was.
    pub untabulated_max_peak: Option<f64>,
}

impl ImpactTable {
    /// Whether impacts were left out.
    pub fn truncated(&self) -> bool {
        self.untabulated > 0
    }
}

#[cfg(test)]
#[path = "table_tests.rs"]
pub(crate) mod tests;
