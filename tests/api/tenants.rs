//! Bearer tokens and tenants: 401 without a valid token, `/healthz` open, `/metrics`
//! open only when public, and each tenant's jobs and sweeps invisible to the others
//! (404 for get, results, histories, dismissal; absent from lists).

use std::time::Duration;

use chocmodal::service::auth::TokenTable;
use reqwest::{RequestBuilder, Response, StatusCode};
use serde_json::{Value, json};

use crate::counting;
use crate::helpers::{
    Backend, TestApp, TestStore, assert_problem, on_both_backends, spawn_app_in, spawn_app_on, spawn_app_with,
};

on_both_backends!(
    another_tenants_job_is_not_found_anywhere,
    identical_inputs_of_another_tenant_are_computed_not_reused,
    another_tenants_sweep_is_not_found_and_its_runs_are_not_listed,
    one_tenants_300_queued_jobs_do_not_delay_another_tenants_single_job,
    a_worker_freed_by_a_tenants_run_serves_the_tenant_that_waited
);

const ALPHA: &str = "alpha-token-0123456789";
const BETA: &str = "beta-token-9876543210";

fn tokens() -> TokenTable {
    TokenTable::parse(&format!("# test tenants\nalpha {ALPHA}\nbeta {BETA}\n")).unwrap()
}

async fn spawn_with_tenants(backend: Backend) -> TestApp {
    spawn_app_on(backend, |config| config.auth = Some(tokens())).await
}

/// Requests made with one tenant's token.
struct As<'a> {
    app: &'a TestApp,
    token: &'a str,
}

impl<'a> As<'a> {
    fn alpha(app: &'a TestApp) -> Self {
        Self { app, token: ALPHA }
    }

    fn beta(app: &'a TestApp) -> Self {
        Self { app, token: BETA }
    }

    async fn send(&self, request: RequestBuilder) -> Response {
        request.bearer_auth(self.token).send().await.unwrap()
    }

    async fn get(&self, path: &str) -> Response {
        self.send(self.app.client.get(self.app.url(path))).await
    }

    async fn get_json(&self, path: &str) -> Value {
        let response = self.get(path).await;
        assert_eq!(response.status(), StatusCode::OK, "GET {path}");
        response.json().await.unwrap()
    }

    async fn delete(&self, path: &str) -> Response {
        self.send(self.app.client.delete(self.app.url(path))).await
    }

    async fn post(&self, path: &str, body: &Value) -> Response {
        let request = self
            .app
            .client
            .post(self.app.url(path))
            .header("content-type", "application/json")
            .body(body.to_string());
        self.send(request).await
    }

    /// GET of `resource` followed by each of `views` (path suffixes), and its DELETE,
    /// are all 404 problems of type `…kind`.
    async fn assert_not_found(&self, resource: &str, views: &[&str], kind: &str) {
        for view in views {
            let path = format!("{resource}{view}");
            assert_problem(self.get(&path).await, StatusCode::NOT_FOUND, kind).await;
        }
        assert_problem(self.delete(resource).await, StatusCode::NOT_FOUND, kind).await;
    }

    /// Submits `count-steps`; returns the job id.
    async fn submit(&self, inputs: Value) -> String {
        let response = self
            .post(
                &format!("/processes/{}/execution", counting::ID),
                &json!({ "inputs": inputs }),
            )
            .await;
        assert_eq!(response.status(), StatusCode::CREATED);
        let status: Value = response.json().await.unwrap();
        status["jobID"].as_str().unwrap().to_owned()
    }

    async fn wait_until_finished(&self, job: &str) -> Value {
        for _ in 0..1000 {
            let status = self.get_json(&format!("/jobs/{job}")).await;
            if ["successful", "failed", "dismissed"].contains(&status["status"].as_str().unwrap()) {
                return status;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        panic!("job {job} did not finish");
    }
}

#[tokio::test]
async fn without_a_token_every_route_but_the_health_check_is_a_401_problem() {
    let app = spawn_with_tenants(Backend::Sqlite).await;
    for path in [
        "/",
        "/processes",
        "/jobs",
        "/sweeps",
        "/openapi.json",
        "/metrics",
        "/jobs/nope",
    ] {
        let response = app.get(path).await;
        let challenge = response.headers()["www-authenticate"]
            .to_str()
            .unwrap()
            .to_owned();
        assert!(challenge.starts_with("Bearer"), "{path}: {challenge}");
        assert_problem(response, StatusCode::UNAUTHORIZED, "/unauthorized").await;
    }
    // Before anything reads the body: no 413, 415 or 422 for an unauthenticated client.
    let response = app.post_execution_raw(counting::ID, "not even json").await;
    assert_problem(response, StatusCode::UNAUTHORIZED, "/unauthorized").await;
    assert_eq!(
        app.get_json("/healthz").await,
        json!({"status": "ok", "writable": true})
    );
    assert_eq!(app.get_json("/readyz").await, json!({"status": "ready"}));
}

#[tokio::test]
async fn a_wrong_token_is_a_401_with_an_invalid_token_challenge() {
    let app = spawn_with_tenants(Backend::Sqlite).await;
    for header in [
        "Bearer alpha-token-012345678".to_owned(),
        format!("Bearer {ALPHA}x"),
        format!("Basic {ALPHA}"),
        ALPHA.to_owned(),
    ] {
        let response = app
            .client
            .get(app.url("/jobs"))
            .header("authorization", &header)
            .send()
            .await
            .unwrap();
        let status = response.status();
        let challenge = response.headers()["www-authenticate"]
            .to_str()
            .unwrap()
            .to_owned();
        assert_eq!(status, StatusCode::UNAUTHORIZED, "{header}");
        assert!(challenge.contains("invalid_token"), "{header}: {challenge}");
    }
    let alpha = As::alpha(&app);
    assert_eq!(alpha.get("/jobs").await.status(), StatusCode::OK);
}

#[tokio::test]
async fn metrics_need_a_token_unless_public() {
    let app = spawn_with_tenants(Backend::Sqlite).await;
    assert_eq!(app.get("/metrics").await.status(), StatusCode::UNAUTHORIZED);
    let alpha = As::alpha(&app);
    assert_eq!(alpha.get("/metrics").await.status(), StatusCode::OK);

    let public = spawn_app_with(|config| {
        config.auth = Some(tokens());
        config.metrics_public = true;
    })
    .await;
    assert_eq!(public.get("/metrics").await.status(), StatusCode::OK);
    assert_eq!(public.get("/jobs").await.status(), StatusCode::UNAUTHORIZED);
}

async fn another_tenants_job_is_not_found_anywhere(backend: Backend) {
    let app = spawn_with_tenants(backend).await;
    let (alpha, beta) = (As::alpha(&app), As::beta(&app));
    let job = alpha.submit(json!({"steps": 5})).await;
    assert_eq!(alpha.wait_until_finished(&job).await["status"], "successful");

    let views = [
        "",
        "/results",
        "/results/signal",
        "/results/signal?format=csv",
        "/results/signal/spectrum",
        "/inputs",
    ];
    beta.assert_not_found(&format!("/jobs/{job}"), &views, "/no-such-job")
        .await;
    assert_eq!(beta.get_json("/jobs").await["jobs"], json!([]));
    assert_eq!(
        beta.get_json("/jobs?status=successful&processID=count-steps")
            .await["jobs"],
        json!([])
    );

    // Beta's attempts changed nothing for alpha.
    let listed = alpha.get_json("/jobs").await;
    assert_eq!(listed["jobs"][0]["jobID"], job.as_str());
    assert_eq!(
        alpha.get_json(&format!("/jobs/{job}")).await["status"],
        "successful"
    );
    assert_eq!(alpha.get_json(&format!("/jobs/{job}/results")).await["sum"], 15);
    assert_eq!(
        alpha.get_json(&format!("/jobs/{job}/inputs")).await["inputs"]["steps"],
        5
    );
    let spectrum = alpha.get(&format!("/jobs/{job}/results/signal/spectrum")).await;
    assert_eq!(spectrum.status(), StatusCode::OK);
}

async fn identical_inputs_of_another_tenant_are_computed_not_reused(backend: Backend) {
    let app = spawn_with_tenants(backend).await;
    let (alpha, beta) = (As::alpha(&app), As::beta(&app));
    let first = alpha.submit(json!({"steps": 7})).await;
    alpha.wait_until_finished(&first).await;
    let second = beta.submit(json!({"steps": 7})).await;
    let status = beta.wait_until_finished(&second).await;
    assert_eq!(status["status"], "successful");
    assert!(
        !status["message"].as_str().unwrap().contains(&first),
        "beta learnt of alpha's job: {status}"
    );
    assert_eq!(app.probe.started(), 2, "both runs computed");
    // The same tenant does reuse.
    let third = alpha.submit(json!({"steps": 7})).await;
    let status = alpha.wait_until_finished(&third).await;
    assert!(status["message"].as_str().unwrap().contains(&first), "{status}");
}

async fn another_tenants_sweep_is_not_found_and_its_runs_are_not_listed(backend: Backend) {
    let app = spawn_with_tenants(backend).await;
    let (alpha, beta) = (As::alpha(&app), As::beta(&app));
    let response = alpha
        .post(
            "/sweeps",
            &json!({"process": counting::ID, "inputs": {"steps": 3},
                    "axes": [{"pointer": "/steps", "values": [3, 4]}]}),
        )
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let sweep: Value = response.json().await.unwrap();
    let id = sweep["sweepID"].as_str().unwrap().to_owned();

    let views = ["", "/results", "/results?format=csv"];
    beta.assert_not_found(&format!("/sweeps/{id}"), &views, "/no-such-sweep")
        .await;
    assert_eq!(beta.get_json("/sweeps").await["sweeps"], json!([]));
    assert_eq!(
        beta.get_json(&format!("/jobs?sweepID={id}")).await["jobs"],
        json!([])
    );

    assert_eq!(
        alpha.get_json("/sweeps").await["sweeps"][0]["sweepID"],
        id.as_str()
    );
    let runs = alpha.get_json(&format!("/jobs?sweepID={id}")).await;
    assert_eq!(runs["jobs"].as_array().unwrap().len(), 2);
    let status = alpha.get_json(&format!("/sweeps/{id}")).await;
    assert_ne!(status["status"], "dismissed", "{status}");
}

/// Fair share: alpha queues 300 jobs, then beta one; once workers start, beta's job is
/// claimed as soon as a worker is free of alpha's first runs (it has no running job,
/// alpha has), not after alpha's 300.
async fn one_tenants_300_queued_jobs_do_not_delay_another_tenants_single_job(backend: Backend) {
    let with_tenants = |workers: usize| {
        move |config: &mut chocmodal::service::ServiceConfig| {
            config.auth = Some(tokens());
            config.workers = workers;
            config.max_queued_jobs = None;
        }
    };
    // Queued with no worker running, so that all 300 are waiting when beta's arrives.
    let queuing = spawn_app_in(TestStore::new(backend).await, with_tenants(0)).await;
    const ALPHA_JOBS: u64 = 300;
    const BETA_STEPS: u64 = 7;
    for k in 0..ALPHA_JOBS {
        // Distinct inputs: identical ones would reuse results instead of running. Each
        // runs for a fifth of a second, so that alpha has a run going whenever a worker
        // claims (instant runs would leave both tenants idle at a claim, and the oldest
        // job, alpha's, would rightly go first).
        As::alpha(&queuing)
            .submit(json!({"steps": 200 + k, "step_ms": 1}))
            .await;
    }
    let beta_job = As::beta(&queuing).submit(json!({"steps": BETA_STEPS})).await;
    let store = queuing.stop().await;

    let workers = 2;
    let app = spawn_app_in(store, with_tenants(workers)).await;
    let status = As::beta(&app).wait_until_finished(&beta_job).await;
    assert_eq!(status["status"], "successful", "{status}");
    let runs = app.probe.runs.lock().unwrap().clone();
    let position = runs
        .iter()
        .position(|&steps| steps == BETA_STEPS)
        .expect("beta's job ran");
    // Concurrent claims may both take alpha's first jobs; the next free worker takes beta's.
    assert!(
        position < 2 * workers,
        "beta's job started as run #{} of {} started so far; expected within the first {}: {runs:?}",
        position + 1,
        runs.len(),
        2 * workers
    );
}

/// Ties between tenants with no running job go to the one served least recently: alpha's
/// run ends (alpha and beta both have nothing running, and alpha's next queued job is
/// older than beta's), and the next claim serves beta. This is the moment two workers
/// freed at once by alpha's runs meet; by queue age alone both would serve alpha again.
async fn a_worker_freed_by_a_tenants_run_serves_the_tenant_that_waited(backend: Backend) {
    let app = spawn_app_in(
        TestStore::new(backend).await,
        |config: &mut chocmodal::service::ServiceConfig| {
            config.auth = Some(tokens());
            config.workers = 0;
        },
    )
    .await;
    for k in 0..3 {
        As::alpha(&app).submit(json!({"steps": 100 + k})).await;
    }
    let beta_job = As::beta(&app).submit(json!({"steps": 7})).await;
    let lease = Duration::from_secs(30);
    // Nobody served yet: the oldest queued job, alpha's first.
    let first = app.queue.claim("w1", lease).await.unwrap().unwrap();
    assert_eq!(first.tenant, "alpha");
    let problem = chocmodal::problem::Problem::job_failed("ended");
    assert!(app.queue.fail(&first.lease, &problem, None).await.unwrap());
    let next = app.queue.claim("w2", lease).await.unwrap().unwrap();
    assert_eq!(next.lease.job_id, beta_job, "beta waited; alpha was just served");
    // Then alpha again: beta has a job running, alpha none.
    let third = app.queue.claim("w3", lease).await.unwrap().unwrap();
    assert_eq!(third.tenant, "alpha");
}
