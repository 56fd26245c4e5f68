//! Assembling the service in either role: the API ([`Application`]: HTTP, and workers
//! unless there are none) or workers alone ([`WorkerService`]: no API, an optional
//! health and metrics port). Both open the database, recover jobs whose worker was lost,
//! and run the queue maintenance periodically, so that lease recovery and retention
//! happen whichever processes are up (they are safe to run in several at once).
//!
//! `build` does everything that can fail (open and migrate the database, recover jobs
//! left behind by a previous run, bind the ports) and returns the bound address, so
//! tests build it on port 0 and talk to it over real HTTP.

use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use tokio::net::TcpListener;
use tokio::sync::Notify;
use tokio::task::JoinHandle;

use super::config::ServiceConfig;
use super::db::{self, Database};
use super::http::{self, AppState, HttpSettings};
use super::metrics::Metrics;
use super::queue::JobQueue;
use super::server;
use super::worker::{Maintenance, RunningJobs, WorkerContext, Workers};
use crate::processes::Registry;

/// Why the service could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartupError {
    #[error("cannot open the database {database}: {source}")]
    Database { database: String, source: sqlx::Error },
    #[error("cannot recover the jobs of lost workers: {0}")]
    Recovery(#[from] sqlx::Error),
    #[error("cannot listen on {address}: {source}")]
    Bind {
        address: SocketAddr,
        source: std::io::Error,
    },
    #[error(
        "refusing to listen on {address} without an auth file: anyone who can reach it could \
         run and read every job; give `--auth-file`, bind a loopback address, or pass `--insecure`"
    )]
    Insecure { address: SocketAddr },
}

/// What both roles run: the queue, its maintenance, the worker slots and their wake-ups.
#[derive(Debug)]
struct Engine {
    queue: JobQueue,
    metrics: Metrics,
    wake: Arc<Notify>,
    running: RunningJobs,
    maintenance: Maintenance,
    workers: Option<Workers>,
    background: Vec<JoinHandle<()>>,
}

impl Engine {
    /// Opens the database and recovers the jobs whose lease expired (a previous run of
    /// this or another process died).
    async fn open(config: &ServiceConfig) -> Result<Self, StartupError> {
        let database = Database::open_limited(
            &config.database,
            config.database_connections,
            config.max_database_bytes,
        )
        .await
        .map_err(|source| StartupError::Database {
            database: config.database.to_string(),
            source,
        })?;
        let queue = JobQueue::new(database, config.clock.clone());
        let metrics = Metrics::new();
        let wake = Arc::new(Notify::new());
        let maintenance = Maintenance {
            queue: queue.clone(),
            metrics: metrics.clone(),
            wake: wake.clone(),
            max_attempts: config.max_attempts,
            retention: config.retention,
        };
        maintenance.run_at_start().await?;
        Ok(Self {
            queue,
            metrics,
            wake,
            running: RunningJobs::default(),
            maintenance,
            workers: None,
            background: Vec::new(),
        })
    }

    /// Starts the worker slots, the periodic maintenance and, on PostgreSQL with
    /// workers, the listener that wakes them when another process queues jobs.
    fn start(&mut self, config: &ServiceConfig, registry: Registry) {
        let context = Arc::new(WorkerContext {
            queue: self.queue.clone(),
            registry,
            running: self.running.clone(),
            metrics: self.metrics.clone(),
            wake: self.wake.clone(),
            lease: config.lease,
            poll_interval: config.poll_interval,
            progress_interval: config.progress_interval,
            max_job_time: config.max_job_time,
        });
        self.workers = Some(Workers::start(context, config.workers));
        self.background.push(tokio::spawn(
            self.maintenance.clone().run_every(config.maintenance_interval),
        ));
        if let Some(pool) = self.queue.database().as_postgres()
            && config.workers > 0
        {
            self.background.push(tokio::spawn(db::postgres::wake_on_notify(
                pool.clone(),
                self.wake.clone(),
            )));
        }
    }

    fn state(&self, registry: Registry, config: &ServiceConfig) -> AppState {
        AppState {
            queue: self.queue.clone(),
            registry,
            running: self.running.clone(),
            metrics: self.metrics.clone(),
            wake: self.wake.clone(),
            max_sweep_runs: config.max_sweep_runs,
            limits: config.limits,
            max_queued_jobs: config.max_queued_jobs,
            max_history_points: config.max_history_points,
            signals: self.queue.signals(),
            max_signal_bytes: config.max_signal_bytes,
            max_signal_samples: config.max_signal_samples,
        }
    }

    /// Stops claiming, lets running jobs finish within `grace` (then hands them back),
    /// stops the background tasks and closes the database.
    async fn stop(self, grace: Duration) {
        tracing::info!("shutting down: no new jobs are claimed");
        if let Some(workers) = self.workers {
            workers.shutdown(grace).await;
        }
        for task in &self.background {
            task.abort();
        }
        self.queue.database().close().await;
        tracing::info!("shut down");
    }
}

async fn bind(address: SocketAddr) -> Result<(TcpListener, SocketAddr), StartupError> {
    let listener = TcpListener::bind(address)
        .await
        .map_err(|source| StartupError::Bind { address, source })?;
    let bound = listener
        .local_addr()
        .map_err(|source| StartupError::Bind { address, source })?;
    Ok((listener, bound))
}

/// The API role, bound to its address, workers started, ready to serve.
#[derive(Debug)]
pub struct Application {
    address: SocketAddr,
    listener: TcpListener,
    router: axum::Router,
    engine: Engine,
    shutdown_grace: Duration,
    header_read_timeout: Duration,
}

impl Application {
    /// Opens `config.database`, recovers jobs whose worker was lost, binds
    /// `config.bind` and starts `config.workers` workers running `registry`'s processes.
    pub async fn build(config: ServiceConfig, registry: Registry) -> Result<Self, StartupError> {
        if config.auth.is_none() && !config.insecure && !config.bind.ip().is_loopback() {
            return Err(StartupError::Insecure { address: config.bind });
        }
        let mut engine = Engine::open(&config).await?;
        let (listener, address) = bind(config.bind).await?;
        engine.start(&config, registry.clone());
        let tenants = config.auth.as_ref().map_or(0, |table| table.len());
        let router = http::router(
            engine.state(registry, &config),
            &HttpSettings {
                max_body_bytes: config.max_body_bytes,
                request_timeout: config.request_timeout,
                auth: config.auth.clone(),
                metrics_public: config.metrics_public,
                cors_origins: config.cors_origins.clone(),
            },
        );
        if tenants == 0 {
            tracing::warn!("no auth file: every client is the one implicit tenant, unauthenticated");
        }
        tracing::info!(%address, workers = config.workers, tokens = tenants, database = %config.database, "chocmodal is ready");
        Ok(Self {
            address,
            listener,
            router,
            engine,
            shutdown_grace: config.shutdown_grace,
            header_read_timeout: config.header_read_timeout,
        })
    }

    /// The bound address (its port is the real one when the configured port was 0).
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// The job queue (tests inspect and stage jobs through it).
    pub fn queue(&self) -> &JobQueue {
        &self.engine.queue
    }

    /// Serves until SIGTERM or ctrl-c, then shuts down gracefully.
    pub async fn run_until_stopped(self) -> std::io::Result<()> {
        self.run_until(shutdown_signal()).await
    }

    /// Serves until `stop` completes, then: stops accepting requests and finishes those
    /// in flight, stops claiming jobs, lets running jobs finish within the grace period,
    /// hands the rest back to the queue, closes the database.
    pub async fn run_until(self, stop: impl Future<Output = ()> + Send + 'static) -> std::io::Result<()> {
        let served = server::serve(self.listener, self.router, self.header_read_timeout, stop).await;
        self.engine.stop(self.shutdown_grace).await;
        served
    }
}

/// The worker role: worker slots and queue maintenance, no API; `/healthz` and
/// `/metrics` on `config.health_bind` when set (no tokens there: they serve no job data).
#[derive(Debug)]
pub struct WorkerService {
    health: Option<(SocketAddr, TcpListener, axum::Router)>,
    engine: Engine,
    workers: usize,
    shutdown_grace: Duration,
    header_read_timeout: Duration,
}

impl WorkerService {
    /// Opens `config.database`, recovers jobs whose worker was lost, binds the health
    /// port if any and starts `config.workers` workers running `registry`'s processes.
    pub async fn build(config: ServiceConfig, registry: Registry) -> Result<Self, StartupError> {
        let mut engine = Engine::open(&config).await?;
        let health = match config.health_bind {
            Some(address) => {
                let (listener, address) = bind(address).await?;
                let router = http::health_router(engine.state(registry.clone(), &config));
                Some((address, listener, router))
            }
            None => None,
        };
        engine.start(&config, registry);
        tracing::info!(
            workers = config.workers,
            health = %health.as_ref().map_or_else(|| "none".to_owned(), |(address, _, _)| address.to_string()),
            database = %config.database,
            "chocmodal worker is ready"
        );
        Ok(Self {
            health,
            engine,
            workers: config.workers,
            shutdown_grace: config.shutdown_grace,
            header_read_timeout: config.header_read_timeout,
        })
    }

    /// The bound health address, if any.
    pub fn health_address(&self) -> Option<SocketAddr> {
        self.health.as_ref().map(|(address, _, _)| *address)
    }

    /// The job queue.
    pub fn queue(&self) -> &JobQueue {
        &self.engine.queue
    }

    /// Number of worker slots.
    pub fn workers(&self) -> usize {
        self.workers
    }

    /// Works until SIGTERM or ctrl-c, then shuts down gracefully.
    pub async fn run_until_stopped(self) -> std::io::Result<()> {
        self.run_until(shutdown_signal()).await
    }

    /// Works until `stop` completes, then shuts down like [`Application::run_until`].
    pub async fn run_until(self, stop: impl Future<Output = ()> + Send + 'static) -> std::io::Result<()> {
        let served = match self.health {
            Some((_, listener, router)) => {
                server::serve(listener, router, self.header_read_timeout, stop).await
            }
            None => {
                stop.await;
                Ok(())
            }
        };
        self.engine.stop(self.shutdown_grace).await;
        served
    }
}

/// Completes on SIGTERM or ctrl-c.
pub async fn shutdown_signal() {
    let ctrl_c = async {
        if let Err(error) = tokio::signal::ctrl_c().await {
            tracing::error!(%error, "cannot listen for ctrl-c");
            std::future::pending::<()>().await;
        }
    };
    #[cfg(unix)]
    let terminate = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut signal) => {
                signal.recv().await;
            }
            Err(error) => {
                tracing::error!(%error, "cannot listen for SIGTERM");
                std::future::pending::<()>().await;
            }
        }
    };
    #[cfg(not(unix))]
    let terminate = std::future::pending::<()>();
    tokio::select! {
        _ = ctrl_c => tracing::info!("ctrl-c received"),
        _ = terminate => tracing::info!("SIGTERM received"),
    }
}
