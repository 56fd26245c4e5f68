//! Statistics tables of a sweep for design: for each grid cell of the list axes, each
//! figure (a numeric column of the results table, or a member of a run's contact or pin
//! entry, [`super::items`]) summarised over the successful runs, with the one-sided
//! upper bound of Wilks at a requested coverage and confidence ([`BoundRequest`]), and
//! how many runs that bound needs.
//!
//! The tables are long (one row per cell, item and figure), flat and the same in JSON
//! and CSV, so that a script reads them straight into a data frame.

use serde::Serialize;
use serde_json::{Map, Value};

use super::aggregate;
use super::table::{Table, is_seed};
use super::wilks;

/// The bound asked for: the `coverage`-quantile p bounded from above with confidence γ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundRequest {
    /// p, in (0, 1).
    pub coverage: f64,
    /// γ, in (0, 1).
    pub confidence: f64,
}

impl Default for BoundRequest {
    /// 95 %/95 %, the aggregates' bound.
    fn default() -> Self {
        Self {
            coverage: wilks::COVERAGE,
            confidence: wilks::LEVEL,
        }
    }
}

/// A query parameter refused: which, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterFault {
    pub parameter: &'static str,
    pub reason: String,
}

impl std::fmt::Display for ParameterFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` {}", self.parameter, self.reason)
    }
}

impl BoundRequest {
    /// The bound of `coverage` and `confidence` as given in a query (each defaults to
    /// 0.95): numbers strictly between 0 and 1 whose first-order bound needs at most
    /// [`wilks::MAX_RUNS_NEEDED`] runs.
    pub fn parse(coverage: Option<&str>, confidence: Option<&str>) -> Result<Self, ParameterFault> {
        let fraction = |parameter: &'static str, text: Option<&str>, default: f64| match text {
            None => Ok(default),
            Some(text) => text
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|p| *p > 0.0 && *p < 1.0)
                .ok_or_else(|| ParameterFault {
                    parameter,
                    reason: format!("must be a number strictly between 0 and 1, not `{text}`"),
                }),
        };
        let request = Self {
            coverage: fraction("coverage", coverage, wilks::COVERAGE)?,
            confidence: fraction("confidence", confidence, wilks::LEVEL)?,
        };
        if request.runs_needed(1).is_none() {
            return Err(ParameterFault {
                parameter: "coverage",
                reason: format!(
                    "{} with confidence {} needs more than {} runs",
                    request.coverage,
                    request.confidence,
                    wilks::MAX_RUNS_NEEDED
                ),
            });
        }
        Ok(request)
    }

    /// The fewest runs whose `rank`-th largest is the bound.
    pub fn runs_needed(&self, rank: usize) -> Option<usize> {
        wilks::runs_needed(rank, self.coverage, self.confidence)
    }
}

/// One figure over the runs: [`aggregate::Statistics`]' summary, the empirical quantile
/// at the requested coverage, and the requested bound.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FigureStatistics {
    /// Runs with a finite value.
    pub count: usize,
    pub mean: f64,
    /// Sample standard deviation (divisor n − 1; 0 for one run).
    pub std: f64,
    pub min: f64,
    pub max: f64,
    pub q05: f64,
    pub q50: f64,
    pub q95: f64,
    /// The empirical quantile at the requested coverage (same interpolation as q95).
    pub quantile: f64,
    /// The one-sided upper bound at the requested coverage and confidence: the
    /// `bound_rank`-th largest value; null with too few runs.
    pub bound: Option<f64>,
    /// Its rank from the top (1: the largest).
    pub bound_rank: Option<usize>,
    /// The fewest runs that give the bound at the rank in use (rank 1 while there is
    /// none): below it, `bound` is null.
    pub runs_needed: Option<usize>,
}

impl FigureStatistics {
    /// The statistics of `values` (finite) for `request`; `None` when empty.
    pub fn of(values: &[f64], request: BoundRequest) -> Option<Self> {
        let summary = aggregate::statistics(values)?;
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let rank = wilks::upper_rank(n, request.coverage, request.confidence);
        Some(Self {
            count: summary.count,
            mean: summary.mean,
            std: summary.std,
            min: summary.min,
            max: summary.max,
            q05: summary.q05,
            q50: summary.q50,
            q95: summary.q95,
            quantile: aggregate::quantile(&sorted, request.coverage),
            bound: rank.map(|r| sorted[n - r]),
            bound_rank: rank,
            runs_needed: request.runs_needed(rank.unwrap_or(1)),
        })
    }
}

/// Names of a statistics row's own columns, after the cell's axes, the item and `figure`.
pub const STATISTICS_COLUMNS: [&str; 13] = [
    "runs",
    "count",
    "mean",
    "std",
    "min",
    "max",
    "q05",
    "q50",
    "q95",
    "quantile",
    "bound",
    "bound_rank",
    "runs_needed",
];

/// A long table: its columns and one flat record per row.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StatisticsTable {
    pub columns: Vec<String>,
    pub rows: Vec<Map<String, Value>>,
}

impl StatisticsTable {
    /// CSV with the columns as header; a null is an empty cell.
    pub fn to_csv(&self) -> String {
        crate::csv_format::records(&self.columns, &self.rows)
    }
}

/// The columns of a statistics table: the list axes, the item's key (`contact`, `pin`;
/// none for run-wide figures), `figure`, then the statistics.
pub fn statistics_columns(list_axes: &[String], item: Option<&str>) -> Vec<String> {
    let mut columns: Vec<String> = list_axes.to_vec();
    columns.extend(item.map(str::to_owned));
    columns.push("figure".into());
    columns.extend(STATISTICS_COLUMNS.iter().map(|c| (*c).to_owned()));
    columns
}

/// One row: the cell's axis values, the item (key and index), the figure, the number of
/// runs in the cell, and the statistics.
pub fn statistics_row(
    cell: &Map<String, Value>,
    item: Option<(&str, usize)>,
    figure: &str,
    runs: usize,
    statistics: &FigureStatistics,
) -> Map<String, Value> {
    let mut row = cell.clone();
    if let Some((key, index)) = item {
        row.insert(key.to_owned(), Value::from(index));
    }
    row.insert("figure".into(), Value::from(figure));
    row.insert("runs".into(), Value::from(runs));
    if let Ok(Value::Object(members)) = serde_json::to_value(statistics) {
        row.extend(members);
    }
    row
}

/// The numeric values of `column` in `rows`, finite ones only, in row order.
fn column_values(rows: &[&Map<String, Value>], column: &str) -> Vec<f64> {
    rows.iter()
        .filter_map(|row| match row.get(column) {
            Some(Value::Number(n)) => n.as_f64().filter(|x| x.is_finite()),
            _ => None,
        })
        .collect()
}

/// The run-wide figures: for each cell of `list_axes`, every numeric column of the
/// results `table` (the random axes `numeric_axes` and the metrics, seeds left out) over
/// its successful runs.
pub fn run_statistics(
    table: &Table,
    list_axes: &[String],
    numeric_axes: &[String],
    request: BoundRequest,
) -> StatisticsTable {
    let figures: Vec<&String> = numeric_axes
        .iter()
        .chain(&table.metrics)
        .filter(|column| !is_seed(column) && !list_axes.contains(column))
        .collect();
    let mut rows = Vec::new();
    for (cell, cell_rows) in aggregate::cells(table, list_axes) {
        for figure in &figures {
            let values = column_values(&cell_rows, figure);
            if let Some(statistics) = FigureStatistics::of(&values, request) {
                rows.push(statistics_row(&cell, None, figure, cell_rows.len(), &statistics));
            }
        }
    }
    StatisticsTable {
        columns: statistics_columns(list_axes, None),
        rows,
    }
}

/// Columns of the convergence table after the cell's axes.
pub const CONVERGENCE_COLUMNS: [&str; 7] = [
    "sample",
    "run",
    "value",
    "quantile",
    "bound",
    "bound_rank",
    "runs",
];

/// How `figure` (a numeric column of `table`) converges: for each cell, at each of its
/// successful runs in the order they were drawn (sample order), the run's value, and the
/// empirical quantile and the bound of the cell's first `runs` values
/// ([`wilks::convergence`]). A run whose value is missing or not finite is skipped.
/// `Err` when no row has `figure` as a number: the numeric columns there are.
pub fn convergence(
    table: &Table,
    list_axes: &[String],
    figure: &str,
    request: BoundRequest,
) -> Result<StatisticsTable, ParameterFault> {
    let mut rows = Vec::new();
    let mut found = false;
    for (cell, cell_rows) in aggregate::cells(table, list_axes) {
        let drawn: Vec<(&Map<String, Value>, f64)> = cell_rows
            .iter()
            .filter_map(|row| match row.get(figure) {
                Some(Value::Number(n)) => n.as_f64().filter(|x| x.is_finite()).map(|x| (*row, x)),
                _ => None,
            })
            .collect();
        found |= !drawn.is_empty();
        let values: Vec<f64> = drawn.iter().map(|(_, x)| *x).collect();
        let track = wilks::convergence(&values, request.coverage, request.confidence);
        for ((row, _), step) in drawn.iter().zip(track) {
            let mut out = cell.clone();
            out.insert("sample".into(), Value::from(step.runs - 1));
            out.insert("run".into(), row.get("run").cloned().unwrap_or(Value::Null));
            out.insert("value".into(), Value::from(step.value));
            out.insert("quantile".into(), Value::from(step.quantile));
            out.insert("bound".into(), step.bound.map_or(Value::Null, Value::from));
            out.insert(
                "bound_rank".into(),
                step.bound_rank.map_or(Value::Null, Value::from),
            );
            out.insert("runs".into(), Value::from(step.runs));
            rows.push(out);
        }
    }
    if !found {
        let numeric: Vec<&str> = table
            .metrics
            .iter()
            .filter(|m| {
                table
                    .rows
                    .iter()
                    .any(|row| row.get(*m).is_some_and(Value::is_number))
            })
            .map(String::as_str)
            .take(20)
            .collect();
        return Err(ParameterFault {
            parameter: "figure",
            reason: format!(
                "`{figure}` is no numeric column of this sweep's successful runs (some that are: {})",
                numeric.join(", ")
            ),
        });
    }
    let mut columns: Vec<String> = list_axes.to_vec();
    columns.extend(CONVERGENCE_COLUMNS.iter().map(|c| (*c).to_owned()));
    Ok(StatisticsTable { columns, rows })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_and_confidence_are_fractions_named_when_refused() {
        assert_eq!(BoundRequest::parse(None, None), Ok(BoundRequest::default()));
        let request = BoundRequest::parse(Some("0.99"), Some("0.9")).unwrap();
        assert_eq!((request.coverage, request.confidence), (0.99, 0.9));
        for (coverage, confidence, parameter) in [
            (Some("1"), None, "coverage"),
            (Some("0"), None, "coverage"),
            (Some("x"), None, "coverage"),
            (Some("NaN"), None, "coverage"),
            (None, Some("1.5"), "confidence"),
            (None, Some("-0.1"), "confidence"),
            (Some("0.9999999999999999"), None, "coverage"),
        ] {
            let fault = BoundRequest::parse(coverage, confidence).unwrap_err();
            assert_eq!(fault.parameter, parameter, "{coverage:?} {confidence:?}: {fault}");
        }
    }

    /// 59 values: the largest is the 95 %/95 % bound; at 99 %/95 % there is none yet and
    /// 299 runs are needed (1 − 0.99^n ≥ 0.95).
    #[test]
    fn figure_statistics_give_the_bound_its_rank_and_the_runs_it_needs() {
        let values: Vec<f64> = (0..59).map(|i| f64::from((i * 7) % 59)).collect();
        let at_95 = FigureStatistics::of(&values, BoundRequest::default()).unwrap();
        assert_eq!(
            (at_95.bound, at_95.bound_rank, at_95.runs_needed),
            (Some(58.0), Some(1), Some(59))
        );
        let at_99 = FigureStatistics::of(&values, BoundRequest::parse(Some("0.99"), None).unwrap()).unwrap();
        assert_eq!(
            (at_99.bound, at_99.bound_rank, at_99.runs_needed),
            (None, None, Some(299))
        );
        let expected_runs = (0.05f64.ln() / 0.99f64.ln()).ceil() as usize;
        assert_eq!(at_99.runs_needed, Some(expected_runs));
        assert_eq!(
            at_99.quantile,
            aggregate::quantile(&(0..59).map(f64::from).collect::<Vec<_>>(), 0.99)
        );
    }
}
