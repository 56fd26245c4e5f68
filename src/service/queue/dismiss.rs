//! Dismiss (`DELETE /jobs/{jobId}`): a queued job never runs, a running job is told to
//! stop, a finished job loses its results. The status becomes `dismissed` at once; the
//! worker of a running job notices through its lease (its next guarded write fails),
//! within half a second by its ownership check in any process, or at once in this
//! process through the in-memory cancel flag the HTTP handler also sets.

use super::{JobQueue, JobRecord, record_columns};
use crate::service::db::with_pool;

impl JobQueue {
    /// Dismisses job `id` of `tenant`; `None` if `tenant` has no such job. Dismissing
    /// twice is harmless.
    pub async fn dismiss(&self, tenant: &str, id: &str) -> Result<Option<JobRecord>, sqlx::Error> {
        let now = self.now();
        with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            let dismissed: Option<JobRecord> = sqlx::query_as(concat!(
                "UPDATE jobs SET status = 'dismissed', cancel_requested = TRUE, message = 'dismissed', \
                     finished_at = COALESCE(finished_at, $2), updated_at = $2, lease_owner = NULL, \
                     lease_expires_at = NULL, results = NULL, verdict = NULL \
                 WHERE id = $1 AND tenant = $3 AND status <> 'dismissed' RETURNING ",
                record_columns!()
            ))
            .bind(id)
            .bind(now)
            .bind(tenant)
            .fetch_optional(&mut *tx)
            .await?;
            let record = match dismissed {
                Some(record) => {
                    sqlx::query("DELETE FROM job_histories WHERE job_id = $1")
                        .bind(id)
                        .execute(&mut *tx)
                        .await?;
                    Some(record)
                }
                None => {
                    sqlx::query_as(concat!(
                        "SELECT ",
                        record_columns!(),
                        " FROM jobs WHERE id = $1 AND tenant = $2"
                    ))
                    .bind(id)
                    .bind(tenant)
                    .fetch_optional(&mut *tx)
                    .await?
                }
            };
            tx.commit().await?;
            Ok(record)
        })
    }
}
