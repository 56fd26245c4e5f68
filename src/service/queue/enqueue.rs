//! Enqueue: one execution request becomes one `accepted` job row of its tenant, with its
//! content hash, unless the tenant already has as many queued jobs as allowed. On
//! PostgreSQL, listening workers in every process are notified.
//!
//! The limit is checked by the insert itself (`INSERT ... SELECT ... WHERE count < limit`).
//! Concurrent submissions can never take a tenant over its limit: SQLite takes the write
//! lock before it counts; on PostgreSQL the transaction first takes the tenant's queue
//! lock ([`TenantQueueLock`]), which every such insert of that tenant waits for.

use super::content_hash::content_hash;
use super::{Admission, JobQueue, JobRecord, record_columns};
use crate::service::db::{TenantQueueLock, with_pool};

impl JobQueue {
    /// Inserts an accepted job of `tenant` for `process_id` with its (already validated)
    /// inputs and their plausibility warnings, unless `tenant` already has `max_queued`
    /// accepted jobs.
    pub async fn enqueue(
        &self,
        tenant: &str,
        process_id: &str,
        inputs: &serde_json::Value,
        warnings: &[crate::processes::Warning],
        max_queued: Option<u64>,
    ) -> Result<Admission<JobRecord>, sqlx::Error> {
        let warnings = serde_json::to_string(warnings).expect("warnings serialize");
        let id = uuid::Uuid::new_v4().to_string();
        let inserted: Option<JobRecord> = with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            tx.lock_tenant_queue(tenant).await?;
            let inserted = sqlx::query_as(concat!(
                "INSERT INTO jobs (id, tenant, process_id, inputs, status, progress, message, created_at, \
                     updated_at, content_hash, warnings) \
                 SELECT $1, $6, $2, $3, 'accepted', 0, 'queued', $4, $4, $5, $8 \
                 WHERE $7 IS NULL OR (SELECT COUNT(*) FROM jobs WHERE tenant = $6 AND status = 'accepted') < $7 \
                 RETURNING ",
                record_columns!()
            ))
            .bind(&id)
            .bind(process_id)
            .bind(inputs.to_string())
            .bind(self.now())
            .bind(content_hash(process_id, inputs))
            .bind(tenant)
            .bind(max_queued.map(|n| i64::try_from(n).unwrap_or(i64::MAX)))
            .bind(&warnings)
            .fetch_optional(&mut *tx)
            .await?;
            tx.commit().await?;
            inserted
        });
        match inserted {
            Some(record) => {
                self.announce_queued().await;
                Ok(Admission::Admitted(record))
            }
            None => Ok(Admission::QueueFull {
                queued: self.queued_count(tenant).await?,
            }),
        }
    }

    /// Number of accepted (queued) jobs of `tenant`, sweep runs included.
    pub async fn queued_count(&self, tenant: &str) -> Result<i64, sqlx::Error> {
        with_pool!(&self.db, pool => {
            sqlx::query_scalar("SELECT COUNT(*) FROM jobs WHERE tenant = $1 AND status = 'accepted'")
                .bind(tenant)
                .fetch_one(pool)
                .await
        })
    }

    /// Wakes the workers of other processes (PostgreSQL `NOTIFY`; nothing on SQLite,
    /// whose workers all live in this process). Best effort: workers also poll.
    pub(crate) async fn announce_queued(&self) {
        if let Some(pool) = self.db.as_postgres()
            && let Err(error) = crate::service::db::postgres::notify_queued(pool).await
        {
            tracing::warn!(%error, "cannot notify the workers; they will poll");
        }
    }
}
