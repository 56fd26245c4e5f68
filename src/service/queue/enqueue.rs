//! Enqueue: one execution request becomes one `accepted` job row, with its content hash.
//! On PostgreSQL, listening workers in every process are notified.

use super::content_hash::content_hash;
use super::{JobQueue, JobRecord, record_columns};
use crate::service::db::with_pool;

impl JobQueue {
    /// Inserts an accepted job for `process_id` with its (already validated) inputs.
    pub async fn enqueue(
        &self,
        process_id: &str,
        inputs: &serde_json::Value,
    ) -> Result<JobRecord, sqlx::Error> {
        let id = uuid::Uuid::new_v4().to_string();
        let record = with_pool!(&self.db, pool => {
            sqlx::query_as(concat!(
                "INSERT INTO jobs (id, process_id, inputs, status, progress, message, created_at, updated_at, \
                     content_hash) \
                 VALUES ($1, $2, $3, 'accepted', 0, 'queued', $4, $4, $5) RETURNING ",
                record_columns!()
            ))
            .bind(&id)
            .bind(process_id)
            .bind(inputs.to_string())
            .bind(self.now())
            .bind(content_hash(process_id, inputs))
            .fetch_one(pool)
            .await?
        });
        self.announce_queued().await;
        Ok(record)
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
