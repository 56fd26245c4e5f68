//! Running one claimed job: compute on a dedicated thread, supervise from the runtime.
//!
//! The computation gets its own OS thread, never a runtime thread, so the API answers
//! while every worker computes. The supervising task wakes every `progress_interval` to
//! copy progress into the row (only when the percent changed), renew the lease (every
//! third of it), and check that the job is still ours (twice a second: a dismissal or a
//! lost lease sets the cancel flag, and the run stops at its next progress callback).
//! The outcome is then written under the lease guard, and retried while the storage
//! refuses it ([`super::persist`]).

use crate::provenance::Provenance;
use std::ops::ControlFlow;
use std::panic::AssertUnwindSafe;
use std::time::{Duration, Instant};

use tokio::sync::{oneshot, watch};

use super::{Cores, WorkerContext};
use crate::problem::{CHOCMODAL_PROBLEMS, Problem};
use crate::processes::{RunError, RunOutput};
use crate::service::queue::{ClaimedJob, Lease};
use crate::service::signals::SignalReadError;
use crate::service::store;

/// How often a running job checks, by a read, that its row still says it is ours (so a
/// dismissal made through another API process stops it within about a second too).
const OWNERSHIP_CHECK: Duration = Duration::from_millis(500);

/// What the compute thread sends back: the run's result, or the panic message.
type ThreadOutcome = Result<Result<RunOutput, RunError>, String>;

/// Runs `job` with the threads of `cores` (the process computes inside a thread pool of
/// that size, whatever it asked for: its results do not depend on it).
pub(super) async fn run_job(
    ctx: &WorkerContext,
    job: ClaimedJob,
    cores: Cores,
    mut hand_back: watch::Receiver<bool>,
) {
    let lease = job.lease.clone();
    let process_id = job.process_id.clone();
    let wait_ms = (job.started_at - job.created_at).max(0) as u64;
    ctx.metrics
        .observe_queue_wait(&process_id, Duration::from_millis(wait_ms));
    let Some(process) = ctx.registry.get(&process_id) else {
        let problem = Problem::job_failed(format!("this service no longer offers process `{process_id}`"));
        record(&lease, "fail", ctx.queue.fail(&lease, &problem, None).await);
        return;
    };
    let started = Instant::now();
    // An identical run already succeeded: take its results instead of computing again.
    if let Some(hash) = &job.content_hash {
        match ctx.queue.reuse(&lease, &job.tenant, hash).await {
            Ok(Some(source)) => {
                ctx.metrics.observe_job(&process_id, "reused", started.elapsed());
                tracing::info!(job = %lease.job_id, source = %source, "job reused the results of an identical job");
                return;
            }
            Ok(None) => {}
            Err(error) => {
                tracing::warn!(job = %lease.job_id, %error, "looking for reusable results failed; computing")
            }
        }
    }
    // The stored signals the job refers to (the job keeps references, not samples:
    // `processes::signal_input`). A signal missing now is reported by the run, at its
    // pointer, as invalid inputs.
    let signals = match ctx.queue.signals().library(&job.tenant, &job.inputs).await {
        Ok(library) => library,
        Err(SignalReadError::Database(error)) => {
            tracing::warn!(job = %lease.job_id, %error, "cannot load the job's signals; handing it back");
            record(&lease, "hand back", ctx.queue.hand_back(&lease).await);
            return;
        }
        Err(error) => {
            tracing::error!(job = %lease.job_id, %error, "a signal of the job cannot be read");
            record(
                &lease,
                "fail",
                ctx.queue.fail(&lease, &crashed_problem(), None).await,
            );
            return;
        }
    };
    let short = lease.job_id[..8.min(lease.job_id.len())].to_owned();
    let pool = {
        let short = short.clone();
        rayon::ThreadPoolBuilder::new()
            .num_threads(cores.count())
            .thread_name(move |k| format!("job-{short}-{k}"))
            .build()
    };
    let pool = match pool {
        Ok(pool) => pool,
        Err(error) => {
            tracing::error!(%error, "cannot start a job's threads; handing the job back");
            record(&lease, "hand back", ctx.queue.hand_back(&lease).await);
            return;
        }
    };
    tracing::info!(
        job = %lease.job_id,
        process = %process_id,
        attempt = lease.attempt,
        threads = cores.count(),
        usable = process.threads(&job.inputs),
        "job started"
    );
    let control = ctx.running.insert(&lease.job_id);
    let threads = i64::try_from(cores.count()).unwrap_or(i64::MAX);
    ctx.metrics.add_threads(threads);

    let (sender, mut receiver) = oneshot::channel::<ThreadOutcome>();
    let thread_control = control.clone();
    // Stamped on the results document where it is assembled ([`finish`]).
    let provenance = Provenance::of(&job.inputs);
    let inputs = job.inputs;
    let spawned = std::thread::Builder::new()
        .name(format!("job-{short}"))
        .spawn(move || {
            let mut progress = |fraction: f64| {
                thread_control.set_fraction(fraction);
                if thread_control.is_cancelled() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            };
            let outcome = pool.install(|| {
                std::panic::catch_unwind(AssertUnwindSafe(|| {
                    process.run_with(&inputs, &signals, &mut progress)
                }))
                .map_err(|payload| panic_message(payload.as_ref()))
            });
            let _ = sender.send(outcome);
        });
    if let Err(error) = spawned {
        tracing::error!(%error, "cannot start a compute thread; handing the job back");
        ctx.running.remove(&lease.job_id);
        ctx.metrics.add_threads(-threads);
        record(&lease, "hand back", ctx.queue.hand_back(&lease).await);
        return;
    }

    let mut ticker = tokio::time::interval(ctx.progress_interval);
    ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    let renew_every = ctx.lease / 3;
    let (mut reported, mut renewed, mut checked) = (0u8, Instant::now(), Instant::now());
    let mut lost = false;
    let mut timed_out = false;
    // The wall-time limit: a run still computing then is cancelled and fails.
    let over_time = async {
        match ctx.max_job_time {
            Some(limit) => tokio::time::sleep(limit).await,
            None => std::future::pending().await,
        }
    };
    tokio::pin!(over_time);
    let mut handing_back = *hand_back.borrow();
    if handing_back {
        control.cancel();
    }
    let outcome = loop {
        tokio::select! {
            outcome = &mut receiver => break outcome.unwrap_or_else(|_| Err("the compute thread vanished".into())),
            () = &mut over_time, if !timed_out && !handing_back && !lost => {
                tracing::warn!(job = %lease.job_id, limit = ?ctx.max_job_time, "job over its wall-time limit: stopping it");
                timed_out = true;
                control.cancel();
            }
            changed = hand_back.changed(), if !handing_back => {
                if changed.is_err() || *hand_back.borrow() {
                    handing_back = true;
                    control.cancel();
                }
            }
            _ = ticker.tick(), if !lost => {
                let percent = control.percent();
                let held = if percent != reported || renewed.elapsed() >= renew_every {
                    let progress = (percent != reported).then_some(percent);
                    let held = ctx.queue.heartbeat(&lease, progress, ctx.lease).await;
                    if matches!(held, Ok(true)) {
                        reported = percent;
                        renewed = Instant::now();
                    }
                    held
                } else if checked.elapsed() >= OWNERSHIP_CHECK {
                    checked = Instant::now();
                    ctx.queue.is_held(&lease).await
                } else {
                    Ok(true)
                };
                match held {
                    Ok(true) => {}
                    Ok(false) => {
                        tracing::info!(job = %lease.job_id, "job dismissed or lease lost: stopping it");
                        lost = true;
                        control.cancel();
                    }
                    Err(error) => {
                        ctx.metrics.storage().check(&error, "heartbeat");
                        tracing::warn!(job = %lease.job_id, %error, "heartbeat failed")
                    }
                }
            }
        }
    };
    ctx.running.remove(&lease.job_id);
    ctx.metrics.add_threads(-threads);
    drop(cores);
    let ending = Ending {
        lost,
        handing_back,
        timed_out: timed_out.then_some(ctx.max_job_time).flatten(),
        reached: control.percent(),
    };
    // The quality verdict of a result, counted once it is stored.
    let verdict = match &outcome {
        Ok(Ok(output)) => output.document["quality"]["verdict"].as_str().map(str::to_owned),
        _ => None,
    };
    let outcome_label = finish(ctx, &lease, outcome, ending, provenance).await;
    ctx.metrics
        .observe_job(&process_id, outcome_label, started.elapsed());
    if let (Some(verdict), "successful") = (verdict, outcome_label) {
        ctx.metrics.count_verdict(&process_id, &verdict);
    }
    tracing::info!(job = %lease.job_id, outcome = outcome_label, seconds = started.elapsed().as_secs_f64(), "job ended");
}

/// Why the supervisor may have cancelled a run.
#[derive(Debug, Clone, Copy)]
struct Ending {
    /// The job is no longer ours (dismissed, lease lost).
    lost: bool,
    /// The service is shutting down: the job goes back to the queue.
    handing_back: bool,
    /// The run went over this wall-time limit.
    timed_out: Option<Duration>,
    /// The percent the run had reached when it ended (its last progress callback): a
    /// failed job keeps it, so its progress says where it stopped.
    reached: u8,
}

/// Writes the outcome of a run under its lease; returns the outcome's metric label.
async fn finish(
    ctx: &WorkerContext,
    lease: &Lease,
    outcome: ThreadOutcome,
    ending: Ending,
    provenance: Provenance,
) -> &'static str {
    let Ending {
        lost,
        handing_back,
        timed_out,
        reached,
    } = ending;
    match outcome {
        Ok(Ok(_)) | Ok(Err(_)) if lost => "lost",
        Ok(Ok(output)) => {
            let job_id = lease.job_id.clone();
            // Compressing long histories is CPU work: keep it off the runtime threads.
            let stored = tokio::task::spawn_blocking(move || {
                let histories = output
                    .histories
                    .iter()
                    .map(store::encode)
                    .collect::<Result<Vec<_>, _>>()?;
                let mut document =
                    output.document_with_outputs(|name| format!("/jobs/{job_id}/results/{name}"));
                provenance.stamp(&mut document);
                Ok::<_, store::HistoryError>((document, histories))
            })
            .await;
            match stored {
                Ok(Ok((document, histories))) => {
                    record(
                        lease,
                        "complete",
                        super::persist::until_stored(ctx, lease, "complete", || {
                            ctx.queue.complete(lease, &document, &histories)
                        })
                        .await,
                    );
                    "successful"
                }
                Ok(Err(error)) => {
                    tracing::error!(job = %lease.job_id, %error, "the process returned an unusable history");
                    record(
                        lease,
                        "fail",
                        fail_stored(ctx, lease, &crashed_problem(), Some(reached)).await,
                    );
                    "crashed"
                }
                Err(error) => {
                    tracing::error!(job = %lease.job_id, %error, "storing the results panicked");
                    record(
                        lease,
                        "fail",
                        fail_stored(ctx, lease, &crashed_problem(), Some(reached)).await,
                    );
                    "crashed"
                }
            }
        }
        Ok(Err(RunError::Cancelled)) if handing_back => {
            record(
                lease,
                "hand back",
                super::persist::until_stored(ctx, lease, "hand back", || ctx.queue.hand_back(lease)).await,
            );
            "handed_back"
        }
        Ok(Err(RunError::Cancelled)) if timed_out.is_some() => {
            let problem = Problem::job_time_limit(timed_out.unwrap_or_default());
            record(
                lease,
                "fail",
                fail_stored(ctx, lease, &problem, Some(reached)).await,
            );
            "timed_out"
        }
        // Stopped by a dismissal the supervisor has not noticed yet: the row says so already.
        Ok(Err(RunError::Cancelled)) => "dismissed",
        Ok(Err(RunError::Failed(reason))) => {
            record(
                lease,
                "fail",
                fail_stored(ctx, lease, &Problem::job_failed(reason), Some(reached)).await,
            );
            "failed"
        }
        Ok(Err(RunError::Invalid(invalid))) => {
            let problem = Problem::invalid_inputs(&invalid);
            record(
                lease,
                "fail",
                fail_stored(ctx, lease, &problem, Some(reached)).await,
            );
            "failed"
        }
        Err(panic) => {
            tracing::error!(job = %lease.job_id, panic = %panic, "the process panicked");
            record(
                lease,
                "fail",
                fail_stored(ctx, lease, &crashed_problem(), Some(reached)).await,
            );
            "crashed"
        }
    }
}

/// Fails the job with `problem`, retrying while the storage refuses the write.
async fn fail_stored(
    ctx: &WorkerContext,
    lease: &Lease,
    problem: &Problem,
    reached: Option<u8>,
) -> Result<bool, sqlx::Error> {
    super::persist::until_stored(ctx, lease, "fail", || ctx.queue.fail(lease, problem, reached)).await
}

/// The problem stored for a job whose process crashed: no internals, they are logged.
fn crashed_problem() -> Problem {
    Problem::new(
        format!("{CHOCMODAL_PROBLEMS}/job-crashed"),
        "Job crashed",
        500,
        "the computation crashed (a bug in chocmodal); the incident is logged",
    )
}

fn record(lease: &Lease, what: &str, result: Result<bool, sqlx::Error>) {
    match result {
        Ok(true) => {}
        Ok(false) => tracing::info!(job = %lease.job_id, "{what}: the lease was lost; nothing written"),
        Err(error) => tracing::error!(job = %lease.job_id, %error, "{what}: database error"),
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "non-string panic payload".to_owned())
}
