//! PostgreSQL (many machines): pool, migrations, and the wake-up channel.
//!
//! Every API and worker process opens its own pool on the same database. Migrations
//! (`migrations/postgres/`) run at every start; sqlx serializes concurrent starts with
//! an advisory lock, so any number of processes may start at once.
//!
//! Wake-ups: a process that queues work sends `NOTIFY chocmodal_jobs` (delivered at
//! commit); worker processes `LISTEN` on one dedicated connection and wake their idle
//! slots. Notifications are best effort (a transaction pooler such as PgBouncer drops
//! them, a reconnect loses those sent meanwhile): idle workers also poll.

use std::sync::Arc;
use std::time::Duration;

use sqlx::PgPool;
use sqlx::postgres::{PgListener, PgPoolOptions};
use tokio::sync::Notify;

/// The channel of "jobs were queued" notifications.
pub const JOBS_CHANNEL: &str = "chocmodal_jobs";

/// Opens a pool on `url` and runs the migrations in `migrations/postgres/`.
pub async fn open(url: &str, max_connections: u32) -> Result<PgPool, sqlx::Error> {
    let pool = PgPoolOptions::new()
        .max_connections(max_connections)
        .min_connections(1)
        .acquire_timeout(Duration::from_secs(10))
        .after_release(super::release::postgres_after_release)
        .connect(url)
        .await?;
    sqlx::migrate!("./migrations/postgres").run(&pool).await?;
    Ok(pool)
}

/// Tells every listening process that jobs were queued.
pub async fn notify_queued<'e>(executor: impl sqlx::PgExecutor<'e>) -> Result<(), sqlx::Error> {
    sqlx::query("SELECT pg_notify($1, '')")
        .bind(JOBS_CHANNEL)
        .execute(executor)
        .await?;
    Ok(())
}

/// Listens for queued jobs and wakes `wake`'s waiters on each notification, forever
/// (the caller aborts the task). A lost connection is re-established; since
/// notifications sent meanwhile are lost, the waiters are woken then too.
pub async fn wake_on_notify(pool: PgPool, wake: Arc<Notify>) {
    let mut listener: Option<PgListener> = None;
    loop {
        let active = match listener.as_mut() {
            Some(active) => active,
            None => match subscribe(&pool).await {
                Ok(subscribed) => listener.insert(subscribed),
                Err(error) => {
                    tracing::warn!(%error, "cannot listen for queued jobs; polling only, retrying in 5 s");
                    tokio::time::sleep(Duration::from_secs(5)).await;
                    continue;
                }
            },
        };
        match active.try_recv().await {
            Ok(Some(_)) => wake.notify_waiters(),
            // The connection was lost and re-established: look for what was missed.
            Ok(None) => wake.notify_waiters(),
            Err(error) => {
                tracing::warn!(%error, "listening for queued jobs failed; reconnecting in 1 s");
                listener = None;
                tokio::time::sleep(Duration::from_secs(1)).await;
            }
        }
    }
}

async fn subscribe(pool: &PgPool) -> Result<PgListener, sqlx::Error> {
    let mut listener = PgListener::connect_with(pool).await?;
    listener.listen(JOBS_CHANNEL).await?;
    Ok(listener)
}
