//! Retention: finished jobs (and, by cascade, their histories) are deleted once old.
//! Idempotent: any number of processes may run it at once.

use super::JobQueue;
use crate::service::db::with_pool;

impl JobQueue {
    /// Deletes jobs that finished before `cutoff_ms` (ms since the Unix epoch); returns how many.
    pub async fn purge_finished_before(&self, cutoff_ms: i64) -> Result<u64, sqlx::Error> {
        let deleted = with_pool!(&self.db, pool => {
            sqlx::query(
                "DELETE FROM jobs WHERE status IN ('successful', 'failed', 'dismissed') AND finished_at < $1",
            )
            .bind(cutoff_ms)
            .execute(pool)
            .await?
            .rows_affected()
        });
        Ok(deleted)
    }
}
