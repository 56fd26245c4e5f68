//! What a run was shaken by, as the integrator saw it: the `excitation` history (one
//! column per acceleration member given, a record at every one of its samples) and, for
//! each synthetic earthquake, what the generator reached against its target
//! ([`GeneratedRecord`], in the results as `generated_records`). Every process with
//! accelerations in its `excitation` gives both, from its members by name.

use serde::Serialize;
use utoipa::ToSchema;

use super::History;
use super::excitation::BaseAccelerationInput;
use super::simulation::{HistoryKind, HistoryOutput};
use crate::physics::loads::BaseAcceleration;

/// The `excitation` history every process with accelerations gives.
pub const OUTPUT: HistoryOutput = HistoryOutput {
    name: "excitation",
    kind: HistoryKind::Acceleration,
    title: "Excitation (m/s²)",
    description: "CSV columns time (s), then one per acceleration member of `excitation` that was given, \
                  named after it (base_acceleration, a wall's or the wrapper's, an x or y component), as the \
                  integrator saw it: at the output times and at every sample of a record (a table, a stored \
                  signal, a synthetic earthquake: the whole record, also past the run's end); a run given \
                  no acceleration has base_acceleration, 0 throughout",
};

/// The member a run given no acceleration reports (0 throughout).
const STILL: &str = "base_acceleration";

/// A synthetic earthquake a run was given (`spectrum_compatible`): the record the seed
/// gave and how close its spectrum came to the target.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct GeneratedRecord {
    /// The excitation member (`base_acceleration`, `base_acceleration_x`, …), also its
    /// column in the `excitation` history, whose
    /// `/jobs/{id}/results/excitation/response_spectrum?series=<member>` compares the
    /// stored record's spectrum with `target`.
    pub member: String,
    /// The seed the record was drawn from.
    pub seed: u64,
    /// Sampling interval (s).
    pub time_step: f64,
    /// Samples.
    pub samples: usize,
    /// Record length (s).
    pub duration: f64,
    /// Largest |acceleration| (m/s²): the spectrum's limit at high frequency.
    pub peak_acceleration: f64,
    /// Correction rounds taken (the first spectrum check counts as one).
    pub rounds: usize,
    /// Largest |PSA/PSA_target − 1| over the target's band on the generator's check grid
    /// (dimensionless).
    pub max_deviation: f64,
    /// Where it occurs (Hz).
    pub deviation_frequency: f64,
    /// The deviation the request allowed (dimensionless).
    pub tolerance: f64,
    /// The target spectrum, as given.
    pub target: TargetEcho,
}

/// A target response spectrum, as given.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct TargetEcho {
    /// Frequencies (Hz); the first and last bound the band.
    pub frequencies: Vec<f64>,
    /// Pseudo-acceleration at each (m/s²), straight between points on log–log axes.
    pub accelerations: Vec<f64>,
    /// Damping ratio (dimensionless).
    pub damping: f64,
}

/// The accelerations of a run, member by member, in the order of the request's schema.
#[derive(Debug, Clone)]
pub struct Excitations {
    /// Member and signal; `None` for still feet (a run given no acceleration).
    columns: Vec<(&'static str, Option<BaseAcceleration>)>,
    generated: Vec<GeneratedRecord>,
}

impl Excitations {
    /// From the excitation members (name, value) of validated inputs: the given ones.
    pub fn of<'a>(
        members: impl IntoIterator<Item = (&'static str, &'a Option<BaseAccelerationInput>)>,
    ) -> Self {
        let mut columns = Vec::new();
        let mut generated = Vec::new();
        for (member, input) in members {
            let Some(input) = input else { continue };
            if let BaseAccelerationInput::SpectrumCompatible(synthetic) = input
                && let Some(record) = synthetic.generated()
            {
                generated.push(GeneratedRecord {
                    member: member.to_owned(),
                    seed: synthetic.seed,
                    time_step: record.time_step,
                    samples: record.samples.len(),
                    duration: record.time_step * record.samples.len().saturating_sub(1) as f64,
                    peak_acceleration: record.samples.iter().fold(0.0, |m: f64, a| m.max(a.abs())),
                    rounds: record.iterations,
                    max_deviation: record.max_deviation,
                    deviation_frequency: record.deviation_frequency,
                    tolerance: synthetic.tolerance,
                    target: TargetEcho {
                        frequencies: synthetic.target.frequencies.clone(),
                        accelerations: synthetic.target.accelerations.clone(),
                        damping: synthetic.target.damping,
                    },
                });
            }
            columns.push((member, Some(input.physics())));
        }
        if columns.is_empty() {
            columns.push((STILL, None));
        }
        Self { columns, generated }
    }

    /// The synthetic earthquakes among them.
    pub fn generated_records(&self) -> Vec<GeneratedRecord> {
        self.generated.clone()
    }

    /// The `excitation` history: every column at the output times `output_times` and at
    /// every sample of every record, sorted; of two times within 1e-9 of the span, one
    /// is kept, a record's sample rather than an output time (a record's value there is
    /// its sample's, not an interpolation between it and a neighbour a rounding away).
    pub fn history(&self, output_times: &[f64]) -> History {
        // (time, whether it is a record's sample)
        let mut times: Vec<(f64, bool)> = output_times.iter().map(|&t| (t, false)).collect();
        for (_, signal) in &self.columns {
            if let Some(BaseAcceleration::Table(table)) = signal {
                times.extend(table.time.iter().map(|&t| (t, true)));
            }
        }
        times.retain(|(t, _)| t.is_finite());
        times.sort_by(|a, b| a.0.total_cmp(&b.0));
        let span = times.last().map_or(0.0, |t| t.0) - times.first().map_or(0.0, |t| t.0);
        let apart = 1e-9 * span.max(f64::MIN_POSITIVE);
        times.dedup_by(|later, kept| {
            let close = later.0 - kept.0 <= apart;
            if close && later.1 && !kept.1 {
                *kept = *later;
            }
            close
        });
        let times: Vec<f64> = times.into_iter().map(|(t, _)| t).collect();
        let series = self
            .columns
            .iter()
            .map(|(member, signal)| {
                let at = |t: f64| signal.as_ref().map_or(0.0, |signal| signal.at(t));
                ((*member).to_owned(), times.iter().map(|&t| at(t)).collect())
            })
            .collect();
        History {
            name: OUTPUT.name.to_owned(),
            time: times,
            series,
        }
    }
}

/// What the column `name` of `excitation` is, read from the results `document`: the
/// acceleration member it reports, and the seed of a synthetic earthquake.
pub fn column_description(name: &str, document: &serde_json::Value) -> String {
    let generated = (document["generated_records"].as_array().into_iter().flatten())
        .find(|record| record["member"] == name);
    match generated {
        Some(record) => format!(
            "{name} as the run was given it: the synthetic earthquake of seed {}",
            record["seed"]
        ),
        None => format!("{name} as the run was given it (absolute acceleration)"),
    }
}

/// The histories of a run but its `excitation`: what the model did, for tests that give
/// the same motion by different members.
#[cfg(test)]
pub fn responses(histories: &[History]) -> Vec<&History> {
    histories.iter().filter(|h| h.name != OUTPUT.name).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::loads::Table;

    fn half_sine(amplitude: f64, duration: f64) -> Option<BaseAccelerationInput> {
        Some(BaseAccelerationInput::HalfSine { amplitude, duration })
    }

    #[test]
    fn a_pulse_is_sampled_at_the_output_times_as_the_integrator_sees_it() {
        let pulse = half_sine(30.0, 0.01);
        let times: Vec<f64> = (0..=40).map(|k| k as f64 * 5e-4).collect();
        let history =
            Excitations::of([("base_acceleration", &pulse), ("wall_acceleration", &None)]).history(&times);
        assert_eq!(history.name, "excitation");
        assert_eq!(history.time, times);
        assert_eq!(history.series.len(), 1, "only the members given");
        let (name, values) = &history.series[0];
        assert_eq!(name, "base_acceleration");
        for (t, a) in times.iter().zip(values) {
            let exact = if *t <= 0.01 {
                30.0 * (std::f64::consts::PI * t / 0.01).sin()
            } else {
                0.0
            };
            assert!((a - exact).abs() <= 1e-12 * 30.0, "a({t}) = {a}, not {exact}");
        }
    }

    #[test]
    fn a_record_keeps_every_sample_also_past_the_run_and_between_output_times() {
        // Samples every 3 ms (linear between them) against outputs every 2 ms for 10 ms.
        let record = Some(BaseAccelerationInput::Table {
            time: (0..=6).map(|k| k as f64 * 3e-3).collect(),
            acceleration: vec![0.0, 1.0, -2.0, 0.5, 0.25, 1.0, 0.0],
            unit: super::super::excitation::AccelerationUnit::G,
        });
        let pulse = half_sine(-4.0, 4e-3);
        let outputs: Vec<f64> = (0..=5).map(|k| k as f64 * 2e-3).collect();
        let excitations = Excitations::of([
            ("left_wall_acceleration", &pulse),
            ("right_wall_acceleration", &record),
        ]);
        assert!(excitations.generated_records().is_empty());
        let history = excitations.history(&outputs);
        // 0, 2, 3, 4, 6 (both), 8, 9, 10, 12, 15, 18 ms.
        let expected = [0.0, 2.0, 3.0, 4.0, 6.0, 8.0, 9.0, 10.0, 12.0, 15.0, 18.0];
        assert_eq!(history.time.len(), expected.len(), "{:?}", history.time);
        for (t, ms) in history.time.iter().zip(expected) {
            assert!((t - ms * 1e-3).abs() < 1e-15, "{t} s against {ms} ms");
        }
        let names: Vec<&str> = history.series.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["left_wall_acceleration", "right_wall_acceleration"]);
        let g = super::super::excitation::STANDARD_GRAVITY;
        let table = Table {
            time: (0..=6).map(|k| k as f64 * 3e-3).collect(),
            values: [0.0, 1.0, -2.0, 0.5, 0.25, 1.0, 0.0]
                .iter()
                .map(|a| a * g)
                .collect(),
        };
        for (t, a) in history.time.iter().zip(&history.series[1].1) {
            assert_eq!(*a, table.at(*t), "at {t} s");
        }
        // At a sample the record's own value, in m/s²: −2 g at 6 ms.
        assert_eq!(history.series[1].1[4], -2.0 * g);
    }

    #[test]
    fn a_run_given_no_acceleration_reports_still_feet() {
        let outputs = [0.0, 1e-3, 2e-3];
        let history = Excitations::of([("base_acceleration", &None)]).history(&outputs);
        assert_eq!(
            history.series,
            vec![("base_acceleration".to_owned(), vec![0.0; 3])]
        );
    }
}
