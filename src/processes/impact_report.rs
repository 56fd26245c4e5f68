//! Impacts as every process reports them (issue 19): the `output.impacts` and
//! `output.blocks` inputs, each contact's impact statistics, the run-wide summary (the
//! contacts ranked by peak force and by impact count, the peak-force histogram), and the
//! per-impact table, an output named `impacts` served page by page
//! (`/jobs/{id}/results/impacts`) and written by the CLI as `impacts.csv`.
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

/// Name of the per-impact table output.
pub const TABLE: &str = "impacts";

/// The per-impact table, as every process declares it.
pub const TABLE_OUTPUT: HistoryOutput = HistoryOutput {
    name: TABLE,
    kind: HistoryKind::Table,
    title: "Impacts, one row each",
    description: "CSV columns contact, start (s), peak_time (s), peak_force (N), impulse (N·s), duration (s), \
                  approach_velocity (m/s), rebounds, dissipated (J), energy (J), sorted by start; \
                  `?contact=` filters, `offset` and `limit` page",
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
    /// Rows of the per-impact table kept (the first impacts to end); the statistics count
    /// every impact. Counts against the history ceiling at 10 values a row, for at most
    /// one impact every two steps per contact.
    #[schema(default = 100000)]
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

/// Values the per-impact table can hold at most: 10 a row, for `max_rows` rows or one
/// impact every two steps per contact (an impact is a loaded step then an unloaded one),
/// whichever is fewer.
pub fn table_values(counting: &ImpactCounting, contacts: usize, steps: f64) -> f64 {
    let possible = contacts as f64 * (steps / 2.0).ceil();
    possible.min(counting.max_rows as f64) * TABLE_COLUMNS as f64
}

/// One contact's impacts.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct ContactImpacts {
    #[serde(flatten)]
    pub statistics: ImpactStatistics,
    /// Impacts per peak-force class (the classes of `impact_summary.histogram`).
    pub histogram: Vec<u64>,
}

/// Every contact's impacts, in contact order.
pub fn contact_reports(simulation: &Simulation) -> Vec<ContactImpacts> {
    simulation
        .impact_statistics
        .iter()
        .zip(&simulation.impact_histogram.per_contact)
        .map(|(statistics, histogram)| ContactImpacts {
            statistics: statistics.clone(),
            histogram: histogram.clone(),
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
    /// Rows of the per-impact table, and impacts left out of it (`max_rows`).
    pub tabulated: u64,
    pub untabulated: u64,
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

/// The table as stored with the histories: `time` holds the starts, the other columns
/// are series (contact and rebound counts exact as f64).
pub fn table_history(table: &ImpactTable) -> History {
    let column = |value: fn(&Impact) -> f64| table.rows.iter().map(value).collect::<Vec<f64>>();
    let series = vec![
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
    History {
        name: TABLE.to_owned(),
        time: column(|r| r.start),
        series,
    }
}

/// The rows of a table stored by [`table_history`]; `None` when it is not one.
pub fn rows_of(history: &History) -> Option<Vec<Impact>> {
    let names: Vec<&str> = history.series.iter().map(|(n, _)| n.as_str()).collect();
    if names
        != COLUMNS
            .iter()
            .copied()
            .filter(|c| *c != "start")
            .collect::<Vec<_>>()
    {
        return None;
    }
    let value = |k: usize, row: usize| history.series[k].1[row];
    Some(
        (0..history.time.len())
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
            .collect(),
    )
}

/// CSV text of `rows` with the [`COLUMNS`] header: counts as integers, every other
/// number as [`crate::csv_format`] writes it (as the histories).
pub fn table_csv<'a>(rows: impl IntoIterator<Item = &'a Impact>) -> String {
    use crate::csv_format::number;
    let mut out = COLUMNS.join(",");
    out.push('\n');
    for r in rows {
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
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
        ));
    }
    out
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

    #[test]
    fn the_stored_table_reads_back_row_for_row() {
        let table = ImpactTable {
            rows: vec![impact(3, 0.1), impact(0, 0.1), impact(7, 0.25)],
            untabulated: 0,
        };
        let history = table_history(&table);
        assert_eq!(rows_of(&history), Some(table.rows.clone()));
        let csv = table_csv(&table.rows);
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(COLUMNS.join(",").as_str()));
        assert!(
            lines
                .next()
                .is_some_and(|l| l.starts_with("3,0.1,") && l.contains(",2,"))
        );
        // A history that is not a table is not read as one.
        let other = History {
            name: "contact_forces".into(),
            time: vec![0.0],
            series: vec![("c0".into(), vec![0.0])],
        };
        assert_eq!(rows_of(&other), None);
    }

    #[test]
    fn the_table_estimate_is_bounded_by_rows_and_by_steps() {
        let counting = ImpactCounting::default();
        assert_eq!(table_values(&counting, 3, 11.0), 3.0 * 6.0 * 10.0);
        let few = ImpactCounting {
            max_rows: 7,
            ..ImpactCounting::default()
        };
        assert_eq!(table_values(&few, 1000, 1e6), 70.0);
    }
}
