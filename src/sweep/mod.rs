//! Sweeps: one request that expands into many runs of a process, and the tables and
//! aggregates made of their results. Pure: no IO, no async; the service stores the runs
//! as ordinary jobs and feeds their results back here.
//!
//! A sweep is a process id, base `inputs`, and axes, each a JSON pointer into the
//! inputs with either a list of values (`values`, `linspace`, `logspace`) or a random
//! law (`uniform`, `normal`, `lognormal`). List axes span a full grid (cartesian
//! product, the last axis varying fastest); random axes draw `samples` points (Monte
//! Carlo or Latin hypercube, reproducible from `seed`, see [`sampling`]), and each grid
//! cell of the list axes gets the same `samples` draws. Run `k` of a sweep is cell
//! `k / samples`, sample `k % samples`.
//!
//! - [`request`]: the request as one serde type, also its OpenAPI schema ([`member`]:
//!   its members as given, so that every problem is reported at once);
//! - [`spec`]: checking the request, with JSON pointers into it for every problem;
//! - [`admission`]: from a request to the runs to queue, or a typed refusal;
//! - [`input_schema`]: whether an axis pointer names an input of the process;
//! - [`definition`]: the request as stored with the sweep, read back for its results;
//! - [`sampling`]: the seeded uniforms and the laws' quantiles;
//! - [`pointer`]: writing a value at a JSON pointer;
//! - [`table`]: one row per run, metrics flattened with dots, as JSON or CSV;
//! - [`aggregate`]: statistics of random sweeps, validity maps of calibration grids;
//! - [`figures`]: long statistics tables at a requested Wilks bound, and how the
//!   quantile and the bound converge as runs are added;
//! - [`items`]: the same per contact and per pin, fed one results document at a time.

pub mod admission;
pub mod aggregate;
pub mod definition;
pub mod figures;
pub mod input_schema;
pub mod items;
pub mod member;
pub mod pointer;
pub mod request;
pub mod sampling;
pub mod spec;
pub mod table;
/// Distribution-free bounds on quantiles (Wilks).
pub mod wilks;

pub use definition::SweepDefinition;
pub use request::{AxisKind, Design, InvalidRuns, Policy, SweepAxis, SweepRequest};
pub use spec::{Axis, AxisValues, SweepError, SweepSpec};

use serde_json::Value;

/// One generated run: its number in the sweep and its complete inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    pub index: usize,
    pub inputs: Value,
}

impl SweepSpec {
    /// Number of grid cells of the list axes (1 without any).
    pub fn cells(&self) -> usize {
        self.axes
            .iter()
            .filter_map(|a| match &a.values {
                AxisValues::List(values) => Some(values.len()),
                AxisValues::Random(_) => None,
            })
            .product()
    }

    /// Samples per cell: `samples` when some axis is random, else 1.
    pub fn samples_per_cell(&self) -> usize {
        if self
            .axes
            .iter()
            .any(|a| matches!(a.values, AxisValues::Random(_)))
        {
            self.samples.unwrap_or(1)
        } else {
            1
        }
    }

    /// Total number of runs.
    pub fn run_count(&self) -> usize {
        self.cells() * self.samples_per_cell()
    }

    /// Every run's inputs, in run order. The pointers were checked by [`spec::parse`].
    pub fn expand(&self) -> Vec<Run> {
        let samples = self.samples_per_cell();
        let random_axes = self
            .axes
            .iter()
            .filter(|a| matches!(a.values, AxisValues::Random(_)))
            .count();
        let uniforms = match self.design {
            Design::Grid => vec![Vec::new()],
            Design::MonteCarlo => sampling::monte_carlo(self.seed, samples, random_axes),
            Design::LatinHypercube => sampling::latin_hypercube(self.seed, samples, random_axes),
        };
        let list_sizes: Vec<usize> = self
            .axes
            .iter()
            .filter_map(|a| match &a.values {
                AxisValues::List(values) => Some(values.len()),
                AxisValues::Random(_) => None,
            })
            .collect();
        let mut runs = Vec::with_capacity(self.run_count());
        for cell in 0..self.cells() {
            // Mixed-radix digits of the cell number, the last list axis fastest.
            let mut digits = vec![0; list_sizes.len()];
            let mut rest = cell;
            for (digit, size) in digits.iter_mut().zip(&list_sizes).rev() {
                *digit = rest % size;
                rest /= size;
            }
            for sample in 0..samples {
                let mut inputs = self.inputs.clone();
                let (mut list, mut random) = (0, 0);
                for axis in &self.axes {
                    let value = match &axis.values {
                        AxisValues::List(values) => {
                            list += 1;
                            values[digits[list - 1]].clone()
                        }
                        AxisValues::Random(law) => {
                            random += 1;
                            axis.number(law.quantile(uniforms[sample][random - 1]))
                        }
                    };
                    // Checked at parse time: the pointer can be written.
                    let _ = pointer::set(&mut inputs, &axis.pointer, value);
                }
                runs.push(Run {
                    index: runs.len(),
                    inputs,
                });
            }
        }
        runs
    }
}

#[cfg(test)]
mod tests;
