//! Dismiss a sweep (`DELETE /sweeps/{id}`): every run still queued or running is
//! dismissed (a queued run never starts, a running one stops within a second); runs
//! that already ended keep their results.

use super::{JobQueue, SweepRecord, sweep_columns};
use crate::service::db::with_pool;

impl JobQueue {
    /// Dismisses sweep `id` of `tenant` and its unfinished runs; returns the sweep and the
    /// ids of the runs dismissed now (to cancel the running ones at once), `None` if
    /// `tenant` has no such sweep. Dismissing twice is harmless.
    pub async fn dismiss_sweep(
        &self,
        tenant: &str,
        id: &str,
    ) -> Result<Option<(SweepRecord, Vec<String>)>, sqlx::Error> {
        let now = self.now();
        with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            let sweep: Option<SweepRecord> = sqlx::query_as(concat!(
                "UPDATE sweeps SET dismissed = TRUE, updated_at = CASE WHEN dismissed THEN updated_at ELSE $2 END \
                 WHERE id = $1 AND tenant = $3 RETURNING ",
                sweep_columns!()
            ))
            .bind(id)
            .bind(now)
            .bind(tenant)
            .fetch_optional(&mut *tx)
            .await?;
            let Some(sweep) = sweep else {
                tx.rollback().await?;
                return Ok(None);
            };
            let dismissed: Vec<String> = sqlx::query_scalar(
                "UPDATE jobs SET status = 'dismissed', cancel_requested = TRUE, message = 'dismissed with its sweep', \
                     finished_at = $2, updated_at = $2, lease_owner = NULL, lease_expires_at = NULL \
                 WHERE sweep_id = $1 AND status IN ('accepted', 'running') RETURNING id",
            )
            .bind(id)
            .bind(now)
            .fetch_all(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(Some((sweep, dismissed)))
        })
    }
}
