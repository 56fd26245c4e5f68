//! A real service on an ephemeral port with a fresh database (SQLite in a temporary
//! directory, or a new PostgreSQL database), and typed requests.

use std::sync::Arc;
use std::time::{Duration, Instant};

use chocmodal::processes::{Process, Registry};
use chocmodal::service::db::DatabaseUrl;
use chocmodal::service::queue::JobQueue;
use chocmodal::service::{Application, ServiceConfig, ShutdownHandle};
use reqwest::{Response, StatusCode};
use serde_json::{Value, json};
use tempfile::TempDir;
use tokio::sync::oneshot;
use tokio::task::JoinHandle;

use crate::counting::{self, CountSteps, Probe};

/// The queue's database backend a test runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    Sqlite,
    Postgres,
}

/// Defines each listed test, an `async fn(Backend)` of the calling module, once per
/// backend: `<module>::sqlite::<name>` and `<module>::postgres::<name>`.
macro_rules! on_both_backends {
    ($($test:ident),+ $(,)?) => {
        mod sqlite {
            $(
                #[tokio::test]
                async fn $test() {
                    super::$test($crate::helpers::Backend::Sqlite).await
                }
            )+
        }
        mod postgres {
            $(
                #[tokio::test]
                #[cfg_attr(
                    chocmodal_skip_postgres_tests,
                    ignore = "needs PostgreSQL: none found at build time, or CHOCMODAL_SKIP_POSTGRES_TESTS=1 (build.rs)"
                )]
                async fn $test() {
                    $crate::postgres::refuse_skip_under_ci(concat!(module_path!(), "::", stringify!($test)));
                    super::$test($crate::helpers::Backend::Postgres).await
                }
            )+
        }
    };
}
pub(crate) use on_both_backends;

/// Where a test service keeps its jobs: kept across a restart of the service.
#[derive(Debug)]
pub struct TestStore {
    pub database: DatabaseUrl,
    /// The SQLite file's directory (unused with PostgreSQL), deleted with the store;
    /// `None` when the test owns the directory ([`TestStore::sqlite_at`]).
    _dir: Option<TempDir>,
}

impl TestStore {
    /// A new empty database of `backend`.
    pub async fn new(backend: Backend) -> Self {
        let dir = TempDir::new().unwrap();
        let database = match backend {
            Backend::Sqlite => DatabaseUrl::Sqlite(dir.path().join("chocmodal.sqlite")),
            Backend::Postgres => DatabaseUrl::Postgres(crate::postgres::fresh_database().await),
        };
        Self {
            database,
            _dir: Some(dir),
        }
    }

    /// A SQLite database at `path`, in a directory the caller owns (a mounted file
    /// system).
    pub fn sqlite_at(path: std::path::PathBuf) -> Self {
        Self {
            database: DatabaseUrl::Sqlite(path),
            _dir: None,
        }
    }
}

/// A running test service.
pub struct TestApp {
    /// `http://127.0.0.1:<port>`
    pub address: String,
    pub client: reqwest::Client,
    pub probe: Arc<Probe>,
    pub queue: JobQueue,
    pub store: Option<TestStore>,
    /// Asks the service to stop as a signal does (the first drains, the second hands
    /// running jobs back at once).
    pub shutdown: ShutdownHandle,
    stop: Option<oneshot::Sender<()>>,
    served: Option<JoinHandle<std::io::Result<()>>>,
}

/// Test settings: 2 workers, quick polling and maintenance, on `store`'s database.
pub fn test_config(store: &TestStore) -> ServiceConfig {
    let mut config = ServiceConfig::with_database(store.database.clone());
    config.bind = "127.0.0.1:0".parse().unwrap();
    config.workers = 2;
    config.poll_interval = Duration::from_millis(50);
    config.progress_interval = Duration::from_millis(50);
    config.maintenance_interval = Duration::from_millis(100);
    config.shutdown_grace = Duration::from_secs(5);
    config
}

/// Logs when `TEST_LOG` is set (`TEST_LOG=1 cargo test --test api -- --nocapture`).
pub fn init_logs() {
    if std::env::var_os("TEST_LOG").is_some() {
        chocmodal::service::telemetry::init(chocmodal::service::config::LogFormat::Human);
    }
}

pub async fn spawn_app() -> TestApp {
    spawn_app_with(|_| {}).await
}

pub async fn spawn_app_with(configure: impl FnOnce(&mut ServiceConfig)) -> TestApp {
    spawn_app_on(Backend::Sqlite, configure).await
}

/// Starts a service on a fresh database of `backend`.
pub async fn spawn_app_on(backend: Backend, configure: impl FnOnce(&mut ServiceConfig)) -> TestApp {
    spawn_app_in(TestStore::new(backend).await, configure).await
}

/// Starts a service on `store` (a restart when it already holds jobs).
pub async fn spawn_app_in(store: TestStore, configure: impl FnOnce(&mut ServiceConfig)) -> TestApp {
    spawn_app_serving(store, Vec::new(), configure).await
}

/// Starts a service that also offers the `extra` processes (e.g. the real ones).
pub async fn spawn_app_with_processes(
    extra: Vec<Arc<dyn Process>>,
    configure: impl FnOnce(&mut ServiceConfig),
) -> TestApp {
    spawn_app_serving(TestStore::new(Backend::Sqlite).await, extra, configure).await
}

/// Starts a service on a fresh database of `backend` that also offers the shipped
/// processes (`cantilever-impact`, `bundle-dynamics`).
pub async fn spawn_app_with_shipped_processes_on(backend: Backend) -> TestApp {
    use chocmodal::processes::bundle_dynamics::BundleDynamics;
    use chocmodal::processes::cantilever_impact::CantileverImpact;
    spawn_app_serving(
        TestStore::new(backend).await,
        vec![Arc::new(CantileverImpact), Arc::new(BundleDynamics)],
        |_| {},
    )
    .await
}

/// Starts a service on a fresh database of `backend` that also offers the `extra`
/// processes, with `configure`'s settings.
pub async fn spawn_app_with_processes_on(
    backend: Backend,
    extra: Vec<Arc<dyn Process>>,
    configure: impl FnOnce(&mut ServiceConfig),
) -> TestApp {
    spawn_app_serving(TestStore::new(backend).await, extra, configure).await
}

/// Starts a service on `store` (a restart when it already holds jobs) that also offers
/// the `extra` processes.
pub async fn spawn_app_in_with_processes(
    store: TestStore,
    extra: Vec<Arc<dyn Process>>,
    configure: impl FnOnce(&mut ServiceConfig),
) -> TestApp {
    spawn_app_serving(store, extra, configure).await
}

async fn spawn_app_serving(
    store: TestStore,
    extra: Vec<Arc<dyn Process>>,
    configure: impl FnOnce(&mut ServiceConfig),
) -> TestApp {
    init_logs();
    let mut config = test_config(&store);
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
    let shutdown = application.shutdown_handle();
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
        store: Some(store),
        shutdown,
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

    /// GET with `If-None-Match: <etag>` (a conditional request).
    pub async fn get_if_none_match(&self, path: &str, etag: &str) -> Response {
        self.client
            .get(self.url(path))
            .header("if-none-match", etag)
            .send()
            .await
            .unwrap()
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

    /// Submits `body` to `process` (a 201) and waits up to two minutes for the job to
    /// succeed: its id.
    pub async fn succeed(&self, process: &str, body: &Value) -> String {
        let response = self.post_execution(process, body).await;
        let code = response.status();
        let created: Value = response.json().await.unwrap();
        assert_eq!(code, StatusCode::CREATED, "{created}");
        let id = created["jobID"].as_str().unwrap().to_owned();
        let status = self
            .wait_for(&id, &["successful", "failed"], Duration::from_secs(120))
            .await;
        assert_eq!(status["status"], "successful", "{status}");
        id
    }

    /// Submits `inputs` to `process`, which must refuse them with a 422: the pointers
    /// of its errors, sorted.
    pub async fn refused_pointers(&self, process: &str, inputs: &Value) -> Vec<String> {
        let response = self
            .post_execution(process, &serde_json::json!({"inputs": inputs}))
            .await;
        let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "/invalid-inputs").await;
        let mut pointers: Vec<String> = problem["errors"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["pointer"].as_str().unwrap().to_owned())
            .collect();
        pointers.sort();
        pointers
    }

    /// [`TestApp::succeed`], then the job's results document.
    pub async fn results_of(&self, process: &str, body: &Value) -> Value {
        let id = self.succeed(process, body).await;
        self.get_json(&format!("/jobs/{id}/results")).await
    }

    pub async fn wait_until_finished(&self, job_id: &str) -> Value {
        self.wait_for(
            job_id,
            &["successful", "failed", "dismissed"],
            Duration::from_secs(20),
        )
        .await
    }

    /// Stops the service gracefully and returns its database (to restart on it).
    pub async fn stop(mut self) -> TestStore {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(served) = self.served.take() {
            served.await.unwrap().unwrap();
        }
        self.store.take().expect("a running app has its store")
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
