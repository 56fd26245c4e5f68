//! Enqueue: one execution request becomes one `accepted` job row.

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
            "INSERT INTO jobs (id, process_id, inputs, status, progress, message, created_at, updated_at) \
             VALUES (?1, ?2, ?3, 'accepted', 0, 'queued', ?4, ?4) RETURNING ",
            record_columns!()
        ))
        .bind(&id)
        .bind(process_id)
        .bind(inputs.to_string())
        .bind(self.now())
        .fetch_one(&self.pool)
        .await
    }
}
