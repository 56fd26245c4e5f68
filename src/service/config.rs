//! Settings of `chocmodal serve`: command-line flags, each also an environment variable,
//! turned into a [`ServiceConfig`] that the rest of the service reads.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use super::clock::{SharedClock, SystemClock};

/// Log output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LogFormat {
    /// Human-readable lines.
    Human,
    /// One JSON object per line.
    Json,
}

/// `chocmodal serve`: the HTTP API and the workers on an embedded SQLite database.
#[derive(Debug, Clone, clap::Args)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long, env = "CHOCMODAL_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,
    /// Directory of the database (`chocmodal.sqlite`); created if missing.
    #[arg(long, env = "CHOCMODAL_DATA_DIR", default_value = "./data")]
    pub data_dir: PathBuf,
    /// Jobs computed at once (default: number of cores). 0 runs the API alone.
    #[arg(long, env = "CHOCMODAL_WORKERS")]
    pub workers: Option<usize>,
    /// Delete finished jobs (and their results) this many days after they finished; 0 keeps them forever.
    #[arg(long, env = "CHOCMODAL_RETENTION_DAYS", default_value_t = 30)]
    pub retention_days: u32,
    /// Largest accepted request body (bytes).
    #[arg(long, env = "CHOCMODAL_MAX_BODY_BYTES", default_value_t = 1 << 20)]
    pub max_body_bytes: usize,
    /// Lease of a running job (s): a worker that stops heartbeating loses its job after this long.
    #[arg(long, env = "CHOCMODAL_LEASE_SECONDS", default_value_t = 30)]
    pub lease_seconds: u64,
    /// Claims of one job before a lost worker fails it instead of re-queueing it.
    #[arg(long, env = "CHOCMODAL_MAX_ATTEMPTS", default_value_t = 3)]
    pub max_attempts: u32,
    /// On SIGTERM/ctrl-c, how long running jobs may take to finish (s) before they are handed back to the queue.
    #[arg(long, env = "CHOCMODAL_SHUTDOWN_GRACE_SECONDS", default_value_t = 30)]
    pub shutdown_grace_seconds: u64,
    /// Most runs one sweep may expand into; larger sweeps are refused (422).
    #[arg(long, env = "CHOCMODAL_MAX_SWEEP_RUNS", default_value_t = DEFAULT_MAX_SWEEP_RUNS)]
    pub max_sweep_runs: usize,
    /// Log format on stderr.
    #[arg(long, env = "CHOCMODAL_LOG_FORMAT", value_enum, default_value = "human")]
    pub log_format: LogFormat,
}

/// Everything the service needs to start, with defaults for the knobs the CLI does not expose.
#[derive(Debug, Clone)]
pub struct ServiceConfig {
    /// Address to listen on; port 0 picks a free port (tests).
    pub bind: SocketAddr,
    /// Directory holding `chocmodal.sqlite`.
    pub data_dir: PathBuf,
    /// Number of worker slots (jobs computed at once).
    pub workers: usize,
    /// Age after which finished jobs are deleted; `None` keeps them.
    pub retention: Option<Duration>,
    /// Largest accepted request body (bytes).
    pub max_body_bytes: usize,
    /// Lease of a running job; heartbeats renew it at a third of this.
    pub lease: Duration,
    /// Claims of one job before a lost worker fails it.
    pub max_attempts: u32,
    /// Time running jobs get to finish on shutdown before they are handed back.
    pub shutdown_grace: Duration,
    /// Period of lease recovery and retention.
    pub maintenance_interval: Duration,
    /// Idle workers look for work at least this often (enqueues also wake them).
    pub poll_interval: Duration,
    /// Period at which a running job's progress and cancel flag are synchronised with its row.
    pub progress_interval: Duration,
    /// Most runs one sweep may expand into.
    pub max_sweep_runs: usize,
    /// The queue's clock.
    pub clock: SharedClock,
}

/// Default limit of runs per sweep.
pub const DEFAULT_MAX_SWEEP_RUNS: usize = 10_000;

/// Default number of workers: the cores available to this process.
pub fn default_workers() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

impl ServiceConfig {
    /// Defaults for a data directory (bind `127.0.0.1:8080`, one worker per core).
    pub fn new(data_dir: impl Into<PathBuf>) -> Self {
        Self {
            bind: SocketAddr::from(([127, 0, 0, 1], 8080)),
            data_dir: data_dir.into(),
            workers: default_workers(),
            retention: Some(Duration::from_secs(30 * 86_400)),
            max_body_bytes: 1 << 20,
            lease: Duration::from_secs(30),
            max_attempts: 3,
            shutdown_grace: Duration::from_secs(30),
            maintenance_interval: Duration::from_secs(15),
            poll_interval: Duration::from_millis(500),
            progress_interval: Duration::from_millis(250),
            max_sweep_runs: DEFAULT_MAX_SWEEP_RUNS,
            clock: Arc::new(SystemClock),
        }
    }

    /// Path of the SQLite database file.
    pub fn database_path(&self) -> PathBuf {
        self.data_dir.join("chocmodal.sqlite")
    }
}

impl From<&ServeArgs> for ServiceConfig {
    fn from(args: &ServeArgs) -> Self {
        Self {
            bind: args.bind,
            workers: args.workers.unwrap_or_else(default_workers),
            retention: (args.retention_days > 0)
                .then(|| Duration::from_secs(u64::from(args.retention_days) * 86_400)),
            max_body_bytes: args.max_body_bytes,
            lease: Duration::from_secs(args.lease_seconds.max(1)),
            max_attempts: args.max_attempts.max(1),
            shutdown_grace: Duration::from_secs(args.shutdown_grace_seconds),
            max_sweep_runs: args.max_sweep_runs,
            ..Self::new(args.data_dir.clone())
        }
    }
}
