//! Impacts as every process reports them (issue 19): the `output.impacts` and
//! `output.blocks` inputs, each contact's impact statistics, the run-wide summary (the
//! contacts ranked by peak force and by impact count, the peak-force histogram), and the
//! per-impact table, an output named `impacts` served page by page
//! (`/jobs/{id}/results/impacts`) and written by the CLI as `impacts.csv`.
//!
//! Past `max_rows` the table keeps the largest impacts with a fair share per contact
//! (the physics' [`crate::physics::impacts::TableKeeper`] states the rule) and says so
//! everywhere it is read: `impact_summary.truncated` and its counts in the results, each
//! contact's `tabulated` rows, five more CSV columns ([`TRUNCATION_COLUMNS`]), and the
//! `Impact-Table` header of the served table ([`header_value`]).
//!
//! The counting itself is the physics' ([`crate::physics::impacts`]), done at every step
//! of the run; this module only says how users ask for it and see it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::History;
use super::simulation::{HistoryKind, HistoryOutput};
use crate::physics::impacts::{
    DEFAULT_CLASSES, DEFAULT_MAX_ROWS, Impact, ImpactCounting, ImpactStatistics, ImpactTable, TABLE_COLUMNS,
};
use crate::physics::integrate::Simulation;
use std::collections::HashMap;

/// Name of the per-impact table output.
pub const TABLE: &str = "impacts";

/// The per-impact table, as every process declares it.
pub const TABLE_OUTPUT: HistoryOutput = HistoryOutput {
    name: TABLE,
    kind: HistoryKind::Table,
    title: "Impacts, one row each",
    description: "CSV columns contact, start (s), peak_time (s), peak_force (N), impulse (N·s), duration (s), \
                  approach_velocity (m/s), rebounds, dissipated (J), energy (J), sorted by start; \
                  `?contact=` filters, `offset` and `limit` page. Past `output.impacts.max_rows` \
                  the largest impacts by peak force with a fair share per contact, then 5 more \
                  columns truncated, impacts, tabulated, contact_impacts, contact_tabulated",
};

/// The table's columns, in CSV order.
pub const COLUMNS: [&str; TABLE_COLUMNS] = [
    "contact",
    "start",
    "peak_time",
    "peak_force",
    "impulse",
    "duration",
    "approach_velocity",
    "rebounds",
    "dissipated",
    "energy",
];

/// How impacts are counted and tabulated (code_aster `POST_DYNA_MODA_T`'s `SEUIL_FORCE`
/// and `DUREE_REPOS`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ImpactsInput {
    /// A closed contact is loaded while its force is at least this (N, ≥ 0); an impact
    /// starts when the force reaches it. Default 0: every closed step.
    #[schema(minimum = 0.0, default = 0.0)]
    pub force_threshold: Option<f64>,
    /// An impact ends once the force has stayed below the threshold this long (s, ≥ 0);
    /// returns within it are the impact's rebounds. Default 0.
    #[schema(minimum = 0.0, default = 0.0)]
    pub rest_time: Option<f64>,
    /// Classes of the peak-force histograms, equal from 0 to the largest peak (1…10000).
    #[schema(minimum = 1, maximum = 10000, default = 10)]
    pub classes: Option<usize>,
    /// Rows of the per-impact table (≥ 1). Every impact is tabulated while the run has at
    /// most this many; past it the table keeps each contact's ⌊max_rows / contacts⌋
    /// largest impacts by peak force (its fair share), then the largest of the others
    /// whatever their contact, and says `truncated` with the counts. The statistics count
    /// every impact. Counts against the history ceiling at 10 values a row (12 when it
    /// may be truncated), for at most one impact every two steps per contact.
    #[schema(minimum = 1, default = 100000)]
    pub max_rows: Option<usize>,
}

/// The physics' counting for `output.impacts` and `output.blocks`.
pub fn counting(impacts: Option<&ImpactsInput>, blocks: Option<usize>) -> ImpactCounting {
    let input = impacts.copied().unwrap_or_default();
    ImpactCounting {
        force_threshold: input.force_threshold.unwrap_or(0.0),
        rest_time: input.rest_time.unwrap_or(0.0),
        blocks: blocks.unwrap_or(1),
        classes: input.classes.unwrap_or(DEFAULT_CLASSES),
        max_rows: input.max_rows.unwrap_or(DEFAULT_MAX_ROWS),
    }
}

/// The pointer of an `impacts/…` path of the integration settings' checks.
pub fn settings_pointer(path: &str) -> Option<&'static str> {
    Some(match path {
        "impacts/force_threshold" => "/inputs/output/impacts/force_threshold",
        "impacts/rest_time" => "/inputs/output/impacts/rest_time",
        "impacts/classes" => "/inputs/output/impacts/classes",
        "impacts/max_rows" => "/inputs/output/impacts/max_rows",
        "impacts/blocks" => "/inputs/output/blocks",
        _ => return None,
    })
}

/// The problems of `counting` at their pointers (for a process that does not check its
/// integration settings with [`super::model_check::check`]).
pub fn errors(counting: &ImpactCounting) -> Vec<super::FieldError> {
    counting
        .validate()
        .into_iter()
        .map(|issue| {
            let pointer =
                settings_pointer(&format!("impacts/{}", issue.field)).unwrap_or("/inputs/output/impacts");
            super::FieldError::new(pointer, issue.reason)
        })
        .collect()
}

/// Values the per-impact table can hold at most: one impact every two steps per contact
/// (an impact is a loaded step then an unloaded one) at 10 values a row when that fits
/// `max_rows`, else `max_rows` rows at 12 (a truncated table also stores each row's
/// counts, [`table_history`]).
pub fn table_values(counting: &ImpactCounting, contacts: usize, steps: f64) -> f64 {
    let possible = contacts as f64 * (steps / 2.0).ceil();
    if possible <= counting.max_rows as f64 {
        possible * TABLE_COLUMNS as f64
    } else {
        counting.max_rows as f64 * (TABLE_COLUMNS + STORED_COUNTS.len()) as f64
    }
}

/// One contact's impacts.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ContactImpacts {
    #[serde(flatten)]
    pub statistics: ImpactStatistics,
    /// Impacts per peak-force class (the classes of `impact_summary.histogram`).
    pub histogram: Vec<u64>,
    /// Its rows in the per-impact table: `impacts` unless the table is truncated, then
    /// its largest impacts (at least `impact_summary.fair_share` of them when it has as
    /// many).
    pub tabulated: u64,
}

/// Every contact's impacts, in contact order.
pub fn contact_reports(simulation: &Simulation) -> Vec<ContactImpacts> {
    simulation
        .impact_statistics
        .iter()
        .zip(&simulation.impact_histogram.per_contact)
        .enumerate()
        .map(|(c, (statistics, histogram))| ContactImpacts {
            statistics: statistics.clone(),
            histogram: histogram.clone(),
            tabulated: simulation
                .impact_table
                .contact_tabulated
                .get(c)
                .copied()
                .unwrap_or(0),
        })
        .collect()
}

/// How many contacts the summary ranks.
const RANKED: usize = 10;

/// The impacts of the whole run.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ImpactSummary {
    /// The counting used (N, s).
    pub force_threshold: f64,
    pub rest_time: f64,
    pub blocks: usize,
    /// Impacts over every contact.
    pub impacts: u64,
    /// Rows of the per-impact table, and impacts left out of it: `tabulated +
    /// untabulated = impacts`.
    pub tabulated: u64,
    pub untabulated: u64,
    /// Whether the table left impacts out (`untabulated > 0`): it then holds the largest
    /// by peak force, each contact's `fair_share` largest first.
    pub truncated: bool,
    /// The cap on the table's rows (`output.impacts.max_rows`).
    pub max_rows: usize,
    /// Rows each contact is guaranteed past the cap: ⌊max_rows / contacts⌋ of its
    /// largest impacts (all of them if it has fewer).
    pub fair_share: usize,
    /// The largest peak force of an impact left out (N): every impact with a larger peak
    /// is in the table. Null when none was left out.
    pub untabulated_max_peak: Option<f64>,
    /// Largest ½ m v² of an approach (J).
    pub max_impact_energy: f64,
    /// Largest impact duration (s).
    pub max_duration: f64,
    /// ∫ F dt over every contact's loaded steps (N·s).
    pub impulse: f64,
    /// Peak forces of every impact.
    pub histogram: HistogramReport,
    /// The contacts with the largest peak forces (up to 10, largest first).
    pub by_peak_force: Vec<RankedContact>,
    /// The contacts with the most impacts (up to 10, most first).
    pub by_impacts: Vec<RankedContact>,
}

/// Peak forces of the impacts in equal classes.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct HistogramReport {
    /// Class edges (N), from 0 to the largest peak: class k holds [edge k, edge k + 1).
    pub edges: Vec<f64>,
    /// Impacts per class, every contact.
    pub counts: Vec<u64>,
}

/// A contact in a ranking.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ToSchema)]
pub struct RankedContact {
    pub contact: usize,
    /// Its largest force (N) and impact count.
    pub max_force: f64,
    pub impacts: u64,
}

/// The summary of `simulation`'s impacts, counted as `counting` says.
pub fn summary(simulation: &Simulation, counting: &ImpactCounting) -> ImpactSummary {
    let statistics = &simulation.impact_statistics;
    let ranked = |key: &dyn Fn(&ImpactStatistics) -> f64| {
        let mut order: Vec<usize> = (0..statistics.len())
            .filter(|&c| statistics[c].summary.impacts > 0)
            .collect();
        // Stable: ties keep contact order.
        order.sort_by(|&a, &b| key(&statistics[b]).total_cmp(&key(&statistics[a])));
        order
            .into_iter()
            .take(RANKED)
            .map(|c| RankedContact {
                contact: c,
                max_force: statistics[c].summary.max_force,
                impacts: statistics[c].summary.impacts,
            })
            .collect()
    };
    let table = &simulation.impact_table;
    ImpactSummary {
        force_threshold: counting.force_threshold,
        rest_time: counting.rest_time,
        blocks: counting.blocks,
        impacts: statistics.iter().map(|s| s.summary.impacts).sum(),
        tabulated: table.rows.len() as u64,
        untabulated: table.untabulated,
        truncated: table.truncated(),
        max_rows: counting.max_rows,
        fair_share: table.fair_share,
        untabulated_max_peak: table.untabulated_max_peak,
        max_impact_energy: statistics.iter().map(|s| s.max_impact_energy).fold(0.0, f64::max),
        max_duration: statistics.iter().map(|s| s.max_duration).fold(0.0, f64::max),
        impulse: statistics.iter().map(|s| s.summary.impulse).sum(),
        histogram: HistogramReport {
            edges: simulation.impact_histogram.edges.clone(),
            counts: simulation.impact_histogram.counts.clone(),
        },
        by_peak_force: ranked(&|s| s.summary.max_force),
        by_impacts: ranked(&|s| s.summary.impacts as f64),
    }
}

/// Series a truncated table stores after the rows' columns: the run's impact count
/// (the same on every row) and the row's contact's.
const STORED_COUNTS: [&str; 2] = ["impacts", "contact_impacts"];

/// The CSV columns a truncated table adds after [`COLUMNS`], on every row: `truncated`
/// (`true`), the run's `impacts` and `tabulated` rows, the row's contact's
/// `contact_impacts` and `contact_tabulated` rows. Counts of the whole table, whatever
/// the filter and the page.
pub const TRUNCATION_COLUMNS: [&str; 5] = [
    "truncated",
    "impacts",
    "tabulated",
    "contact_impacts",
    "contact_tabulated",
];

/// The table as stored with the histories: `time` holds the starts, the other columns
/// are series (contact and rebound counts exact as f64); a truncated table adds the
/// [`STORED_COUNTS`] series, so that its counts are read with its rows.
pub fn table_history(table: &ImpactTable) -> History {
    let column = |value: fn(&Impact) -> f64| table.rows.iter().map(value).collect::<Vec<f64>>();
    let mut series = vec![
        ("contact".to_owned(), column(|r| r.contact as f64)),
        ("peak_time".to_owned(), column(|r| r.peak_time)),
        ("peak_force".to_owned(), column(|r| r.peak_force)),
        ("impulse".to_owned(), column(|r| r.impulse)),
        ("duration".to_owned(), column(|r| r.duration)),
        ("approach_velocity".to_owned(), column(|r| r.approach_velocity)),
        ("rebounds".to_owned(), column(|r| r.rebounds as f64)),
        ("dissipated".to_owned(), column(|r| r.dissipated)),
        ("energy".to_owned(), column(|r| r.energy)),
    ];
    if table.truncated() {
        let [run, contact] = STORED_COUNTS.map(str::to_owned);
        series.push((run, vec![table.impacts as f64; table.rows.len()]));
        let of_contact = |r: &Impact| table.contact_impacts.get(r.contact).copied().unwrap_or(0) as f64;
        series.push((contact, table.rows.iter().map(of_contact).collect()));
    }
    History {
        name: TABLE.to_owned(),
        time: column(|r| r.start),
        series,
    }
}

/// The per-impact table as read back from the store.
#[derive(Debug, Clone, PartialEq)]
pub struct StoredTable {
    /// Sorted by start, then contact.
    pub rows: Vec<Impact>,
    /// What a truncated table left out; `None` for a complete one.
    pub truncation: Option<Truncation>,
}

/// The counts of a truncated table.
#[derive(Debug, Clone, PartialEq)]
pub struct Truncation {
    /// Every impact of the run.
    pub impacts: u64,
    /// Per contact with rows: its impacts, and its rows.
    contacts: HashMap<usize, (u64, u64)>,
}

impl Truncation {
    /// A contact's impacts and rows (a contact without rows: its impacts are not stored
    /// with the table, `None`).
    pub fn contact(&self, contact: usize) -> Option<(u64, u64)> {
        self.contacts.get(&contact).copied()
    }
}

impl StoredTable {
    /// Impacts of the run: every one, tabulated or not.
    pub fn impacts(&self) -> u64 {
        self.truncation
            .as_ref()
            .map_or(self.rows.len() as u64, |t| t.impacts)
    }

    /// Rows of the whole table.
    pub fn tabulated(&self) -> u64 {
        self.rows.len() as u64
    }
}

/// The table stored by [`table_history`]; `None` when `history` is not one.
pub fn read_table(history: &History) -> Option<StoredTable> {
    let names: Vec<&str> = history.series.iter().map(|(n, _)| n.as_str()).collect();
    let columns: Vec<&str> = COLUMNS.iter().copied().filter(|c| *c != "start").collect();
    let truncated = match names.strip_prefix(columns.as_slice()) {
        Some([]) => false,
        Some(rest) if rest == STORED_COUNTS => true,
        _ => return None,
    };
    let value = |k: usize, row: usize| history.series[k].1[row];
    let rows: Vec<Impact> = (0..history.time.len())
        .map(|row| Impact {
            contact: value(0, row) as usize,
            start: history.time[row],
            peak_time: value(1, row),
            peak_force: value(2, row),
            impulse: value(3, row),
            duration: value(4, row),
            approach_velocity: value(5, row),
            rebounds: value(6, row) as u64,
            dissipated: value(7, row),
            energy: value(8, row),
        })
        .collect();
    let truncation = truncated.then(|| {
        let mut contacts: HashMap<usize, (u64, u64)> = HashMap::new();
        for (row, impact) in rows.iter().enumerate() {
            let entry = contacts.entry(impact.contact).or_default();
            entry.0 = value(10, row) as u64;
            entry.1 += 1;
        }
        Truncation {
            // A truncated table holds at least one row (`max_rows` ≥ 1).
            impacts: rows.first().map_or(0, |_| value(9, 0) as u64),
            contacts,
        }
    });
    Some(StoredTable { rows, truncation })
}

/// CSV text of `rows` of `table` (a page of it, or all of it) with the [`COLUMNS`]
/// header, and when the table is truncated the [`TRUNCATION_COLUMNS`]: counts as
/// integers, every other number as [`crate::csv_format`] writes it (as the histories).
pub fn table_csv<'a>(table: &StoredTable, rows: impl IntoIterator<Item = &'a Impact>) -> String {
    use crate::csv_format::number;
    use std::fmt::Write;
    let mut out = COLUMNS.join(",");
    if table.truncation.is_some() {
        out.push(',');
        out.push_str(&TRUNCATION_COLUMNS.join(","));
    }
    out.push('\n');
    for r in rows {
        let _ = write!(
            out,
            "{},{},{},{},{},{},{},{},{},{}",
            r.contact,
            number(r.start),
            number(r.peak_time),
            number(r.peak_force),
            number(r.impulse),
            number(r.duration),
            number(r.approach_velocity),
            r.rebounds,
            number(r.dissipated),
            number(r.energy)
        );
        if let Some(truncation) = &table.truncation {
            let (impacts, tabulated) = truncation.contact(r.contact).unwrap_or_default();
            let _ = write!(
                out,
                ",true,{},{},{impacts},{tabulated}",
                truncation.impacts,
                table.tabulated()
            );
        }
        out.push('\n');
    }
    out
}

/// Name of the response header that says whether the served table is complete.
pub const HEADER: &str = "impact-table";

/// The [`HEADER`] value of `table`, a structured-field dictionary (RFC 8941):
/// `complete, impacts=6, tabulated=6`, or `truncated, impacts=2034117, tabulated=100000`
/// (counts of the whole table, whatever the filter and the page).
pub fn header_value(table: &StoredTable) -> String {
    let state = if table.truncation.is_some() {
        "truncated"
    } else {
        "complete"
    };
    format!(
        "{state}, impacts={}, tabulated={}",
        table.impacts(),
        table.tabulated()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn impact(contact: usize, start: f64) -> Impact {
        Impact {
            contact,
            start,
            peak_time: start + 1e-4,
            peak_force: 12.5,
            impulse: 1e-3,
            duration: 2e-4,
            approach_velocity: -0.1,
            rebounds: 2,
            dissipated: 1e-6,
            energy: 3e-5,
        }
    }

    fn table(rows: Vec<Impact>, contact_impacts: Vec<u64>) -> ImpactTable {
        let mut contact_tabulated = vec![0; contact_impacts.len()];
        for r in &rows {
            contact_tabulated[r.contact] += 1;
        }
        let impacts: u64 = contact_impacts.iter().sum();
        ImpactTable {
            untabulated: impacts - rows.len() as u64,
            rows,
            impacts,
            max_rows: 3,
            fair_share: 0,
            contact_impacts,
            contact_tabulated,
            untabulated_max_peak: None,
        }
    }

    #[test]
    fn the_stored_table_reads_back_row_for_row() {
        let complete = table(vec![impact(3, 0.1), impact(0, 0.1), impact(7, 0.25)], {
            let mut counts = vec![0; 8];
            (counts[0], counts[3], counts[7]) = (1, 1, 1);
            counts
        });
        let history = table_history(&complete);
        let stored = read_table(&history).expect("a table");
        assert_eq!(stored.rows, complete.rows);
        assert_eq!(stored.truncation, None);
        assert_eq!((stored.impacts(), stored.tabulated()), (3, 3));
        let csv = table_csv(&stored, &stored.rows);
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(COLUMNS.join(",").as_str()));
        assert!(
            lines
                .next()
                .is_some_and(|l| l.starts_with("3,0.1,") && l.split(',').count() == COLUMNS.len())
        );
        assert_eq!(header_value(&stored), "complete, impacts=3, tabulated=3");
        // A history that is not a table is not read as one.
        let other = History {
            name: "contact_forces".into(),
            time: vec![0.0],
            series: vec![("c0".into(), vec![0.0])],
        };
        assert_eq!(read_table(&other), None);
    }

    /// Three rows kept of 12 impacts (contact 0: 2 of 10, contact 5: 1 of 2): the counts
    /// come back with the rows, on every CSV row, in the header.
    #[test]
    fn a_truncated_table_stores_and_writes_its_counts() {
        let mut counts = vec![0; 6];
        (counts[0], counts[5]) = (10, 2);
        let truncated = table(vec![impact(0, 0.1), impact(5, 0.2), impact(0, 0.3)], counts);
        let stored = read_table(&table_history(&truncated)).expect("a table");
        assert_eq!(stored.rows, truncated.rows);
        let truncation = stored.truncation.as_ref().expect("truncated");
        assert_eq!(
            (truncation.impacts, truncation.contact(0), truncation.contact(5)),
            (12, Some((10, 2)), Some((2, 1)))
        );
        assert_eq!(header_value(&stored), "truncated, impacts=12, tabulated=3");
        // A page of contact 5 alone still gives the whole table's counts.
        let csv = table_csv(&stored, stored.rows.iter().filter(|r| r.contact == 5));
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines[0],
            format!("{},{}", COLUMNS.join(","), TRUNCATION_COLUMNS.join(","))
        );
        assert_eq!(lines.len(), 2);
        assert!(lines[1].starts_with("5,0.2,"), "{}", lines[1]);
        assert!(lines[1].ends_with(",true,12,3,2,1"), "{}", lines[1]);
    }

    #[test]
    fn the_table_estimate_is_bounded_by_rows_and_by_steps() {
        let counting = ImpactCounting::default();
        assert_eq!(table_values(&counting, 3, 11.0), 3.0 * 6.0 * 10.0);
        // Past the cap, a row also stores its counts.
        let few = ImpactCounting {
            max_rows: 7,
            ..ImpactCounting::default()
        };
        assert_eq!(table_values(&few, 1000, 1e6), 7.0 * 12.0);
    }
}
