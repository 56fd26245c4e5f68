//! The shutdown of a service process, in phases that every part watches.
//!
//! [`Phase::Serving`] until the first request to stop (SIGTERM, ctrl-c, or a test's
//! [`ShutdownHandle::request`]). Then [`Phase::Draining`]: the workers stop claiming at
//! once and their running jobs get the grace period to finish (what still runs after it
//! is handed back to the queue); meanwhile the HTTP server keeps answering reads, and
//! answers writes with 503 and `Retry-After` (this process is going away: another one,
//! or this one restarted, takes them). A second request makes it [`Phase::Immediate`]:
//! running jobs are handed back now instead of at the end of the grace period. Once the
//! workers are done, the HTTP server stops accepting connections and finishes the
//! requests in flight, and the database closes.

use std::future::Future;

use tokio::sync::watch;

/// Where a process is in its shutdown; phases only advance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Phase {
    /// Claiming jobs and accepting every request.
    Serving,
    /// Asked to stop once: no new claims, running jobs finish within the grace period,
    /// reads are answered, writes get 503.
    Draining,
    /// Asked to stop twice: running jobs are handed back at once.
    Immediate,
}

/// Requests the next phase of the shutdown; cheap to clone.
#[derive(Debug, Clone)]
pub struct ShutdownHandle {
    phase: watch::Sender<Phase>,
}

impl Default for ShutdownHandle {
    fn default() -> Self {
        Self {
            phase: watch::Sender::new(Phase::Serving),
        }
    }
}

impl ShutdownHandle {
    /// A request to stop, as a signal would make one: the first drains, the second
    /// hands running jobs back at once; later ones change nothing.
    pub fn request(&self) {
        self.phase.send_modify(|phase| {
            *phase = match *phase {
                Phase::Serving => Phase::Draining,
                Phase::Draining | Phase::Immediate => Phase::Immediate,
            }
        });
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        *self.phase.borrow()
    }

    /// Completes once the phase is `phase` or later.
    pub fn reached(&self, phase: Phase) -> impl Future<Output = ()> + Send + 'static {
        let mut watcher = self.phase.subscribe();
        async move {
            // The sender lives as long as any handle; if all are gone, nothing advances.
            if watcher.wait_for(|current| *current >= phase).await.is_err() {
                std::future::pending::<()>().await;
            }
        }
    }

    /// Whether the process is past [`Phase::Serving`].
    pub fn is_stopping(&self) -> bool {
        self.phase() > Phase::Serving
    }
}

/// Forwards every SIGTERM and ctrl-c to `handle` (the first drains, the second is
/// immediate), for the life of the process.
pub async fn forward_signals(handle: ShutdownHandle) {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{SignalKind, signal};
        let (mut terminate, mut interrupt) =
            match (signal(SignalKind::terminate()), signal(SignalKind::interrupt())) {
                (Ok(terminate), Ok(interrupt)) => (terminate, interrupt),
                (Err(error), _) | (_, Err(error)) => {
                    tracing::error!(%error, "cannot listen for SIGTERM and SIGINT");
                    return;
                }
            };
        loop {
            let name = tokio::select! {
                Some(()) = terminate.recv() => "SIGTERM",
                Some(()) = interrupt.recv() => "SIGINT",
                else => return,
            };
            announce(&handle, name);
        }
    }
    #[cfg(not(unix))]
    loop {
        if let Err(error) = tokio::signal::ctrl_c().await {
            tracing::error!(%error, "cannot listen for ctrl-c");
            return;
        }
        announce(&handle, "ctrl-c");
    }
}

fn announce(handle: &ShutdownHandle, signal: &str) {
    handle.request();
    match handle.phase() {
        Phase::Draining => tracing::info!(
            signal,
            "stopping: no new jobs are claimed, running jobs get the grace period; a second signal hands them back at once"
        ),
        _ => tracing::warn!(signal, "second signal: handing the running jobs back now"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_advance_the_phase_and_stop_at_immediate() {
        let handle = ShutdownHandle::default();
        assert_eq!(handle.phase(), Phase::Serving);
        assert!(!handle.is_stopping());
        handle.request();
        assert_eq!(handle.phase(), Phase::Draining);
        handle.request();
        assert_eq!(handle.phase(), Phase::Immediate);
        handle.request();
        assert_eq!(handle.phase(), Phase::Immediate);
    }

    #[tokio::test]
    async fn reached_completes_for_the_current_and_earlier_phases_only() {
        let handle = ShutdownHandle::default();
        handle.request();
        handle.reached(Phase::Serving).await;
        handle.reached(Phase::Draining).await;
        let immediate = tokio::spawn(handle.reached(Phase::Immediate));
        tokio::task::yield_now().await;
        assert!(!immediate.is_finished(), "immediate before the second request");
        handle.request();
        immediate.await.unwrap();
    }
}
