//! The embedded SQLite database (one machine): connection settings and migrations.
//!
//! WAL lets the API read while a worker writes; `busy_timeout` makes concurrent writers
//! wait for the lock instead of failing with `database is locked`; foreign keys make
//! deleting a job delete its histories. Settings are per connection, so they live in the
//! connect options and apply to every pooled connection.

use std::path::Path;
use std::str::FromStr;
use std::time::Duration;

use sqlx::SqlitePool;
use sqlx::sqlite::{SqliteConnectOptions, SqliteJournalMode, SqlitePoolOptions, SqliteSynchronous};

/// How long a connection waits for another writer before giving up.
pub const BUSY_TIMEOUT: Duration = Duration::from_secs(10);

/// Size of a database page (bytes): SQLite's default, set explicitly so that a size
/// limit converts to pages exactly.
pub const PAGE_SIZE: u64 = 4096;

/// Opens (creating if missing) the database at `path` and runs the migrations in
/// `migrations/`. With `max_bytes`, every connection caps the file at that many bytes
/// (`max_page_count`): a write that needs more fails with `SQLITE_FULL`, exactly as on a
/// full disk, and pages freed by deletions are used again.
pub async fn open(path: &Path, max_bytes: Option<u64>) -> Result<SqlitePool, sqlx::Error> {
    let mut options = SqliteConnectOptions::from_str("sqlite:")?
        .filename(path)
        .create_if_missing(true)
        .journal_mode(SqliteJournalMode::Wal)
        // NORMAL is durable across application crashes in WAL mode; only an OS crash
        // can lose the last transactions.
        .synchronous(SqliteSynchronous::Normal)
        .busy_timeout(BUSY_TIMEOUT)
        .foreign_keys(true)
        .page_size(PAGE_SIZE as u32);
    if let Some(bytes) = max_bytes {
        options = options.pragma("max_page_count", (bytes / PAGE_SIZE).max(1).to_string());
    }
    let pool = SqlitePoolOptions::new()
        .max_connections(8)
        .min_connections(1)
        .after_release(super::release::sqlite_after_release)
        .connect_with(options)
        .await?;
    sqlx::migrate!("./migrations").run(&pool).await?;
    Ok(pool)
}
