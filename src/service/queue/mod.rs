//! The durable job queue: a `jobs` table in SQLite or PostgreSQL ([`Database`]), the
//! same statements and guarantees on both (`migrations/`, `migrations/postgres/`).
//!
//! Life of a job: `accepted` (enqueued) → `running` (claimed by a worker, under a lease
//! that its heartbeat renews) → `successful` | `failed` | `dismissed`. Every write a
//! worker makes after its claim is guarded by its [`Lease`] (owner and attempt), so a
//! worker that lost its lease (it stalled, the job was dismissed, recovery re-queued it)
//! can never overwrite the row. No transaction is held while a job computes: each step
//! is one short statement. Each operation runs the same Rust on either backend
//! (`with_pool!`); where SQL differs, both texts sit side by side in its file.
//!
//! Every job and sweep belongs to a tenant (`tenant` column, `migrations/0003`). The
//! reads and writes made for a request take the requesting tenant explicitly and match
//! it in SQL, so another tenant's job is simply "no such job". One operation per file:
//!
//! - [`enqueue`]: insert an accepted job;
//! - [`claim`]: atomically take the oldest accepted job;
//! - [`heartbeat`]: renew the lease, record progress, notice cancellation;
//! - [`finish`]: successful, failed, or handed back to the queue;
//! - [`dismiss`]: cancel a queued or running job, or drop a finished job's results;
//! - [`recovery`]: re-queue (or fail) jobs whose lease expired;
//! - [`retention`]: delete old finished jobs;
//! - [`read`]: status, listing with keyset paging, results and histories;
//! - [`inputs`]: the inputs a job was submitted with;
//! - [`reuse`]: complete a claimed job with the results of an identical one
//!   ([`content_hash`]);
//! - [`sweep_create`], [`sweep_read`], [`sweep_dismiss`]: sweeps, whose runs are jobs;
//! - [`idempotency`]: `Idempotency-Key`s, stored with the job, sweep or signal they create.
//!
//! Every write is a transaction whose outcome the caller sees: a statement that returns
//! rows (`... RETURNING`) or a write of several statements runs in an explicit
//! transaction and is committed before the call returns (an autocommit `RETURNING` read
//! with `fetch_one`/`fetch_optional` loses the commit's error, sqlx issue #3430); a lone
//! `UPDATE`/`DELETE` runs to completion with `execute`, which reports its commit. A
//! connection never goes back to the pool inside a transaction ([`super::db::release`]).

pub mod claim;
pub mod content_hash;
pub mod dismiss;
pub mod enqueue;
pub mod finish;
pub mod heartbeat;
pub mod idempotency;
pub mod inputs;
pub mod read;
pub mod recovery;
pub mod retention;
pub mod reuse;
pub mod sweep_create;
pub mod sweep_dismiss;
pub mod sweep_read;

use super::clock::SharedClock;
use super::db::Database;

/// Status of a job (OGC API – Processes `statusCode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize, utoipa::ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum JobStatus {
    /// Queued, waiting for a worker.
    Accepted,
    /// A worker is computing it.
    Running,
    /// Finished with results.
    Successful,
    /// Finished without results; see the results problem document.
    Failed,
    /// Cancelled by `DELETE /jobs/{jobId}`.
    Dismissed,
}

impl JobStatus {
    pub const ALL: [JobStatus; 5] = [
        JobStatus::Accepted,
        JobStatus::Running,
        JobStatus::Successful,
        JobStatus::Failed,
        JobStatus::Dismissed,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Accepted => "accepted",
            JobStatus::Running => "running",
            JobStatus::Successful => "successful",
            JobStatus::Failed => "failed",
            JobStatus::Dismissed => "dismissed",
        }
    }

    pub fn parse(text: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.as_str() == text)
    }

    /// True once the job will not change any more (but for dismissing its results).
    pub fn is_finished(self) -> bool {
        matches!(
            self,
            JobStatus::Successful | JobStatus::Failed | JobStatus::Dismissed
        )
    }
}

/// What the API shows of a job: everything but its inputs and results.
#[derive(Debug, Clone, PartialEq)]
pub struct JobRecord {
    /// Insertion order (keyset of the job list).
    pub seq: i64,
    pub id: String,
    pub process_id: String,
    pub status: JobStatus,
    /// Percent done, 0..=100.
    pub progress: u8,
    pub message: Option<String>,
    /// Times in ms since the Unix epoch.
    pub created_at: i64,
    pub started_at: Option<i64>,
    pub finished_at: Option<i64>,
    pub updated_at: i64,
    /// Number of claims so far.
    pub attempt: i64,
    /// The sweep this job is a run of, if any.
    pub sweep_id: Option<String>,
    /// Plausibility warnings about its inputs, found at submission (none for jobs
    /// submitted before warnings existed).
    pub warnings: Vec<crate::processes::Warning>,
    /// Labels given at submission (`[]` when none).
    pub labels: Vec<String>,
    /// The note given at submission.
    pub note: Option<String>,
    /// `quality.verdict` of a successful job's results (`good`, `doubtful`, `poor`).
    pub verdict: Option<String>,
}

/// Columns of [`JobRecord`] for `SELECT` and `RETURNING` clauses (a literal, for `concat!`:
/// queries are static strings).
macro_rules! record_columns {
    () => {
        "seq, id, process_id, status, progress, message, created_at, started_at, finished_at, \
         updated_at, attempt, sweep_id, warnings, labels, note, verdict"
    };
}
pub(crate) use record_columns;

impl<'r, R> sqlx::FromRow<'r, R> for JobRecord
where
    R: sqlx::Row,
    &'r str: sqlx::ColumnIndex<R>,
    String: sqlx::Decode<'r, R::Database> + sqlx::Type<R::Database>,
    i64: sqlx::Decode<'r, R::Database> + sqlx::Type<R::Database>,
{
    fn from_row(row: &'r R) -> Result<Self, sqlx::Error> {
        let status: String = row.try_get("status")?;
        let progress: i64 = row.try_get("progress")?;
        Ok(Self {
            seq: row.try_get("seq")?,
            id: row.try_get("id")?,
            process_id: row.try_get("process_id")?,
            status: JobStatus::parse(&status).ok_or_else(|| sqlx::Error::ColumnDecode {
                index: "status".into(),
                source: format!("unknown job status `{status}`").into(),
            })?,
            progress: progress.clamp(0, 100) as u8,
            message: row.try_get("message")?,
            created_at: row.try_get("created_at")?,
            started_at: row.try_get("started_at")?,
            finished_at: row.try_get("finished_at")?,
            updated_at: row.try_get("updated_at")?,
            attempt: row.try_get("attempt")?,
            sweep_id: row.try_get("sweep_id")?,
            warnings: {
                let text: Option<String> = row.try_get("warnings")?;
                match text {
                    Some(text) => serde_json::from_str(&text).map_err(|e| sqlx::Error::ColumnDecode {
                        index: "warnings".into(),
                        source: Box::new(e),
                    })?,
                    None => Vec::new(),
                }
            },
            labels: {
                let text: String = row.try_get("labels")?;
                serde_json::from_str(&text).map_err(|e| sqlx::Error::ColumnDecode {
                    index: "labels".into(),
                    source: Box::new(e),
                })?
            },
            note: row.try_get("note")?,
            verdict: row.try_get("verdict")?,
        })
    }
}

/// A worker's hold on a running job: every write after the claim is guarded by it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lease {
    pub job_id: String,
    /// Unique per worker (and per service instance).
    pub owner: String,
    /// The claim number this lease belongs to.
    pub attempt: i64,
}

/// A job a worker has just claimed.
#[derive(Debug, Clone)]
pub struct ClaimedJob {
    pub lease: Lease,
    pub process_id: String,
    /// The validated `inputs` object.
    pub inputs: serde_json::Value,
    /// The tenant that owns the job.
    pub tenant: String,
    /// Content hash of process and inputs (jobs queued before hashes existed have none).
    pub content_hash: Option<String>,
    /// When it was enqueued and claimed (ms since the Unix epoch).
    pub created_at: i64,
    pub started_at: i64,
}

/// The queue: a database (either backend) and the clock that stamps every write.
#[derive(Debug, Clone)]
pub struct JobQueue {
    db: Database,
    clock: SharedClock,
}

impl JobQueue {
    pub fn new(db: Database, clock: SharedClock) -> Self {
        Self { db, clock }
    }

    pub fn database(&self) -> &Database {
        &self.db
    }

    pub fn clock(&self) -> &SharedClock {
        &self.clock
    }

    /// The stored signals of the same database, stamped by the same clock.
    pub fn signals(&self) -> super::signals::SignalStore {
        super::signals::SignalStore::new(self.db.clone(), self.clock.clone())
    }

    fn now(&self) -> i64 {
        self.clock.now_ms()
    }
}

/// The outcome of a submission under the per-tenant limit on queued jobs.
#[derive(Debug, Clone, PartialEq)]
pub enum Admission<T> {
    /// Queued.
    Admitted(T),
    /// Nothing was queued: the tenant has `queued` accepted jobs, and the new ones would
    /// take it over the limit.
    QueueFull { queued: i64 },
    /// Nothing was queued: the request's idempotency key created this, for the same
    /// request, before.
    Replayed(T),
    /// Nothing was queued: the request's idempotency key was first used with another
    /// request.
    KeyConflict(idempotency::KeyConflict),
}

/// A sweep as stored: its definition and bookkeeping (its runs are jobs).
#[derive(Debug, Clone, PartialEq, sqlx::FromRow)]
pub struct SweepRecord {
    /// Insertion order (keyset of the sweep list).
    pub seq: i64,
    pub id: String,
    pub process_id: String,
    /// The normalized definition (JSON text).
    pub definition: String,
    pub design: String,
    pub policy: String,
    /// Number of runs.
    pub runs: i64,
    /// Dismissed by `DELETE /sweeps/{id}`.
    pub dismissed: bool,
    /// Times in ms since the Unix epoch.
    pub created_at: i64,
    pub updated_at: i64,
    /// Labels given at creation.
    #[sqlx(try_from = "String")]
    pub labels: crate::annotations::StoredLabels,
    /// The note given at creation.
    pub note: Option<String>,
}

/// Columns of [`SweepRecord`] (a literal, for `concat!`).
macro_rules! sweep_columns {
    () => {
        "seq, id, process_id, definition, design, policy, runs, dismissed, created_at, updated_at, labels, note"
    };
}
pub(crate) use sweep_columns;
