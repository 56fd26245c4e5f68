//! Connections go back to the pool outside any transaction, or not at all.
//!
//! The root cause of issue 30's stuck write lock: on a full disk SQLite may roll a whole
//! transaction back by itself when a statement fails with `SQLITE_FULL` (or an I/O
//! error). sqlx does not know: its depth counter still says 1, so the `ROLLBACK` it sends
//! when the `Transaction` is dropped fails ("no transaction is active") and the counter
//! stays at 1 on a connection that is in no transaction. The next `begin()` on that
//! connection then sends `SAVEPOINT _sqlx_savepoint_1` (which opens a real transaction),
//! and when that one fails too, `ROLLBACK TO SAVEPOINT` undoes its changes but leaves
//! the transaction open, holding the write lock: every other writer waits for the busy
//! timeout and fails, later "commits" on that connection only release a savepoint (a
//! `201` whose row no other connection sees, lost at restart).
//!
//! The hook below runs every time a connection is released: first a statement that
//! waits for anything sqlx queued (a pending rollback), then a check of both sqlx's
//! counter and, on SQLite, the connection's real state (`BEGIN` fails inside a
//! transaction). A connection in any transaction, known or not, is closed (closing a
//! SQLite connection rolls back and frees its locks) and the pool opens a fresh one.

use futures_util::future::BoxFuture;
use sqlx::pool::PoolConnectionMetadata;
use sqlx::{Connection, PgConnection, SqliteConnection};

/// `after_release` of the SQLite pool: `Ok(true)` keeps the connection, `Ok(false)`
/// closes it.
pub fn sqlite_after_release(
    connection: &mut SqliteConnection,
    _meta: PoolConnectionMetadata,
) -> BoxFuture<'_, Result<bool, sqlx::Error>> {
    Box::pin(async move {
        // Runs after any rollback the dropped `Transaction` queued (one command queue);
        // fails when the connection is in a transaction, whoever opened it.
        if let Err(error) = sqlx::query("BEGIN").execute(&mut *connection).await {
            tracing::warn!(%error, "a released SQLite connection is inside a transaction: closing it");
            return Ok(false);
        }
        if let Err(error) = sqlx::query("ROLLBACK").execute(&mut *connection).await {
            tracing::warn!(%error, "cannot end the probe transaction: closing the connection");
            return Ok(false);
        }
        if connection.is_in_transaction() {
            tracing::warn!("a released SQLite connection has an unfinished sqlx transaction: closing it");
            return Ok(false);
        }
        Ok(true)
    })
}

/// `after_release` of the PostgreSQL pool: a connection sqlx still counts inside a
/// transaction (a failed `COMMIT` or `ROLLBACK`) is closed.
pub fn postgres_after_release(
    connection: &mut PgConnection,
    _meta: PoolConnectionMetadata,
) -> BoxFuture<'_, Result<bool, sqlx::Error>> {
    // sqlx counts a dropped transaction's queued `ROLLBACK` at once (the pool then pings
    // the connection, which sends it): the counter is current here.
    Box::pin(async move {
        if connection.is_in_transaction() {
            tracing::warn!("a released PostgreSQL connection is inside a transaction: closing it");
            return Ok(false);
        }
        Ok(true)
    })
}
