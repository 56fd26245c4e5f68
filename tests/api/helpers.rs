//! A real service on an ephemeral port with a fresh data directory, and typed requests.

use std::sync::Arc;
use std::time::{Duration, Instant};

use chocmodal::processes::{Process, Registry};
use chocmodal::service::queue::JobQueue;
use chocmodal::service::{Application, ServiceConfig};
use reqwest::{Response, StatusCode};
use serde_json::{Value, json};
use tempfile::TempDir;
use tokio::sync::oneshot;
use tokio::task::JoinHandle;

use crate::counting::{self, CountSteps, Probe};

/// A running test service.
pub struct TestApp {
    /// `http://127.0.0.1:<port>`
    pub address: String,
    pub client: reqwest::Client,
    pub probe: Arc<Probe>,
    pub queue: JobQueue,
    pub data_dir: TempDir,
    stop: Option<oneshot::Sender<()>>,
    served: Option<JoinHandle<std::io::Result<()>>>,
}

/// Test settings: 2 workers, quick polling and maintenance, SQLite under a fresh tempdir.
pub fn test_config(data_dir: &TempDir) -> ServiceConfig {
    let mut config = ServiceConfig::new(data_dir.path());
    config.bind = "127.0.0.1:0".parse().unwrap();
    config.workers = 2;
    config.poll_interval = Duration::from_millis(50);
    config.progress_interval = Duration::from_millis(50);
    config.maintenance_interval = Duration::from_millis(100);
    config.shutdown_grace = Duration::from_secs(5);
    config
}

/// Logs when `TEST_LOG` is set (`TEST_LOG=1 cargo test --test api -- --nocapture`).
fn init_logs() {
    if std::env::var_os("TEST_LOG").is_some() {
        chocmodal::service::telemetry::init(chocmodal::service::config::LogFormat::Human);
    }
}

pub async fn spawn_app() -> TestApp {
    spawn_app_with(|_| {}).await
}

pub async fn spawn_app_with(configure: impl FnOnce(&mut ServiceConfig)) -> TestApp {
    spawn_app_in(TempDir::new().unwrap(), configure).await
}

/// Starts a service on `data_dir` (a restart when it already holds a database).
pub async fn spawn_app_in(data_dir: TempDir, configure: impl FnOnce(&mut ServiceConfig)) -> TestApp {
    spawn_app_serving(data_dir, Vec::new(), configure).await
}

/// Starts a service that also offers the `extra` processes (e.g. the real ones).
pub async fn spawn_app_with_processes(
    extra: Vec<Arc<dyn Process>>,
    configure: impl FnOnce(&mut ServiceConfig),
) -> TestApp {
    spawn_app_serving(TempDir::new().unwrap(), extra, configure).await
}

async fn spawn_app_serving(
    data_dir: TempDir,
    extra: Vec<Arc<dyn Process>>,
    configure: impl FnOnce(&mut ServiceConfig),
) -> TestApp {
    init_logs();
    let mut config = test_config(&data_dir);
    configure(&mut config);
    let probe = Arc::new(Probe::default());
    let mut processes: Vec<Arc<dyn Process>> = vec![Arc::new(CountSteps { probe: probe.clone() })];
    processes.extend(extra);
    let registry = Registry::new(processes);
    let application = Application::build(config, registry)
        .await
        .expect("the service starts");
    let address = format!("http://{}", application.address());
    let queue = application.queue().clone();
    let (stop, stopped) = oneshot::channel::<()>();
    let served = tokio::spawn(application.run_until(async {
        let _ = stopped.await;
    }));
    TestApp {
        address,
        client: reqwest::Client::builder()
            .redirect(reqwest::redirect::Policy::none())
            .build()
            .unwrap(),
        probe,
        queue,
        data_dir,
        stop: Some(stop),
        served: Some(served),
    }
}

impl TestApp {
    pub fn url(&self, path: &str) -> String {
        format!("{}{path}", self.address)
    }

    pub async fn get(&self, path: &str) -> Response {
        self.client.get(self.url(path)).send().await.unwrap()
    }

    pub async fn get_json(&self, path: &str) -> Value {
        let response = self.get(path).await;
        assert_eq!(response.status(), StatusCode::OK, "GET {path}");
        response.json().await.unwrap()
    }

    pub async fn delete(&self, path: &str) -> Response {
        self.client.delete(self.url(path)).send().await.unwrap()
    }

    /// POSTs `body` (any bytes) as JSON to the process's execution endpoint.
    pub async fn post_execution_raw(&self, process: &str, body: impl Into<reqwest::Body>) -> Response {
        self.client
            .post(self.url(&format!("/processes/{process}/execution")))
            .header("content-type", "application/json")
            .body(body)
            .send()
            .await
            .unwrap()
    }

    pub async fn post_execution(&self, process: &str, body: &Value) -> Response {
        self.post_execution_raw(process, body.to_string()).await
    }

    /// Submits `count-steps` with these inputs; returns the job id.
    pub async fn submit(&self, inputs: Value) -> String {
        let response = self
            .post_execution(counting::ID, &json!({ "inputs": inputs }))
            .await;
        assert_eq!(response.status(), StatusCode::CREATED);
        let status: Value = response.json().await.unwrap();
        status["jobID"].as_str().unwrap().to_owned()
    }

    pub async fn status(&self, job_id: &str) -> Value {
        self.get_json(&format!("/jobs/{job_id}")).await
    }

    /// Polls the job until its status is one of `wanted`, for at most `within`.
    pub async fn wait_for(&self, job_id: &str, wanted: &[&str], within: Duration) -> Value {
        let deadline = Instant::now() + within;
        loop {
            let status = self.status(job_id).await;
            if wanted.contains(&status["status"].as_str().unwrap_or_default()) {
                return status;
            }
            assert!(
                Instant::now() < deadline,
                "job {job_id} did not reach {wanted:?} within {within:?}: {status}"
            );
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }

    pub async fn wait_until_finished(&self, job_id: &str) -> Value {
        self.wait_for(
            job_id,
            &["successful", "failed", "dismissed"],
            Duration::from_secs(20),
        )
        .await
    }

    /// Stops the service gracefully and returns its data directory (to restart on it).
    pub async fn stop(mut self) -> TempDir {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(served) = self.served.take() {
            served.await.unwrap().unwrap();
        }
        std::mem::replace(&mut self.data_dir, TempDir::new().unwrap())
    }
}

/// Asserts a problem document with this status and type suffix; returns it.
pub async fn assert_problem(response: Response, status: StatusCode, type_suffix: &str) -> Value {
    assert_eq!(response.status(), status);
    let content_type = response
        .headers()
        .get("content-type")
        .and_then(|v| v.to_str().ok())
        .unwrap_or_default()
        .to_owned();
    assert_eq!(content_type, "application/problem+json");
    let problem: Value = response.json().await.unwrap();
    assert_eq!(problem["status"], status.as_u16(), "{problem}");
    assert!(
        problem["type"]
            .as_str()
            .unwrap_or_default()
            .ends_with(type_suffix),
        "expected a problem of type …{type_suffix}, got {problem}"
    );
    assert!(
        problem["title"].is_string() && problem["detail"].is_string(),
        "{problem}"
    );
    problem
}
