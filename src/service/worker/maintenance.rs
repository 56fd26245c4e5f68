//! Periodic queue maintenance: recover jobs whose lease expired, apply retention.

use std::sync::Arc;
use std::time::Duration;

use tokio::sync::Notify;

use crate::service::clock::duration_ms;
use crate::service::metrics::Metrics;
use crate::service::queue::JobQueue;

/// One maintenance pass's settings and collaborators.
#[derive(Debug, Clone)]
pub struct Maintenance {
    pub queue: JobQueue,
    pub metrics: Metrics,
    pub wake: Arc<Notify>,
    pub max_attempts: u32,
    /// Age after which finished jobs are deleted; `None` keeps them.
    pub retention: Option<Duration>,
}

impl Maintenance {
    /// Recovers expired leases, then deletes finished jobs past retention.
    pub async fn run_once(&self) -> Result<(), sqlx::Error> {
        let recovered = self.queue.recover_expired(self.max_attempts).await?;
        if !recovered.requeued.is_empty() || !recovered.failed.is_empty() {
            tracing::warn!(
                requeued = ?recovered.requeued,
                failed = ?recovered.failed,
                "recovered jobs whose worker was lost"
            );
            self.metrics
                .count_recovery(recovered.requeued.len(), recovered.failed.len());
            self.wake.notify_waiters();
        }
        if let Some(retention) = self.retention {
            let cutoff = self.queue.clock().now_ms().saturating_sub(duration_ms(retention));
            let purged = self.queue.purge_finished_before(cutoff).await?;
            if purged > 0 {
                tracing::info!(purged, "deleted finished jobs past retention");
            }
        }
        Ok(())
    }

    /// The pass at start-up: a storage that refuses writes (a full disk) does not keep
    /// the service from starting (it serves reads, refuses writes with 507, and the
    /// periodic passes recover the leases once space is freed); other errors do.
    pub async fn run_at_start(&self) -> Result<(), sqlx::Error> {
        match self.run_once().await {
            Err(error) if self.metrics.storage().check(&error, "maintenance").is_some() => {
                tracing::error!(%error, "queue maintenance at start-up: the storage refuses writes; starting anyway");
                Ok(())
            }
            outcome => outcome,
        }
    }

    /// Runs a pass every `interval`, forever (the caller aborts the task).
    pub async fn run_every(self, interval: Duration) {
        let mut ticker = tokio::time::interval(interval);
        ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        ticker.tick().await;
        loop {
            ticker.tick().await;
            if let Err(error) = self.run_once().await {
                self.metrics.storage().check(&error, "maintenance");
                tracing::error!(%error, "queue maintenance failed");
            }
        }
    }
}
