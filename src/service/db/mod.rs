//! The queue's database: embedded SQLite on one machine, or PostgreSQL shared by any
//! number of API and worker processes on many machines.
//!
//! Both backends have the same tables with the same meaning (`migrations/` and
//! `migrations/postgres/`), so most queue statements are one SQL text run on either
//! pool ([`with_pool!`]); the few that differ (the claim, JSON array parameters) pick
//! their text with [`Database::choose`].

pub mod fault;
pub mod postgres;
pub mod release;
pub mod sqlite;

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use sqlx::{PgPool, SqlitePool};

/// Evaluates `$body` with `$pool` bound to the pool of `$database`, whichever backend
/// it is: the same Rust (and, with `$N` parameters, the same SQL text) compiled once per
/// backend, each with its own row and argument types.
macro_rules! with_pool {
    ($database:expr, $pool:ident => $body:expr) => {
        match $database {
            $crate::service::db::Database::Sqlite($pool) => $body,
            $crate::service::db::Database::Postgres($pool) => $body,
        }
    };
}
pub(crate) use with_pool;

/// Where the queue lives: `sqlite://<path>` or `postgres://...` (`postgresql://...`).
#[derive(Clone, PartialEq, Eq)]
pub enum DatabaseUrl {
    /// A SQLite file (created if missing).
    Sqlite(PathBuf),
    /// A PostgreSQL connection URL, as libpq understands it.
    Postgres(String),
}

impl FromStr for DatabaseUrl {
    type Err = String;

    /// `sqlite://relative/path.sqlite`, `sqlite:///absolute/path.sqlite` (or `sqlite:path`;
    /// a `?query` is ignored), `postgres://user:password@host:port/database?options`.
    fn from_str(url: &str) -> Result<Self, Self::Err> {
        if url.starts_with("postgres://") || url.starts_with("postgresql://") {
            return Ok(Self::Postgres(url.to_owned()));
        }
        if let Some(rest) = url.strip_prefix("sqlite:") {
            let path = rest.strip_prefix("//").unwrap_or(rest);
            let path = path.split('?').next().unwrap_or_default();
            if path.is_empty() || path == ":memory:" {
                return Err(format!("`{url}`: a SQLite database URL needs a file path"));
            }
            return Ok(Self::Sqlite(PathBuf::from(path)));
        }
        Err(format!(
            "`{url}`: expected `sqlite://<path>` or `postgres://<user>@<host>/<database>`"
        ))
    }
}

impl fmt::Display for DatabaseUrl {
    /// The URL with any password replaced by `***` (safe to log).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Sqlite(path) => write!(f, "sqlite://{}", path.display()),
            Self::Postgres(url) => f.write_str(&redact_password(url)),
        }
    }
}

impl fmt::Debug for DatabaseUrl {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// `scheme://user:secret@host/...` → `scheme://user:***@host/...`.
fn redact_password(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_owned();
    };
    let authority_end = rest.find(['/', '?']).unwrap_or(rest.len());
    let (authority, path) = rest.split_at(authority_end);
    match authority.rsplit_once('@') {
        Some((user_info, host)) => match user_info.split_once(':') {
            Some((user, _)) => format!("{scheme}://{user}:***@{host}{path}"),
            None => url.to_owned(),
        },
        None => url.to_owned(),
    }
}

/// An open database of either backend.
#[derive(Debug, Clone)]
pub enum Database {
    Sqlite(SqlitePool),
    Postgres(PgPool),
}

impl Database {
    /// Opens the database at `url` (creating a SQLite file and its directory if
    /// missing) and brings its schema up to date. `max_connections` sizes a PostgreSQL
    /// pool (SQLite has one writer anyway and keeps its own size).
    pub async fn open(url: &DatabaseUrl, max_connections: u32) -> Result<Self, sqlx::Error> {
        Self::open_limited(url, max_connections, None).await
    }

    /// [`Database::open`], with a SQLite database capped at `max_sqlite_bytes`
    /// ([`sqlite::open`]; ignored for PostgreSQL, whose size is its server's business).
    pub async fn open_limited(
        url: &DatabaseUrl,
        max_connections: u32,
        max_sqlite_bytes: Option<u64>,
    ) -> Result<Self, sqlx::Error> {
        match url {
            DatabaseUrl::Sqlite(path) => {
                if let Some(dir) = path.parent().filter(|dir| !dir.as_os_str().is_empty()) {
                    std::fs::create_dir_all(dir)?;
                }
                Ok(Self::Sqlite(sqlite::open(path, max_sqlite_bytes).await?))
            }
            DatabaseUrl::Postgres(url) => Ok(Self::Postgres(postgres::open(url, max_connections).await?)),
        }
    }

    /// `sqlite` or `postgres`.
    pub fn backend(&self) -> &'static str {
        match self {
            Self::Sqlite(_) => "sqlite",
            Self::Postgres(_) => "postgres",
        }
    }

    /// The SQL text for this backend, when the two differ.
    pub fn choose(&self, sqlite: &'static str, postgres: &'static str) -> &'static str {
        match self {
            Self::Sqlite(_) => sqlite,
            Self::Postgres(_) => postgres,
        }
    }

    pub fn as_sqlite(&self) -> Option<&SqlitePool> {
        match self {
            Self::Sqlite(pool) => Some(pool),
            Self::Postgres(_) => None,
        }
    }

    pub fn as_postgres(&self) -> Option<&PgPool> {
        match self {
            Self::Sqlite(_) => None,
            Self::Postgres(pool) => Some(pool),
        }
    }

    /// Whether the database answers (health checks).
    pub async fn ping(&self) -> Result<(), sqlx::Error> {
        with_pool!(self, pool => sqlx::query("SELECT 1").execute(pool).await.map(|_| ()))
    }

    /// Whether the database takes a write: rewrites the one row of `write_probe`
    /// (`migrations/0007`) in a transaction and commits it (`/readyz`).
    pub async fn probe_write(&self, now_ms: i64) -> Result<(), sqlx::Error> {
        with_pool!(self, pool => {
            let mut tx = pool.begin().await?;
            sqlx::query(
                "INSERT INTO write_probe (id, probed_at) VALUES (1, $1) \
                 ON CONFLICT (id) DO UPDATE SET probed_at = excluded.probed_at",
            )
            .bind(now_ms)
            .execute(&mut *tx)
            .await?;
            tx.commit().await
        })
    }

    /// Closes every connection (pending statements fail from now on).
    pub async fn close(&self) {
        with_pool!(self, pool => pool.close().await);
    }
}

/// Serializes, per tenant, the transactions that count a tenant's queued jobs before
/// adding more (its limit on queued jobs): taken first in such a transaction, held until
/// it ends.
pub(crate) trait TenantQueueLock {
    async fn lock_tenant_queue(&mut self, tenant: &str) -> Result<(), sqlx::Error>;
}

impl TenantQueueLock for sqlx::SqliteConnection {
    /// Nothing to do: the transaction's first write takes the database's write lock, and
    /// the counting insert is that first write.
    async fn lock_tenant_queue(&mut self, _tenant: &str) -> Result<(), sqlx::Error> {
        Ok(())
    }
}

impl TenantQueueLock for sqlx::PgConnection {
    /// A transaction-level advisory lock on (`'choc'`, hash of the tenant): concurrent
    /// submissions of one tenant queue up here, other tenants' go on (a hash collision
    /// only serializes two tenants).
    async fn lock_tenant_queue(&mut self, tenant: &str) -> Result<(), sqlx::Error> {
        sqlx::query("SELECT pg_advisory_xact_lock(1667788643, hashtext($1))")
            .bind(tenant)
            .execute(self)
            .await?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_name_their_backend() {
        assert_eq!(
            "sqlite://data/chocmodal.sqlite".parse::<DatabaseUrl>(),
            Ok(DatabaseUrl::Sqlite("data/chocmodal.sqlite".into()))
        );
        assert_eq!(
            "sqlite:///var/lib/chocmodal/db.sqlite?mode=rwc".parse::<DatabaseUrl>(),
            Ok(DatabaseUrl::Sqlite("/var/lib/chocmodal/db.sqlite".into()))
        );
        assert_eq!(
            "postgresql://u@h/db".parse::<DatabaseUrl>(),
            Ok(DatabaseUrl::Postgres("postgresql://u@h/db".into()))
        );
        assert!("mysql://u@h/db".parse::<DatabaseUrl>().is_err());
        assert!("sqlite://".parse::<DatabaseUrl>().is_err());
    }

    #[test]
    fn passwords_never_reach_the_logs() {
        let url: DatabaseUrl = "postgres://chocmodal:s3cret@db.internal:5432/queue?sslmode=require"
            .parse()
            .unwrap();
        assert_eq!(
            url.to_string(),
            "postgres://chocmodal:***@db.internal:5432/queue?sslmode=require"
        );
        assert_eq!(format!("{url:?}"), url.to_string());
        let no_password: DatabaseUrl = "postgres://chocmodal@db/queue".parse().unwrap();
        assert_eq!(no_password.to_string(), "postgres://chocmodal@db/queue");
    }
}
