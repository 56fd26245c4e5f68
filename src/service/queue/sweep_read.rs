//! Reads of sweeps: one sweep, the sweep list (keyset paging), the counts of its runs
//! per status, and its ended runs with their results.

use std::collections::HashMap;

use super::{JobQueue, JobStatus, SweepRecord, sweep_columns};
use crate::service::db::with_pool;

/// Counts of runs per sweep and status; $1 is a JSON array of sweep ids, $2 the tenant.
const COUNTS_SQLITE: &str = "\
    SELECT sweep_id, status, COUNT(*) AS n, CAST(SUM(progress) AS BIGINT) AS progress, \
        MAX(updated_at) AS updated, MAX(finished_at) AS finished \
    FROM jobs WHERE sweep_id IN (SELECT value FROM json_each($1)) AND tenant = $2 \
    GROUP BY sweep_id, status";

const COUNTS_POSTGRES: &str = "\
    SELECT sweep_id, status, COUNT(*) AS n, CAST(SUM(progress) AS BIGINT) AS progress, \
        MAX(updated_at) AS updated, MAX(finished_at) AS finished \
    FROM jobs WHERE sweep_id IN (SELECT json_array_elements_text(CAST($1 AS json))) AND tenant = $2 \
    GROUP BY sweep_id, status";

/// How a sweep's runs stand.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SweepCounts {
    pub accepted: i64,
    pub running: i64,
    pub successful: i64,
    pub failed: i64,
    pub dismissed: i64,
    /// Sum of the progress (percent) of the running runs.
    pub running_progress: i64,
    /// Latest change of any run (ms since the Unix epoch).
    pub updated_at: Option<i64>,
    /// Latest end of any run.
    pub finished_at: Option<i64>,
}

impl SweepCounts {
    /// Runs that have not ended.
    pub fn pending(&self) -> i64 {
        self.accepted + self.running
    }

    fn add(&mut self, status: &str, count: i64, progress: i64, updated: Option<i64>, finished: Option<i64>) {
        match JobStatus::parse(status) {
            Some(JobStatus::Accepted) => self.accepted += count,
            Some(JobStatus::Running) => {
                self.running += count;
                self.running_progress += progress;
            }
            Some(JobStatus::Successful) => self.successful += count,
            Some(JobStatus::Failed) => self.failed += count,
            Some(JobStatus::Dismissed) => self.dismissed += count,
            None => {}
        }
        self.updated_at = self.updated_at.max(updated);
        self.finished_at = self.finished_at.max(finished);
    }
}

/// `GET /sweeps`: a page of the tenant's sweeps ($3) older than $1, at most $2, with
/// every label of the JSON array $4 (NULL: any).
const LIST_SWEEPS_SQLITE: &str = concat!(
    "SELECT ",
    sweep_columns!(),
    " FROM sweeps WHERE ($1 IS NULL OR seq < $1) AND tenant = $3 \
       AND ($4 IS NULL OR NOT EXISTS (SELECT 1 FROM json_each($4) AS wanted \
            WHERE wanted.value NOT IN (SELECT value FROM json_each(sweeps.labels)))) \
     ORDER BY seq DESC LIMIT $2"
);
const LIST_SWEEPS_POSTGRES: &str = concat!(
    "SELECT ",
    sweep_columns!(),
    " FROM sweeps WHERE ($1 IS NULL OR seq < $1) AND tenant = $3 \
       AND (CAST($4 AS text) IS NULL OR CAST(labels AS jsonb) @> CAST($4 AS jsonb)) \
     ORDER BY seq DESC LIMIT $2"
);

/// An ended run of a sweep with what it produced.
#[derive(Debug, Clone)]
pub struct SweepRun {
    pub run: i64,
    pub job_id: String,
    pub status: JobStatus,
    /// The run's inputs (JSON text).
    pub inputs: String,
    /// Results document (JSON text) of a successful run.
    pub results: Option<String>,
}

impl JobQueue {
    /// Sweep `id` if `tenant` owns it.
    pub async fn get_sweep(&self, tenant: &str, id: &str) -> Result<Option<SweepRecord>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            sqlx::query_as(concat!(
                "SELECT ",
                sweep_columns!(),
                " FROM sweeps WHERE id = $1 AND tenant = $2"
            ))
            .bind(id)
            .bind(tenant)
            .fetch_optional(pool)
            .await
        })
    }

    /// Up to `limit` sweeps of `tenant`, newest first, strictly older than sequence
    /// `before` when given; with `labels`, only the sweeps that have all of them.
    pub async fn list_sweeps(
        &self,
        tenant: &str,
        limit: u32,
        before: Option<i64>,
        labels: &[String],
    ) -> Result<Vec<SweepRecord>, sqlx::Error> {
        let labels = (!labels.is_empty()).then(|| serde_json::to_string(labels).unwrap_or_default());
        let sql = self.db.choose(LIST_SWEEPS_SQLITE, LIST_SWEEPS_POSTGRES);
        with_pool!(&self.db, pool => {
            sqlx::query_as(sql)
                .bind(before)
                .bind(i64::from(limit))
                .bind(tenant)
                .bind(&labels)
                .fetch_all(pool)
                .await
        })
    }

    /// Counts of the runs of each of `sweep_ids` of `tenant` (every id present, zeros included).
    pub async fn sweep_counts(
        &self,
        tenant: &str,
        sweep_ids: &[String],
    ) -> Result<HashMap<String, SweepCounts>, sqlx::Error> {
        type Row = (String, String, i64, Option<i64>, Option<i64>, Option<i64>);
        let sql = self.db.choose(COUNTS_SQLITE, COUNTS_POSTGRES);
        let rows: Vec<Row> = with_pool!(&self.db, pool => {
            sqlx::query_as(sql)
                .bind(serde_json::to_string(sweep_ids).unwrap_or_default())
                .bind(tenant)
                .fetch_all(pool)
                .await?
        });
        let mut counts: HashMap<String, SweepCounts> = sweep_ids
            .iter()
            .map(|id| (id.clone(), SweepCounts::default()))
            .collect();
        for (id, status, count, progress, updated, finished) in rows {
            counts
                .entry(id)
                .or_default()
                .add(&status, count, progress.unwrap_or(0), updated, finished);
        }
        Ok(counts)
    }

    /// The runs of sweep `id` of `tenant` that ended (successful, failed, dismissed), in run order.
    pub async fn ended_sweep_runs(&self, tenant: &str, id: &str) -> Result<Vec<SweepRun>, sqlx::Error> {
        let rows: Vec<RunRow> = with_pool!(&self.db, pool => {
            sqlx::query_as(
                "SELECT id, sweep_run, status, inputs, results FROM jobs \
                 WHERE sweep_id = $1 AND tenant = $2 AND status IN ('successful', 'failed', 'dismissed') \
                 ORDER BY sweep_run",
            )
            .bind(id)
            .bind(tenant)
            .fetch_all(pool)
            .await?
        });
        Ok(rows.into_iter().map(sweep_run).collect())
    }

    /// The successful runs of sweep `id` numbered after `after` (−1: from the first), at
    /// most `limit`, in run order: the results documents a page at a time, so that a
    /// reader holds a few of them, not the sweep's.
    pub async fn successful_sweep_runs_after(
        &self,
        tenant: &str,
        id: &str,
        after: i64,
        limit: i64,
    ) -> Result<Vec<SweepRun>, sqlx::Error> {
        let rows: Vec<RunRow> = with_pool!(&self.db, pool => {
            sqlx::query_as(
                "SELECT id, sweep_run, status, inputs, results FROM jobs \
                 WHERE sweep_id = $1 AND tenant = $2 AND status = 'successful' AND sweep_run > $3 \
                 ORDER BY sweep_run LIMIT $4",
            )
            .bind(id)
            .bind(tenant)
            .bind(after)
            .bind(limit)
            .fetch_all(pool)
            .await?
        });
        Ok(rows.into_iter().map(sweep_run).collect())
    }
}

/// A sweep run's row: id, run number, status, inputs, results.
type RunRow = (String, Option<i64>, String, String, Option<String>);

fn sweep_run((job_id, run, status, inputs, results): RunRow) -> SweepRun {
    SweepRun {
        run: run.unwrap_or(0),
        job_id,
        status: JobStatus::parse(&status).unwrap_or(JobStatus::Failed),
        inputs,
        results,
    }
}
