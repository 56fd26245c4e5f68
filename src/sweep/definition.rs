//! The definition stored with a sweep: its request as admitted, with the defaults made
//! explicit. Served back in the sweep's status, and read back, typed, to render its
//! results (the axes and the design come from here, not from the runs).

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::aggregate::{self, Aggregates};
use super::request::{Design, InvalidRuns, Policy, SweepAxis};
use super::spec::SweepSpec;
use super::table::{self, RunRecord, Table};

/// A sweep's definition, as stored (JSON) and served in its status.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepDefinition {
    pub process: String,
    /// Base inputs of every run (an object).
    pub inputs: Value,
    /// The axes as written in the request.
    pub axes: Vec<SweepAxis>,
    pub design: Design,
    /// Draws per grid cell (`null` without random axes).
    pub samples: Option<usize>,
    pub seed: u64,
    pub policy: Policy,
    pub invalid_runs: InvalidRuns,
}

impl SweepSpec {
    /// The definition to store with this sweep.
    pub fn definition(&self) -> SweepDefinition {
        SweepDefinition {
            process: self.process.clone(),
            inputs: self.inputs.clone(),
            axes: self.axes.iter().map(|axis| axis.given.clone()).collect(),
            design: self.design,
            samples: self.samples,
            seed: self.seed,
            policy: self.policy,
            invalid_runs: self.invalid_runs,
        }
    }
}

impl SweepDefinition {
    /// A definition as stored (JSON text).
    pub fn from_stored(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// The pointer of every axis, in order: the axis columns of the results table.
    pub fn pointers(&self) -> Vec<String> {
        self.pointers_where(|_| true)
    }

    /// The pointers of the list axes (`values`, `linspace`, `logspace`): the grid.
    pub fn list_pointers(&self) -> Vec<String> {
        self.pointers_where(|axis| !is_random(axis))
    }

    /// The pointers of the random axes (`uniform`, `normal`, `lognormal`).
    pub fn random_pointers(&self) -> Vec<String> {
        self.pointers_where(is_random)
    }

    /// The results table of the ended runs `records`: one column per axis, then the metrics.
    pub fn table(&self, records: &[RunRecord]) -> Table {
        table::build(&self.pointers(), records)
    }

    /// The aggregates of this sweep's results `table`: the calibration map of a grid,
    /// the statistics per grid cell of a random design, and the quality verdicts per
    /// value of each list axis.
    pub fn aggregates(&self, table: &Table) -> Aggregates {
        let list_axes = self.list_pointers();
        let (calibration, statistics) = match self.design {
            Design::Grid => (aggregate::calibration(table, &self.pointers()), None),
            Design::MonteCarlo | Design::LatinHypercube => (
                None,
                Some(aggregate::cell_statistics(
                    table,
                    &list_axes,
                    &self.random_pointers(),
                )),
            ),
        };
        Aggregates {
            calibration,
            quality: aggregate::quality_counts(table, &list_axes),
            statistics,
        }
    }

    fn pointers_where(&self, keep: impl Fn(&SweepAxis) -> bool) -> Vec<String> {
        self.axes
            .iter()
            .filter(|axis| keep(axis))
            .filter_map(|axis| axis.pointer.typed().cloned())
            .collect()
    }
}

fn is_random(axis: &SweepAxis) -> bool {
    axis.kind().is_some_and(|kind| kind.is_random())
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;
    use crate::sweep::spec::parse;

    #[test]
    fn the_definition_is_the_request_with_its_defaults_and_reads_back() {
        let request = json!({"process": "p", "inputs": {"a": 1, "g": 0.5},
            "axes": [{"pointer": "/a", "linspace": [1, 3, 3]},
                     {"pointer": "/g", "lognormal": {"mean": 0, "std": 0.1}}],
            "samples": 4});
        let spec = parse(&request, 100).unwrap();
        let stored = serde_json::to_value(spec.definition()).unwrap();
        assert_eq!(
            stored,
            json!({"process": "p", "inputs": {"a": 1, "g": 0.5}, "axes": request["axes"],
                   "design": "monte_carlo", "samples": 4, "seed": 0, "policy": "continue",
                   "invalid_runs": "refuse"})
        );
        let definition = SweepDefinition::from_stored(&stored.to_string()).unwrap();
        assert_eq!(definition, spec.definition());
        assert_eq!(definition.pointers(), ["/a", "/g"]);
        assert_eq!(definition.list_pointers(), ["/a"]);
        assert_eq!(definition.random_pointers(), ["/g"]);
    }

    #[test]
    fn a_grid_stores_null_samples() {
        let spec = parse(
            &json!({"process": "p", "inputs": {}, "axes": [{"pointer": "/a", "values": [1, "x"]}]}),
            100,
        )
        .unwrap();
        let stored = serde_json::to_value(spec.definition()).unwrap();
        assert_eq!(stored["samples"], Value::Null);
        assert_eq!(stored["design"], "grid");
    }
}
