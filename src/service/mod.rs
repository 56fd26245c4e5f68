//! The service behind `chocmodal serve` and `chocmodal worker`: OGC API – Processes
//! over HTTP, a durable job queue in SQLite or PostgreSQL ([`db`]), and workers that run
//! the processes on their own threads, in the API process or in worker processes.
//!
//! Data flows one way: [`http`] validates an execution request with the process and
//! [`queue`]s a job; a [`worker`] claims it, runs the process, and stores the results
//! document and the compressed histories ([`store`]); [`http`] serves them, thinned on
//! request ([`thinning`]), and their spectra ([`spectrum_table`]).

pub mod auth;
pub mod callbacks;
pub mod clock;
pub mod config;
pub mod db;
pub mod http;
pub mod metrics;
pub mod queue;
mod server;
pub mod shutdown;
pub mod signals;
pub mod spectrum_table;
mod startup;
pub mod storage_health;
pub mod store;
pub mod telemetry;
pub mod thinning;
pub mod worker;

pub use config::{ServeArgs, ServiceConfig, WorkerArgs};
pub use shutdown::ShutdownHandle;
pub use startup::{Application, StartupError, WorkerService};

/// `chocmodal serve`: logs, builds the service and serves until SIGTERM or ctrl-c.
pub fn serve(args: &ServeArgs, registry: crate::processes::Registry) -> std::process::ExitCode {
    telemetry::init(args.queue.log_format);
    block_on(async {
        let config = ServiceConfig::from_args(args)?;
        let application = Application::build(config, registry).await?;
        Ok(application.run_until_stopped().await?)
    })
}

/// `chocmodal worker`: logs, starts the workers and works until SIGTERM or ctrl-c.
pub fn worker(args: &WorkerArgs, registry: crate::processes::Registry) -> std::process::ExitCode {
    telemetry::init(args.queue.log_format);
    block_on(async {
        let service = WorkerService::build(ServiceConfig::from(args), registry).await?;
        Ok(service.run_until_stopped().await?)
    })
}

/// Runs a role on a new runtime; any error is logged and fails the process.
fn block_on(
    role: impl std::future::Future<Output = Result<(), Box<dyn std::error::Error>>>,
) -> std::process::ExitCode {
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(runtime) => runtime,
        Err(error) => {
            eprintln!("chocmodal: cannot start the async runtime: {error}");
            return std::process::ExitCode::FAILURE;
        }
    };
    match runtime.block_on(role) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            tracing::error!(%error, "stopped on an error");
            std::process::ExitCode::FAILURE
        }
    }
}
