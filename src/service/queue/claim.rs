//! Claim: a worker atomically takes the next accepted job and a lease on it.
//!
//! SQLite: one `UPDATE ... WHERE seq = (SELECT ...) RETURNING` statement; SQLite takes
//! the write lock before it reads, so two workers can never claim the same row.
//! PostgreSQL: the candidate is picked in a CTE with `FOR UPDATE SKIP LOCKED` and
//! `LIMIT 1` (a CTE is evaluated once, so the planner cannot claim more rows than
//! asked), then updated: concurrent claimers skip each other's row instead of waiting
//! or taking the same one. The statement runs in its own explicit transaction, committed
//! before the claim is returned: a `RETURNING` read alone in autocommit would drop the
//! commit's error (sqlx issue #3430), and a worker would run a job whose claim was never
//! stored. Nothing is held once the claim returns.
//!
//! Order: single jobs first (oldest first), then sweep runs (oldest first). A sweep of
//! thousands of runs queued before a single job never makes it wait for more than the
//! runs already computing: it only gets the workers no single job wants.

use std::time::Duration;

use sqlx::Row;

use super::{ClaimedJob, JobQueue, Lease};
use crate::service::clock::duration_ms;
use crate::service::db::with_pool;

const CLAIM_SQLITE: &str = "\
    UPDATE jobs SET status = 'running', attempt = attempt + 1, lease_owner = $1, \
        lease_expires_at = $2, started_at = $3, updated_at = $3, progress = 0, message = 'running' \
    WHERE seq = COALESCE( \
        (SELECT seq FROM jobs WHERE status = 'accepted' AND sweep_id IS NULL ORDER BY seq LIMIT 1), \
        (SELECT seq FROM jobs WHERE status = 'accepted' ORDER BY seq LIMIT 1)) \
    RETURNING id, process_id, inputs, attempt, created_at, content_hash, tenant";

const CLAIM_POSTGRES: &str = "\
    WITH next AS ( \
        SELECT seq FROM jobs WHERE status = 'accepted' \
        ORDER BY sweep_id IS NOT NULL, seq LIMIT 1 \
        FOR UPDATE SKIP LOCKED) \
    UPDATE jobs SET status = 'running', attempt = attempt + 1, lease_owner = $1, \
        lease_expires_at = $2, started_at = $3, updated_at = $3, progress = 0, message = 'running' \
    FROM next WHERE jobs.seq = next.seq \
    RETURNING jobs.id, jobs.process_id, jobs.inputs, jobs.attempt, jobs.created_at, jobs.content_hash, \
        jobs.tenant";

impl JobQueue {
    /// Takes the next accepted job for `owner`, leased for `lease`; `None` if the queue is empty.
    pub async fn claim(&self, owner: &str, lease: Duration) -> Result<Option<ClaimedJob>, sqlx::Error> {
        let now = self.now();
        let sql = self.db.choose(CLAIM_SQLITE, CLAIM_POSTGRES);
        with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            let row = sqlx::query(sql)
                .bind(owner)
                .bind(now.saturating_add(duration_ms(lease)))
                .bind(now)
                .fetch_optional(&mut *tx)
                .await?;
            let Some(row) = row else {
                tx.rollback().await?;
                return Ok(None);
            };
            tx.commit().await?;
            let inputs: String = row.try_get("inputs")?;
            let inputs = serde_json::from_str(&inputs).map_err(|e| sqlx::Error::ColumnDecode {
                index: "inputs".into(),
                source: Box::new(e),
            })?;
            Ok(Some(ClaimedJob {
                lease: Lease {
                    job_id: row.try_get("id")?,
                    owner: owner.to_owned(),
                    attempt: row.try_get("attempt")?,
                },
                process_id: row.try_get("process_id")?,
                inputs,
                tenant: row.try_get("tenant")?,
                content_hash: row.try_get("content_hash")?,
                created_at: row.try_get("created_at")?,
                started_at: now,
            }))
        })
    }
}
