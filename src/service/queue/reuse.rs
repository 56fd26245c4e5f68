//! Reuse: a claimed job whose content hash matches a successful job takes that job's
//! results document and histories (copied, so that dismissing or purging either job
//! never affects the other) instead of computing again.
//!
//! Checked at claim time rather than at submission, so that identical runs queued
//! together (in one sweep, or while the first one computes) are computed once too.
//! Only the same tenant's jobs are reused: another tenant must not learn, from a reuse
//! message naming a job, that someone ran the same inputs.

use super::{JobQueue, Lease};
use crate::quality_note::finished_message;
use crate::service::db::with_pool;

/// Completes the leased job ($1–$3) with results $5 copied from job $6, only while $6
/// is still successful; $7 is the status message (the reuse, and the results' quality
/// verdict when it is not good), $8 the verdict. SQLite: this first write takes the database's write lock, so
/// the source cannot change before the histories are copied. PostgreSQL: the source
/// row is locked `FOR SHARE` (a dismissal or purge of it waits for this transaction).
const TAKE_SQLITE: &str = "\
    UPDATE jobs SET status = 'successful', progress = 100, finished_at = $4, updated_at = $4, \
        lease_owner = NULL, lease_expires_at = NULL, results = $5, \
        message = $7, verdict = $8 \
    WHERE id = $1 AND lease_owner = $2 AND attempt = $3 AND status = 'running' \
        AND EXISTS (SELECT 1 FROM jobs WHERE id = $6 AND status = 'successful')";

const TAKE_POSTGRES: &str = "\
    UPDATE jobs SET status = 'successful', progress = 100, finished_at = $4, updated_at = $4, \
        lease_owner = NULL, lease_expires_at = NULL, results = $5, \
        message = $7, verdict = $8 \
    WHERE id = $1 AND lease_owner = $2 AND attempt = $3 AND status = 'running' \
        AND EXISTS (SELECT 1 FROM jobs source WHERE source.id = $6 AND source.status = 'successful' \
            FOR SHARE OF source)";

impl JobQueue {
    /// If a successful job of `tenant` has `hash`, completes the leased job with a copy
    /// of its results and histories and returns that job's id; `None` when nothing
    /// matches (or the lease was lost).
    pub async fn reuse(
        &self,
        lease: &Lease,
        tenant: &str,
        hash: &str,
    ) -> Result<Option<String>, sqlx::Error> {
        let take = self.db.choose(TAKE_SQLITE, TAKE_POSTGRES);
        with_pool!(&self.db, pool => {
            let source: Option<(String, String)> = sqlx::query_as(
                "SELECT id, results FROM jobs \
                 WHERE content_hash = $1 AND status = 'successful' AND id <> $2 AND results IS NOT NULL \
                     AND tenant = $3 \
                 ORDER BY seq LIMIT 1",
            )
            .bind(hash)
            .bind(&lease.job_id)
            .bind(tenant)
            .fetch_optional(pool)
            .await?;
            let Some((source_id, results)) = source else {
                return Ok(None);
            };
            // The results document links to the histories of its own job.
            let results = results.replace(
                &format!("/jobs/{source_id}/"),
                &format!("/jobs/{}/", lease.job_id),
            );
            let document = serde_json::from_str::<serde_json::Value>(&results).ok();
            let message = document
                .as_ref()
                .map(|document| {
                    finished_message(document, Some(&format!("reused the results of job {source_id}")))
                })
                .unwrap_or_else(|| format!("finished: reused the results of job {source_id}"));
            let verdict = document.as_ref().and_then(super::finish::verdict).map(str::to_owned);
            let now = self.now();
            let mut tx = pool.begin().await?;
            let updated = sqlx::query(take)
                .bind(&lease.job_id)
                .bind(&lease.owner)
                .bind(lease.attempt)
                .bind(now)
                .bind(&results)
                .bind(&source_id)
                .bind(&message)
                .bind(&verdict)
                .execute(&mut *tx)
                .await?;
            if updated.rows_affected() != 1 {
                tx.rollback().await?;
                return Ok(None);
            }
            sqlx::query(
                "INSERT INTO job_histories (job_id, name, series, samples, data) \
                 SELECT $1, name, series, samples, data FROM job_histories WHERE job_id = $2",
            )
            .bind(&lease.job_id)
            .bind(&source_id)
            .execute(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(Some(source_id))
        })
    }
}
