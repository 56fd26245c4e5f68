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
use std::pin::Pin;
use std::sync::Arc;
use std::time::Duration;

use tokio::net::TcpListener;
use tokio::sync::{Notify, oneshot};
use tokio::task::JoinHandle;
use tokio::time::Instant;

use super::callbacks::Deliverer;
use super::config::ServiceConfig;
use super::db::{self, Database};
use super::http::streamed::ResponseMemory;
use super::http::{self, AppState, HttpSettings};
use super::metrics::Metrics;
use super::queue::JobQueue;
use super::server;
use super::shutdown::{Phase, ShutdownHandle, forward_signals};
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
    #[error(transparent)]
    Callbacks(#[from] super::callbacks::deliverer::ClientError),
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
    /// Shared by every router of the process (API and health port alike).
    response_memory: ResponseMemory,
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
            response_memory: ResponseMemory::new(config.response_memory_bytes),
        })
    }

    /// Starts the worker slots, the periodic maintenance and, on PostgreSQL with
    /// workers, the listener that wakes them when another process queues jobs.
    fn start(&mut self, config: &ServiceConfig, registry: Registry, shutdown: &ShutdownHandle) {
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
        self.workers = Some(Workers::start(context, config.workers, shutdown.clone()));
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

    fn state(&self, registry: Registry, config: &ServiceConfig, shutdown: &ShutdownHandle) -> AppState {
        AppState {
            shutdown: shutdown.clone(),
            queue: self.queue.clone(),
            registry,
            running: self.running.clone(),
            metrics: self.metrics.clone(),
            wake: self.wake.clone(),
            max_sweep_runs: config.max_sweep_runs,
            limits: config.limits,
            max_queued_jobs: config.max_queued_jobs,
            max_history_points: config.max_history_points,
            response_memory: self.response_memory.clone(),
            signals: self.queue.signals(),
            max_signal_bytes: config.max_signal_bytes,
            max_signal_samples: config.max_signal_samples,
            callbacks: Arc::new(config.callbacks.policy.clone()),
        }
    }

    /// Stops claiming, lets running jobs finish within `grace` or until `hurry`
    /// completes (then hands them back), and stops the background tasks.
    async fn stop_work(&mut self, grace: Duration, hurry: impl Future<Output = ()>) {
        tracing::info!("shutting down: no new jobs are claimed");
        if let Some(workers) = self.workers.take() {
            workers.shutdown(grace, hurry).await;
        }
        for task in &self.background {
            task.abort();
        }
    }

    async fn close(self) {
        self.queue.database().close().await;
        tracing::info!("shut down");
    }

    /// The whole shutdown once `shutdown` asks for it: the workers drain (within
    /// `grace`, or until a second request) while `server` keeps serving; then the server
    /// stops (its requests in flight get what is left of the grace period) and the
    /// database closes.
    async fn shut_down_when_asked(
        mut self,
        shutdown: &ShutdownHandle,
        grace: Duration,
        server: impl FnOnce(
            Pin<Box<dyn Future<Output = ()> + Send>>,
            Pin<Box<dyn Future<Output = ()> + Send>>,
        ) -> JoinHandle<std::io::Result<()>>,
    ) -> std::io::Result<()> {
        let (workers_done, stop_serving) = oneshot::channel::<()>();
        let (deadline_tx, deadline_rx) = oneshot::channel::<Instant>();
        let hurry = shutdown.reached(Phase::Immediate);
        let give_up = async move {
            let deadline = deadline_rx.await.unwrap_or_else(|_| Instant::now());
            tokio::select! {
                () = tokio::time::sleep_until(deadline.max(Instant::now() + MIN_REQUEST_DRAIN)) => {}
                () = hurry => {}
            }
        };
        let served = server(
            Box::pin(async move {
                let _ = stop_serving.await;
            }),
            Box::pin(give_up),
        );
        shutdown.reached(Phase::Draining).await;
        let _ = deadline_tx.send(Instant::now() + grace);
        self.stop_work(grace, shutdown.reached(Phase::Immediate)).await;
        let _ = workers_done.send(());
        let served = served
            .await
            .unwrap_or_else(|error| Err(std::io::Error::other(error)));
        self.close().await;
        served
    }
}

/// Requests in flight when the server stops get at least this long, even when the
/// workers used up the grace period.
const MIN_REQUEST_DRAIN: Duration = Duration::from_secs(1);

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
    shutdown: ShutdownHandle,
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
        let shutdown = ShutdownHandle::default();
        engine.start(&config, registry.clone(), &shutdown);
        // Callbacks go out from the API processes, whose flags hold the policy.
        let deliverer = Deliverer::new(
            engine.queue.clone(),
            engine.metrics.clone(),
            config.callbacks.clone(),
        )?;
        engine.background.push(tokio::spawn(deliverer.run()));
        let tenants = config.auth.as_ref().map_or(0, |table| table.len());
        let router = http::router(
            engine.state(registry, &config, &shutdown),
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
            shutdown,
        })
    }

    /// Asks this service to stop, as SIGTERM does (a second request, as a second
    /// signal does): see [`super::shutdown`].
    pub fn shutdown_handle(&self) -> ShutdownHandle {
        self.shutdown.clone()
    }

    /// The bound address (its port is the real one when the configured port was 0).
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// The job queue (tests inspect and stage jobs through it).
    pub fn queue(&self) -> &JobQueue {
        &self.engine.queue
    }

    /// Serves until SIGTERM or ctrl-c, then shuts down gracefully; a second signal
    /// hands the running jobs back at once.
    pub async fn run_until_stopped(self) -> std::io::Result<()> {
        let signals = tokio::spawn(forward_signals(self.shutdown.clone()));
        let served = self.run().await;
        signals.abort();
        served
    }

    /// Serves until `stop` completes, then shuts down as on a first SIGTERM (a second
    /// request through [`Self::shutdown_handle`] hurries it).
    pub async fn run_until(self, stop: impl Future<Output = ()> + Send + 'static) -> std::io::Result<()> {
        let shutdown = self.shutdown.clone();
        let trigger = tokio::spawn(async move {
            stop.await;
            shutdown.request();
        });
        let served = self.run().await;
        trigger.abort();
        served
    }

    /// Serves until the shutdown handle is asked to stop, then: stops claiming jobs at
    /// once and lets running jobs finish within the grace period (handing the rest back
    /// to the queue) while the API keeps answering reads (writes get 503); then stops
    /// accepting connections, finishes the requests in flight and closes the database.
    pub async fn run(self) -> std::io::Result<()> {
        let Self {
            listener,
            router,
            engine,
            shutdown_grace,
            header_read_timeout,
            shutdown,
            ..
        } = self;
        engine
            .shut_down_when_asked(&shutdown, shutdown_grace, move |stop, give_up| {
                tokio::spawn(server::serve(
                    listener,
                    router,
                    header_read_timeout,
                    stop,
                    give_up,
                ))
            })
            .await
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
    shutdown: ShutdownHandle,
}

impl WorkerService {
    /// Opens `config.database`, recovers jobs whose worker was lost, binds the health
    /// port if any and starts `config.workers` workers running `registry`'s processes.
    pub async fn build(config: ServiceConfig, registry: Registry) -> Result<Self, StartupError> {
        let mut engine = Engine::open(&config).await?;
        let shutdown = ShutdownHandle::default();
        let health = match config.health_bind {
            Some(address) => {
                let (listener, address) = bind(address).await?;
                let router = http::health_router(engine.state(registry.clone(), &config, &shutdown));
                Some((address, listener, router))
            }
            None => None,
        };
        engine.start(&config, registry, &shutdown);
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
            shutdown,
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

    /// Asks this service to stop, as SIGTERM does.
    pub fn shutdown_handle(&self) -> ShutdownHandle {
        self.shutdown.clone()
    }

    /// Works until SIGTERM or ctrl-c, then shuts down gracefully; a second signal
    /// hands the running jobs back at once.
    pub async fn run_until_stopped(self) -> std::io::Result<()> {
        let signals = tokio::spawn(forward_signals(self.shutdown.clone()));
        let served = self.run().await;
        signals.abort();
        served
    }

    /// Works until `stop` completes, then shuts down like [`Application::run_until`].
    pub async fn run_until(self, stop: impl Future<Output = ()> + Send + 'static) -> std::io::Result<()> {
        let shutdown = self.shutdown.clone();
        let trigger = tokio::spawn(async move {
            stop.await;
            shutdown.request();
        });
        let served = self.run().await;
        trigger.abort();
        served
    }

    /// Works until the shutdown handle is asked to stop, then shuts down like
    /// [`Application::run`] (the health port answers until the workers are done).
    pub async fn run(self) -> std::io::Result<()> {
        let Self {
            health,
            engine,
            shutdown_grace,
            header_read_timeout,
            shutdown,
            ..
        } = self;
        engine
            .shut_down_when_asked(&shutdown, shutdown_grace, move |stop, give_up| match health {
                Some((_, listener, router)) => tokio::spawn(server::serve(
                    listener,
                    router,
                    header_read_timeout,
                    stop,
                    give_up,
                )),
                None => tokio::spawn(async move {
                    stop.await;
                    Ok(())
                }),
            })
            .await
    }
}
