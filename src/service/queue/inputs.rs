//! The inputs a job was submitted with (`GET /jobs/{jobId}/inputs`): what the dashboard
//! summarizes and offers to edit and resubmit.

use super::JobQueue;
use crate::service::db::with_pool;

impl JobQueue {
    /// The validated `inputs` object of job `id` (JSON text); `None` if there is no such job.
    pub async fn inputs(&self, id: &str) -> Result<Option<String>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            sqlx::query_scalar("SELECT inputs FROM jobs WHERE id = $1")
                .bind(id)
                .fetch_optional(pool)
                .await
        })
    }
}
