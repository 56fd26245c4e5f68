//! The service behind `chocmodal serve`: OGC API – Processes over HTTP, a durable job
//! queue in SQLite, and workers that run the processes on their own threads.
//!
//! Data flows one way: [`http`] validates an execution request with the process and
//! [`queue`]s a job; a [`worker`] claims it, runs the process, and stores the results
//! document and the compressed histories ([`store`]); [`http`] serves them, thinned on
//! request ([`thinning`]).

pub mod auth;
pub mod clock;
pub mod config;
pub mod db;
pub mod http;
pub mod metrics;
pub mod queue;
mod server;
mod startup;
pub mod store;
pub mod telemetry;
pub mod thinning;
pub mod worker;

pub use config::{ServeArgs, ServiceConfig};
pub use startup::{Application, StartupError, shutdown_signal};

/// `chocmodal serve`: logs, builds the service and serves until SIGTERM or ctrl-c.
pub fn serve(args: &ServeArgs, registry: crate::processes::Registry) -> std::process::ExitCode {
    telemetry::init(args.log_format);
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(runtime) => runtime,
        Err(error) => {
            eprintln!("chocmodal: cannot start the async runtime: {error}");
            return std::process::ExitCode::FAILURE;
        }
    };
    runtime.block_on(async {
        let config = match ServiceConfig::from_args(args) {
            Ok(config) => config,
            Err(error) => {
                tracing::error!(%error, "cannot start");
                return std::process::ExitCode::FAILURE;
            }
        };
        let application = match Application::build(config, registry).await {
            Ok(application) => application,
            Err(error) => {
                tracing::error!(%error, "cannot start");
                return std::process::ExitCode::FAILURE;
            }
        };
        match application.run_until_stopped().await {
            Ok(()) => std::process::ExitCode::SUCCESS,
            Err(error) => {
                tracing::error!(%error, "server error");
                std::process::ExitCode::FAILURE
            }
        }
    })
}
