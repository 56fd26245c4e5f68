//! The running jobs of this service instance, each with a progress value and a cancel
//! flag shared between its compute thread, its supervising task and the HTTP handlers.
//!
//! The compute thread's progress callback only touches two atomics, so checking for
//! cancellation costs nothing even when called every step; `DELETE /jobs/{id}` sets the
//! flag directly, and the supervisor also sets it when the job's row says so.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// Progress and cancellation of one running job.
#[derive(Debug, Default)]
pub struct RunControl {
    /// Fraction done (0..=1), as f64 bits.
    fraction_bits: AtomicU64,
    cancelled: AtomicBool,
}

impl RunControl {
    pub fn set_fraction(&self, fraction: f64) {
        let fraction = if fraction.is_finite() {
            fraction.clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.fraction_bits.store(fraction.to_bits(), Ordering::Relaxed);
    }

    /// Percent done for the job row; 100 is reserved for finished jobs.
    pub fn percent(&self) -> u8 {
        let fraction = f64::from_bits(self.fraction_bits.load(Ordering::Relaxed));
        ((fraction * 100.0).floor() as u8).min(99)
    }

    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }
}

/// Jobs running in this instance, by job id.
#[derive(Debug, Default, Clone)]
pub struct RunningJobs(Arc<Mutex<HashMap<String, Arc<RunControl>>>>);

impl RunningJobs {
    pub(crate) fn insert(&self, job_id: &str) -> Arc<RunControl> {
        let control = Arc::new(RunControl::default());
        self.lock().insert(job_id.to_owned(), control.clone());
        control
    }

    pub(crate) fn remove(&self, job_id: &str) {
        self.lock().remove(job_id);
    }

    /// Asks job `job_id` to stop if it runs here; returns whether it did.
    pub fn cancel(&self, job_id: &str) -> bool {
        match self.lock().get(job_id) {
            Some(control) => {
                control.cancel();
                true
            }
            None => false,
        }
    }

    pub fn len(&self) -> usize {
        self.lock().len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, Arc<RunControl>>> {
        // A panic while holding this lock cannot leave the map inconsistent.
        self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}
