//! Stored signals: accelerograms uploaded once (`POST /signals`) and referenced by jobs
//! and sweeps, in the `signals` table of either backend (`migrations/0004_signals.sql`
//! and its PostgreSQL twin).
//!
//! A signal belongs to the tenant that uploaded it: every statement takes the tenant and
//! matches it in SQL, so another tenant's signal is "no such signal". A signal never
//! changes; its samples are kept as a stored history ([`crate::service::store`]) and
//! its summary (PGA, Arias intensity, sampling) as columns, computed once. One
//! operation per file:
//!
//! - [`create`]: store a checked record with its summary;
//! - [`read`]: one signal's summary, the tenant's list (keyset paging), the samples, and
//!   the [`crate::processes::signal_input::SignalLibrary`] a job's references resolve to;
//! - [`delete`]: remove a signal no queued or running job refers to.

pub mod create;
pub mod delete;
pub mod read;

use super::clock::SharedClock;
use super::db::Database;

/// A stored signal's summary (everything but its samples).
#[derive(Debug, Clone, PartialEq, sqlx::FromRow)]
pub struct SignalRecord {
    /// Insertion order (keyset of the signal list).
    pub seq: i64,
    pub id: String,
    /// Number of samples.
    pub samples: i64,
    /// Time of the first sample (s).
    pub start_time: f64,
    /// Last time minus first time (s).
    pub duration: f64,
    /// Mean, shortest and longest sample intervals (s).
    pub sampling_interval: f64,
    pub shortest_interval: f64,
    pub longest_interval: f64,
    /// Every interval equal to the mean (to 1e-6 relative).
    pub uniform: bool,
    /// Peak ground acceleration (m/s²) and the time of its first sample (s).
    pub pga: f64,
    pub pga_time: f64,
    /// Arias intensity π/(2g) ∫ a² dt (m/s).
    pub arias_intensity: f64,
    /// When it was stored (ms since the Unix epoch).
    pub created_at: i64,
    /// Labels given at upload.
    #[sqlx(try_from = "String")]
    pub labels: crate::annotations::StoredLabels,
    /// The note given at upload.
    pub note: Option<String>,
}

/// Columns of [`SignalRecord`] (a literal, for `concat!`: queries are static strings).
macro_rules! signal_columns {
    () => {
        "seq, id, samples, start_time, duration, sampling_interval, shortest_interval, \
         longest_interval, uniform, pga, pga_time, arias_intensity, created_at, labels, note"
    };
}
pub(crate) use signal_columns;

/// The signals of a database, stamped by the service's clock.
#[derive(Debug, Clone)]
pub struct SignalStore {
    db: Database,
    clock: SharedClock,
}

impl SignalStore {
    pub fn new(db: Database, clock: SharedClock) -> Self {
        Self { db, clock }
    }
}

/// Why a stored record cannot be read back.
#[derive(Debug, thiserror::Error)]
pub enum SignalReadError {
    #[error("database: {0}")]
    Database(#[from] sqlx::Error),
    #[error("signal `{0}`: stored samples are corrupt")]
    Corrupt(String),
}
