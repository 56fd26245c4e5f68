//! Job callbacks: the OGC API – Processes `subscriber` of an execution request. The
//! service POSTs the job's status document (the JSON of `GET /jobs/{jobId}`) to
//! `successUri` when the job is `successful`, to `failedUri` when it is `failed` or
//! `dismissed`, and to `inProgressUri` while it runs, at most once per
//! [`CallbackSettings::progress_interval`] and only when the progress changed.
//!
//! - [`subscriber`]: the request member, refused at its pointer unless each URI is an
//!   absolute http(s) URI of a host the operator allows ([`allow`]) and the tenant has
//!   a signing secret ([`secrets`]);
//! - [`outbox`]: the subscriber is stored with the job (`job_callbacks`, written in the
//!   transaction that queues the job) and the delivery's state with it, so it survives
//!   restarts;
//! - [`deliverer`]: a background task of every API process polls the outbox, claims
//!   due deliveries (several processes never send the same attempt twice), POSTs them
//!   signed ([`signature`]) on tasks of their own (a worker never waits for a
//!   receiver), retries an outcome with exponential back-off and abandons it
//!   [`CallbackSettings::give_up_after`] after the job finished. A progress callback is
//!   sent once: the next one supersedes it.

pub mod allow;
pub mod deliverer;
pub mod outbox;
pub mod secrets;
pub mod signature;
pub mod subscriber;

use std::time::Duration;

pub use allow::{AllowList, HostPattern};
pub use deliverer::Deliverer;
pub use secrets::{CallbackSecrets, SecretsFileError};
pub use subscriber::Subscriber;

/// What a submission's `subscriber` is checked against.
#[derive(Debug, Clone, Default)]
pub struct CallbackPolicy {
    /// Hosts callbacks may go to; empty: subscribers are refused.
    pub allow: AllowList,
    /// The tenants' signing secrets; a tenant without one cannot subscribe.
    pub secrets: CallbackSecrets,
}

/// The callbacks' settings.
#[derive(Debug, Clone)]
pub struct CallbackSettings {
    pub policy: CallbackPolicy,
    /// An outcome not delivered this long after the job finished is abandoned.
    pub give_up_after: Duration,
    /// Least time between two progress callbacks of one job.
    pub progress_interval: Duration,
    /// Wait before the first retry of an outcome; each further retry waits twice as
    /// long as the one before, up to [`Self::max_retry_interval`].
    pub first_retry: Duration,
    /// Longest wait between two attempts.
    pub max_retry_interval: Duration,
    /// How often the deliverer looks for due deliveries.
    pub poll_interval: Duration,
    /// Longest time one POST may take (connecting included) before it counts as failed.
    pub request_timeout: Duration,
    /// Most POSTs in flight at once from one process.
    pub max_in_flight: usize,
}

/// Default `--callback-give-up-seconds`: a day.
pub const DEFAULT_GIVE_UP_SECONDS: u64 = 86_400;
/// Default `--callback-progress-seconds`.
pub const DEFAULT_PROGRESS_SECONDS: u64 = 5;

impl Default for CallbackSettings {
    fn default() -> Self {
        Self {
            policy: CallbackPolicy::default(),
            give_up_after: Duration::from_secs(DEFAULT_GIVE_UP_SECONDS),
            progress_interval: Duration::from_secs(DEFAULT_PROGRESS_SECONDS),
            first_retry: Duration::from_secs(1),
            max_retry_interval: Duration::from_secs(600),
            poll_interval: Duration::from_millis(200),
            request_timeout: Duration::from_secs(10),
            max_in_flight: 16,
        }
    }
}

impl CallbackSettings {
    /// The wait after the `failures`-th failed attempt (1, 2, ...): `first_retry`
    /// doubled each time, at most `max_retry_interval`.
    pub fn retry_delay(&self, failures: u32) -> Duration {
        let factor = 2u32.saturating_pow(failures.saturating_sub(1).min(30));
        self.first_retry
            .saturating_mul(factor)
            .min(self.max_retry_interval)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn retries_back_off_exponentially_up_to_the_ceiling() {
        let settings = CallbackSettings::default();
        let waits: Vec<u64> = (1..=12).map(|n| settings.retry_delay(n).as_secs()).collect();
        assert_eq!(waits, [1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 600, 600]);
        assert_eq!(settings.retry_delay(u32::MAX).as_secs(), 600);
    }
}
