//! Recovery: running jobs whose lease expired lost their worker (crash, kill, stall).
//!
//! At start-up and periodically, each such job goes back to the queue, unless it has
//! already been claimed `max_attempts` times: a job that keeps killing its worker fails
//! with a message that says so instead of looping forever.
//!
//! Safe to run in every process at once: each statement re-checks `status = 'running'`
//! and the expiry on the row it changes (PostgreSQL re-evaluates them after waiting for
//! a concurrent writer's row lock), so a job is recovered by exactly one pass, and a
//! heartbeat that renews the lease first keeps the job where it is.

use super::JobQueue;
use crate::problem::CHOCMODAL_PROBLEMS;
use crate::service::db::with_pool;

/// Jobs taken back from lost workers by one recovery pass.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Recovered {
    /// Ids of jobs queued again.
    pub requeued: Vec<String>,
    /// Ids of jobs failed after too many lost workers.
    pub failed: Vec<String>,
}

/// Fails the jobs that lost their worker `max_attempts` times; the statement builds
/// the problem document (it names the attempts).
const ABANDON_SQLITE: &str = "\
    UPDATE jobs SET status = 'failed', finished_at = $1, updated_at = $1, lease_owner = NULL, \
        lease_expires_at = NULL, \
        message = 'failed: its worker was lost ' || attempt || ' times', \
        error = json_object('type', $3, 'title', 'Job abandoned', 'status', 500, 'detail', \
            'the worker running this job stopped (crash, kill or stall) ' || attempt || \
            ' times before it finished; it is not retried again') \
    WHERE status = 'running' AND lease_expires_at < $1 AND attempt >= $2 RETURNING id";

const ABANDON_POSTGRES: &str = "\
    UPDATE jobs SET status = 'failed', finished_at = $1, updated_at = $1, lease_owner = NULL, \
        lease_expires_at = NULL, \
        message = 'failed: its worker was lost ' || attempt || ' times', \
        error = CAST(jsonb_build_object('type', $3, 'title', 'Job abandoned', 'status', 500, 'detail', \
            'the worker running this job stopped (crash, kill or stall) ' || attempt || \
            ' times before it finished; it is not retried again') AS TEXT) \
    WHERE status = 'running' AND lease_expires_at < $1 AND attempt >= $2 RETURNING id";

impl JobQueue {
    /// Re-queues (or fails, after `max_attempts` claims) every running job whose lease expired.
    pub async fn recover_expired(&self, max_attempts: u32) -> Result<Recovered, sqlx::Error> {
        let now = self.now();
        let abandon = self.db.choose(ABANDON_SQLITE, ABANDON_POSTGRES);
        let recovered = with_pool!(&self.db, pool => {
            // One transaction: both updates land, or neither (and the caller sees which).
            let mut tx = pool.begin().await?;
            let failed: Vec<String> = sqlx::query_scalar(abandon)
                .bind(now)
                .bind(i64::from(max_attempts))
                .bind(format!("{CHOCMODAL_PROBLEMS}/job-abandoned"))
                .fetch_all(&mut *tx)
                .await?;
            let requeued: Vec<String> = sqlx::query_scalar(
                "UPDATE jobs SET status = 'accepted', lease_owner = NULL, lease_expires_at = NULL, \
                     started_at = NULL, progress = 0, updated_at = $1, \
                     message = 'queued again: its worker was lost (attempt ' || attempt || ' of ' || $2 || ')' \
                 WHERE status = 'running' AND lease_expires_at < $1 RETURNING id",
            )
            .bind(now)
            .bind(i64::from(max_attempts))
            .fetch_all(&mut *tx)
            .await?;
            tx.commit().await?;
            Recovered { requeued, failed }
        });
        if !recovered.requeued.is_empty() {
            self.announce_queued().await;
        }
        Ok(recovered)
    }
}
