//! The callbacks' durable state (`job_callbacks`, migration 0009): the subscriber stored
//! with its job, and what was delivered. Both backends' SQL side by side; each claim
//! runs in an explicit transaction committed before it returns (see [`crate::service::queue`]).
//!
//! A deliverer claims a due outcome by moving its `next_attempt_at` past the attempt
//! ([`CLAIM_WINDOW`]) and naming itself in `claimed_by`; its record of the attempt is
//! guarded by that name. A deliverer that dies mid-attempt leaves a claim that expires
//! by itself: the outcome is then claimed again (at least once, never lost). On
//! PostgreSQL concurrent claimers skip each other's locked rows.

use std::time::Duration;

use sqlx::Row;

use super::Subscriber;
use crate::service::clock::{SharedClock, duration_ms};
use crate::service::db::{Database, with_pool};

/// How long a claim holds an outcome: longer than an attempt can take.
pub const CLAIM_WINDOW: Duration = Duration::from_secs(60);

/// Stores a job's subscriber; run by the enqueue in the transaction that inserts the job.
/// Parameters: job id, tenant, the three URIs, now (ms).
pub const INSERT: &str = "INSERT INTO job_callbacks \
    (job_id, tenant, success_uri, failed_uri, in_progress_uri, created_at) \
    VALUES ($1, $2, $3, $4, $5, $6)";

/// The `INSERT` parameters of a subscriber: its three URIs as text.
pub fn uri_columns(subscriber: &Subscriber) -> [Option<String>; 3] {
    [
        &subscriber.success_uri,
        &subscriber.failed_uri,
        &subscriber.in_progress_uri,
    ]
    .map(|uri| uri.as_ref().map(|u| u.to_string()))
}

/// Whether any outcome is due (parameter: now): a read, so that an idle deliverer never
/// takes SQLite's write lock (nor writes to a full disk) to claim nothing.
const ANY_OUTCOME_DUE: &str = "SELECT EXISTS ( \
    SELECT 1 FROM job_callbacks c JOIN jobs j ON j.id = c.job_id \
    WHERE c.final_state = 'pending' AND c.next_attempt_at <= $1 \
        AND j.status IN ('successful', 'failed', 'dismissed'))";

/// Whether any progress is due (parameter: the latest time a last progress may have
/// been sent at).
const ANY_PROGRESS_DUE: &str = "SELECT EXISTS ( \
    SELECT 1 FROM job_callbacks c JOIN jobs j ON j.id = c.job_id \
    WHERE c.final_state = 'pending' AND c.in_progress_uri IS NOT NULL AND j.status = 'running' \
        AND (c.progress_sent_at IS NULL OR c.progress_sent_at <= $1) \
        AND (c.progress_sent IS NULL OR c.progress_sent <> j.progress))";

const CLAIM_OUTCOMES_SQLITE: &str = "\
    UPDATE job_callbacks SET next_attempt_at = $1, claimed_by = $2 \
    WHERE job_id IN ( \
        SELECT c.job_id FROM job_callbacks c JOIN jobs j ON j.id = c.job_id \
        WHERE c.final_state = 'pending' AND c.next_attempt_at <= $3 \
            AND j.status IN ('successful', 'failed', 'dismissed') \
        ORDER BY c.next_attempt_at LIMIT $4) \
    RETURNING job_id, tenant, success_uri, failed_uri, attempts";

const CLAIM_OUTCOMES_POSTGRES: &str = "\
    WITH due AS ( \
        SELECT c.job_id FROM job_callbacks c JOIN jobs j ON j.id = c.job_id \
        WHERE c.final_state = 'pending' AND c.next_attempt_at <= $3 \
            AND j.status IN ('successful', 'failed', 'dismissed') \
        ORDER BY c.next_attempt_at LIMIT $4 \
        FOR UPDATE OF c SKIP LOCKED) \
    UPDATE job_callbacks SET next_attempt_at = $1, claimed_by = $2 \
    FROM due WHERE job_callbacks.job_id = due.job_id \
    RETURNING job_callbacks.job_id, tenant, success_uri, failed_uri, attempts";

const CLAIM_PROGRESS_SQLITE: &str = "\
    UPDATE job_callbacks SET progress_sent_at = $1, \
        progress_sent = (SELECT progress FROM jobs WHERE jobs.id = job_callbacks.job_id) \
    WHERE job_id IN ( \
        SELECT c.job_id FROM job_callbacks c JOIN jobs j ON j.id = c.job_id \
        WHERE c.final_state = 'pending' AND c.in_progress_uri IS NOT NULL AND j.status = 'running' \
            AND (c.progress_sent_at IS NULL OR c.progress_sent_at <= $2) \
            AND (c.progress_sent IS NULL OR c.progress_sent <> j.progress) \
        LIMIT $3) \
    RETURNING job_id, tenant, in_progress_uri";

const CLAIM_PROGRESS_POSTGRES: &str = "\
    WITH due AS ( \
        SELECT c.job_id, j.progress FROM job_callbacks c JOIN jobs j ON j.id = c.job_id \
        WHERE c.final_state = 'pending' AND c.in_progress_uri IS NOT NULL AND j.status = 'running' \
            AND (c.progress_sent_at IS NULL OR c.progress_sent_at <= $2) \
            AND (c.progress_sent IS NULL OR c.progress_sent <> j.progress) \
        LIMIT $3 \
        FOR UPDATE OF c SKIP LOCKED) \
    UPDATE job_callbacks SET progress_sent_at = $1, progress_sent = due.progress \
    FROM due WHERE job_callbacks.job_id = due.job_id \
    RETURNING job_callbacks.job_id, tenant, in_progress_uri";

/// A finished job whose outcome this deliverer now holds a claim on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DueOutcome {
    pub job_id: String,
    pub tenant: String,
    pub success_uri: Option<String>,
    pub failed_uri: Option<String>,
    /// Failed attempts so far.
    pub attempts: i64,
}

/// A running job whose progress is due to its `in_progress_uri` (marked as sent).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DueProgress {
    pub job_id: String,
    pub tenant: String,
    pub in_progress_uri: String,
}

/// What became of a claimed outcome.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// The receiver answered 2xx.
    Delivered,
    /// The attempt failed for `error`; try again at `at` (ms).
    Retry { at: i64, error: String },
    /// Given up for `error`: never tried again.
    Abandoned { error: String },
    /// The subscriber has no URI for the job's outcome.
    Unsubscribed,
}

/// The callbacks' table, stamped by the queue's clock.
#[derive(Debug, Clone)]
pub struct Outbox {
    db: Database,
    clock: SharedClock,
}

impl Outbox {
    pub fn new(db: Database, clock: SharedClock) -> Self {
        Self { db, clock }
    }

    pub fn now(&self) -> i64 {
        self.clock.now_ms()
    }

    /// Claims up to `limit` due outcomes of finished jobs for `owner`, due first.
    pub async fn claim_outcomes(&self, owner: &str, limit: usize) -> Result<Vec<DueOutcome>, sqlx::Error> {
        let now = self.now();
        let until = now + duration_ms(CLAIM_WINDOW);
        let sql = self.db.choose(CLAIM_OUTCOMES_SQLITE, CLAIM_OUTCOMES_POSTGRES);
        let limit = i64::try_from(limit).unwrap_or(i64::MAX);
        with_pool!(&self.db, pool => {
            let due: bool = sqlx::query_scalar(ANY_OUTCOME_DUE).bind(now).fetch_one(pool).await?;
            if !due {
                return Ok(Vec::new());
            }
            let mut tx = pool.begin().await?;
            let rows = sqlx::query(sql)
                .bind(until)
                .bind(owner)
                .bind(now)
                .bind(limit)
                .fetch_all(&mut *tx)
                .await?;
            tx.commit().await?;
            rows.iter()
                .map(|row| {
                    Ok(DueOutcome {
                        job_id: row.try_get("job_id")?,
                        tenant: row.try_get("tenant")?,
                        success_uri: row.try_get("success_uri")?,
                        failed_uri: row.try_get("failed_uri")?,
                        attempts: row.try_get("attempts")?,
                    })
                })
                .collect()
        })
    }

    /// Marks up to `limit` running jobs' progress as sent now and returns them: those
    /// whose progress changed since the last one sent, at least `interval` ago.
    pub async fn claim_progress(
        &self,
        interval: Duration,
        limit: usize,
    ) -> Result<Vec<DueProgress>, sqlx::Error> {
        let now = self.now();
        let sql = self.db.choose(CLAIM_PROGRESS_SQLITE, CLAIM_PROGRESS_POSTGRES);
        let limit = i64::try_from(limit).unwrap_or(i64::MAX);
        let sent_before = now - duration_ms(interval);
        with_pool!(&self.db, pool => {
            let due: bool = sqlx::query_scalar(ANY_PROGRESS_DUE).bind(sent_before).fetch_one(pool).await?;
            if !due {
                return Ok(Vec::new());
            }
            let mut tx = pool.begin().await?;
            let rows = sqlx::query(sql)
                .bind(now)
                .bind(sent_before)
                .bind(limit)
                .fetch_all(&mut *tx)
                .await?;
            tx.commit().await?;
            rows.iter()
                .map(|row| {
                    Ok(DueProgress {
                        job_id: row.try_get("job_id")?,
                        tenant: row.try_get("tenant")?,
                        in_progress_uri: row.try_get("in_progress_uri")?,
                    })
                })
                .collect()
        })
    }

    /// Records what became of `owner`'s claim on `job_id`'s outcome; false when the
    /// claim was no longer `owner`'s (it expired and another deliverer took it).
    pub async fn record(&self, job_id: &str, owner: &str, outcome: &Outcome) -> Result<bool, sqlx::Error> {
        let (state, attempted, next_attempt_at, error): (&str, i64, Option<i64>, Option<&str>) = match outcome
        {
            Outcome::Delivered => ("delivered", 1, None, None),
            Outcome::Retry { at, error } => ("pending", 1, Some(*at), Some(error)),
            Outcome::Abandoned { error } => ("abandoned", 1, None, Some(error)),
            Outcome::Unsubscribed => ("unsubscribed", 0, None, None),
        };
        let updated = with_pool!(&self.db, pool => {
            sqlx::query(
                "UPDATE job_callbacks SET final_state = $3, attempts = attempts + $4, \
                     next_attempt_at = COALESCE($5, next_attempt_at), last_error = $6, claimed_by = NULL \
                 WHERE job_id = $1 AND claimed_by = $2 AND final_state = 'pending'",
            )
            .bind(job_id)
            .bind(owner)
            .bind(state)
            .bind(attempted)
            .bind(next_attempt_at)
            .bind(error)
            .execute(pool)
            .await?
            .rows_affected()
        });
        Ok(updated == 1)
    }

    /// The delivery state of `job_id`'s outcome: (`final_state`, attempts, last error);
    /// `None` when the job has no subscriber.
    pub async fn state(&self, job_id: &str) -> Result<Option<(String, i64, Option<String>)>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            let row = sqlx::query("SELECT final_state, attempts, last_error FROM job_callbacks WHERE job_id = $1")
                .bind(job_id)
                .fetch_optional(pool)
                .await?;
            row.map(|row| Ok((row.try_get("final_state")?, row.try_get("attempts")?, row.try_get("last_error")?)))
                .transpose()
        })
    }
}
