//! Whether this instance can write: the last write refused by the storage (a full disk,
//! an I/O error), for `/readyz`, `/healthz` and the `chocmodal_failed_writes_total`
//! metric.
//!
//! Every write refused for a [`StorageFault`] is reported here: by the HTTP layer (a
//! problem response carries its fault) and by the workers (results, failures, claims).
//! The instance counts as "not writable" for [`FAILURE_MEMORY`] after the last refusal:
//! a small write that lands (a deletion, the readiness probe) proves little on a disk
//! that just refused a larger one, while writers that keep failing (a worker holding
//! results retries at least every 5 s) keep the state fresh. Once space is freed the
//! refusals stop and the service says "writable" again on its own.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use prometheus::IntCounterVec;

use super::db::fault::StorageFault;

/// How long a refused write keeps the instance "not writable" when nothing has been
/// written since (seconds; also the `Retry-After` of a refused write).
pub const FAILURE_MEMORY: Duration = Duration::from_secs(5);

/// The last refused write, shared by the API and the workers of one instance.
#[derive(Clone)]
pub struct StorageHealth {
    last_failure: Arc<Mutex<Option<Failure>>>,
    failed_writes: IntCounterVec,
}

#[derive(Debug, Clone, Copy)]
struct Failure {
    fault: StorageFault,
    at: Instant,
}

/// What [`StorageHealth::current`] says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CannotWrite {
    pub fault: StorageFault,
    /// How long ago the last write was refused.
    pub since: Duration,
}

impl std::fmt::Debug for StorageHealth {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StorageHealth")
            .field("last_failure", &self.last_failure)
            .finish_non_exhaustive()
    }
}

impl StorageHealth {
    /// `failed_writes` is the `chocmodal_failed_writes_total{cause, during}` counter.
    pub fn new(failed_writes: IntCounterVec) -> Self {
        Self {
            last_failure: Arc::new(Mutex::new(None)),
            failed_writes,
        }
    }

    /// A write `during` (`request`, `results`, `claim`, ...) was refused for `fault`.
    pub fn failed(&self, fault: StorageFault, during: &str) {
        self.failed_writes
            .with_label_values(&[fault.cause(), during])
            .inc();
        *self.lock() = Some(Failure {
            fault,
            at: Instant::now(),
        });
    }

    /// Reports `error` if it is a storage fault; returns the fault.
    pub fn check(&self, error: &sqlx::Error, during: &str) -> Option<StorageFault> {
        let fault = StorageFault::of(error)?;
        self.failed(fault, during);
        Some(fault)
    }

    /// The refused write that still makes the instance "not writable", if any.
    pub fn current(&self) -> Option<CannotWrite> {
        let failure = (*self.lock())?;
        let since = failure.at.elapsed();
        (since < FAILURE_MEMORY).then_some(CannotWrite {
            fault: failure.fault,
            since,
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Failure>> {
        // A panic while holding this lock leaves a plain value behind: keep using it.
        self.last_failure
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}
