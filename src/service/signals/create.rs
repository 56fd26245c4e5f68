//! Create: a checked record becomes one row of its tenant, with its summary and its
//! compressed samples.

use super::{SignalRecord, SignalStore, signal_columns};
use crate::physics::accelerogram::RecordSummary;
use crate::physics::loads::Table;
use crate::processes::History;
use crate::service::db::with_pool;
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
    /// Stores `record` (already checked) as a new signal of `tenant`.
    pub async fn create(&self, tenant: &str, record: &Table) -> Result<SignalRecord, CreateError> {
        let summary = RecordSummary::of(record)
            .ok_or_else(|| CreateError::Unchecked("fewer than 2 samples or times not increasing".into()))?;
        let stored = store::encode(&as_history(record)).map_err(|e| CreateError::Unchecked(e.to_string()))?;
        let id = uuid::Uuid::new_v4().to_string();
        let now = self.clock.now_ms();
        let samples = i64::try_from(summary.samples).unwrap_or(i64::MAX);
        let created = with_pool!(&self.db, pool => {
            sqlx::query_as(concat!(
                "INSERT INTO signals (id, tenant, samples, start_time, duration, sampling_interval, \
                     shortest_interval, longest_interval, uniform, pga, pga_time, arias_intensity, data, \
                     created_at) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12, $13, $14) RETURNING ",
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
            .fetch_one(pool)
            .await?
        });
        Ok(created)
    }
}
