//! Retention: finished jobs (and, by cascade, their histories) are deleted once old.

use super::JobQueue;

impl JobQueue {
    /// Deletes jobs that finished before `cutoff_ms` (ms since the Unix epoch); returns how many.
    pub async fn purge_finished_before(&self, cutoff_ms: i64) -> Result<u64, sqlx::Error> {
        let deleted = sqlx::query(
            "DELETE FROM jobs WHERE status IN ('successful', 'failed', 'dismissed') AND finished_at < ?1",
        )
        .bind(cutoff_ms)
        .execute(&self.pool)
        .await?;
        Ok(deleted.rows_affected())
    }
}
