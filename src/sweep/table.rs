//! The results table of a sweep: one row per run that ended, with its run number, job id,
//! status, the value of every axis (a column named by its pointer, `/contact/rk`), then
//! the run's scalar results flattened with dots (`comparison.f_err`,
//! `contacts.3.max_force`).

use serde_json::{Map, Value};

/// What the table needs of one run.
#[derive(Debug, Clone)]
pub struct RunRecord {
    pub run: usize,
    pub job: String,
    /// Job status (`successful`, `failed`, `dismissed`, ...).
    pub status: String,
    /// The run's inputs (the axis values are read from them).
    pub inputs: Value,
    /// Scalar results, flattened (empty unless successful).
    pub metrics: Vec<(String, Value)>,
}

/// Columns and rows (each row an object keyed by column).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    /// Names of the metric columns (after `run`, `job`, `status` and the axes).
    pub metrics: Vec<String>,
    pub rows: Vec<Map<String, Value>>,
}

/// Fixed leading columns.
pub const LEADING: [&str; 3] = ["run", "job", "status"];

/// Whether a column (an axis pointer, `/bundle/gaps/seed`, or a metric, `gaps.seed`) is
/// a random generator's seed: an integer that names a draw, not a quantity. Seeds are
/// generated as integers and left out of the statistics.
pub fn is_seed(column: &str) -> bool {
    column.rsplit(['/', '.']).next() == Some("seed")
}

/// Builds the table of `records` for axes at `pointers`; metric columns in order of
/// first appearance.
pub fn build(pointers: &[String], records: &[RunRecord]) -> Table {
    let mut metrics: Vec<String> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for record in records {
        for (name, _) in &record.metrics {
            if seen.insert(name.as_str()) {
                metrics.push(name.clone());
            }
        }
    }
    let rows = records
        .iter()
        .map(|record| {
            let mut row = Map::new();
            row.insert("run".into(), Value::from(record.run));
            row.insert("job".into(), Value::from(record.job.clone()));
            row.insert("status".into(), Value::from(record.status.clone()));
            for pointer in pointers {
                row.insert(
                    pointer.clone(),
                    record.inputs.pointer(pointer).cloned().unwrap_or(Value::Null),
                );
            }
            for (name, value) in &record.metrics {
                row.insert(name.clone(), value.clone());
            }
            row
        })
        .collect();
    let columns = LEADING
        .iter()
        .map(|c| (*c).to_owned())
        .chain(pointers.iter().cloned())
        .chain(metrics.iter().cloned())
        .collect();
    Table {
        columns,
        metrics,
        rows,
    }
}

impl Table {
    /// CSV with a header of the column names; absent values are empty cells, the rest
    /// as [`crate::csv_format::cell`] writes them (numbers in full precision).
    pub fn to_csv(&self) -> String {
        crate::csv_format::records(&self.columns, &self.rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn tables_have_axis_columns_then_metrics_and_render_as_csv() {
        let records = vec![
            RunRecord {
                run: 0,
                job: "a".into(),
                status: "successful".into(),
                inputs: json!({"contact": {"rk": 1.0}}),
                metrics: vec![("sum".into(), json!(3))],
            },
            RunRecord {
                run: 1,
                job: "b".into(),
                status: "failed".into(),
                inputs: json!({"contact": {"rk": 10.0}}),
                metrics: vec![],
            },
        ];
        let table = build(&["/contact/rk".to_owned()], &records);
        assert_eq!(table.columns, vec!["run", "job", "status", "/contact/rk", "sum"]);
        assert_eq!(
            table.to_csv(),
            "run,job,status,/contact/rk,sum\n0,a,successful,1.0,3\n1,b,failed,10.0,\n"
        );
    }

    #[test]
    fn seeds_are_the_columns_named_seed() {
        for seed in ["/bundle/gaps/seed", "/seed", "gaps.seed", "seed"] {
            assert!(is_seed(seed), "{seed}");
        }
        for other in [
            "/bundle/gaps/seeds",
            "/seed/mean",
            "reseed",
            "/contact/rk",
            "seed_count",
        ] {
            assert!(!is_seed(other), "{other}");
        }
    }
}
