//! Create a sweep: the sweep row and all its runs, as `accepted` jobs of its tenant, in
//! one transaction (a sweep is queued whole or not at all), unless its runs would take
//! the tenant over its limit of queued jobs: checked by the first insert, after the
//! tenant's queue lock ([`TenantQueueLock`]: SQLite's write lock, a PostgreSQL advisory
//! lock), held until the runs are in.
//!
//! The runs go in with one `INSERT ... SELECT` over a JSON array parameter
//! (`json_each` in SQLite, `jsonb_array_elements` in PostgreSQL): ten thousand runs are
//! one round trip to the database, not ten thousand.

use serde_json::{Value, json};

use super::content_hash::content_hash;
use super::enqueue::{BEGIN_WRITE_POSTGRES, BEGIN_WRITE_SQLITE};
use super::idempotency::{IdempotencyStore, KeyedRequest, Prior, is_key_taken};
use super::{Admission, JobQueue, SweepRecord, sweep_columns};
use crate::problem::Problem;
use crate::service::db::{TenantQueueLock, with_pool};

/// Inserts the runs of sweep $3 of process $1 of tenant $5 at time $2 from $4, a JSON
/// array of `{id, run, inputs, hash, error, message, warnings}` (an `error` makes the run
/// `failed`).
const RUNS_SQLITE: &str = "\
    INSERT INTO jobs (id, process_id, inputs, status, progress, message, created_at, updated_at, \
        finished_at, error, sweep_id, sweep_run, content_hash, tenant, warnings) \
    SELECT json_extract(value, '$.id'), $1, json_extract(value, '$.inputs'), \
        CASE WHEN json_extract(value, '$.error') IS NULL THEN 'accepted' ELSE 'failed' END, 0, \
        COALESCE(json_extract(value, '$.message'), \
            'queued (sweep run ' || json_extract(value, '$.run') || ')'), $2, $2, \
        CASE WHEN json_extract(value, '$.error') IS NULL THEN NULL ELSE $2 END, \
        json_extract(value, '$.error'), $3, json_extract(value, '$.run'), json_extract(value, '$.hash'), \
        $5, json_extract(value, '$.warnings') \
    FROM json_each($4) ORDER BY key";

const RUNS_POSTGRES: &str = "\
    INSERT INTO jobs (id, process_id, inputs, status, progress, message, created_at, updated_at, \
        finished_at, error, sweep_id, sweep_run, content_hash, tenant, warnings) \
    SELECT run->>'id', $1, run->>'inputs', \
        CASE WHEN run->>'error' IS NULL THEN 'accepted' ELSE 'failed' END, 0, \
        COALESCE(run->>'message', 'queued (sweep run ' || (run->>'run') || ')'), $2, $2, \
        CASE WHEN run->>'error' IS NULL THEN NULL ELSE $2 END, \
        run->>'error', $3, CAST(run->>'run' AS BIGINT), run->>'hash', $5, run->>'warnings' \
    FROM jsonb_array_elements(CAST($4 AS jsonb)) WITH ORDINALITY AS runs (run, position) \
    ORDER BY position";

/// What the queue stores of a new sweep.
#[derive(Debug, Clone)]
pub struct NewSweep<'a> {
    /// The tenant that owns the sweep and its runs.
    pub tenant: &'a str,
    pub process_id: &'a str,
    /// The normalized definition (JSON), served back by `GET /sweeps/{id}`.
    pub definition: &'a Value,
    /// `grid`, `monte_carlo` or `latin_hypercube`.
    pub design: &'a str,
    /// `continue` or `fail_fast`.
    pub policy: &'a str,
    /// Every run, in run order.
    pub runs: &'a [NewRun],
    /// Labels and note of the sweep.
    pub annotations: &'a crate::annotations::Annotations,
}

/// One run of a new sweep.
#[derive(Debug, Clone)]
pub struct NewRun {
    pub inputs: Value,
    /// Why the process refuses these inputs: the run is recorded as `failed` with this
    /// problem and never queued.
    pub invalid: Option<Problem>,
    /// Plausibility warnings about its inputs.
    pub warnings: Vec<crate::processes::Warning>,
}

impl JobQueue {
    /// Inserts the sweep and its runs (invalid runs directly as `failed`); returns the
    /// sweep, or nothing when its queued runs would give the tenant more than
    /// `max_queued` accepted jobs.
    ///
    /// With `key`, a sweep the key already created for the same request is returned
    /// instead ([`Admission::Replayed`]), another request with that key is refused
    /// ([`Admission::KeyConflict`]), and a new key is stored with the new sweep.
    pub async fn create_sweep(
        &self,
        sweep: &NewSweep<'_>,
        max_queued: Option<u64>,
        key: Option<&KeyedRequest>,
    ) -> Result<Admission<SweepRecord>, sqlx::Error> {
        match self.create_sweep_once(sweep, max_queued, key).await {
            // A concurrent first use of the same key won: this one now finds it.
            Err(error) if key.is_some() && is_key_taken(&error) => {
                self.create_sweep_once(sweep, max_queued, key).await
            }
            outcome => outcome,
        }
    }

    async fn create_sweep_once(
        &self,
        sweep: &NewSweep<'_>,
        max_queued: Option<u64>,
        key: Option<&KeyedRequest>,
    ) -> Result<Admission<SweepRecord>, sqlx::Error> {
        let queued_runs = sweep.runs.iter().filter(|run| run.invalid.is_none()).count();
        let id = uuid::Uuid::new_v4().to_string();
        let now = self.now();
        let children: Vec<Value> = sweep
            .runs
            .iter()
            .enumerate()
            .map(|(run, new)| {
                json!({
                    "id": uuid::Uuid::new_v4().to_string(),
                    "run": run,
                    "inputs": new.inputs.to_string(),
                    "hash": content_hash(sweep.process_id, &new.inputs),
                    "error": new.invalid.as_ref().map(|p| serde_json::to_string(p).unwrap_or_default()),
                    "message": new.invalid.as_ref().map(|p| format!("failed: invalid inputs: {}", p.detail)),
                    "warnings": serde_json::to_string(&new.warnings).unwrap_or_default(),
                })
            })
            .collect();
        let runs = self.db.choose(RUNS_SQLITE, RUNS_POSTGRES);
        let begin = self.db.choose(BEGIN_WRITE_SQLITE, BEGIN_WRITE_POSTGRES);
        let record = with_pool!(&self.db, pool => {
            let mut tx = pool.begin_with(begin).await?;
            tx.lock_tenant_queue(sweep.tenant).await?;
            if let Some(request) = key
                && let Some(stored) = tx.find_key(sweep.tenant, &request.key).await?
            {
                let prior = match stored.prior_for(request) {
                    Prior::Same(sweep_id) => Admission::Replayed(
                        sqlx::query_as(concat!("SELECT ", sweep_columns!(), " FROM sweeps WHERE id = $1 AND tenant = $2"))
                            .bind(&sweep_id)
                            .bind(sweep.tenant)
                            .fetch_one(&mut *tx)
                            .await?,
                    ),
                    Prior::Conflict(conflict) => Admission::KeyConflict(conflict),
                };
                tx.rollback().await?;
                return Ok(prior);
            }
            let record: Option<SweepRecord> = sqlx::query_as(concat!(
                "INSERT INTO sweeps (id, tenant, process_id, definition, design, policy, runs, created_at, \
                     updated_at, labels, note) \
                 SELECT $1, $8, $2, $3, $4, $5, $6, $7, $7, $11, $12 \
                 WHERE $9 IS NULL \
                    OR (SELECT COUNT(*) FROM jobs WHERE tenant = $8 AND status = 'accepted') + $10 <= $9 \
                 RETURNING ",
                sweep_columns!()
            ))
            .bind(&id)
            .bind(sweep.process_id)
            .bind(sweep.definition.to_string())
            .bind(sweep.design)
            .bind(sweep.policy)
            .bind(sweep.runs.len() as i64)
            .bind(now)
            .bind(sweep.tenant)
            .bind(max_queued.map(|n| i64::try_from(n).unwrap_or(i64::MAX)))
            .bind(queued_runs as i64)
            .bind(sweep.annotations.labels_json())
            .bind(&sweep.annotations.note)
            .fetch_optional(&mut *tx)
            .await?;
            if record.is_some() {
                sqlx::query(runs)
                    .bind(sweep.process_id)
                    .bind(now)
                    .bind(&id)
                    .bind(Value::Array(children).to_string())
                    .bind(sweep.tenant)
                    .execute(&mut *tx)
                    .await?;
                if let (Some(record), Some(request)) = (&record, key) {
                    tx.store_key(sweep.tenant, request, &record.id, now).await?;
                }
                tx.commit().await?;
            } else {
                tx.rollback().await?;
            }
            record
        });
        match record {
            Some(record) => {
                self.announce_queued().await;
                Ok(Admission::Admitted(record))
            }
            None => Ok(Admission::QueueFull {
                queued: self.queued_count(sweep.tenant).await?,
            }),
        }
    }
}
