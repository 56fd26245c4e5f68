//! The JSON documents of `/sweeps`, with their OpenAPI schemas.

use serde::Serialize;
use utoipa::ToSchema;

use super::models::Link;
use crate::service::clock::rfc3339;
use crate::service::queue::SweepRecord;
use crate::service::queue::sweep_read::SweepCounts;

/// Link relation of results (OGC API – Processes).
const RESULTS_REL: &str = "http://www.opengis.net/def/rel/ogc/1.0/results";

/// Status of a sweep: `accepted` (no run started), `running`, then once every run
/// ended `successful` (none failed), `partial` (some succeeded, `counts.failed` failed)
/// or `failed` (none succeeded; under `fail_fast`, the first failure); `dismissed`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum SweepState {
    /// No run has started yet.
    Accepted,
    /// Some runs have started or ended, some have not.
    Running,
    /// Every run ended and none failed (runs dismissed one by one aside).
    Successful,
    /// Every run ended, some successful and some failed (`counts.failed` of them).
    Partial,
    /// Every run ended and none succeeded because runs failed; or, under the `fail_fast`
    /// policy, a run failed and the runs not finished were dismissed.
    Failed,
    /// Dismissed by `DELETE /sweeps/{sweepId}`, or every run dismissed one by one.
    Dismissed,
}

impl SweepState {
    /// The state of a sweep whose runs all ended: `failed` runs make it `partial`, or
    /// `failed` when no run succeeded.
    fn ended(counts: &SweepCounts) -> Self {
        match (counts.successful, counts.failed) {
            (0, 0) if counts.dismissed > 0 => SweepState::Dismissed,
            (_, 0) => SweepState::Successful,
            (0, _) => SweepState::Failed,
            _ => SweepState::Partial,
        }
    }
}

/// Number of runs in each job status.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct RunCounts {
    pub accepted: i64,
    pub running: i64,
    pub successful: i64,
    pub failed: i64,
    pub dismissed: i64,
}

/// The state of one sweep.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct SweepStatus {
    #[serde(rename = "sweepID")]
    pub sweep_id: String,
    #[serde(rename = "processID")]
    pub process_id: String,
    pub status: SweepState,
    /// `grid`, `monte_carlo` or `latin_hypercube`.
    pub design: String,
    /// `continue` or `fail_fast`.
    pub policy: String,
    /// Number of runs (jobs).
    pub runs: i64,
    pub counts: RunCounts,
    /// Percent done over all runs (ended runs count 100, running ones their progress).
    #[schema(minimum = 0, maximum = 100)]
    pub progress: u8,
    /// When the sweep was submitted (RFC 3339, UTC).
    pub created: String,
    /// When its last run ended (RFC 3339, UTC), once every run ended.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finished: Option<String>,
    /// Last change of the sweep or any of its runs (RFC 3339, UTC).
    pub updated: String,
    /// The sweep request as normalized: process, base inputs, axes, design, samples, seed, policy.
    #[schema(value_type = Object)]
    pub definition: serde_json::Value,
    /// The labels given with the sweep (empty when none): `GET /sweeps?label=` filters on them.
    pub labels: Vec<String>,
    /// The note given with the sweep.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    pub links: Vec<Link>,
}

impl SweepStatus {
    pub fn new(record: &SweepRecord, counts: &SweepCounts) -> Self {
        let ended = counts.successful + counts.failed + counts.dismissed;
        let status = if record.dismissed {
            SweepState::Dismissed
        } else if record.policy == "fail_fast" && counts.failed > 0 {
            SweepState::Failed
        } else if counts.pending() == 0 {
            SweepState::ended(counts)
        } else if counts.running > 0 || ended > 0 {
            SweepState::Running
        } else {
            SweepState::Accepted
        };
        let progress = if record.runs > 0 {
            ((ended * 100 + counts.running_progress) / record.runs).clamp(0, 100) as u8
        } else {
            100
        };
        let href = format!("/sweeps/{}", record.id);
        let links = vec![
            Link::new(&href, "self", "application/json").titled("Sweep status"),
            Link::new(format!("{href}/results"), RESULTS_REL, "application/json")
                .titled("Results table and aggregates"),
            Link::new(format!("{href}/results?format=csv"), RESULTS_REL, "text/csv")
                .titled("Results table as CSV"),
            Link::new(format!("{href}/statistics"), "describedby", "application/json").titled(
                "Statistics of the run-wide figures, with a Wilks bound at a chosen coverage and confidence",
            ),
            Link::new(
                format!("{href}/statistics/contacts"),
                "describedby",
                "application/json",
            )
            .titled("Statistics of each contact's figures"),
            Link::new(
                format!("{href}/statistics/pins"),
                "describedby",
                "application/json",
            )
            .titled("Statistics of each pin's figures"),
            Link::new(
                format!("/jobs?sweepID={}", record.id),
                "http://www.opengis.net/def/rel/ogc/1.0/job-list",
                "application/json",
            )
            .titled("The runs, as jobs"),
            Link::new(
                format!("/processes/{}", record.process_id),
                "up",
                "application/json",
            ),
        ];
        Self {
            sweep_id: record.id.clone(),
            process_id: record.process_id.clone(),
            status,
            design: record.design.clone(),
            policy: record.policy.clone(),
            runs: record.runs,
            counts: RunCounts {
                accepted: counts.accepted,
                running: counts.running,
                successful: counts.successful,
                failed: counts.failed,
                dismissed: counts.dismissed,
            },
            progress,
            created: rfc3339(record.created_at),
            finished: (counts.pending() == 0).then(|| {
                rfc3339(
                    counts
                        .finished_at
                        .unwrap_or(record.updated_at)
                        .max(record.created_at),
                )
            }),
            updated: rfc3339(counts.updated_at.unwrap_or(0).max(record.updated_at)),
            definition: serde_json::from_str(&record.definition).unwrap_or(serde_json::Value::Null),
            labels: record.labels.0.clone(),
            note: record.note.clone(),
            links,
        }
    }

    /// True once nothing will change any more.
    pub fn is_finished(&self) -> bool {
        self.counts.accepted + self.counts.running == 0
    }
}

/// A page of sweeps, newest first; follow the `next` link for older ones.
#[derive(Debug, Serialize, ToSchema)]
pub struct SweepList {
    pub sweeps: Vec<SweepStatus>,
    pub links: Vec<Link>,
}

/// The results of a sweep: one row per ended run, and aggregates.
#[derive(Debug, Serialize, ToSchema)]
pub struct SweepResults {
    #[serde(rename = "sweepID")]
    pub sweep_id: String,
    pub status: SweepState,
    /// Number of runs.
    pub runs: i64,
    /// `run`, `job`, `status`, one column per axis (its pointer), then the metrics
    /// flattened with dots (`comparison.f_err`, `contacts.3.max_force`,
    /// `quality.verdict`, `quality.energy_residual`), in SI units.
    pub columns: Vec<String>,
    /// One object per ended run (successful, failed or dismissed), in run order, keyed by column.
    #[schema(value_type = Vec<Object>)]
    pub rows: Vec<serde_json::Map<String, serde_json::Value>>,
    /// `statistics` (random designs: per grid cell of the list axes, count, mean, std,
    /// min, max, q05, q50, q95, and the one-sided 95 %/95 % upper bound of Wilks
    /// `bound_95_95` with its rank from the top `bound_95_95_rank` (null below 59 runs), of
    /// every numeric column but seeds over the successful runs) or
    /// `calibration` (grids with `comparison.f_err`: validity map, cheapest valid
    /// `/solver/time_step`, `/beam/modes`, `/beam/elements`); and `quality` when the
    /// runs carry a verdict: `{"runs", "good", "unchecked", "doubtful", "poor", "by_axis": [{"axis",
    /// "values": [{"value", "runs", "good", "unchecked", "doubtful", "poor"}]}]}`, counts of the
    /// successful runs in total and per value of each list axis.
    #[schema(value_type = Object)]
    pub aggregates: serde_json::Value,
    pub links: Vec<Link>,
}

/// Which statistics table of a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum SweepStatisticsKind {
    /// Run-wide figures (`/sweeps/{sweepId}/statistics`).
    Runs,
    /// Per contact (`/statistics/contacts`).
    Contacts,
    /// Per pin (`/statistics/pins`).
    Pins,
    /// One figure run by run (`/statistics/convergence`).
    Convergence,
}

impl SweepStatisticsKind {
    /// The path of the table under `/sweeps/{sweepId}`.
    fn path(self) -> &'static str {
        match self {
            SweepStatisticsKind::Runs => "/statistics",
            SweepStatisticsKind::Contacts => "/statistics/contacts",
            SweepStatisticsKind::Pins => "/statistics/pins",
            SweepStatisticsKind::Convergence => "/statistics/convergence",
        }
    }
}

/// A statistics table of a sweep: one flat record per row, the same columns as its CSV.
#[derive(Debug, Serialize, ToSchema)]
pub struct SweepStatistics {
    #[serde(rename = "sweepID")]
    pub sweep_id: String,
    pub status: SweepState,
    pub kind: SweepStatisticsKind,
    /// The quantile bounded, p (default 0.95).
    pub coverage: f64,
    /// The confidence of the bound, γ (default 0.95).
    pub confidence: f64,
    /// The fewest runs (per grid cell) whose largest value is the bound:
    /// ⌈ln(1 − γ) / ln p⌉ (59 at 95 %/95 %).
    pub runs_needed: Option<usize>,
    /// The list axes (pointers), the item's key (`contact`, `pin`) for per-item tables,
    /// `figure`, then `runs`, `count`, `mean`, `std`, `min`, `max`, `q05`, `q50`, `q95`,
    /// `quantile`, `bound`, `bound_rank`, `runs_needed`; for the convergence table the
    /// list axes, `sample`, `run`, `value`, `quantile`, `bound`, `bound_rank`, `runs`.
    /// Values in the figure's unit (SI).
    pub columns: Vec<String>,
    /// One object per row, keyed by column; a bound is null below the runs it needs.
    #[schema(value_type = Vec<Object>)]
    pub rows: Vec<serde_json::Map<String, serde_json::Value>>,
    pub links: Vec<Link>,
}

impl SweepStatistics {
    pub fn new(
        record: &SweepRecord,
        status: SweepState,
        kind: SweepStatisticsKind,
        request: crate::sweep::figures::BoundRequest,
        table: crate::sweep::figures::StatisticsTable,
    ) -> Self {
        let href = format!("/sweeps/{}", record.id);
        let query = format!("coverage={}&confidence={}", request.coverage, request.confidence);
        let path = kind.path();
        Self {
            sweep_id: record.id.clone(),
            status,
            kind,
            coverage: request.coverage,
            confidence: request.confidence,
            runs_needed: request.runs_needed(1),
            columns: table.columns,
            rows: table.rows,
            links: vec![
                Link::new(format!("{href}{path}?{query}"), "self", "application/json"),
                Link::new(
                    format!("{href}{path}?{query}&format=csv"),
                    "alternate",
                    "text/csv",
                ),
                Link::new(&href, "up", "application/json").titled("Sweep status"),
            ],
        }
    }
}

/// The runs a one-sided Wilks bound needs, rank by rank (`/sweeps/runs-needed`).
#[derive(Debug, Serialize, ToSchema)]
pub struct RunsNeeded {
    /// The quantile bounded, p.
    pub coverage: f64,
    /// The confidence of the bound, γ.
    pub confidence: f64,
    /// Rank 1 (the largest value) first.
    pub runs_needed: Vec<RankRuns>,
}

/// The fewest independent runs whose `rank`-th largest value is the bound.
#[derive(Debug, Serialize, ToSchema)]
pub struct RankRuns {
    /// From the top: 1 is the largest value.
    pub rank: usize,
    /// Null beyond 10¹² runs.
    pub runs: Option<usize>,
}
