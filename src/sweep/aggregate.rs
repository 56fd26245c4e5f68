//! Aggregates of a sweep's results table.
//!
//! - Random sweeps: for every numeric column (random axes and metrics; not seeds) over the
//!   successful runs of each grid cell of the list axes (one cell without list axes):
//!   count, mean, sample standard deviation (divisor n − 1; 0 for one run), min, max and
//!   the 5 %, 50 %, 95 % quantiles (linear interpolation between order statistics: the
//!   p-quantile of sorted x₀..xₙ₋₁ is at position p·(n − 1)), and the one-sided
//!   95 %/95 % upper bound of Wilks ([`super::wilks`]; from 59 runs).
//! - Calibration grids (rows with `comparison.f_err`): the validity map, run by run
//!   (valid when f_err < threshold, the run's own `comparison.threshold`, else 0.2; a
//!   failed run, e.g. diverged, is not valid), and for each combination of the other
//!   axes the cheapest valid value of `/solver/time_step` (largest), `/beam/modes` and
//!   `/beam/elements` (fewest) when the sweep has such an axis.
//! - Quality (any sweep whose rows have `quality.verdict`): how many successful runs
//!   were judged `good`, `doubtful` and `poor`, in total and for each value of each list
//!   axis (a random axis has a value per run: its runs are counted in the total only).

use serde_json::{Map, Value, json};

use super::table::Table;
use crate::physics::integrate::Verdict;
use crate::quality_note::parse_verdict;

/// A row of the results table.
type Row = Map<String, Value>;
/// The list-axis values of a grid cell, with its rows.
pub type Cell<'a> = (Row, Vec<&'a Row>);
/// For given values of the other axes: the best valid (value, value as JSON, run) so far.
type Choice = (Row, Option<(f64, Value, Value)>);

/// Validity threshold of f_err when a run does not state its own (paper: 0.2).
pub const DEFAULT_THRESHOLD: f64 = 0.2;

/// Metric column of the calibration map.
pub const F_ERR: &str = "comparison.f_err";

/// Axes whose cheapest valid value is reported, and whether cheapest means largest.
pub const COST_AXES: [(&str, bool); 3] = [
    ("/solver/time_step", true),
    ("/beam/modes", false),
    ("/beam/elements", false),
];

/// Metric column of a run's quality verdict (`good`, `unchecked`, `doubtful`, `poor`).
pub const VERDICT: &str = "quality.verdict";

/// The aggregates of a sweep's results (`aggregates` of its results document); which
/// ones depend on its design and its runs' metrics.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Aggregates {
    /// Grids whose runs report f_err: the validity map ([`calibration`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub calibration: Option<Value>,
    /// Runs that carry a quality verdict: the counts ([`quality_counts`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quality: Option<QualityCounts>,
    /// Random designs: statistics per grid cell of the list axes ([`cell_statistics`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub statistics: Option<Value>,
}

/// How many successful runs got each verdict.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct VerdictCounts {
    /// Successful runs with a verdict.
    pub runs: usize,
    pub good: usize,
    /// Within the tolerance by every measure taken, the step's error not measured
    /// (`solver.check: "none"`, the usual setting of a sweep).
    pub unchecked: usize,
    pub doubtful: usize,
    pub poor: usize,
}

impl VerdictCounts {
    fn add(&mut self, verdict: Verdict) {
        self.runs += 1;
        match verdict {
            Verdict::Good => self.good += 1,
            Verdict::Unchecked => self.unchecked += 1,
            Verdict::Doubtful => self.doubtful += 1,
            Verdict::Poor => self.poor += 1,
        }
    }
}

/// The verdict counts of the runs that share one value of an axis.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ValueQuality {
    /// The axis value, as in the table.
    pub value: Value,
    #[serde(flatten)]
    pub counts: VerdictCounts,
}

/// The verdict counts along one list axis, one entry per value in order of first appearance.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AxisQuality {
    /// The axis pointer, e.g. `/solver/time_step`.
    pub axis: String,
    pub values: Vec<ValueQuality>,
}

/// The quality of a sweep's runs: verdict counts in total and per list-axis value.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct QualityCounts {
    #[serde(flatten)]
    pub total: VerdictCounts,
    pub by_axis: Vec<AxisQuality>,
}

/// Verdict counts of the successful runs, in total and per value of each of
/// `list_axes`; `None` when no row has a verdict (a process without a quality section).
pub fn quality_counts(table: &Table, list_axes: &[String]) -> Option<QualityCounts> {
    if !table.metrics.iter().any(|m| m == VERDICT) {
        return None;
    }
    let mut total = VerdictCounts::default();
    let mut by_axis: Vec<AxisQuality> = list_axes
        .iter()
        .map(|axis| AxisQuality {
            axis: axis.clone(),
            values: Vec::new(),
        })
        .collect();
    for row in &table.rows {
        if row.get("status").and_then(Value::as_str) != Some("successful") {
            continue;
        }
        let Some(verdict) = row.get(VERDICT).and_then(Value::as_str).and_then(parse_verdict) else {
            continue;
        };
        total.add(verdict);
        for axis in &mut by_axis {
            let value = row.get(&axis.axis).cloned().unwrap_or(Value::Null);
            match axis.values.iter_mut().find(|v| v.value == value) {
                Some(entry) => entry.counts.add(verdict),
                None => {
                    let mut counts = VerdictCounts::default();
                    counts.add(verdict);
                    axis.values.push(ValueQuality { value, counts });
                }
            }
        }
    }
    Some(QualityCounts { total, by_axis })
}

/// Summary statistics of one column.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Statistics {
    pub count: usize,
    pub mean: f64,
    /// Sample standard deviation (divisor n − 1).
    pub std: f64,
    pub min: f64,
    pub max: f64,
    pub q05: f64,
    pub q50: f64,
    pub q95: f64,
    /// The one-sided 95 %/95 % upper tolerance bound (Wilks, distribution-free): the
    /// value the 95 % quantile stays below with 95 % confidence, the `bound_95_95_rank`-th
    /// largest; null below 59 runs.
    pub bound_95_95: Option<f64>,
    /// Its rank from the top (1: the largest, from 59 runs; 2 from 93; 3 from 124).
    pub bound_95_95_rank: Option<usize>,
}

/// Statistics of `values` (finite numbers); `None` when empty.
pub fn statistics(values: &[f64]) -> Option<Statistics> {
    if values.is_empty() {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let mean = sorted.iter().sum::<f64>() / n as f64;
    let variance = if n > 1 {
        sorted.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64
    } else {
        0.0
    };
    Some(Statistics {
        count: n,
        mean,
        std: variance.sqrt(),
        min: sorted[0],
        max: sorted[n - 1],
        q05: quantile(&sorted, 0.05),
        q50: quantile(&sorted, 0.50),
        q95: quantile(&sorted, 0.95),
        bound_95_95: super::wilks::upper_bound(&sorted).map(|(value, _)| value),
        bound_95_95_rank: super::wilks::upper_bound(&sorted).map(|(_, rank)| rank),
    })
}

/// The p-quantile of sorted values, interpolating linearly at position p·(n − 1).
pub fn quantile(sorted: &[f64], p: f64) -> f64 {
    let position = p * (sorted.len() - 1) as f64;
    let below = position.floor() as usize;
    let above = (below + 1).min(sorted.len() - 1);
    let weight = position - below as f64;
    sorted[below] + (sorted[above] - sorted[below]) * weight
}

/// The successful rows of `table` grouped by grid cell of `list_axes` (the axes' values
/// of the row), cells in order of first appearance, rows in table order.
pub fn cells<'a>(table: &'a Table, list_axes: &[String]) -> Vec<Cell<'a>> {
    let mut cells: Vec<Cell<'a>> = Vec::new();
    for row in &table.rows {
        if row.get("status").and_then(Value::as_str) != Some("successful") {
            continue;
        }
        let cell = cell_of(row, list_axes);
        match cells.iter_mut().find(|(c, _)| *c == cell) {
            Some((_, rows)) => rows.push(row),
            None => cells.push((cell, vec![row])),
        }
    }
    cells
}

/// The values at `list_axes` of a row.
fn cell_of(row: &Row, list_axes: &[String]) -> Row {
    list_axes
        .iter()
        .map(|p| (p.clone(), row.get(p).cloned().unwrap_or(Value::Null)))
        .collect()
}

/// Statistics per grid cell of `list_axes`, for `numeric_axes` and every metric column
/// but seeds ([`super::table::is_seed`]).
pub fn cell_statistics(table: &Table, list_axes: &[String], numeric_axes: &[String]) -> Value {
    let cells = cells(table, list_axes);
    // A seed names a draw: its mean or spread means nothing.
    let columns: Vec<&String> = numeric_axes
        .iter()
        .chain(&table.metrics)
        .filter(|column| !super::table::is_seed(column))
        .collect();
    let groups: Vec<Value> = cells
        .into_iter()
        .map(|(cell, rows)| {
            let mut metrics = Map::new();
            for column in &columns {
                let values: Vec<f64> = rows
                    .iter()
                    .filter_map(|row| match row.get(column.as_str()) {
                        Some(Value::Number(n)) => n.as_f64().filter(|x| x.is_finite()),
                        _ => None,
                    })
                    .collect();
                if let Some(stats) = statistics(&values) {
                    metrics.insert((*column).clone(), json!(stats));
                }
            }
            json!({"cell": cell, "runs": rows.len(), "metrics": metrics})
        })
        .collect();
    Value::Array(groups)
}

/// The validity map of a calibration grid over `axes`; `None` without any f_err.
pub fn calibration(table: &Table, axes: &[String]) -> Option<Value> {
    if !table.metrics.iter().any(|m| m == F_ERR) {
        return None;
    }
    let mut threshold = DEFAULT_THRESHOLD;
    let mut cells = Vec::new();
    for row in &table.rows {
        let status = row.get("status").and_then(Value::as_str).unwrap_or_default();
        if !(status == "successful" || status == "failed") {
            continue;
        }
        let f_err = row.get(F_ERR).and_then(Value::as_f64);
        let run_threshold = row
            .get("comparison.threshold")
            .and_then(Value::as_f64)
            .unwrap_or(DEFAULT_THRESHOLD);
        threshold = run_threshold;
        let parameters: Map<String, Value> = axes
            .iter()
            .map(|p| (p.clone(), row.get(p).cloned().unwrap_or(Value::Null)))
            .collect();
        cells.push(json!({
            "run": row.get("run"),
            "parameters": parameters,
            "f_err": f_err,
            "valid": f_err.is_some_and(|e| e < run_threshold),
        }));
    }
    let cheapest: Vec<Value> = COST_AXES
        .iter()
        .filter(|(axis, _)| axes.iter().any(|a| a == axis))
        .map(|(axis, largest)| cheapest_along(&cells, axes, axis, *largest))
        .collect();
    Some(json!({
        "metric": F_ERR,
        "threshold": threshold,
        "cells": cells,
        "cheapest": cheapest,
    }))
}

/// For each combination of the axes other than `axis`, its largest (or smallest) valid value.
fn cheapest_along(cells: &[Value], axes: &[String], axis: &str, largest: bool) -> Value {
    let mut choices: Vec<Choice> = Vec::new();
    for cell in cells {
        let parameters = cell["parameters"].as_object().cloned().unwrap_or_default();
        let given: Map<String, Value> = axes
            .iter()
            .filter(|a| *a != axis)
            .map(|a| (a.clone(), parameters.get(a).cloned().unwrap_or(Value::Null)))
            .collect();
        let index = match choices.iter().position(|(g, _)| *g == given) {
            Some(index) => index,
            None => {
                choices.push((given, None));
                choices.len() - 1
            }
        };
        let value = parameters.get(axis).and_then(Value::as_f64);
        if let (true, Some(x)) = (cell["valid"].as_bool() == Some(true), value) {
            let best = &mut choices[index].1;
            let better = match best {
                None => true,
                Some((current, _, _)) => {
                    if largest {
                        x > *current
                    } else {
                        x < *current
                    }
                }
            };
            if better {
                *best = Some((x, parameters[axis].clone(), cell["run"].clone()));
            }
        }
    }
    json!({
        "axis": axis,
        "rule": if largest { "largest valid value" } else { "smallest valid value" },
        "choices": choices.into_iter().map(|(given, best)| json!({
            "given": given,
            "value": best.as_ref().map(|b| b.1.clone()),
            "run": best.map(|b| b.2),
        })).collect::<Vec<_>>(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::table::{RunRecord, build};

    /// A random seed axis and a seed echoed in the results are columns of the table but
    /// not quantities: no mean of a seed; the other columns keep their statistics.
    #[test]
    fn seeds_are_left_out_of_the_statistics() {
        let records: Vec<RunRecord> = [(11_u64, 2.0), (573_700_123, 4.0)]
            .into_iter()
            .enumerate()
            .map(|(run, (seed, force))| RunRecord {
                run,
                job: format!("j{run}"),
                status: "successful".into(),
                inputs: json!({"gaps": {"seed": seed}, "rk": 1.0 + run as f64}),
                metrics: vec![("force".into(), json!(force)), ("gaps.seed".into(), json!(seed))],
            })
            .collect();
        let axes = ["/gaps/seed".to_owned(), "/rk".to_owned()];
        let table = build(&axes, &records);
        let cells = cell_statistics(&table, &[], &axes);
        let metrics = cells[0]["metrics"].as_object().unwrap();
        let mut names: Vec<&str> = metrics.keys().map(String::as_str).collect();
        names.sort_unstable();
        assert_eq!(names, ["/rk", "force"], "{metrics:?}");
        assert_eq!(metrics["force"]["mean"], 3.0);
    }

    #[test]
    fn statistics_match_values_computed_by_hand() {
        let stats = statistics(&[4.0, 1.0, 3.0, 2.0]).unwrap();
        assert_eq!(
            (stats.count, stats.mean, stats.min, stats.max),
            (4, 2.5, 1.0, 4.0)
        );
        assert!((stats.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-15, "{}", stats.std);
        assert!((stats.q50 - 2.5).abs() < 1e-15);
        assert!((stats.q05 - 1.15).abs() < 1e-12, "{}", stats.q05);
        assert!((stats.q95 - 3.85).abs() < 1e-12, "{}", stats.q95);
        assert_eq!(
            (stats.bound_95_95, stats.bound_95_95_rank),
            (None, None),
            "4 runs bound nothing"
        );
    }

    #[test]
    fn verdicts_are_counted_in_total_and_per_axis_value_over_successful_runs() {
        let record = |run: usize, status: &str, dt: f64, verdict: Option<&str>| RunRecord {
            run,
            job: format!("j{run}"),
            status: status.into(),
            inputs: json!({"solver": {"time_step": dt}}),
            metrics: verdict
                .map(|v| vec![(VERDICT.to_owned(), json!(v))])
                .unwrap_or_default(),
        };
        let axes = vec!["/solver/time_step".to_owned()];
        let table = build(
            &axes,
            &[
                record(0, "successful", 1e-5, Some("good")),
                record(1, "successful", 1e-5, Some("doubtful")),
                record(2, "successful", 1e-4, Some("poor")),
                record(3, "successful", 1e-4, Some("poor")),
                record(4, "failed", 1e-4, None),
                record(5, "successful", 1e-4, Some("unchecked")),
            ],
        );
        let counts = quality_counts(&table, &axes).unwrap();
        let expected = |runs, good, unchecked, doubtful, poor| VerdictCounts {
            runs,
            good,
            unchecked,
            doubtful,
            poor,
        };
        assert_eq!(counts.total, expected(5, 1, 1, 1, 2));
        let values = &counts.by_axis[0].values;
        assert_eq!(values.len(), 2, "{values:?}");
        assert_eq!(
            (values[0].value.clone(), values[0].counts.clone()),
            (json!(1e-5), expected(2, 1, 0, 1, 0))
        );
        assert_eq!(
            (values[1].value.clone(), values[1].counts.clone()),
            (json!(1e-4), expected(3, 0, 1, 0, 2))
        );
        let document = serde_json::to_value(&counts).unwrap();
        assert_eq!(document["poor"], 2);
        assert_eq!(document["by_axis"][0]["values"][1]["poor"], 2);
        let without = build(&axes, &[record(0, "successful", 1e-5, None)]);
        assert_eq!(quality_counts(&without, &axes), None);
    }

    #[test]
    fn the_largest_valid_time_step_is_found_for_each_rk() {
        let record = |run: usize, rk: f64, dt: f64, f_err: f64| RunRecord {
            run,
            job: format!("j{run}"),
            status: "successful".into(),
            inputs: json!({"contact": {"rk": rk}, "solver": {"time_step": dt}}),
            metrics: vec![(F_ERR.into(), json!(f_err))],
        };
        let axes = vec!["/contact/rk".to_owned(), "/solver/time_step".to_owned()];
        let table = build(
            &axes,
            &[
                record(0, 1.0, 1e-5, 0.01),
                record(1, 1.0, 1e-4, 0.1),
                record(2, 100.0, 1e-5, 0.05),
                record(3, 100.0, 1e-4, 0.9),
            ],
        );
        let map = calibration(&table, &axes).unwrap();
        let valid: Vec<bool> = map["cells"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["valid"].as_bool().unwrap())
            .collect();
        assert_eq!(valid, vec![true, true, true, false]);
        let choices = &map["cheapest"][0]["choices"];
        assert_eq!(choices[0]["value"], json!(1e-4));
        assert_eq!(choices[1]["value"], json!(1e-5));
        assert_eq!(choices[1]["given"], json!({"/contact/rk": 100.0}));
    }
}
