//! Reads: one signal's summary, the tenant's signals newest first (keyset paging), the
//! samples, and the library of records a job's signal references resolve to.

use std::sync::Arc;

use super::{SignalReadError, SignalRecord, SignalStore, signal_columns};
use crate::physics::loads::Table;
use crate::processes::signal_input::{SignalLibrary, SignalSource, referenced_keys};
use crate::service::db::with_pool;
use crate::service::store::{self, StoredHistory};

/// At most this many distinct ids are looked up for one request (a sweep over more
/// signals than this is refused at the ids left out, as unknown).
pub const MAX_REFERENCED: usize = 1000;

/// `GET /signals`: the tenant's ($1) signals older than $2, at most $3, with every label
/// of the JSON array $4 (NULL: any).
const LIST_SQLITE: &str = concat!(
    "SELECT ",
    signal_columns!(),
    " FROM signals WHERE tenant = $1 AND ($2 IS NULL OR seq < $2) \
       AND ($4 IS NULL OR NOT EXISTS (SELECT 1 FROM json_each($4) AS wanted \
            WHERE wanted.value NOT IN (SELECT value FROM json_each(signals.labels)))) \
     ORDER BY seq DESC LIMIT $3"
);
const LIST_POSTGRES: &str = concat!(
    "SELECT ",
    signal_columns!(),
    " FROM signals WHERE tenant = $1 AND ($2 IS NULL OR seq < $2) \
       AND (CAST($4 AS text) IS NULL OR CAST(labels AS jsonb) @> CAST($4 AS jsonb)) \
     ORDER BY seq DESC LIMIT $3"
);

impl SignalStore {
    /// Signal `id` if `tenant` owns it.
    pub async fn get(&self, tenant: &str, id: &str) -> Result<Option<SignalRecord>, sqlx::Error> {
        with_pool!(&self.db, pool => {
            sqlx::query_as(concat!(
                "SELECT ",
                signal_columns!(),
                " FROM signals WHERE id = $1 AND tenant = $2"
            ))
            .bind(id)
            .bind(tenant)
            .fetch_optional(pool)
            .await
        })
    }

    /// Up to `limit` signals of `tenant`, newest first, strictly older than the one with
    /// sequence number `before` when given; with `labels`, only those with all of them.
    pub async fn list(
        &self,
        tenant: &str,
        limit: u32,
        before: Option<i64>,
        labels: &[String],
    ) -> Result<Vec<SignalRecord>, sqlx::Error> {
        let labels = (!labels.is_empty()).then(|| serde_json::to_string(labels).unwrap_or_default());
        let sql = self.db.choose(LIST_SQLITE, LIST_POSTGRES);
        with_pool!(&self.db, pool => {
            sqlx::query_as(sql)
                .bind(tenant)
                .bind(before)
                .bind(i64::from(limit))
                .bind(&labels)
                .fetch_all(pool)
                .await
        })
    }

    /// The samples of signal `id`, if `tenant` owns it.
    pub async fn record(&self, tenant: &str, id: &str) -> Result<Option<Table>, SignalReadError> {
        let row: Option<(i64, Vec<u8>)> = with_pool!(&self.db, pool => {
            sqlx::query_as("SELECT samples, data FROM signals WHERE id = $1 AND tenant = $2")
                .bind(id)
                .bind(tenant)
                .fetch_optional(pool)
                .await?
        });
        row.map(|(samples, data)| decode(id, samples, data)).transpose()
    }

    /// The records of every stored signal of `tenant` that `document` (an execution
    /// request's inputs, a sweep request, a stored job's inputs) may refer to
    /// ([`referenced_keys`]): what [`crate::processes::Process::validate_with`] and
    /// `run_with` resolve its references from. Ids that name no signal of the tenant are
    /// left out (the process reports them at their pointer).
    pub async fn library(
        &self,
        tenant: &str,
        document: &serde_json::Value,
    ) -> Result<SignalLibrary, SignalReadError> {
        let mut library = SignalLibrary::new(SignalSource::Stored);
        let keys: Vec<String> = referenced_keys(document)
            .into_iter()
            .filter(|key| uuid::Uuid::parse_str(key).is_ok())
            .take(MAX_REFERENCED)
            .collect();
        if keys.is_empty() {
            return Ok(library);
        }
        let ids = serde_json::to_string(&keys).unwrap_or_default();
        let sql = self.db.choose(
            "SELECT id, samples, data FROM signals \
             WHERE tenant = $1 AND id IN (SELECT value FROM json_each($2))",
            "SELECT id, samples, data FROM signals \
             WHERE tenant = $1 AND id IN (SELECT json_array_elements_text(CAST($2 AS json)))",
        );
        let rows: Vec<(String, i64, Vec<u8>)> = with_pool!(&self.db, pool => {
            sqlx::query_as(sql).bind(tenant).bind(&ids).fetch_all(pool).await?
        });
        // Decompressing a long record is CPU work: keep it off the runtime threads.
        let decoded = tokio::task::spawn_blocking(move || {
            rows.into_iter()
                .map(|(id, samples, data)| decode(&id, samples, data).map(|record| (id, record)))
                .collect::<Result<Vec<_>, _>>()
        })
        .await
        .map_err(|_| SignalReadError::Corrupt("decoding panicked".into()))??;
        for (id, record) in decoded {
            library.insert(id, Arc::new(record));
        }
        Ok(library)
    }
}

fn decode(id: &str, samples: i64, data: Vec<u8>) -> Result<Table, SignalReadError> {
    let stored = StoredHistory {
        name: "signal".into(),
        series: vec!["acceleration".into()],
        samples: usize::try_from(samples).unwrap_or(0),
        data,
    };
    let mut history = store::decode(&stored).map_err(|_| SignalReadError::Corrupt(id.to_owned()))?;
    let (_, values) = history
        .series
        .pop()
        .ok_or_else(|| SignalReadError::Corrupt(id.to_owned()))?;
    Ok(Table {
        time: history.time,
        values,
    })
}
