//! Assembling the service: database, queue, workers, maintenance and HTTP server.
//!
//! [`Application::build`] does everything that can fail (open and migrate the database,
//! recover jobs left behind by a previous run, bind the port) and returns the bound
//! address, so tests build it on port 0 and talk to it over real HTTP.

use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use tokio::net::TcpListener;
use tokio::sync::Notify;

use super::config::ServiceConfig;
use super::db;
use super::http::{self, AppState, HttpSettings};
use super::metrics::Metrics;
use super::queue::JobQueue;
use super::server;
use super::worker::{Maintenance, RunningJobs, WorkerContext, Workers};
use crate::processes::Registry;

/// Why the service could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartupError {
    #[error("cannot create the data directory {path}: {source}")]
    DataDir { path: String, source: std::io::Error },
    #[error("cannot open the database: {0}")]
    Database(#[from] sqlx::Error),
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

/// A built service, bound to its address, workers started, ready to serve.
#[derive(Debug)]
pub struct Application {
    address: SocketAddr,
    listener: TcpListener,
    router: axum::Router,
    queue: JobQueue,
    workers: Workers,
    maintenance: tokio::task::JoinHandle<()>,
    shutdown_grace: Duration,
    header_read_timeout: Duration,
}

impl Application {
    /// Opens the database under `config.data_dir`, recovers jobs whose worker was lost,
    /// binds `config.bind` and starts `config.workers` workers running `registry`'s processes.
    pub async fn build(config: ServiceConfig, registry: Registry) -> Result<Self, StartupError> {
        if config.auth.is_none() && !config.insecure && !config.bind.ip().is_loopback() {
            return Err(StartupError::Insecure { address: config.bind });
        }
        std::fs::create_dir_all(&config.data_dir).map_err(|source| StartupError::DataDir {
            path: config.data_dir.display().to_string(),
            source,
        })?;
        let pool = db::open(&config.database_path()).await?;
        let queue = JobQueue::new(pool, config.clock.clone());
        let metrics = Metrics::new();
        let wake = Arc::new(Notify::new());
        let running = RunningJobs::default();

        let maintenance = Maintenance {
            queue: queue.clone(),
            metrics: metrics.clone(),
            wake: wake.clone(),
            max_attempts: config.max_attempts,
            retention: config.retention,
        };
        // Jobs a previous run left `running` with an expired lease go back to the queue now.
        maintenance.run_once().await?;

        let listener = TcpListener::bind(config.bind)
            .await
            .map_err(|source| StartupError::Bind {
                address: config.bind,
                source,
            })?;
        let address = listener.local_addr().map_err(|source| StartupError::Bind {
            address: config.bind,
            source,
        })?;

        let context = Arc::new(WorkerContext {
            queue: queue.clone(),
            registry: registry.clone(),
            running: running.clone(),
            metrics: metrics.clone(),
            wake: wake.clone(),
            lease: config.lease,
            poll_interval: config.poll_interval,
            progress_interval: config.progress_interval,
            max_job_time: config.max_job_time,
        });
        let workers = Workers::start(context, config.workers);
        let maintenance = tokio::spawn(maintenance.run_every(config.maintenance_interval));

        let state = AppState {
            queue: queue.clone(),
            registry,
            running,
            metrics,
            wake,
            max_sweep_runs: config.max_sweep_runs,
            limits: config.limits,
            max_queued_jobs: config.max_queued_jobs,
            max_history_points: config.max_history_points,
        };
        let tenants = config.auth.as_ref().map_or(0, |table| table.len());
        let database = config.database_path();
        let router = http::router(
            state,
            &HttpSettings {
                max_body_bytes: config.max_body_bytes,
                request_timeout: config.request_timeout,
                auth: config.auth,
                metrics_public: config.metrics_public,
            },
        );
        if tenants == 0 {
            tracing::warn!("no auth file: every client is the one implicit tenant, unauthenticated");
        }
        tracing::info!(%address, workers = config.workers, tokens = tenants, database = %database.display(), "chocmodal is ready");
        Ok(Self {
            address,
            listener,
            router,
            queue,
            workers,
            maintenance,
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
        &self.queue
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
        tracing::info!("shutting down: no new jobs are claimed");
        self.workers.shutdown(self.shutdown_grace).await;
        self.maintenance.abort();
        self.queue.pool().close().await;
        tracing::info!("shut down");
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
