//! Enqueue: one execution request becomes one `accepted` job row of its tenant, with its
//! content hash, unless the tenant already has as many queued jobs as allowed. On
//! PostgreSQL, listening workers in every process are notified.
//!
//! The limit is checked by the insert itself (`INSERT ... SELECT ... WHERE count < limit`).
//! Concurrent submissions can never take a tenant over its limit: SQLite takes the write
//! lock before it counts; on PostgreSQL the transaction first takes the tenant's queue
//! lock ([`TenantQueueLock`]), which every such insert of that tenant waits for.
//!
//! With an idempotency key ([`super::idempotency`]) the transaction first looks the key
//! up (a SQLite transaction then starts `IMMEDIATE`, holding the write lock before it
//! reads, so no concurrent writer can slip in between): the same request gets the job
//! the key created, another request a conflict; a new key is stored with the new job.

use super::content_hash::content_hash;
use super::idempotency::{IdempotencyStore, KeyedRequest, Prior, is_key_taken};
use super::{Admission, JobQueue, JobRecord, record_columns};
use crate::annotations::Annotations;
use crate::service::callbacks::{Subscriber, outbox};
use crate::service::db::{TenantQueueLock, with_pool};

/// `BEGIN` of a creation that may look up a key before it writes (SQLite: take the
/// write lock first, or a concurrent commit makes the later write fail with `BUSY`).
pub(crate) const BEGIN_WRITE_SQLITE: &str = "BEGIN IMMEDIATE";
pub(crate) const BEGIN_WRITE_POSTGRES: &str = "BEGIN";

impl JobQueue {
    /// Inserts an accepted job of `tenant` for `process_id` with its (already validated)
    /// inputs and their plausibility warnings, its labels and note (and its `subscriber`,
    /// stored in the same transaction: [`crate::service::callbacks`]), unless `tenant` already has `max_queued`
    /// accepted jobs. With `key`, a job the key already created for the same request is
    /// returned instead ([`Admission::Replayed`]), and another request with that key is
    /// refused ([`Admission::KeyConflict`]).
    pub async fn enqueue(
        &self,
        tenant: &str,
        process_id: &str,
        inputs: &serde_json::Value,
        warnings: &[crate::processes::Warning],
        max_queued: Option<u64>,
        key: Option<&KeyedRequest>,
        subscriber: Option<&Subscriber>,
        annotations: &Annotations,
    ) -> Result<Admission<JobRecord>, sqlx::Error> {
        let enqueue_once = || {
            self.enqueue_once(
                tenant,
                process_id,
                inputs,
                warnings,
                max_queued,
                key,
                subscriber,
                annotations,
            )
        };
        match enqueue_once().await {
            // A concurrent first use of the same key won: this one now finds it.
            Err(error) if key.is_some() && is_key_taken(&error) => enqueue_once().await,
            outcome => outcome,
        }
    }

    async fn enqueue_once(
        &self,
        tenant: &str,
        process_id: &str,
        inputs: &serde_json::Value,
        warnings: &[crate::processes::Warning],
        max_queued: Option<u64>,
        key: Option<&KeyedRequest>,
        subscriber: Option<&Subscriber>,
        annotations: &Annotations,
    ) -> Result<Admission<JobRecord>, sqlx::Error> {
        let warnings = serde_json::to_string(warnings).expect("warnings serialize");
        let id = uuid::Uuid::new_v4().to_string();
        let now = self.now();
        let begin = self.db.choose(BEGIN_WRITE_SQLITE, BEGIN_WRITE_POSTGRES);
        let inserted: Option<JobRecord> = with_pool!(&self.db, pool => {
            let mut tx = pool.begin_with(begin).await?;
            tx.lock_tenant_queue(tenant).await?;
            if let Some(request) = key
                && let Some(stored) = tx.find_key(tenant, &request.key).await?
            {
                let prior = match stored.prior_for(request) {
                    Prior::Same(job_id) => Admission::Replayed(
                        sqlx::query_as(concat!("SELECT ", record_columns!(), " FROM jobs WHERE id = $1 AND tenant = $2"))
                            .bind(&job_id)
                            .bind(tenant)
                            .fetch_one(&mut *tx)
                            .await?,
                    ),
                    Prior::Conflict(conflict) => Admission::KeyConflict(conflict),
                };
                tx.rollback().await?;
                return Ok(prior);
            }
            let inserted: Option<JobRecord> = sqlx::query_as(concat!(
                "INSERT INTO jobs (id, tenant, process_id, inputs, status, progress, message, created_at, \
                     updated_at, content_hash, warnings, labels, note) \
                 SELECT $1, $6, $2, $3, 'accepted', 0, 'queued', $4, $4, $5, $8, $9, $10 \
                 WHERE $7 IS NULL OR (SELECT COUNT(*) FROM jobs WHERE tenant = $6 AND status = 'accepted') < $7 \
                 RETURNING ",
                record_columns!()
            ))
            .bind(&id)
            .bind(process_id)
            .bind(inputs.to_string())
            .bind(now)
            .bind(content_hash(process_id, inputs))
            .bind(tenant)
            .bind(max_queued.map(|n| i64::try_from(n).unwrap_or(i64::MAX)))
            .bind(&warnings)
            .bind(annotations.labels_json())
            .bind(&annotations.note)
            .fetch_optional(&mut *tx)
            .await?;
            if let (Some(record), Some(request)) = (&inserted, key) {
                tx.store_key(tenant, request, &record.id, now).await?;
            }
            if let (Some(record), Some(subscriber)) = (&inserted, subscriber) {
                let [success, failed, in_progress] = outbox::uri_columns(subscriber);
                sqlx::query(outbox::INSERT)
                    .bind(&record.id)
                    .bind(tenant)
                    .bind(success)
                    .bind(failed)
                    .bind(in_progress)
                    .bind(now)
                    .execute(&mut *tx)
                    .await?;
            }
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
