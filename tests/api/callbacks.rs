//! Job callbacks (the OGC `subscriber` of an execution request), through a real
//! receiver: a small HTTP server on the loopback that records every POST it gets and
//! answers with the status codes a test scripts. Each test checks what a workflow tool
//! relies on: the outcome arrives (signed, with the job's status document) soon after the
//! job ends, is retried with growing waits when the receiver fails, survives a restart
//! of the service, and only goes to hosts the operator allowed.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use axum::body::Bytes;
use axum::http::{HeaderMap, StatusCode as AxumStatus, Uri};
use chocmodal::service::ServiceConfig;
use chocmodal::service::callbacks::AllowList;
use chocmodal::service::callbacks::outbox::Outbox;
use chocmodal::service::callbacks::signature::hmac_sha256;
use reqwest::StatusCode;
use serde_json::{Value, json};
use tokio::sync::Notify;

use crate::counting;
use crate::helpers::{Backend, TestApp, assert_problem, on_both_backends, spawn_app_in, spawn_app_on};

const SECRET: &str = "callback-secret-of-default-0123";

/// One POST the receiver got.
#[derive(Debug, Clone)]
struct Received {
    path: String,
    content_type: Option<String>,
    signature: Option<String>,
    body: Vec<u8>,
    at: Instant,
}

impl Received {
    fn document(&self) -> Value {
        serde_json::from_slice(&self.body).expect("a JSON body")
    }
}

#[derive(Default)]
struct ReceiverState {
    received: Mutex<Vec<Received>>,
    /// Status codes of the next answers, in order; 200 once empty.
    script: Mutex<VecDeque<u16>>,
    arrived: Notify,
}

/// A webhook receiver on the loopback.
struct Receiver {
    address: String,
    state: Arc<ReceiverState>,
    task: tokio::task::JoinHandle<()>,
}

impl Receiver {
    /// Starts a receiver that answers `script`'s statuses first, then 200.
    async fn start(script: &[u16]) -> Self {
        let state = Arc::new(ReceiverState::default());
        state.script.lock().unwrap().extend(script);
        let handler_state = state.clone();
        let router = axum::Router::new().fallback(move |uri: Uri, headers: HeaderMap, body: Bytes| {
            let state = handler_state.clone();
            async move {
                let header = |name: &str| headers.get(name).and_then(|v| v.to_str().ok()).map(str::to_owned);
                state.received.lock().unwrap().push(Received {
                    path: uri.path().to_owned(),
                    content_type: header("content-type"),
                    signature: header("chocmodal-signature"),
                    body: body.to_vec(),
                    at: Instant::now(),
                });
                state.arrived.notify_waiters();
                let status = state.script.lock().unwrap().pop_front().unwrap_or(200);
                AxumStatus::from_u16(status).unwrap()
            }
        });
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
        let address = format!("http://{}", listener.local_addr().unwrap());
        let task = tokio::spawn(async move {
            axum::serve(listener, router).await.unwrap();
        });
        Self { address, state, task }
    }

    fn url(&self, path: &str) -> String {
        format!("{}{path}", self.address)
    }

    fn received(&self) -> Vec<Received> {
        self.state.received.lock().unwrap().clone()
    }

    /// Waits until `count` POSTs arrived (to `path`, if given), for at most `within`.
    async fn wait_for(&self, count: usize, path: Option<&str>, within: Duration) -> Vec<Received> {
        let deadline = Instant::now() + within;
        loop {
            let arrived = self.state.arrived.notified();
            let received: Vec<Received> = self
                .received()
                .into_iter()
                .filter(|r| path.is_none_or(|p| r.path == p))
                .collect();
            if received.len() >= count {
                return received;
            }
            let left = deadline.saturating_duration_since(Instant::now());
            assert!(
                !left.is_zero(),
                "{count} callbacks to {path:?} expected within {within:?}, got {}: {:?}",
                received.len(),
                self.received().iter().map(|r| &r.path).collect::<Vec<_>>()
            );
            let _ = tokio::time::timeout(left, arrived).await;
        }
    }
}

impl Drop for Receiver {
    fn drop(&mut self) {
        self.task.abort();
    }
}

/// Callbacks allowed to the loopback, with a secret for the implicit tenant.
fn allow_loopback(config: &mut ServiceConfig) {
    config.callbacks.policy.allow = AllowList::new(vec!["127.0.0.1".parse().unwrap()]);
    config.callbacks.policy.secrets.insert("default", SECRET);
}

/// Submits `count-steps` with `inputs` and `subscriber`; returns the job id.
async fn submit_with(app: &TestApp, inputs: Value, subscriber: Value) -> String {
    let response = app
        .post_execution(counting::ID, &json!({"inputs": inputs, "subscriber": subscriber}))
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    let status: Value = response.json().await.unwrap();
    status["jobID"].as_str().unwrap().to_owned()
}

/// Checks `Chocmodal-Signature: t=<unix>,v1=<hex>` against the body and the secret.
fn assert_signed(received: &Received) {
    let header = received
        .signature
        .as_deref()
        .expect("a Chocmodal-Signature header");
    let (t, v1) = header
        .split_once(',')
        .and_then(|(t, v1)| Some((t.strip_prefix("t=")?, v1.strip_prefix("v1=")?)))
        .unwrap_or_else(|| panic!("expected `t=<unix>,v1=<hex>`, got `{header}`"));
    let sent: i64 = t.parse().unwrap();
    let now = SystemTime::now().duration_since(UNIX_EPOCH).unwrap().as_secs() as i64;
    assert!((now - sent).abs() <= 60, "signed at {sent}, now {now}");
    let mut signed = format!("{t}.").into_bytes();
    signed.extend_from_slice(&received.body);
    let expected: String = hmac_sha256(SECRET.as_bytes(), &signed)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(
        v1, expected,
        "the signature is not the HMAC of `t.body` under the tenant's secret"
    );
    // A forged body does not verify.
    let mut forged = format!("{t}.").into_bytes();
    forged.extend_from_slice(&received.body[..received.body.len() - 1]);
    let forged: String = hmac_sha256(SECRET.as_bytes(), &forged)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_ne!(v1, forged);
}

fn outbox(app: &TestApp) -> Outbox {
    Outbox::new(app.queue.database().clone(), app.queue.clock().clone())
}

/// The outcome's delivery state once it is no longer `pending`: (state, attempts, last
/// error). The deliverer records an attempt after the receiver answered, so a test that
/// saw the POST arrive waits here for its record.
async fn settled(app: &TestApp, job: &str) -> (String, i64, Option<String>) {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let state = outbox(app)
            .state(job)
            .await
            .unwrap()
            .expect("the job has a subscriber");
        if state.0 != "pending" {
            return state;
        }
        assert!(
            Instant::now() < deadline,
            "the callback of {job} is still pending: {state:?}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// The value of `chocmodal_callback_deliveries_total{uri, outcome}` in `/metrics`.
async fn deliveries(app: &TestApp, uri: &str, outcome: &str) -> f64 {
    let text = app.get("/metrics").await.text().await.unwrap();
    text.lines()
        .find(|line| {
            line.starts_with("chocmodal_callback_deliveries_total{")
                && line.contains(&format!("uri=\"{uri}\""))
                && line.contains(&format!("outcome=\"{outcome}\""))
        })
        .and_then(|line| line.rsplit(' ').next()?.parse().ok())
        .unwrap_or_else(|| panic!("no deliveries series {uri}/{outcome} in:\n{text}"))
}

async fn a_successful_job_posts_its_signed_status_document_within_a_second(backend: Backend) {
    let receiver = Receiver::start(&[]).await;
    let app = spawn_app_on(backend, allow_loopback).await;
    let job = submit_with(
        &app,
        json!({"steps": 3, "step_ms": 10}),
        json!({"successUri": receiver.url("/done"), "failedUri": receiver.url("/failed")}),
    )
    .await;
    let finished = app.wait_until_finished(&job).await;
    let seen_finished = Instant::now();
    assert_eq!(finished["status"], "successful");
    let received = receiver.wait_for(1, None, Duration::from_secs(1)).await;
    let callback = &received[0];
    assert!(
        callback.at <= seen_finished + Duration::from_secs(1),
        "the callback came {:?} after the job was seen finished",
        callback.at - seen_finished
    );
    assert_eq!(callback.path, "/done");
    assert_eq!(callback.content_type.as_deref(), Some("application/json"));
    assert_eq!(
        callback.document(),
        app.status(&job).await,
        "the body is GET /jobs/{{id}}'s document"
    );
    assert_signed(callback);
    let (state, attempts, _) = settled(&app, &job).await;
    assert_eq!((state.as_str(), attempts), ("delivered", 1));
    assert_eq!(deliveries(&app, "success", "delivered").await, 1.0);
    assert_eq!(receiver.received().len(), 1, "delivered once, nothing to /failed");
    app.stop().await;
}

async fn a_receiver_that_fails_twice_gets_it_on_the_third_try_after_growing_waits(backend: Backend) {
    let receiver = Receiver::start(&[500, 503]).await;
    let app = spawn_app_on(backend, |config| {
        allow_loopback(config);
        config.callbacks.first_retry = Duration::from_millis(400);
        config.callbacks.poll_interval = Duration::from_millis(50);
    })
    .await;
    let job = submit_with(
        &app,
        json!({"steps": 2}),
        json!({"successUri": receiver.url("/done")}),
    )
    .await;
    app.wait_until_finished(&job).await;
    let received = receiver.wait_for(3, Some("/done"), Duration::from_secs(10)).await;
    let first_wait = received[1].at - received[0].at;
    let second_wait = received[2].at - received[1].at;
    assert!(
        first_wait >= Duration::from_millis(400),
        "first retry after {first_wait:?}"
    );
    assert!(
        second_wait >= Duration::from_millis(800),
        "second retry after {second_wait:?} (doubled)"
    );
    for callback in &received {
        assert_eq!(callback.document()["status"], "successful");
        assert_signed(callback);
    }
    let (state, attempts, error) = settled(&app, &job).await;
    assert_eq!((state.as_str(), attempts, error), ("delivered", 3, None));
    assert_eq!(deliveries(&app, "success", "failed").await, 2.0);
    assert_eq!(deliveries(&app, "success", "delivered").await, 1.0);
    app.stop().await;
}

async fn a_callback_pending_across_a_restart_is_delivered_after_it(backend: Backend) {
    let receiver = Receiver::start(&[]).await;
    // The first service's deliverer looks once, at start, before the job exists, and
    // never again: the job ends with its callback undelivered.
    let app = spawn_app_on(backend, |config| {
        allow_loopback(config);
        config.callbacks.poll_interval = Duration::from_secs(3600);
    })
    .await;
    let job = submit_with(
        &app,
        json!({"steps": 2}),
        json!({"successUri": receiver.url("/done")}),
    )
    .await;
    app.wait_until_finished(&job).await;
    let (state, attempts, _) = outbox(&app).state(&job).await.unwrap().unwrap();
    assert_eq!((state.as_str(), attempts), ("pending", 0));
    let store = app.stop().await;
    let stopped = Instant::now();
    assert!(receiver.received().is_empty());
    let app = spawn_app_in(store, allow_loopback).await;
    let received = receiver.wait_for(1, Some("/done"), Duration::from_secs(5)).await;
    assert!(received[0].at > stopped);
    assert_eq!(received[0].document()["jobID"], job.as_str());
    assert_eq!(received[0].document()["status"], "successful");
    assert_signed(&received[0]);
    app.stop().await;
}

on_both_backends!(
    a_successful_job_posts_its_signed_status_document_within_a_second,
    a_receiver_that_fails_twice_gets_it_on_the_third_try_after_growing_waits,
    a_callback_pending_across_a_restart_is_delivered_after_it,
);

#[tokio::test]
async fn a_failed_job_posts_to_the_failed_uri() {
    let receiver = Receiver::start(&[]).await;
    let app = spawn_app_on(Backend::Sqlite, allow_loopback).await;
    let job = submit_with(
        &app,
        json!({"steps": 5, "fail_at": 2}),
        json!({"successUri": receiver.url("/done"), "failedUri": receiver.url("/failed")}),
    )
    .await;
    assert_eq!(app.wait_until_finished(&job).await["status"], "failed");
    let received = receiver.wait_for(1, None, Duration::from_secs(2)).await;
    assert_eq!(received[0].path, "/failed");
    assert_eq!(received[0].document()["status"], "failed");
    assert_eq!(received[0].document(), app.status(&job).await);
    assert_signed(&received[0]);
    app.stop().await;
}

#[tokio::test]
async fn a_dismissed_job_posts_to_the_failed_uri() {
    let receiver = Receiver::start(&[]).await;
    let app = spawn_app_on(Backend::Sqlite, allow_loopback).await;
    let job = submit_with(
        &app,
        json!({"steps": 1000, "step_ms": 20}),
        json!({"successUri": receiver.url("/done"), "failedUri": receiver.url("/failed")}),
    )
    .await;
    app.wait_for(&job, &["running"], Duration::from_secs(5)).await;
    assert_eq!(app.delete(&format!("/jobs/{job}")).await.status(), StatusCode::OK);
    let received = receiver.wait_for(1, None, Duration::from_secs(2)).await;
    assert_eq!(received[0].path, "/failed");
    assert_eq!(received[0].document()["status"], "dismissed");
    app.stop().await;
}

#[tokio::test]
async fn progress_goes_to_the_in_progress_uri_at_most_once_per_interval() {
    let receiver = Receiver::start(&[]).await;
    let app = spawn_app_on(Backend::Sqlite, |config| {
        allow_loopback(config);
        config.callbacks.progress_interval = Duration::from_millis(500);
        config.callbacks.poll_interval = Duration::from_millis(50);
    })
    .await;
    let job = submit_with(
        &app,
        json!({"steps": 40, "step_ms": 50}),
        json!({"successUri": receiver.url("/done"), "inProgressUri": receiver.url("/progress")}),
    )
    .await;
    app.wait_until_finished(&job).await;
    receiver.wait_for(1, Some("/done"), Duration::from_secs(2)).await;
    let progress: Vec<Received> = receiver
        .received()
        .into_iter()
        .filter(|r| r.path == "/progress")
        .collect();
    // A 2 s run, at most one every 0.5 s: 2 to 5 of them.
    assert!(
        (2..=5).contains(&progress.len()),
        "{} progress callbacks in a 2 s run",
        progress.len()
    );
    let mut last = -1;
    for pair in progress.windows(2) {
        let gap = pair[1].at - pair[0].at;
        // The interval is kept by the database's clock; allow the network some jitter.
        assert!(
            gap >= Duration::from_millis(400),
            "two progress callbacks {gap:?} apart"
        );
    }
    for callback in &progress {
        let document = callback.document();
        assert_eq!(document["status"], "running");
        let percent = document["progress"].as_i64().unwrap();
        assert!(
            percent > last,
            "progress {percent} after {last}: it must have changed"
        );
        last = percent;
        assert_signed(callback);
    }
    app.stop().await;
}

#[tokio::test]
async fn subscribers_outside_the_policy_are_refused_at_their_pointer() {
    // An allow-list without the loopback.
    let app = spawn_app_on(Backend::Sqlite, |config| {
        allow_loopback(config);
        config.callbacks.policy.allow = AllowList::new(vec!["hooks.example.com".parse().unwrap()]);
    })
    .await;
    let response = app
        .post_execution(
            counting::ID,
            &json!({"inputs": {"steps": 2}, "subscriber": {
                "successUri": "http://127.0.0.1:9/done",
                "failedUri": "ftp://hooks.example.com/failed",
                "inProgressUri": "hooks.example.com/progress"
            }}),
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "invalid-inputs").await;
    let detail = |pointer: &str| -> String {
        problem["errors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["pointer"] == pointer)
            .unwrap_or_else(|| panic!("no error at {pointer}: {problem}"))["detail"]
            .as_str()
            .unwrap()
            .to_owned()
    };
    let success = detail("/subscriber/successUri");
    assert!(
        success.contains("127.0.0.1") && success.contains("--callback-allow"),
        "{success}"
    );
    assert!(detail("/subscriber/failedUri").contains("`http` or `https`"));
    assert!(detail("/subscriber/inProgressUri").contains("not an absolute URI"));
    // The inputs' errors come with the subscriber's.
    let response = app
        .post_execution(
            counting::ID,
            &json!({"inputs": {"steps": 0}, "subscriber": {"successUri": "http://127.0.0.1:9/"}}),
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "invalid-inputs").await;
    let pointers: Vec<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["pointer"].as_str().unwrap())
        .collect();
    assert_eq!(pointers, ["/inputs/steps", "/subscriber/successUri"]);
    assert_eq!(
        app.get_json("/jobs").await["jobs"],
        json!([]),
        "nothing was queued"
    );
    app.stop().await;

    // No allow-list at all (the default): refused, naming the option.
    let app = spawn_app_on(Backend::Sqlite, |_| {}).await;
    let response = app
        .post_execution(
            counting::ID,
            &json!({"inputs": {"steps": 2}, "subscriber": {"successUri": "https://hooks.example.com/done"}}),
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/subscriber/successUri");
    let reason = problem["errors"][0]["detail"].as_str().unwrap();
    assert!(
        reason.contains("allowed no host (`--callback-allow`)"),
        "{reason}"
    );
    // A subscriber without URIs asks for nothing and is no error.
    let response = app
        .post_execution(counting::ID, &json!({"inputs": {"steps": 2}, "subscriber": {}}))
        .await;
    assert_eq!(response.status(), StatusCode::CREATED);
    app.stop().await;
}

#[tokio::test]
async fn a_tenant_without_a_secret_cannot_subscribe() {
    let app = spawn_app_on(Backend::Sqlite, |config| {
        config.callbacks.policy.allow = AllowList::new(vec!["127.0.0.1".parse().unwrap()]);
    })
    .await;
    let response = app
        .post_execution(
            counting::ID,
            &json!({"inputs": {"steps": 2}, "subscriber": {"successUri": "http://127.0.0.1:9/done"}}),
        )
        .await;
    let problem = assert_problem(response, StatusCode::UNPROCESSABLE_ENTITY, "invalid-inputs").await;
    assert_eq!(problem["errors"][0]["pointer"], "/subscriber");
    let reason = problem["errors"][0]["detail"].as_str().unwrap();
    assert!(
        reason.contains("`default`") && reason.contains("--callback-secrets"),
        "{reason}"
    );
    app.stop().await;
}

/// A retry with the same `Idempotency-Key` gets the same job only with the same
/// subscriber: another subscriber is another request.
#[tokio::test]
async fn an_idempotency_key_covers_the_subscriber() {
    let app = spawn_app_on(Backend::Sqlite, |config| {
        allow_loopback(config);
        config.workers = 0;
    })
    .await;
    let post = |subscriber: Value| {
        app.client
            .post(app.url(&format!("/processes/{}/execution", counting::ID)))
            .header("content-type", "application/json")
            .header("Idempotency-Key", "campaign-7")
            .body(json!({"inputs": {"steps": 2}, "subscriber": subscriber}).to_string())
            .send()
    };
    let first = post(json!({"successUri": "http://127.0.0.1:9/a"})).await.unwrap();
    assert_eq!(first.status(), StatusCode::CREATED);
    let job: Value = first.json().await.unwrap();
    let again = post(json!({"successUri": "http://127.0.0.1:9/a"})).await.unwrap();
    assert_eq!(again.status(), StatusCode::CREATED);
    assert_eq!(again.json::<Value>().await.unwrap()["jobID"], job["jobID"]);
    let other = post(json!({"successUri": "http://127.0.0.1:9/b"})).await.unwrap();
    assert_problem(other, StatusCode::UNPROCESSABLE_ENTITY, "idempotency-key-reused").await;
    app.stop().await;
}

/// A receiver that never answers 2xx: the outcome is retried until its next attempt
/// would fall beyond the give-up time after the job's end, then abandoned for good.
#[tokio::test]
async fn an_outcome_never_accepted_is_abandoned_after_the_give_up_time() {
    let receiver = Receiver::start(&[500; 20]).await;
    let app = spawn_app_on(Backend::Sqlite, |config| {
        allow_loopback(config);
        config.callbacks.first_retry = Duration::from_millis(300);
        config.callbacks.give_up_after = Duration::from_secs(1);
        config.callbacks.poll_interval = Duration::from_millis(50);
    })
    .await;
    let job = submit_with(
        &app,
        json!({"steps": 2}),
        json!({"successUri": receiver.url("/done")}),
    )
    .await;
    app.wait_until_finished(&job).await;
    let (state, attempts, error) = settled(&app, &job).await;
    assert_eq!(state, "abandoned");
    // Waits of 0.3 s, 0.6 s, 1.2 s: the third would end past 1 s after the job.
    assert!((2..=3).contains(&attempts), "{attempts} attempts");
    let error = error.unwrap();
    assert!(
        error.contains("answered 500") && error.contains("gave up"),
        "{error}"
    );
    assert_eq!(receiver.received().len() as i64, attempts);
    assert_eq!(deliveries(&app, "success", "abandoned").await, 1.0);
    assert_eq!(deliveries(&app, "success", "failed").await, (attempts - 1) as f64);
    app.stop().await;
}
