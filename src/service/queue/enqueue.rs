//! Enqueue: one execution request becomes one `accepted` job row, with its content hash.

use super::content_hash::content_hash;
use super::{JobQueue, JobRecord, record_columns};

impl JobQueue {
    /// Inserts an accepted job for `process_id` with its (already validated) inputs.
    pub async fn enqueue(
        &self,
        process_id: &str,
        inputs: &serde_json::Value,
    ) -> Result<JobRecord, sqlx::Error> {
        let id = uuid::Uuid::new_v4().to_string();
        sqlx::query_as(concat!(
            "INSERT INTO jobs (id, process_id, inputs, status, progress, message, created_at, updated_at, \
                 content_hash) \
             VALUES (?1, ?2, ?3, 'accepted', 0, 'queued', ?4, ?4, ?5) RETURNING ",
            record_columns!()
        ))
        .bind(&id)
        .bind(process_id)
        .bind(inputs.to_string())
        .bind(self.now())
        .bind(content_hash(process_id, inputs))
        .fetch_one(&self.pool)
        .await
    }
}
