//! The deliverer: a background task of every API process that sends the callbacks of
//! [`super::outbox`]. Every [`CallbackSettings::poll_interval`] it claims the due
//! outcomes of finished jobs and the due progress of running ones, as many as it has
//! room for ([`CallbackSettings::max_in_flight`]), and sends each on a task of its own,
//! so a slow receiver delays nothing but its own callback.
//!
//! Each callback is one POST of the job's status document (`GET /jobs/{jobId}`'s JSON,
//! rendered when sent) with `Content-Type: application/json` and the signature header
//! ([`super::signature`]). Redirects are not followed (their target may be a host that
//! is not allowed): only a 2xx answer delivers. A failed outcome is tried again after
//! [`CallbackSettings::retry_delay`], and abandoned once the next try would fall later
//! than [`CallbackSettings::give_up_after`] after the job finished; the policy is read
//! again before each attempt, so a host taken off the allow-list (or a tenant whose
//! secrets were removed) is not called any more.

use std::sync::Arc;

use reqwest::Url;
use reqwest::header::{CONTENT_TYPE, USER_AGENT};
use tokio::sync::Semaphore;

use super::CallbackSettings;
use super::outbox::{DueOutcome, DueProgress, Outbox, Outcome};
use super::signature::{SIGNATURE_HEADER, signature_header};
use crate::service::clock::duration_ms;
use crate::service::http::models::StatusInfo;
use crate::service::metrics::Metrics;
use crate::service::queue::{JobQueue, JobRecord, JobStatus};

/// The `User-Agent` of callbacks.
const AGENT: &str = concat!("chocmodal/", env!("CARGO_PKG_VERSION"), " (job callback)");

/// Sends the callbacks of one process.
#[derive(Debug, Clone)]
pub struct Deliverer {
    inner: Arc<Inner>,
}

#[derive(Debug)]
struct Inner {
    outbox: Outbox,
    queue: JobQueue,
    metrics: Metrics,
    settings: CallbackSettings,
    client: reqwest::Client,
    /// This deliverer's name in `claimed_by`.
    owner: String,
    in_flight: Arc<Semaphore>,
}

/// Why the HTTP client of callbacks cannot be made.
#[derive(Debug, thiserror::Error)]
#[error("cannot make the HTTP client of job callbacks: {0}")]
pub struct ClientError(#[from] reqwest::Error);

impl Deliverer {
    pub fn new(queue: JobQueue, metrics: Metrics, settings: CallbackSettings) -> Result<Self, ClientError> {
        // The process-wide TLS provider (an error only says one is installed already).
        let _ = rustls::crypto::ring::default_provider().install_default();
        let client = reqwest::Client::builder()
            .redirect(reqwest::redirect::Policy::none())
            .timeout(settings.request_timeout)
            .connect_timeout(settings.request_timeout)
            .build()?;
        Ok(Self {
            inner: Arc::new(Inner {
                outbox: Outbox::new(queue.database().clone(), queue.clock().clone()),
                queue,
                metrics,
                in_flight: Arc::new(Semaphore::new(settings.max_in_flight.max(1))),
                settings,
                client,
                owner: format!("callbacks-{}", uuid::Uuid::new_v4()),
            }),
        })
    }

    /// Polls and sends until the task is aborted (at shutdown). A claimed outcome whose
    /// POST is cut short by the abort is claimed again when its claim expires.
    pub async fn run(self) {
        let mut ticks = tokio::time::interval(self.inner.settings.poll_interval);
        ticks.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        loop {
            ticks.tick().await;
            if let Err(error) = self.poll_once().await {
                tracing::warn!(%error, "cannot read the job callbacks to deliver; trying again");
            }
        }
    }

    /// Claims what is due and room allows, and starts sending it.
    pub async fn poll_once(&self) -> Result<(), sqlx::Error> {
        let inner = &self.inner;
        let room = inner.in_flight.available_permits();
        if room == 0 {
            return Ok(());
        }
        let outcomes = inner.outbox.claim_outcomes(&inner.owner, room).await?;
        for due in outcomes {
            let this = self.clone();
            self.spawn_held(async move { this.deliver_outcome(due).await })
                .await;
        }
        let room = inner.in_flight.available_permits();
        if room == 0 {
            return Ok(());
        }
        let progress = inner
            .outbox
            .claim_progress(inner.settings.progress_interval, room)
            .await?;
        for due in progress {
            let this = self.clone();
            self.spawn_held(async move { this.deliver_progress(due).await })
                .await;
        }
        Ok(())
    }

    /// Runs `send` on a task of its own holding one of the in-flight permits.
    async fn spawn_held(&self, send: impl std::future::Future<Output = ()> + Send + 'static) {
        let permit = self
            .inner
            .in_flight
            .clone()
            .acquire_owned()
            .await
            .expect("never closed");
        tokio::spawn(async move {
            send.await;
            drop(permit);
        });
    }

    async fn deliver_outcome(&self, due: DueOutcome) {
        let inner = &self.inner;
        let outcome = match inner.queue.get(&due.tenant, &due.job_id).await {
            // Deleted (retention) meanwhile: its callback row went with it.
            Ok(None) => return,
            Ok(Some(job)) => self.attempt_outcome(&due, &job).await,
            Err(error) => {
                tracing::warn!(job = %due.job_id, %error, "cannot read a job to call back; its claim will expire");
                return;
            }
        };
        match inner.outbox.record(&due.job_id, &inner.owner, &outcome).await {
            Ok(true) => {}
            Ok(false) => tracing::warn!(job = %due.job_id, "a callback's claim expired during its attempt"),
            Err(error) => {
                tracing::warn!(job = %due.job_id, %error, "cannot record a callback's attempt; its claim will expire")
            }
        }
    }

    /// One attempt at the outcome of finished `job`, and what to record of it.
    async fn attempt_outcome(&self, due: &DueOutcome, job: &JobRecord) -> Outcome {
        let inner = &self.inner;
        let (member, uri) = match job.status {
            JobStatus::Successful => ("success", &due.success_uri),
            JobStatus::Failed | JobStatus::Dismissed => ("failed", &due.failed_uri),
            // Claimed as finished, so never the case; try again later rather than guess.
            JobStatus::Accepted | JobStatus::Running => {
                return Outcome::Retry {
                    at: inner.outbox.now() + duration_ms(inner.settings.first_retry),
                    error: format!("the job is {} again", job.status.as_str()),
                };
            }
        };
        let Some(uri) = uri else {
            return Outcome::Unsubscribed;
        };
        let deadline = job.finished_at.unwrap_or(job.updated_at) + duration_ms(inner.settings.give_up_after);
        let outcome = match self.post(&due.tenant, uri, job).await {
            Ok(()) => {
                tracing::info!(job = %job.id, status = job.status.as_str(), %uri, "job callback delivered");
                Outcome::Delivered
            }
            Err(Refusal::Policy(error)) => Outcome::Abandoned { error },
            Err(Refusal::Failed(error)) => {
                let failures = u32::try_from(due.attempts + 1).unwrap_or(u32::MAX);
                // The wait counts from the failure (after the request, not before it),
                // from its millisecond rounded up: no wait is shorter than the delay.
                let at = inner.outbox.now() + 1 + duration_ms(inner.settings.retry_delay(failures));
                if at > deadline {
                    Outcome::Abandoned {
                        error: format!(
                            "{error}; gave up after {failures} attempts, {} s after the job finished",
                            inner.settings.give_up_after.as_secs()
                        ),
                    }
                } else {
                    tracing::info!(job = %job.id, %uri, %error, attempt = failures, "job callback failed; will retry");
                    inner.metrics.count_callback(member, "failed");
                    Outcome::Retry { at, error }
                }
            }
        };
        match &outcome {
            Outcome::Delivered => inner.metrics.count_callback(member, "delivered"),
            Outcome::Abandoned { error } => {
                tracing::warn!(job = %job.id, %uri, %error, "job callback abandoned");
                inner.metrics.count_callback(member, "abandoned");
            }
            Outcome::Retry { .. } | Outcome::Unsubscribed => {}
        }
        outcome
    }

    async fn deliver_progress(&self, due: DueProgress) {
        let inner = &self.inner;
        let job = match inner.queue.get(&due.tenant, &due.job_id).await {
            Ok(Some(job)) if job.status == JobStatus::Running => job,
            // Finished (or gone) since the claim: its outcome says the rest.
            Ok(_) => return,
            Err(error) => {
                tracing::warn!(job = %due.job_id, %error, "cannot read a job to send its progress");
                return;
            }
        };
        match self.post(&due.tenant, &due.in_progress_uri, &job).await {
            Ok(()) => inner.metrics.count_callback("in_progress", "delivered"),
            Err(Refusal::Failed(error)) => {
                tracing::info!(job = %job.id, uri = %due.in_progress_uri, %error, "progress callback failed (not retried: the next one supersedes it)");
                inner.metrics.count_callback("in_progress", "failed");
            }
            Err(Refusal::Policy(error)) => {
                tracing::warn!(job = %job.id, uri = %due.in_progress_uri, %error, "progress callback not sent");
                inner.metrics.count_callback("in_progress", "abandoned");
            }
        }
    }

    /// POSTs `job`'s status document to `uri`, signed with `tenant`'s secrets.
    async fn post(&self, tenant: &str, uri: &str, job: &JobRecord) -> Result<(), Refusal> {
        let inner = &self.inner;
        let policy = &inner.settings.policy;
        let url = Url::parse(uri)
            .map_err(|error| Refusal::Policy(format!("the stored URI is unreadable: {error}")))?;
        if !policy.allow.allows(&url) {
            return Err(Refusal::Policy(format!(
                "host `{}` is no longer allowed (`--callback-allow`)",
                url.host_str().unwrap_or_default()
            )));
        }
        let secrets = policy.secrets.of(tenant);
        if secrets.is_empty() {
            return Err(Refusal::Policy(format!(
                "tenant `{tenant}` no longer has a callback secret (`--callback-secrets`)"
            )));
        }
        let body = serde_json::to_vec(&StatusInfo::from_record(job))
            .map_err(|error| Refusal::Policy(format!("cannot render the status document: {error}")))?;
        let signature = signature_header(secrets, inner.outbox.now().div_euclid(1000), &body);
        let response = inner
            .client
            .post(url)
            .header(CONTENT_TYPE, "application/json")
            .header(USER_AGENT, AGENT)
            .header(SIGNATURE_HEADER, signature)
            .body(body)
            .send()
            .await
            .map_err(|error| Refusal::Failed(describe(&error)))?;
        let status = response.status();
        if status.is_success() {
            Ok(())
        } else {
            Err(Refusal::Failed(format!("the receiver answered {status}")))
        }
    }
}

/// Why a callback was not delivered.
#[derive(Debug)]
enum Refusal {
    /// No answer, or not a 2xx one: worth trying again.
    Failed(String),
    /// The policy forbids it now (or it cannot be made): never worth trying again.
    Policy(String),
}

/// A transport error with its causes (reqwest's own text is often just "error sending
/// request").
fn describe(error: &reqwest::Error) -> String {
    let mut text = if error.is_timeout() {
        "no answer in time".to_owned()
    } else {
        error.to_string()
    };
    let mut source = std::error::Error::source(error);
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}
