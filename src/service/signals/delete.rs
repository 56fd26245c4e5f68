//! Delete (`DELETE /signals/{id}`): a signal goes away for good, unless a queued or
//! running job of its tenant refers to it (that job would find no record when a worker
//! claims it, or claims it again after a crash).
//!
//! The check and the delete are one statement. Job inputs are stored as JSON text, and a
//! reference writes the id as a JSON string: a job refers to signal `id` when its inputs
//! contain `"<id>"`. Ids are UUIDs, which no other input string can be by accident.

use super::SignalStore;
use crate::service::db::with_pool;

/// What deleting a signal did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Deletion {
    /// The signal is gone.
    Deleted,
    /// The tenant has no such signal.
    NotFound,
    /// Kept: this many queued or running jobs of the tenant refer to it.
    InUse { jobs: i64 },
}

impl SignalStore {
    /// Deletes signal `id` of `tenant` unless an unfinished job of `tenant` refers to it.
    pub async fn delete(&self, tenant: &str, id: &str) -> Result<Deletion, sqlx::Error> {
        let pattern = format!("%\"{id}\"%");
        // An explicit transaction: a `204` means the commit succeeded (sqlx issue #3430).
        let deleted: Option<String> = with_pool!(&self.db, pool => {
            let mut tx = pool.begin().await?;
            let deleted = sqlx::query_scalar(
                "DELETE FROM signals WHERE id = $1 AND tenant = $2 AND NOT EXISTS (\
                     SELECT 1 FROM jobs WHERE tenant = $2 AND status IN ('accepted', 'running') \
                     AND inputs LIKE $3) \
                 RETURNING id",
            )
            .bind(id)
            .bind(tenant)
            .bind(&pattern)
            .fetch_optional(&mut *tx)
            .await?;
            tx.commit().await?;
            deleted
        });
        if deleted.is_some() {
            return Ok(Deletion::Deleted);
        }
        if self.get(tenant, id).await?.is_none() {
            return Ok(Deletion::NotFound);
        }
        let jobs: i64 = with_pool!(&self.db, pool => {
            sqlx::query_scalar(
                "SELECT COUNT(*) FROM jobs WHERE tenant = $1 AND status IN ('accepted', 'running') \
                 AND inputs LIKE $2",
            )
            .bind(tenant)
            .bind(&pattern)
            .fetch_one(pool)
            .await?
        });
        Ok(Deletion::InUse { jobs })
    }
}
