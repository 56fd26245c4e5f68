//! Settings of `chocmodal serve`: command-line flags, each also an environment variable,
//! turned into a [`ServiceConfig`] that the rest of the service reads.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use super::auth::{AuthFileError, TokenTable};
use super::callbacks::{
    AllowList, CallbackPolicy, CallbackSecrets, CallbackSettings, DEFAULT_GIVE_UP_SECONDS,
    DEFAULT_PROGRESS_SECONDS, HostPattern, SecretsFileError,
};
use super::clock::{SharedClock, SystemClock};
use super::db::DatabaseUrl;
use super::http::cors::CorsOrigin;
use crate::processes::CostLimits;
use crate::processes::cost::{DEFAULT_MAX_HISTORY_VALUES, DEFAULT_MAX_WORK};

/// Log output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LogFormat {
    /// Human-readable lines.
    Human,
    /// One JSON object per line.
    Json,
}

/// Flags of every process that opens the queue (`serve` and `worker`).
#[derive(Debug, Clone, clap::Args)]
pub struct QueueArgs {
    /// Database: `sqlite://<path>` (one machine) or
    /// `postgres://<user>:<password>@<host>:<port>/<database>` (shared by API and worker
    /// processes on any number of machines). Default: `sqlite://<data-dir>/chocmodal.sqlite`.
    #[arg(
        long,
        env = "CHOCMODAL_DATABASE_URL",
        value_name = "URL",
        hide_env_values = true
    )]
    pub database: Option<DatabaseUrl>,
    /// Directory of the default SQLite database (`chocmodal.sqlite`); created if missing.
    #[arg(long, env = "CHOCMODAL_DATA_DIR", default_value = "./data")]
    pub data_dir: PathBuf,
    /// Jobs computed at once by this process (default: number of cores). 0: none.
    #[arg(long, env = "CHOCMODAL_WORKERS")]
    pub workers: Option<usize>,
    /// Largest number of connections this process opens to a PostgreSQL database.
    #[arg(long, env = "CHOCMODAL_DATABASE_CONNECTIONS", default_value_t = 10)]
    pub database_connections: u32,
    /// A SQLite database never grows beyond this many MiB (SQLite's `max_page_count`):
    /// writes that need more space are refused with 507, as on a full disk, while reads
    /// go on. 0: no limit but the disk's.
    #[arg(long, env = "CHOCMODAL_MAX_DATABASE_MIB", default_value_t = 0)]
    pub max_database_mib: u64,
    /// Delete finished jobs (and their results) this many days after they finished; 0 keeps them forever.
    #[arg(long, env = "CHOCMODAL_RETENTION_DAYS", default_value_t = 30)]
    pub retention_days: u32,
    /// Lease of a running job (s): a worker that stops heartbeating loses its job after this long.
    #[arg(long, env = "CHOCMODAL_LEASE_SECONDS", default_value_t = 30)]
    pub lease_seconds: u64,
    /// Claims of one job before a lost worker fails it instead of re-queueing it.
    #[arg(long, env = "CHOCMODAL_MAX_ATTEMPTS", default_value_t = 3)]
    pub max_attempts: u32,
    /// On SIGTERM/ctrl-c, how long running jobs may take to finish (s) before they are handed back to the queue.
    #[arg(long, env = "CHOCMODAL_SHUTDOWN_GRACE_SECONDS", default_value_t = 30)]
    pub shutdown_grace_seconds: u64,
    /// Wall-time limit of one job (s): a run still computing after this long fails. 0: no limit.
    #[arg(long, env = "CHOCMODAL_MAX_JOB_SECONDS", default_value_t = 900)]
    pub max_job_seconds: u64,
    /// Log format on stderr.
    #[arg(long, env = "CHOCMODAL_LOG_FORMAT", value_enum, default_value = "human")]
    pub log_format: LogFormat,
}

/// `chocmodal serve`: the HTTP API, and workers unless `--workers 0`.
#[derive(Debug, Clone, clap::Args)]
pub struct ServeArgs {
    /// Address to listen on.
    #[arg(long, env = "CHOCMODAL_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,
    #[command(flatten)]
    pub queue: QueueArgs,
    /// Largest accepted request body (bytes).
    #[arg(long, env = "CHOCMODAL_MAX_BODY_BYTES", default_value_t = 1 << 20)]
    pub max_body_bytes: usize,
    /// Largest body of `POST /signals` (bytes): an accelerogram upload, CSV or JSON.
    #[arg(long, env = "CHOCMODAL_MAX_SIGNAL_BYTES", default_value_t = DEFAULT_MAX_SIGNAL_BYTES)]
    pub max_signal_bytes: usize,
    /// Most samples of one stored signal (accelerogram).
    #[arg(long, env = "CHOCMODAL_MAX_SIGNAL_SAMPLES", default_value_t = DEFAULT_MAX_SIGNAL_SAMPLES)]
    pub max_signal_samples: usize,
    /// Most runs one sweep may expand into; larger sweeps are refused (422).
    #[arg(long, env = "CHOCMODAL_MAX_SWEEP_RUNS", default_value_t = DEFAULT_MAX_SWEEP_RUNS)]
    pub max_sweep_runs: usize,
    /// Tenants and their bearer tokens, one `<tenant> <token>` per line (`#` comments).
    /// Every route but `/healthz` then needs `Authorization: Bearer <token>`.
    #[arg(long, env = "CHOCMODAL_AUTH_FILE", value_name = "PATH")]
    pub auth_file: Option<PathBuf>,
    /// Serve `/metrics` without a token even when an auth file is set.
    #[arg(long, env = "CHOCMODAL_METRICS_PUBLIC", value_parser = clap::builder::BoolishValueParser::new())]
    pub metrics_public: bool,
    /// Allow binding a non-loopback address without an auth file (anyone who can reach
    /// the port can then submit and read every job).
    #[arg(long, env = "CHOCMODAL_INSECURE", value_parser = clap::builder::BoolishValueParser::new())]
    pub insecure: bool,
    /// Largest estimated work of one run: steps × (pins × modes + contacts); larger runs are refused (422).
    #[arg(long, env = "CHOCMODAL_MAX_WORK", default_value_t = DEFAULT_MAX_WORK, value_parser = positive_number)]
    pub max_work: f64,
    /// Largest number of values (samples × columns) the histories of one run may hold (422 above).
    #[arg(long, env = "CHOCMODAL_MAX_HISTORY_VALUES", default_value_t = DEFAULT_MAX_HISTORY_VALUES, value_parser = positive_number)]
    pub max_history_values: f64,
    /// Most rows one history response holds: longer windows are thinned (peaks kept).
    #[arg(long, env = "CHOCMODAL_MAX_HISTORY_POINTS", default_value_t = DEFAULT_MAX_HISTORY_POINTS)]
    pub max_history_points: usize,
    /// Working memory the history responses being made may use together (MiB): the
    /// decoded histories and their windows (their text is streamed); a response that does
    /// not fit gets a 503 with `Retry-After`.
    #[arg(long, env = "CHOCMODAL_RESPONSE_MEMORY_MB", default_value_t = DEFAULT_RESPONSE_MEMORY_MB, value_parser = clap::value_parser!(u64).range(1..))]
    pub response_memory_mb: u64,
    /// Most queued (accepted) jobs per tenant, sweep runs included; more is a 429. 0: no limit.
    #[arg(long, env = "CHOCMODAL_MAX_QUEUED_JOBS", default_value_t = DEFAULT_MAX_QUEUED_JOBS)]
    pub max_queued_jobs: u64,
    /// Longest time one request may take, its body included (s): slower ones get a 408.
    #[arg(long, env = "CHOCMODAL_REQUEST_TIMEOUT_SECONDS", default_value_t = 30)]
    pub request_timeout_seconds: u64,
    /// Web origins allowed to call the API from a browser (CORS), e.g.
    /// `https://dash.example.com`; repeat the flag or separate with commas; `*`: every
    /// origin. Default: none (no CORS headers, preflights refused).
    #[arg(
        long = "cors-origin",
        env = "CHOCMODAL_CORS_ORIGIN",
        value_name = "ORIGIN",
        value_delimiter = ','
    )]
    pub cors_origins: Vec<CorsOrigin>,
    /// Longest time a client may take to send a request's headers (s), and to start the
    /// next request on a kept-alive connection; the connection is closed after that.
    #[arg(long, env = "CHOCMODAL_HEADER_TIMEOUT_SECONDS", default_value_t = 10)]
    pub header_timeout_seconds: u64,
    /// Hosts job callbacks (an execution request's `subscriber`) may be sent to:
    /// `hooks.example.com`, `*.example.com` (its subdomains), `10.0.0.7`, `[::1]`, each
    /// optionally with `:port`; repeat the flag or separate with commas. Default: none
    /// (subscribers are refused with a 422 that names this option).
    #[arg(
        long = "callback-allow",
        env = "CHOCMODAL_CALLBACK_ALLOW",
        value_name = "HOST",
        value_delimiter = ','
    )]
    pub callback_allow: Vec<HostPattern>,
    /// The tenants' callback signing secrets, one `<tenant> <secret>` per line (`#`
    /// comments; the tenant is `default` without an auth file): each callback carries
    /// `Chocmodal-Signature`, an HMAC-SHA256 of its body with its tenant's secret. A
    /// tenant without a secret cannot subscribe.
    #[arg(long, env = "CHOCMODAL_CALLBACK_SECRETS", value_name = "PATH")]
    pub callback_secrets: Option<PathBuf>,
    /// A job callback not delivered this long after its job finished is abandoned (s).
    #[arg(long, env = "CHOCMODAL_CALLBACK_GIVE_UP_SECONDS", default_value_t = DEFAULT_GIVE_UP_SECONDS,
        value_parser = clap::value_parser!(u64).range(1..))]
    pub callback_give_up_seconds: u64,
    /// Least time between two progress callbacks of one job (s).
    #[arg(long, env = "CHOCMODAL_CALLBACK_PROGRESS_SECONDS", default_value_t = DEFAULT_PROGRESS_SECONDS,
        value_parser = clap::value_parser!(u64).range(1..))]
    pub callback_progress_seconds: u64,
}

fn positive_number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() && value > 0.0 => Ok(value),
        _ => Err(format!("`{text}` is not a positive number")),
    }
}

/// `chocmodal worker`: workers alone, no API (any number of such processes, on any
/// machines, sharing one PostgreSQL database with the API processes).
#[derive(Debug, Clone, clap::Args)]
pub struct WorkerArgs {
    #[command(flatten)]
    pub queue: QueueArgs,
    /// Also serve `/healthz` and `/metrics` on this address (e.g. `0.0.0.0:9090`).
    #[arg(long, env = "CHOCMODAL_HEALTH_BIND", value_name = "ADDR")]
    pub health_bind: Option<SocketAddr>,
}

/// Everything the service needs to start, with defaults for the knobs the CLI does not expose.
#[derive(Debug, Clone)]
pub struct ServiceConfig {
    /// Address the API listens on; port 0 picks a free port (tests).
    pub bind: SocketAddr,
    /// Worker role only: address of `/healthz` and `/metrics`, if any.
    pub health_bind: Option<SocketAddr>,
    /// The queue's database.
    pub database: DatabaseUrl,
    /// Largest number of connections to a PostgreSQL database.
    pub database_connections: u32,
    /// Largest size of a SQLite database (bytes, rounded down to whole pages); `None`:
    /// the disk's.
    pub max_database_bytes: Option<u64>,
    /// Number of worker slots (jobs computed at once).
    pub workers: usize,
    /// Age after which finished jobs are deleted; `None` keeps them.
    pub retention: Option<Duration>,
    /// Largest accepted request body (bytes).
    pub max_body_bytes: usize,
    /// Largest body of `POST /signals` (bytes).
    pub max_signal_bytes: usize,
    /// Most samples of one stored signal.
    pub max_signal_samples: usize,
    /// Lease of a running job; heartbeats renew it at a third of this.
    pub lease: Duration,
    /// Claims of one job before a lost worker fails it.
    pub max_attempts: u32,
    /// Time running jobs get to finish on shutdown before they are handed back.
    pub shutdown_grace: Duration,
    /// Period of lease recovery and retention (every process runs them).
    pub maintenance_interval: Duration,
    /// Idle workers look for work at least this often (enqueues also wake them).
    pub poll_interval: Duration,
    /// Period at which a running job's progress and cancel flag are synchronised with its row.
    pub progress_interval: Duration,
    /// Most runs one sweep may expand into.
    pub max_sweep_runs: usize,
    /// Tenants' tokens; `None`: one implicit tenant, no authentication.
    pub auth: Option<TokenTable>,
    /// `/metrics` answers without a token.
    pub metrics_public: bool,
    /// Web origins allowed to call the API from a browser; empty: no CORS.
    pub cors_origins: Vec<CorsOrigin>,
    /// Bind a non-loopback address even without `auth`.
    pub insecure: bool,
    /// Ceilings on the estimated cost of one run.
    pub limits: CostLimits,
    /// Most rows of one history response (longer windows are thinned).
    pub max_history_points: usize,
    /// Working memory the history responses being made may use together (bytes).
    pub response_memory_bytes: usize,
    /// Most queued jobs per tenant; `None`: no limit.
    pub max_queued_jobs: Option<u64>,
    /// Wall-time limit of one job; `None`: no limit.
    pub max_job_time: Option<Duration>,
    /// Longest time one request may take (408 after that).
    pub request_timeout: Duration,
    /// Longest time a client may take to send request headers.
    pub header_read_timeout: Duration,
    /// Job callbacks: allowed hosts, signing secrets, retries (API role only).
    pub callbacks: CallbackSettings,
    /// The queue's clock.
    pub clock: SharedClock,
}

/// Default limit of runs per sweep.
pub const DEFAULT_MAX_SWEEP_RUNS: usize = 10_000;
/// Default limit of queued jobs per tenant: two sweeps of the largest size.
pub const DEFAULT_MAX_QUEUED_JOBS: u64 = 2 * DEFAULT_MAX_SWEEP_RUNS as u64;
/// Default body limit of `POST /signals`: 48 MiB, a million samples of CSV
/// `time,acceleration` at full precision.
pub const DEFAULT_MAX_SIGNAL_BYTES: usize = 48 << 20;
/// Default limit of samples per stored signal: 1.4 hours at 200 samples per second.
pub const DEFAULT_MAX_SIGNAL_SAMPLES: usize = 1_000_000;
/// Default cap of rows per history response.
pub const DEFAULT_MAX_HISTORY_POINTS: usize = 500_000;
/// Default `--response-memory-mb`.
pub const DEFAULT_RESPONSE_MEMORY_MB: u64 = 1024;

/// Default number of workers: the cores available to this process.
pub fn default_workers() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

impl ServiceConfig {
    /// Defaults with the SQLite database `chocmodal.sqlite` in `data_dir` (bind
    /// `127.0.0.1:8080`, one worker per core).
    pub fn new(data_dir: impl Into<PathBuf>) -> Self {
        Self::with_database(DatabaseUrl::Sqlite(data_dir.into().join(SQLITE_FILE)))
    }

    /// Defaults with this database.
    pub fn with_database(database: DatabaseUrl) -> Self {
        Self {
            bind: SocketAddr::from(([127, 0, 0, 1], 8080)),
            health_bind: None,
            database,
            database_connections: 10,
            max_database_bytes: None,
            workers: default_workers(),
            retention: Some(Duration::from_secs(30 * 86_400)),
            max_body_bytes: 1 << 20,
            max_signal_bytes: DEFAULT_MAX_SIGNAL_BYTES,
            max_signal_samples: DEFAULT_MAX_SIGNAL_SAMPLES,
            lease: Duration::from_secs(30),
            max_attempts: 3,
            shutdown_grace: Duration::from_secs(30),
            maintenance_interval: Duration::from_secs(15),
            poll_interval: Duration::from_millis(500),
            progress_interval: Duration::from_millis(250),
            max_sweep_runs: DEFAULT_MAX_SWEEP_RUNS,
            auth: None,
            metrics_public: false,
            cors_origins: Vec::new(),
            insecure: false,
            limits: CostLimits::default(),
            max_history_points: DEFAULT_MAX_HISTORY_POINTS,
            response_memory_bytes: (DEFAULT_RESPONSE_MEMORY_MB as usize) << 20,
            max_queued_jobs: Some(DEFAULT_MAX_QUEUED_JOBS),
            max_job_time: Some(Duration::from_secs(900)),
            request_timeout: Duration::from_secs(30),
            header_read_timeout: Duration::from_secs(10),
            callbacks: CallbackSettings::default(),
            clock: Arc::new(SystemClock),
        }
    }

    /// Settings shared by both roles, from their flags.
    fn from_queue_args(args: &QueueArgs) -> Self {
        let lease = Duration::from_secs(args.lease_seconds.max(1));
        let database = args
            .database
            .clone()
            .unwrap_or_else(|| DatabaseUrl::Sqlite(args.data_dir.join(SQLITE_FILE)));
        Self {
            database_connections: args.database_connections.max(2),
            max_database_bytes: (args.max_database_mib > 0)
                .then(|| args.max_database_mib.saturating_mul(1 << 20)),
            workers: args.workers.unwrap_or_else(default_workers),
            retention: (args.retention_days > 0)
                .then(|| Duration::from_secs(u64::from(args.retention_days) * 86_400)),
            lease,
            // A lost worker's job is back in the queue within 1.5 leases.
            maintenance_interval: (lease / 2).clamp(Duration::from_secs(1), Duration::from_secs(15)),
            max_attempts: args.max_attempts.max(1),
            shutdown_grace: Duration::from_secs(args.shutdown_grace_seconds),
            max_job_time: (args.max_job_seconds > 0).then(|| Duration::from_secs(args.max_job_seconds)),
            ..Self::with_database(database)
        }
    }
}

/// File name of the default SQLite database in the data directory.
pub const SQLITE_FILE: &str = "chocmodal.sqlite";

impl ServiceConfig {
    /// The settings of `chocmodal serve`'s flags; fails when the auth file or the
    /// callback secrets file is unusable.
    pub fn from_args(args: &ServeArgs) -> Result<Self, ConfigError> {
        let auth = args.auth_file.as_deref().map(TokenTable::load).transpose()?;
        let secrets = args
            .callback_secrets
            .as_deref()
            .map(CallbackSecrets::load)
            .transpose()?
            .unwrap_or_default();
        Ok(Self {
            bind: args.bind,
            max_body_bytes: args.max_body_bytes,
            max_signal_bytes: args.max_signal_bytes,
            max_signal_samples: args.max_signal_samples.max(2),
            max_sweep_runs: args.max_sweep_runs,
            auth,
            metrics_public: args.metrics_public,
            cors_origins: args.cors_origins.clone(),
            insecure: args.insecure,
            limits: CostLimits {
                max_steps: crate::processes::cost::MAX_STEPS,
                max_work: args.max_work,
                max_history_values: args.max_history_values,
            },
            max_history_points: args.max_history_points.max(2),
            response_memory_bytes: usize::try_from(args.response_memory_mb)
                .unwrap_or(usize::MAX)
                .saturating_mul(1 << 20),
            max_queued_jobs: (args.max_queued_jobs > 0).then_some(args.max_queued_jobs),
            request_timeout: Duration::from_secs(args.request_timeout_seconds.max(1)),
            header_read_timeout: Duration::from_secs(args.header_timeout_seconds.max(1)),
            callbacks: CallbackSettings {
                policy: CallbackPolicy {
                    allow: AllowList::new(args.callback_allow.clone()),
                    secrets,
                },
                give_up_after: Duration::from_secs(args.callback_give_up_seconds),
                progress_interval: Duration::from_secs(args.callback_progress_seconds),
                ..CallbackSettings::default()
            },
            ..Self::from_queue_args(&args.queue)
        })
    }
}

/// Why `chocmodal serve`'s flags cannot be used (the service refuses to start).
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error(transparent)]
    Auth(#[from] AuthFileError),
    #[error(transparent)]
    CallbackSecrets(#[from] SecretsFileError),
}

impl From<&WorkerArgs> for ServiceConfig {
    fn from(args: &WorkerArgs) -> Self {
        Self {
            health_bind: args.health_bind,
            ..Self::from_queue_args(&args.queue)
        }
    }
}
