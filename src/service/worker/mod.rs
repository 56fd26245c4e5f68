//! Workers: `N` slots that claim jobs from the queue and run them, plus the periodic
//! maintenance (lease recovery, retention) of the queue.
//!
//! Each slot is a small async loop: take a core, claim the oldest accepted job, run it
//! (see [`run`]), repeat; when the queue is empty, sleep until an enqueue wakes it or
//! the poll interval passes. The `N` slots share `N` cores: a run that asks for
//! several threads (`solver.threads`) gets as many of the free ones, and the other
//! slots claim nothing until cores are free again, so the runs never use more threads
//! than the worker has slots. Shutdown happens in two steps: stop claiming at once, wait for the
//! running jobs up to a grace period (or until a second signal); then cancel what still
//! runs and hand it back to the queue, its attempt not counted.

pub mod control;
mod maintenance;
mod persist;
mod run;

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use tokio::sync::{Notify, OwnedSemaphorePermit, Semaphore, watch};
use tokio::task::JoinSet;

pub use control::{RunControl, RunningJobs};
pub use maintenance::Maintenance;

use super::metrics::Metrics;
use super::queue::JobQueue;
use super::shutdown::{Phase, ShutdownHandle};
use crate::processes::Registry;

/// What every worker slot shares.
#[derive(Debug)]
pub struct WorkerContext {
    pub queue: JobQueue,
    pub registry: Registry,
    pub running: RunningJobs,
    pub metrics: Metrics,
    /// Notified on every enqueue, so idle workers start at once.
    pub wake: Arc<Notify>,
    /// Lease of a running job.
    pub lease: Duration,
    /// Idle workers look for work at least this often.
    pub poll_interval: Duration,
    /// Period of progress and cancellation checks of a running job.
    pub progress_interval: Duration,
    /// A run still computing after this long is stopped and fails.
    pub max_job_time: Option<Duration>,
}

/// The running worker slots.
#[derive(Debug)]
pub struct Workers {
    tasks: JoinSet<()>,
    stop_claiming: watch::Sender<bool>,
    hand_back: watch::Sender<bool>,
}

impl Workers {
    /// Starts `count` worker slots, each leasing jobs under its own owner id.
    /// A slot claims nothing once `shutdown` has left [`Phase::Serving`], even before
    /// [`Workers::shutdown`] runs: the request is seen by the next claim at once.
    pub fn start(context: Arc<WorkerContext>, count: usize, shutdown: ShutdownHandle) -> Self {
        let (stop_claiming, stop_rx) = watch::channel(false);
        let (hand_back, hand_back_rx) = watch::channel(false);
        let instance = instance_id();
        let cores = Arc::new(Semaphore::new(count));
        let mut tasks = JoinSet::new();
        for slot in 0..count {
            let owner = format!("{instance}/{slot}");
            tasks.spawn(worker_loop(
                context.clone(),
                (owner, cores.clone()),
                (stop_rx.clone(), shutdown.clone()),
                hand_back_rx.clone(),
            ));
        }
        Self {
            tasks,
            stop_claiming,
            hand_back,
        }
    }

    /// Stops claiming at once; lets running jobs finish within `grace` or until
    /// `hurry` completes (a second signal), whichever comes first; then cancels the rest
    /// and hands them back to the queue (waiting a few more seconds for them to stop).
    pub async fn shutdown(mut self, grace: Duration, hurry: impl Future<Output = ()>) {
        let _ = self.stop_claiming.send(true);
        let finished = tokio::select! {
            finished = tokio::time::timeout(grace, drain(&mut self.tasks)) => finished.is_ok(),
            () = hurry => false,
        };
        if finished {
            return;
        }
        tracing::warn!("handing the running jobs back to the queue");
        let _ = self.hand_back.send(true);
        if tokio::time::timeout(Duration::from_secs(10), drain(&mut self.tasks))
            .await
            .is_err()
        {
            tracing::error!(
                "some jobs ignore cancellation; their leases will expire and recovery will re-queue them"
            );
            self.tasks.abort_all();
        }
    }
}

/// `<host>:<pid>:<random>`: names the machine and process holding a lease (seen in
/// `jobs.lease_owner` and the logs), unique even when a process restarts with the same pid.
fn instance_id() -> String {
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|host| host.trim().to_owned())
        .filter(|host| !host.is_empty())
        .unwrap_or_else(|| "localhost".to_owned());
    let random = uuid::Uuid::new_v4().simple().to_string();
    format!("{host}:{}:{}", std::process::id(), &random[..8])
}

async fn drain(tasks: &mut JoinSet<()>) {
    while tasks.join_next().await.is_some() {}
}

/// The cores a run holds: the one its slot took, and those it could take besides for
/// its threads (freed when it ends).
pub(super) struct Cores {
    held: Vec<OwnedSemaphorePermit>,
}

/// How long a run that asks for several threads waits for each core it lacks: an idle
/// slot holds a core for the moment of its (empty) claim, and every idle slot claims at
/// once when a job is queued. Cores held by running jobs are not waited for.
const CORE_WAIT: Duration = Duration::from_millis(200);

impl Cores {
    /// Adds cores of `all` until `threads` are held, or until none frees within
    /// [`CORE_WAIT`].
    async fn take(&mut self, all: &Arc<Semaphore>, threads: usize) {
        while self.held.len() < threads {
            match tokio::time::timeout(CORE_WAIT, all.clone().acquire_owned()).await {
                Ok(Ok(core)) => self.held.push(core),
                _ => break,
            }
        }
    }

    pub(super) fn count(&self) -> usize {
        self.held.len()
    }
}

async fn worker_loop(
    ctx: Arc<WorkerContext>,
    (owner, cores): (String, Arc<Semaphore>),
    (mut stop, shutdown): (watch::Receiver<bool>, ShutdownHandle),
    hand_back: watch::Receiver<bool>,
) {
    loop {
        if *stop.borrow() {
            break;
        }
        // A core first: while runs hold every core, this slot claims nothing.
        let core = tokio::select! {
            core = cores.clone().acquire_owned() => match core {
                Ok(core) => core,
                Err(_) => break,
            },
            changed = stop.changed() => if changed.is_err() { break } else { continue },
        };
        // The core may have come with the request to stop: claim nothing after it (the
        // phase is the request itself, seen before the workers are told).
        if *stop.borrow() || shutdown.phase() != Phase::Serving {
            break;
        }
        // Register for wake-ups before looking, so an enqueue right after an empty
        // claim is not missed.
        let wake = ctx.wake.notified();
        tokio::pin!(wake);
        wake.as_mut().enable();
        match ctx.queue.claim(&owner, ctx.lease).await {
            Ok(Some(job)) => {
                // The request to stop may have come while the claim ran: the job was
                // queued (perhaps after the signal) and is not ours to start. Hand it
                // straight back, its attempt not counted.
                if *stop.borrow() || shutdown.phase() != Phase::Serving {
                    let lease = job.lease;
                    if let Err(error) = ctx.queue.hand_back(&lease).await {
                        ctx.metrics.storage().check(&error, "hand back");
                        tracing::error!(%error, job = %lease.job_id, "handing back a job claimed during shutdown failed; its lease will expire");
                    }
                    break;
                }
                let mut held = Cores { held: vec![core] };
                let usable = ctx
                    .registry
                    .get(&job.process_id)
                    .map_or(1, |p| p.threads(&job.inputs));
                held.take(&cores, usable).await;
                run::run_job(&ctx, job, held, hand_back.clone()).await;
                continue;
            }
            Ok(None) => {}
            Err(error) => {
                ctx.metrics.storage().check(&error, "claim");
                tracing::error!(%error, worker = %owner, "claiming a job failed")
            }
        }
        drop(core);
        tokio::select! {
            _ = &mut wake => {}
            _ = tokio::time::sleep(ctx.poll_interval) => {}
            changed = stop.changed() => if changed.is_err() { break },
        }
    }
}
