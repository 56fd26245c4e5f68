//! Finish: the lease owner records the outcome of its run, or hands the job back.
//!
//! Every statement is guarded by the lease (id, owner, attempt, still `running`); a
//! `false` return means the worker had lost the job and nothing was written. On
//! PostgreSQL the guarded `UPDATE` locks the row, so a concurrent dismissal or recovery
//! either happens first (the guard then fails) or waits for this transaction.

use super::{JobQueue, Lease};
use crate::problem::Problem;
use crate::quality_note::finished_message;
use crate::service::db::with_pool;
use crate::service::store::StoredHistory;

/// `quality.verdict` of a results document, if it has one.
pub(super) fn verdict(results: &serde_json::Value) -> Option<&str> {
    results["quality"]["verdict"].as_str()
}

/// The lease guard shared by every statement below (parameters $1, $2, $3).
macro_rules! guard {
    () => {
        " WHERE id = $1 AND lease_owner = $2 AND attempt = $3 AND status = 'running'"
    };
}

impl JobQueue {
    /// Marks the job successful with its results document and histories (one transaction:
    /// the row and its histories appear together or not at all). The status message is
    /// `finished`, with the quality verdict and its reasons when they are not good
    /// ([`finished_message`]); the verdict is also kept on its own, for the job list.
    pub async fn complete(
        &self,
        lease: &Lease,
        results: &serde_json::Value,
        histories: &[StoredHistory],
    ) -> Result<bool, sqlx::Error> {
        let now = self.now();
        let message = finished_message(results, None);
        with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            // The first statement writes, so the transaction holds the write lock (SQLite)
            // or the row lock (PostgreSQL) from the start.
            let updated = sqlx::query(concat!(
                "UPDATE jobs SET status = 'successful', progress = 100, message = $6, \
                     finished_at = $4, updated_at = $4, lease_owner = NULL, lease_expires_at = NULL, \
                     results = $5, verdict = $7",
                guard!()
            ))
            .bind(&lease.job_id)
            .bind(&lease.owner)
            .bind(lease.attempt)
            .bind(now)
            .bind(results.to_string())
            .bind(&message)
            .bind(verdict(results))
            .execute(&mut *tx)
            .await?;
            if updated.rows_affected() != 1 {
                tx.rollback().await?;
                return Ok(false);
            }
            for history in histories {
                sqlx::query(
                    "INSERT INTO job_histories (job_id, name, series, samples, data) VALUES ($1, $2, $3, $4, $5)",
                )
                .bind(&lease.job_id)
                .bind(&history.name)
                .bind(serde_json::to_string(&history.series).unwrap_or_else(|_| "[]".into()))
                .bind(history.samples as i64)
                .bind(&history.data)
                .execute(&mut *tx)
                .await?;
            }
            tx.commit().await?;
            Ok(true)
        })
    }

    /// Marks the job failed with `problem` as its error (served by `/jobs/{id}/results`).
    /// `reached`: the percent the run had reached when it stopped (a diverged run's
    /// progress says where it stopped, even between two heartbeats); `None` keeps the
    /// last recorded progress (a job that failed before computing). A run of a
    /// `fail_fast` sweep also dismisses the sweep's runs that have not ended (their
    /// workers notice within a second), in the same transaction.
    pub async fn fail(
        &self,
        lease: &Lease,
        problem: &Problem,
        reached: Option<u8>,
    ) -> Result<bool, sqlx::Error> {
        let now = self.now();
        with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            let updated = sqlx::query(concat!(
                "UPDATE jobs SET status = 'failed', message = $5, error = $6, finished_at = $4, \
                     updated_at = $4, lease_owner = NULL, lease_expires_at = NULL, \
                     progress = COALESCE($7, progress)",
                guard!()
            ))
            .bind(&lease.job_id)
            .bind(&lease.owner)
            .bind(lease.attempt)
            .bind(now)
            .bind(format!("failed: {}", problem.detail))
            .bind(serde_json::to_string(problem).unwrap_or_default())
            .bind(reached.map(i64::from))
            .execute(&mut *tx)
            .await?;
            if updated.rows_affected() != 1 {
                tx.rollback().await?;
                return Ok(false);
            }
            sqlx::query(
                "UPDATE jobs SET status = 'dismissed', cancel_requested = TRUE, finished_at = $2, updated_at = $2, \
                     lease_owner = NULL, lease_expires_at = NULL, \
                     message = 'dismissed: job ' || $1 || ' of its fail-fast sweep failed' \
                 WHERE sweep_id = (SELECT sweep_id FROM jobs WHERE id = $1) \
                   AND status IN ('accepted', 'running') \
                   AND EXISTS (SELECT 1 FROM sweeps s WHERE s.id = jobs.sweep_id AND s.policy = 'fail_fast')",
            )
            .bind(&lease.job_id)
            .bind(now)
            .execute(&mut *tx)
            .await?;
            tx.commit().await?;
            Ok(true)
        })
    }

    /// Returns the job to the queue without counting the attempt (graceful shutdown ran
    /// out of time): another worker, or this service after its restart, starts it again.
    pub async fn hand_back(&self, lease: &Lease) -> Result<bool, sqlx::Error> {
        let now = self.now();
        let updated = with_pool!(&self.db, pool => {
            sqlx::query(concat!(
                "UPDATE jobs SET status = 'accepted', attempt = attempt - 1, lease_owner = NULL, \
                     lease_expires_at = NULL, started_at = NULL, progress = 0, updated_at = $4, \
                     message = 'queued again: the service stopped before the job finished'",
                guard!()
            ))
            .bind(&lease.job_id)
            .bind(&lease.owner)
            .bind(lease.attempt)
            .bind(now)
            .execute(pool)
            .await?
            .rows_affected()
        });
        if updated == 1 {
            self.announce_queued().await;
        }
        Ok(updated == 1)
    }
}
