//! Storage faults: database errors that say the disk (not the request, not a bug) is
//! the problem, told apart from the rest so the API can answer 507/503 naming the cause
//! instead of a generic 500, and the worker can hold results until the write lands.
//!
//! - full: SQLite `SQLITE_FULL` (13), PostgreSQL `53100` (`disk_full`), an I/O error
//!   `ENOSPC` (os error 28; also PostgreSQL's "No space left on device" in a `58030`);
//! - I/O: SQLite `SQLITE_IOERR` and its extended codes (10 + 256·k: a failed write or
//!   fsync, what a full tmpfs often reports), PostgreSQL `58030` (`io_error`).

use std::fmt;

/// The POSIX errno of "No space left on device".
const ENOSPC: i32 = 28;

/// Why the database could not write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StorageFault {
    /// No space left: SQLITE_FULL, PostgreSQL 53100 `disk_full`, or ENOSPC.
    Full(FullCause),
    /// The storage failed an I/O operation (SQLITE_IOERR*, PostgreSQL 58030 `io_error`).
    Io,
}

/// Which report of a full disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FullCause {
    SqliteFull,
    PostgresDiskFull,
    Enospc,
}

impl StorageFault {
    /// The storage fault `error` reports, if any.
    pub fn of(error: &sqlx::Error) -> Option<Self> {
        match error {
            sqlx::Error::Io(io) if io.raw_os_error() == Some(ENOSPC) => Some(Self::Full(FullCause::Enospc)),
            sqlx::Error::Database(database) => {
                let code = database.code()?;
                if database.try_downcast_ref::<sqlx::sqlite::SqliteError>().is_some() {
                    let extended: i32 = code.parse().ok()?;
                    // The primary result code is the low byte of the extended one.
                    match extended & 0xff {
                        13 => Some(Self::Full(FullCause::SqliteFull)),
                        10 if database.message().contains("No space left") => {
                            Some(Self::Full(FullCause::Enospc))
                        }
                        10 => Some(Self::Io),
                        _ => None,
                    }
                } else {
                    match &*code {
                        "53100" => Some(Self::Full(FullCause::PostgresDiskFull)),
                        "58030" if database.message().contains("No space left") => {
                            Some(Self::Full(FullCause::Enospc))
                        }
                        "58030" => Some(Self::Io),
                        _ => None,
                    }
                }
            }
            _ => None,
        }
    }

    /// The cause as the API and the metrics name it: `SQLITE_FULL`, `disk_full` (53100),
    /// `ENOSPC`, `io_error`.
    pub fn cause(self) -> &'static str {
        match self {
            Self::Full(FullCause::SqliteFull) => "SQLITE_FULL",
            Self::Full(FullCause::PostgresDiskFull) => "disk_full",
            Self::Full(FullCause::Enospc) => "ENOSPC",
            Self::Io => "io_error",
        }
    }

    /// The HTTP status of a write refused for this fault: 507 Insufficient Storage for
    /// a full disk, 503 for an I/O error (both with `Retry-After`).
    pub fn status(self) -> u16 {
        match self {
            Self::Full(_) => 507,
            Self::Io => 503,
        }
    }
}

impl fmt::Display for StorageFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Full(FullCause::SqliteFull) => f.write_str("the database's disk is full (SQLITE_FULL)"),
            Self::Full(FullCause::PostgresDiskFull) => {
                f.write_str("the database's disk is full (PostgreSQL 53100 disk_full)")
            }
            Self::Full(FullCause::Enospc) => f.write_str("the database's disk is full (ENOSPC)"),
            Self::Io => f.write_str("the database's storage failed an I/O operation (I/O error)"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_enospc_io_error_is_a_full_disk() {
        let error = sqlx::Error::Io(std::io::Error::from_raw_os_error(ENOSPC));
        assert_eq!(
            StorageFault::of(&error),
            Some(StorageFault::Full(FullCause::Enospc))
        );
        let other = sqlx::Error::Io(std::io::Error::from_raw_os_error(13));
        assert_eq!(StorageFault::of(&other), None);
        assert_eq!(StorageFault::of(&sqlx::Error::RowNotFound), None);
    }

    #[tokio::test]
    async fn sqlite_full_is_recognized_from_a_real_database() {
        use sqlx::{Connection, Executor};
        let mut connection = sqlx::SqliteConnection::connect("sqlite::memory:").await.unwrap();
        connection
            .execute("CREATE TABLE t (x BLOB); PRAGMA max_page_count = 3;")
            .await
            .unwrap();
        let error = sqlx::query("INSERT INTO t VALUES (zeroblob(100000))")
            .execute(&mut connection)
            .await
            .expect_err("the page limit refuses the row");
        let fault = StorageFault::of(&error);
        assert_eq!(fault, Some(StorageFault::Full(FullCause::SqliteFull)), "{error}");
        assert_eq!(fault.map(StorageFault::status), Some(507));
    }
}
