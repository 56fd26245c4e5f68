//! Heartbeat: the owner of a running job renews its lease and records progress.
//!
//! Only the lease's owner, for the same attempt, on a job still `running`, can extend it:
//! when the statement touches no row the worker has lost the job (dismissed, or
//! recovered by another worker or process after a stall) and must stop.

use std::time::Duration;

use super::{JobQueue, Lease};
use crate::service::clock::duration_ms;
use crate::service::db::with_pool;

impl JobQueue {
    /// Extends the lease to now + `lease`, and sets `progress` (percent) when given; the
    /// update time moves only when the progress changes, so a heartbeat alone does not
    /// change the job's representation. Returns whether the lease is still held.
    pub async fn heartbeat(
        &self,
        lease: &Lease,
        progress: Option<u8>,
        lease_for: Duration,
    ) -> Result<bool, sqlx::Error> {
        let now = self.now();
        let updated = with_pool!(&self.db, pool => {
            sqlx::query(
                "UPDATE jobs SET lease_expires_at = $4, \
                     updated_at = CASE WHEN $5 IS NOT NULL AND $5 <> progress THEN $6 ELSE updated_at END, \
                     progress = COALESCE($5, progress) \
                 WHERE id = $1 AND lease_owner = $2 AND attempt = $3 AND status = 'running' \
                     AND NOT cancel_requested",
            )
            .bind(&lease.job_id)
            .bind(&lease.owner)
            .bind(lease.attempt)
            .bind(now.saturating_add(duration_ms(lease_for)))
            .bind(progress.map(i64::from))
            .bind(now)
            .execute(pool)
            .await?
            .rows_affected()
        });
        Ok(updated == 1)
    }

    /// Whether the lease is still held (a read: cheap enough to poll for cancellation).
    pub async fn is_held(&self, lease: &Lease) -> Result<bool, sqlx::Error> {
        let held: Option<i64> = with_pool!(&self.db, pool => {
            sqlx::query_scalar(
                "SELECT attempt FROM jobs WHERE id = $1 AND lease_owner = $2 AND attempt = $3 \
                     AND status = 'running' AND NOT cancel_requested",
            )
            .bind(&lease.job_id)
            .bind(&lease.owner)
            .bind(lease.attempt)
            .fetch_optional(pool)
            .await?
        });
        Ok(held.is_some())
    }
}
