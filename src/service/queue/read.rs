//! Reads for the API: one job, the job list (keyset paging), results, histories, counts.

use sqlx::Row;

use super::{JobQueue, JobRecord, JobStatus, record_columns};
use crate::service::db::with_pool;
use crate::service::store::StoredHistory;

/// `GET /jobs`. Each list filter is one parameter, a JSON array of text (NULL: any),
/// whatever its length; a job matches the labels filter ($8) when it has every label
/// named.
const LIST_SQLITE: &str = concat!(
    "SELECT ",
    record_columns!(),
    " FROM jobs \
     WHERE ($1 IS NULL OR status IN (SELECT value FROM json_each($1))) \
       AND ($2 IS NULL OR process_id IN (SELECT value FROM json_each($2))) \
       AND ($3 IS NULL OR seq < $3) \
       AND ($5 IS NULL OR sweep_id IN (SELECT value FROM json_each($5))) \
       AND ($7 IS NULL OR (sweep_id IS NOT NULL) = $7) \
       AND ($8 IS NULL OR NOT EXISTS (SELECT 1 FROM json_each($8) AS wanted \
            WHERE wanted.value NOT IN (SELECT value FROM json_each(jobs.labels)))) \
       AND tenant = $6 \
     ORDER BY seq DESC LIMIT $4"
);
const LIST_POSTGRES: &str = concat!(
    "SELECT ",
    record_columns!(),
    " FROM jobs \
     WHERE ($1 IS NULL OR status IN (SELECT json_array_elements_text(CAST($1 AS json)))) \
       AND ($2 IS NULL OR process_id IN (SELECT json_array_elements_text(CAST($2 AS json)))) \
       AND ($3 IS NULL OR seq < $3) \
       AND ($5 IS NULL OR sweep_id IN (SELECT json_array_elements_text(CAST($5 AS json)))) \
       AND (CAST($7 AS boolean) IS NULL OR (sweep_id IS NOT NULL) = $7) \
       AND (CAST($8 AS text) IS NULL OR CAST(labels AS jsonb) @> CAST($8 AS jsonb)) \
       AND tenant = $6 \
     ORDER BY seq DESC LIMIT $4"
);

/// Filters of `GET /jobs`; an empty list means "any".
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct JobFilter {
    pub statuses: Vec<JobStatus>,
    pub process_ids: Vec<String>,
    /// Only runs of these sweeps.
    pub sweep_ids: Vec<String>,
    /// `Some(false)`: only jobs submitted on their own; `Some(true)`: only sweep runs.
    pub in_sweep: Option<bool>,
    /// Only jobs that have every one of these labels.
    pub labels: Vec<String>,
}

/// A job with what it produced: results document (successful) or problem (failed).
#[derive(Debug, Clone)]
pub struct JobOutcome {
    pub record: JobRecord,
    /// Results document (JSON text) of a successful job.
    pub results: Option<String>,
    /// Problem document (JSON text) of a failed job.
    pub error: Option<String>,
}

impl JobQueue {
    /// Job `id` if `tenant` owns it.
    pub async fn get(&self, tenant: &str, id: &str) -> Result<Option<JobRecord>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            sqlx::query_as(concat!(
                "SELECT ",
                record_columns!(),
                " FROM jobs WHERE id = $1 AND tenant = $2"
            ))
            .bind(id)
            .bind(tenant)
            .fetch_optional(pool)
            .await
        })
    }

    /// Up to `limit` jobs of `tenant` matching `filter`, newest first, strictly older than
    /// the job with sequence number `before` when given (keyset paging: stable under inserts).
    pub async fn list(
        &self,
        tenant: &str,
        filter: &JobFilter,
        limit: u32,
        before: Option<i64>,
    ) -> Result<Vec<JobRecord>, sqlx::Error> {
        let statuses = (!filter.statuses.is_empty()).then(|| {
            serde_json::to_string(&filter.statuses.iter().map(|s| s.as_str()).collect::<Vec<_>>())
                .unwrap_or_default()
        });
        let process_ids = (!filter.process_ids.is_empty())
            .then(|| serde_json::to_string(&filter.process_ids).unwrap_or_default());
        let sweep_ids = (!filter.sweep_ids.is_empty())
            .then(|| serde_json::to_string(&filter.sweep_ids).unwrap_or_default());
        let labels =
            (!filter.labels.is_empty()).then(|| serde_json::to_string(&filter.labels).unwrap_or_default());
        let sql = self.db.choose(LIST_SQLITE, LIST_POSTGRES);
        with_pool!(&self.db, pool => {
            sqlx::query_as(sql)
                .bind(&statuses)
                .bind(&process_ids)
                .bind(before)
                .bind(i64::from(limit))
                .bind(&sweep_ids)
                .bind(tenant)
                .bind(filter.in_sweep)
                .bind(&labels)
                .fetch_all(pool)
                .await
        })
    }

    /// Job `id` with its results or error, if `tenant` owns it.
    pub async fn outcome(&self, tenant: &str, id: &str) -> Result<Option<JobOutcome>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            let row = sqlx::query(concat!(
                "SELECT ",
                record_columns!(),
                ", results, error FROM jobs WHERE id = $1 AND tenant = $2"
            ))
            .bind(id)
            .bind(tenant)
            .fetch_optional(pool)
            .await?;
            row.map(|row| {
                Ok(JobOutcome {
                    record: sqlx::FromRow::from_row(&row)?,
                    results: row.try_get("results")?,
                    error: row.try_get("error")?,
                })
            })
            .transpose()
        })
    }

    /// The stored history `name` of job `id`, if `tenant` owns the job.
    pub async fn history(
        &self,
        tenant: &str,
        id: &str,
        name: &str,
    ) -> Result<Option<StoredHistory>, sqlx::Error> {
        let row = with_pool!(&self.db, pool => {
            sqlx::query_as::<_, (String, String, i64, Vec<u8>)>(
                "SELECT h.name, h.series, h.samples, h.data FROM job_histories h JOIN jobs j ON j.id = h.job_id \
                 WHERE h.job_id = $1 AND h.name = $2 AND j.tenant = $3",
            )
            .bind(id)
            .bind(name)
            .bind(tenant)
            .fetch_optional(pool)
            .await?
        });
        row.map(|(name, series, samples, data)| {
            Ok(StoredHistory {
                name,
                series: serde_json::from_str(&series).map_err(|e| sqlx::Error::ColumnDecode {
                    index: "series".into(),
                    source: Box::new(e),
                })?,
                samples: usize::try_from(samples).unwrap_or(0),
                data,
            })
        })
        .transpose()
    }

    /// Number of jobs in each status (every status present, zeros included).
    pub async fn count_by_status(&self) -> Result<Vec<(JobStatus, i64)>, sqlx::Error> {
        let rows: Vec<(String, i64)> = with_pool!(&self.db, pool => {
            sqlx::query_as("SELECT status, COUNT(*) FROM jobs GROUP BY status")
                .fetch_all(pool)
                .await?
        });
        Ok(JobStatus::ALL
            .into_iter()
            .map(|status| {
                let count = rows
                    .iter()
                    .find(|(s, _)| s == status.as_str())
                    .map_or(0, |(_, n)| *n);
                (status, count)
            })
            .collect())
    }
}
