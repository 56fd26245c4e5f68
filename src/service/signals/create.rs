//! Create: a checked record becomes one row of its tenant, with its summary and its
//! compressed samples.

use super::{SignalRecord, SignalStore, signal_columns};
use crate::annotations::Annotations;
use crate::physics::accelerogram::RecordSummary;
use crate::physics::loads::Table;
use crate::processes::History;
use crate::service::db::with_pool;
use crate::service::queue::enqueue::{BEGIN_WRITE_POSTGRES, BEGIN_WRITE_SQLITE};
use crate::service::queue::idempotency::{IdempotencyStore, Keyed, KeyedRequest, Prior, is_key_taken};
use crate::service::store;

/// Why a record cannot be stored.
#[derive(Debug, thiserror::Error)]
pub enum CreateError {
    /// The record is not a checked one (fewer than 2 samples, times not increasing):
    /// callers parse with [`crate::signal_record::parse`] first.
    #[error("the record is not checked: {0}")]
    Unchecked(String),
    #[error("database: {0}")]
    Database(#[from] sqlx::Error),
}

/// The record as the history the store encodes: `time`, then `acceleration`.
pub(super) fn as_history(record: &Table) -> History {
    History {
        name: "signal".into(),
        time: record.time.clone(),
        series: vec![("acceleration".into(), record.values.clone())],
    }
}

impl SignalStore {
    /// Stores `record` (already checked) as a new signal of `tenant`. With `key`, a
    /// signal the key already created for the same request is returned instead
    /// ([`Keyed::Replayed`]) and another request with that key is refused
    /// ([`Keyed::Conflict`]); a new key is stored with the new signal.
    pub async fn create(
        &self,
        tenant: &str,
        record: &Table,
        key: Option<&KeyedRequest>,
        annotations: &Annotations,
    ) -> Result<Keyed<SignalRecord>, CreateError> {
        match self.create_once(tenant, record, key, annotations).await {
            // A concurrent first use of the same key won: this one now finds it.
            Err(CreateError::Database(error)) if key.is_some() && is_key_taken(&error) => {
                self.create_once(tenant, record, key, annotations).await
            }
            outcome => outcome,
        }
    }

    async fn create_once(
        &self,
        tenant: &str,
        record: &Table,
        key: Option<&KeyedRequest>,
        annotations: &Annotations,
    ) -> Result<Keyed<SignalRecord>, CreateError> {
        let summary = RecordSummary::of(record)
            .ok_or_else(|| CreateError::Unchecked("fewer than 2 samples or times not increasing".into()))?;
        let stored = store::encode(&as_history(record)).map_err(|e| CreateError::Unchecked(e.to_string()))?;
        let id = uuid::Uuid::new_v4().to_string();
        let now = self.clock.now_ms();
        let samples = i64::try_from(summary.samples).unwrap_or(i64::MAX);
        // An explicit transaction: the commit's outcome is this call's outcome (an
        // autocommit `RETURNING` read with `fetch_one` drops it, sqlx issue #3430).
        let begin = self.db.choose(BEGIN_WRITE_SQLITE, BEGIN_WRITE_POSTGRES);
        let created = with_pool!(&self.db, pool => {
            let mut tx = pool.begin_with(begin).await?;
            if let Some(request) = key
                && let Some(stored) = tx.find_key(tenant, &request.key).await?
            {
                let prior = match stored.prior_for(request) {
                    Prior::Same(signal_id) => Keyed::Replayed(
                        sqlx::query_as(concat!("SELECT ", signal_columns!(), " FROM signals WHERE id = $1 AND tenant = $2"))
                            .bind(&signal_id)
                            .bind(tenant)
                            .fetch_one(&mut *tx)
                            .await?,
                    ),
                    Prior::Conflict(conflict) => Keyed::Conflict(conflict),
                };
                tx.rollback().await?;
                return Ok(prior);
            }
            let created: SignalRecord = sqlx::query_as(concat!(
                "INSERT INTO signals (id, tenant, samples, start_time, duration, sampling_interval, \
                     shortest_interval, longest_interval, uniform, pga, pga_time, arias_intensity, data, \
                     created_at, labels, note) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16) RETURNING ",
                signal_columns!()
            ))
            .bind(&id)
            .bind(tenant)
            .bind(samples)
            .bind(summary.start)
            .bind(summary.duration)
            .bind(summary.sampling_interval)
            .bind(summary.shortest_interval)
            .bind(summary.longest_interval)
            .bind(summary.uniform)
            .bind(summary.pga)
            .bind(summary.pga_time)
            .bind(summary.arias_intensity)
            .bind(&stored.data)
            .bind(now)
            .bind(annotations.labels_json())
            .bind(&annotations.note)
            .fetch_one(&mut *tx)
            .await?;
            if let Some(request) = key {
                tx.store_key(tenant, request, &created.id, now).await?;
            }
            tx.commit().await?;
            created
        });
        Ok(Keyed::Created(created))
    }
}
