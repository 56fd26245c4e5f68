//! Enqueue: one execution request becomes one `accepted` job row of its tenant, with its
//! content hash, unless the tenant already has as many queued jobs as allowed.
//!
//! The limit is checked by the insert itself (`INSERT ... SELECT ... WHERE count < limit`):
//! SQLite takes the write lock before it counts, so concurrent submissions can never
//! take a tenant over its limit.

use super::content_hash::content_hash;
use super::{Admission, JobQueue, JobRecord, record_columns};

impl JobQueue {
    /// Inserts an accepted job of `tenant` for `process_id` with its (already validated)
    /// inputs, unless `tenant` already has `max_queued` accepted jobs.
    pub async fn enqueue(
        &self,
        tenant: &str,
        process_id: &str,
        inputs: &serde_json::Value,
        max_queued: Option<u64>,
    ) -> Result<Admission<JobRecord>, sqlx::Error> {
        let id = uuid::Uuid::new_v4().to_string();
        let inserted: Option<JobRecord> = sqlx::query_as(concat!(
            "INSERT INTO jobs (id, tenant, process_id, inputs, status, progress, message, created_at, \
                 updated_at, content_hash) \
             SELECT ?1, ?6, ?2, ?3, 'accepted', 0, 'queued', ?4, ?4, ?5 \
             WHERE ?7 IS NULL OR (SELECT COUNT(*) FROM jobs WHERE tenant = ?6 AND status = 'accepted') < ?7 \
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
        .fetch_optional(&self.pool)
        .await?;
        match inserted {
            Some(record) => Ok(Admission::Admitted(record)),
            None => Ok(Admission::QueueFull {
                queued: self.queued_count(tenant).await?,
            }),
        }
    }

    /// Number of accepted (queued) jobs of `tenant`, sweep runs included.
    pub async fn queued_count(&self, tenant: &str) -> Result<i64, sqlx::Error> {
        sqlx::query_scalar("SELECT COUNT(*) FROM jobs WHERE tenant = ?1 AND status = 'accepted'")
            .bind(tenant)
            .fetch_one(&self.pool)
            .await
    }
}
