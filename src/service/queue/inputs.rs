//! The inputs a job was submitted with (`GET /jobs/{jobId}/inputs`): what the dashboard
//! summarizes and offers to edit and resubmit.

use super::JobQueue;
use crate::service::db::with_pool;

impl JobQueue {
    /// The validated `inputs` object of job `id` (JSON text), if `tenant` owns it.
    pub async fn inputs(&self, tenant: &str, id: &str) -> Result<Option<String>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            sqlx::query_scalar("SELECT inputs FROM jobs WHERE id = $1 AND tenant = $2")
                .bind(id)
                .bind(tenant)
                .fetch_optional(pool)
                .await
        })
    }
}
