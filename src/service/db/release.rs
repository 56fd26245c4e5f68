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

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use super::super::fault::StorageFault;

    /// A database full to its page limit refuses transactions (as a full disk does);
    /// once rows are deleted, every pooled connection takes a write at once: none was
    /// returned to the pool inside a transaction holding the write lock (it would make
    /// the others wait for the busy timeout, and its own "commits" would be lost).
    #[tokio::test]
    async fn failed_transactions_on_a_full_database_leave_no_connection_inside_one() {
        let dir = tempfile::TempDir::new().unwrap();
        let path = dir.path().join("full.sqlite");
        let pool = super::super::sqlite::open(&path, Some(1 << 20)).await.unwrap();
        sqlx::query("CREATE TABLE filler (data BLOB)")
            .execute(&pool)
            .await
            .unwrap();
        let mut rows = 0;
        loop {
            match sqlx::query("INSERT INTO filler VALUES (randomblob(16384))")
                .execute(&pool)
                .await
            {
                Ok(_) => rows += 1,
                Err(error) => {
                    assert!(StorageFault::of(&error).is_some(), "{error}");
                    break;
                }
            }
            assert!(rows < 1000, "the page limit never refused a row");
        }
        // Several failed transactions, as failed submissions would make.
        for _ in 0..4 {
            let mut tx = pool.begin().await.unwrap();
            let error = sqlx::query("INSERT INTO filler VALUES (randomblob(300000))")
                .execute(&mut *tx)
                .await
                .expect_err("the database is full");
            assert!(StorageFault::of(&error).is_some(), "{error}");
            drop(tx);
        }
        sqlx::query("DELETE FROM filler").execute(&pool).await.unwrap();
        let started = Instant::now();
        let mut held = Vec::new();
        for k in 0..8 {
            // Hold each connection so that every pooled one is used once.
            let mut connection = pool.acquire().await.unwrap();
            let mut tx = sqlx::Connection::begin(&mut *connection).await.unwrap();
            sqlx::query("INSERT INTO filler VALUES (randomblob(16))")
                .execute(&mut *tx)
                .await
                .unwrap_or_else(|error| panic!("write {k} after freeing space: {error}"));
            tx.commit().await.unwrap();
            held.push(connection);
        }
        drop(held);
        assert!(
            started.elapsed() < Duration::from_secs(3),
            "writes after freeing space took {:?}",
            started.elapsed()
        );
        pool.close().await;
        // Every commit is in the file, as another process sees it.
        let reopened = super::super::sqlite::open(&path, None).await.unwrap();
        let count: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM filler")
            .fetch_one(&reopened)
            .await
            .unwrap();
        assert_eq!(count, 8);
    }
}
