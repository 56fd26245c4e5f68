//! Prometheus metrics, one registry per service instance (tests run several at once).
//!
//! Names follow the Prometheus conventions (`chocmodal_` prefix, base units, `_total`
//! for counters). Jobs by status is read from the database at scrape time, so it is
//! right even for jobs other instances changed.

use std::time::Duration;

use prometheus::{
    Encoder, HistogramOpts, HistogramVec, IntCounter, IntCounterVec, IntGauge, IntGaugeVec, Opts, Registry,
    TextEncoder,
};

use super::queue::JobStatus;
use super::storage_health::StorageHealth;

/// The `uri` labels of `chocmodal_callback_deliveries_total`.
pub const CALLBACK_URIS: [&str; 3] = ["success", "failed", "in_progress"];
/// Its `outcome` labels.
pub const CALLBACK_OUTCOMES: [&str; 3] = ["delivered", "failed", "abandoned"];

/// The service's metrics.
#[derive(Clone)]
pub struct Metrics {
    registry: Registry,
    jobs: IntGaugeVec,
    job_duration: HistogramVec,
    job_verdicts: IntCounterVec,
    queue_wait: HistogramVec,
    jobs_rescued: IntCounter,
    jobs_abandoned: IntCounter,
    threads: IntGauge,
    http_requests: IntCounterVec,
    http_duration: HistogramVec,
    callback_deliveries: IntCounterVec,
    storage: StorageHealth,
}

impl std::fmt::Debug for Metrics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Metrics").finish_non_exhaustive()
    }
}

impl Default for Metrics {
    fn default() -> Self {
        Self::new()
    }
}

impl Metrics {
    pub fn new() -> Self {
        let registry = Registry::new();
        // Buckets from 50 ms to about an hour, doubling.
        let job_buckets = prometheus::exponential_buckets(0.05, 2.0, 17).expect("valid buckets");
        let jobs = IntGaugeVec::new(
            Opts::new("chocmodal_jobs", "Jobs in the database, by status."),
            &["status"],
        )
        .expect("valid metric");
        let job_duration = HistogramVec::new(
            HistogramOpts::new(
                "chocmodal_job_duration_seconds",
                "Time from claim to end of a job run (s), by process and outcome.",
            )
            .buckets(job_buckets.clone()),
            &["process", "outcome"],
        )
        .expect("valid metric");
        let job_verdicts = IntCounterVec::new(
            Opts::new(
                "chocmodal_job_verdicts_total",
                "Jobs computed to success, by process and quality verdict (good, unchecked, \
                 doubtful, poor).",
            ),
            &["process", "verdict"],
        )
        .expect("valid metric");
        let queue_wait = HistogramVec::new(
            HistogramOpts::new(
                "chocmodal_job_queue_wait_seconds",
                "Time from submission (or re-queueing) to claim (s), by process.",
            )
            .buckets(job_buckets),
            &["process"],
        )
        .expect("valid metric");
        let jobs_rescued = IntCounter::new(
            "chocmodal_jobs_rescued_total",
            "Running jobs re-queued after their worker lost its lease.",
        )
        .expect("valid metric");
        let jobs_abandoned = IntCounter::new(
            "chocmodal_jobs_abandoned_total",
            "Running jobs failed after losing their worker too many times.",
        )
        .expect("valid metric");
        let threads = IntGauge::new(
            "chocmodal_worker_threads",
            "Threads the jobs running in this instance compute on (at most its worker slots).",
        )
        .expect("valid metric");
        let http_requests = IntCounterVec::new(
            Opts::new(
                "chocmodal_http_requests_total",
                "HTTP requests, by method, route and status.",
            ),
            &["method", "route", "status"],
        )
        .expect("valid metric");
        let http_duration = HistogramVec::new(
            HistogramOpts::new(
                "chocmodal_http_request_duration_seconds",
                "Time to answer an HTTP request (s), by method and route.",
            ),
            &["method", "route"],
        )
        .expect("valid metric");
        let failed_writes = IntCounterVec::new(
            Opts::new(
                "chocmodal_failed_writes_total",
                "Writes the storage refused (full disk, I/O error), by cause (SQLITE_FULL, \
                 disk_full, ENOSPC, io_error) and by what was written (request, results, claim, \
                 heartbeat, maintenance, probe).",
            ),
            &["cause", "during"],
        )
        .expect("valid metric");
        let callback_deliveries = IntCounterVec::new(
            Opts::new(
                "chocmodal_callback_deliveries_total",
                "Job callback attempts, by subscriber URI (success, failed, in_progress) and \
                 outcome (delivered: a 2xx answer; failed: another answer or none, retried \
                 later unless a progress callback; abandoned: given up, never retried).",
            ),
            &["uri", "outcome"],
        )
        .expect("valid metric");
        // Every series exists from the start, so rates and alerts see a zero, not nothing.
        for uri in CALLBACK_URIS {
            for outcome in CALLBACK_OUTCOMES {
                callback_deliveries.with_label_values(&[uri, outcome]);
            }
        }
        for collector in [
            Box::new(jobs.clone()) as Box<dyn prometheus::core::Collector>,
            Box::new(job_duration.clone()),
            Box::new(job_verdicts.clone()),
            Box::new(queue_wait.clone()),
            Box::new(jobs_rescued.clone()),
            Box::new(jobs_abandoned.clone()),
            Box::new(threads.clone()),
            Box::new(http_requests.clone()),
            Box::new(http_duration.clone()),
            Box::new(failed_writes.clone()),
            Box::new(callback_deliveries.clone()),
        ] {
            registry.register(collector).expect("metric names are unique");
        }
        Self {
            registry,
            jobs,
            job_duration,
            job_verdicts,
            queue_wait,
            jobs_rescued,
            jobs_abandoned,
            threads,
            http_requests,
            http_duration,
            callback_deliveries,
            storage: StorageHealth::new(failed_writes),
        }
    }

    /// Whether this instance can write ([`StorageHealth`]), which also counts failed
    /// writes.
    pub fn storage(&self) -> &StorageHealth {
        &self.storage
    }

    /// A run starts (`delta` > 0) or ends (< 0) on `delta` threads.
    pub fn add_threads(&self, delta: i64) {
        self.threads.add(delta);
    }

    pub fn observe_job(&self, process: &str, outcome: &str, duration: Duration) {
        self.job_duration
            .with_label_values(&[process, outcome])
            .observe(duration.as_secs_f64());
    }

    /// A job of `process` computed to success with the quality verdict `verdict`.
    pub fn count_verdict(&self, process: &str, verdict: &str) {
        self.job_verdicts.with_label_values(&[process, verdict]).inc();
    }

    pub fn observe_queue_wait(&self, process: &str, wait: Duration) {
        self.queue_wait
            .with_label_values(&[process])
            .observe(wait.as_secs_f64());
    }

    pub fn count_recovery(&self, rescued: usize, abandoned: usize) {
        self.jobs_rescued.inc_by(rescued as u64);
        self.jobs_abandoned.inc_by(abandoned as u64);
    }

    pub fn observe_request(&self, method: &str, route: &str, status: u16, duration: Duration) {
        self.http_requests
            .with_label_values(&[method, route, &status.to_string()])
            .inc();
        self.http_duration
            .with_label_values(&[method, route])
            .observe(duration.as_secs_f64());
    }

    /// One attempt at a job callback to the subscriber's `uri` member (`success`,
    /// `failed`, `in_progress`) ended with `outcome` (`delivered`, `failed`, `abandoned`).
    pub fn count_callback(&self, uri: &str, outcome: &str) {
        self.callback_deliveries.with_label_values(&[uri, outcome]).inc();
    }

    /// The Prometheus text exposition, with the job counts given.
    pub fn render(&self, jobs_by_status: &[(JobStatus, i64)]) -> String {
        for (status, count) in jobs_by_status {
            self.jobs.with_label_values(&[status.as_str()]).set(*count);
        }
        let mut buffer = Vec::new();
        TextEncoder::new()
            .encode(&self.registry.gather(), &mut buffer)
            .expect("text encoding into memory");
        String::from_utf8(buffer).unwrap_or_default()
    }
}
