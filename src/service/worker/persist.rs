//! Writing a run's outcome until it lands: a job that finishes while the disk is full
//! keeps its results in memory and retries the write with backoff until it commits, or
//! until the job is no longer this worker's (dismissed, or re-queued by recovery: it
//! then runs again). Nothing is silently dropped: every refused attempt is logged and
//! counted (`chocmodal_failed_writes_total{during="results"}`).
//!
//! While it waits, the worker renews its lease whenever the storage takes that small
//! write, so recovery does not hand the job to another worker meanwhile.

use std::future::Future;
use std::time::Duration;

use super::WorkerContext;
use crate::service::db::fault::StorageFault;
use crate::service::queue::Lease;

/// First wait after a refused write; doubled each time up to [`MAX_BACKOFF`].
const FIRST_BACKOFF: Duration = Duration::from_millis(100);
const MAX_BACKOFF: Duration = Duration::from_secs(5);

/// Runs `write` (a lease-guarded write returning whether the lease was held) until it
/// succeeds, fails for a reason retrying cannot fix, or the lease is lost.
pub(super) async fn until_stored<F, Fut>(
    ctx: &WorkerContext,
    lease: &Lease,
    what: &str,
    mut write: F,
) -> Result<bool, sqlx::Error>
where
    F: FnMut() -> Fut,
    Fut: Future<Output = Result<bool, sqlx::Error>>,
{
    let storage = ctx.metrics.storage();
    let mut backoff = FIRST_BACKOFF;
    let mut attempts = 0u32;
    loop {
        let error = match write().await {
            Ok(held) => {
                if attempts > 0 {
                    tracing::info!(job = %lease.job_id, attempts = attempts + 1, "{what}: stored after retrying");
                }
                return Ok(held);
            }
            Err(error) => error,
        };
        attempts += 1;
        let fault = storage.check(&error, "results");
        if fault.is_none() && !is_transient(&error) {
            return Err(error);
        }
        tracing::warn!(
            job = %lease.job_id,
            %error,
            cause = fault.map_or("busy", StorageFault::cause),
            attempts,
            retry_in = ?backoff,
            "{what}: the write was refused; holding the outcome and retrying"
        );
        tokio::time::sleep(backoff).await;
        backoff = (backoff * 2).min(MAX_BACKOFF);
        // Keep the lease while waiting (a small write that may land where the results did
        // not); a lease found lost ends the wait: the job is dismissed or runs again.
        match ctx.queue.heartbeat(lease, None, ctx.lease).await {
            Ok(true) => {}
            Ok(false) => {
                tracing::warn!(
                    job = %lease.job_id,
                    "{what}: the lease was lost while the write was refused; the job was dismissed \
                     or re-queued (it runs again), the held outcome is dropped"
                );
                return Ok(false);
            }
            Err(error) => {
                storage.check(&error, "heartbeat");
            }
        }
    }
}

/// Errors that pass by themselves: the database busy or locked (a writer holding the
/// lock), no connection free in time, a broken connection.
fn is_transient(error: &sqlx::Error) -> bool {
    match error {
        sqlx::Error::PoolTimedOut | sqlx::Error::Io(_) => true,
        sqlx::Error::Database(database) => {
            let code = database.code().unwrap_or_default();
            // SQLite SQLITE_BUSY (5) and SQLITE_LOCKED (6) with their extended codes;
            // PostgreSQL serialization failure, deadlock, and connection failures.
            code.parse::<i32>().is_ok_and(|code| matches!(code & 0xff, 5 | 6))
                || matches!(&*code, "40001" | "40P01")
                || code.starts_with("08")
        }
        _ => false,
    }
}
