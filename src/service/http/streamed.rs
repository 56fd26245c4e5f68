//! Bounded memory per response: bodies written as they are sent, and a budget for the
//! working memory of the large ones being made.
//!
//! A history's JSON or CSV text is 2–3 times its binary size, and building it whole
//! (then a copy for the body) made a response cost 5–6 times the history. Here the text
//! is written on the blocking pool straight into the response body, in chunks of
//! [`CHUNK_BYTES`], with at most [`CHUNKS_IN_FLIGHT`] chunks waiting for the client: the
//! text is never whole in memory, and a slow client slows the writer instead of
//! growing a buffer (a client that reads nothing for [`STALLED_CLIENT`] is dropped).
//!
//! What remains is the working memory of the view: the decoded history and the window
//! picked from it. [`ResponseMemory`] bounds its sum over the responses being made
//! (`--response-memory-mb`): each response takes its estimate ([`working_bytes`]) from
//! the budget until its body is sent, and a response that does not fit now is a 503
//! `server-busy` with `Retry-After` instead of a wait that would hold its request.

use std::io::{self, Write};
use std::sync::Arc;
use std::time::Duration;

use axum::body::{Body, Bytes};
use axum::http::HeaderValue;
use futures_util::StreamExt;
use tokio::runtime::Handle;
use tokio::sync::{OwnedSemaphorePermit, Semaphore, mpsc};

use super::error::ApiError;
use crate::problem::Problem;
use crate::service::store::StoredHistory;

/// Size of the chunks a streamed body is sent in (bytes).
pub const CHUNK_BYTES: usize = 64 * 1024;
/// Chunks written but not yet taken by the connection, per response.
pub const CHUNKS_IN_FLIGHT: usize = 4;
/// A client that takes no chunk for this long is dropped (its writer stops).
pub const STALLED_CLIENT: Duration = Duration::from_secs(60);
/// Seconds a client refused for lack of response memory is asked to wait.
pub const BUSY_RETRY_SECONDS: u64 = 2;

/// Writes a whole body into the writer it is given, as the client takes it.
pub type WriteBody = Box<dyn FnOnce(&mut dyn Write) -> io::Result<()> + Send>;

/// A view's body: bytes made at once (small documents), or written as sent, with the
/// entity tag of what it will write (computed from what it is made of, since the bytes
/// are not there to hash before the headers go).
pub enum Rendered {
    Bytes(Vec<u8>),
    Stream { etag: HeaderValue, write: WriteBody },
}

impl std::fmt::Debug for Rendered {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Rendered::Bytes(bytes) => f.debug_tuple("Bytes").field(&bytes.len()).finish(),
            Rendered::Stream { etag, .. } => f
                .debug_struct("Stream")
                .field("etag", etag)
                .finish_non_exhaustive(),
        }
    }
}

impl From<Vec<u8>> for Rendered {
    fn from(bytes: Vec<u8>) -> Self {
        Rendered::Bytes(bytes)
    }
}

/// The budget of working memory for the large responses being made, shared by every
/// request; cheap to clone.
#[derive(Debug, Clone)]
pub struct ResponseMemory {
    permits: Arc<Semaphore>,
    /// The budget, in KiB (one permit each).
    total_kib: u32,
}

impl ResponseMemory {
    /// A budget of `bytes` (at least 1 MiB).
    pub fn new(bytes: usize) -> Self {
        let total_kib = u32::try_from(bytes / 1024).unwrap_or(u32::MAX).max(1024);
        Self {
            permits: Arc::new(Semaphore::new(total_kib as usize)),
            total_kib,
        }
    }

    /// Takes `bytes` of the budget (all of it at most: a response larger than the budget
    /// runs alone), or answers 503 `server-busy` when they are not free now.
    pub fn admit(&self, bytes: usize) -> Result<OwnedSemaphorePermit, ApiError> {
        let kib = u32::try_from(bytes.div_ceil(1024))
            .unwrap_or(u32::MAX)
            .clamp(1, self.total_kib);
        self.permits
            .clone()
            .try_acquire_many_owned(kib)
            .map_err(|_| ApiError::RetryLater {
                problem: Box::new(Problem::server_busy(format!(
                    "this response needs about {} MiB of working memory and the server's budget \
                     for responses (`--response-memory-mb`, {} MiB) is in use by others",
                    kib.div_ceil(1024),
                    self.total_kib / 1024
                ))),
                retry_after: BUSY_RETRY_SECONDS,
            })
    }
}

/// Working memory of a view of `stored` (bytes): the compressed data, the decoded columns
/// and a window picked from them (decoding needs as much again for a moment, while the
/// window does not exist yet).
pub fn working_bytes(stored: &StoredHistory) -> usize {
    let decoded = stored
        .samples
        .saturating_mul(stored.series.len() + 1)
        .saturating_mul(std::mem::size_of::<f64>());
    stored.data.len().saturating_add(decoded.saturating_mul(2))
}

/// A body of `bytes` that keeps `permit` until it is sent.
pub fn held_bytes(permit: OwnedSemaphorePermit, bytes: Vec<u8>) -> Body {
    let stream = futures_util::stream::unfold((Some(bytes), permit), |(bytes, permit)| async move {
        // The permit goes when the connection asks for what follows the bytes.
        let bytes = bytes?;
        Some((Ok::<_, io::Error>(Bytes::from(bytes)), (None, permit)))
    });
    // Fused: a layer that polls again after the end (the compression encoder does) must
    // see the end again, not a panic of `unfold`.
    Body::from_stream(stream.fuse())
}

/// A body that `write` writes on the blocking pool as the client takes it; `permit` is
/// kept until the end. An error after the first chunk ends the body early (the client
/// sees a truncated response and the connection closes); it is logged.
pub fn streamed(permit: OwnedSemaphorePermit, write: WriteBody) -> Body {
    let (sender, receiver) = mpsc::channel::<io::Result<Bytes>>(CHUNKS_IN_FLIGHT);
    let runtime = Handle::current();
    tokio::task::spawn_blocking(move || {
        let mut sink = ChunkSink {
            buffer: Vec::with_capacity(CHUNK_BYTES),
            sender,
            runtime,
        };
        let written = write(&mut sink).and_then(|()| sink.send_buffer());
        // The working memory is free once everything is written (the last chunks wait
        // in the channel); released before the channel closes, so the end of the body
        // means the permit is back.
        drop(permit);
        if let Err(error) = written {
            if error.kind() == io::ErrorKind::BrokenPipe {
                tracing::debug!(%error, "the client left before the end of a streamed response");
            } else {
                tracing::error!(%error, "writing a streamed response failed");
                let _ = sink.sender.blocking_send(Err(error));
            }
        }
    });
    let chunks = futures_util::stream::unfold(receiver, |mut receiver| async move {
        receiver.recv().await.map(|chunk| (chunk, receiver))
    });
    Body::from_stream(chunks.fuse())
}

/// The writer of a streamed body: fills a chunk, then hands it to the connection,
/// waiting while [`CHUNKS_IN_FLIGHT`] are already waiting.
struct ChunkSink {
    buffer: Vec<u8>,
    sender: mpsc::Sender<io::Result<Bytes>>,
    runtime: Handle,
}

impl ChunkSink {
    fn send_buffer(&mut self) -> io::Result<()> {
        if self.buffer.is_empty() {
            return Ok(());
        }
        let chunk = Bytes::from(std::mem::replace(
            &mut self.buffer,
            Vec::with_capacity(CHUNK_BYTES),
        ));
        let sender = &self.sender;
        let sent = self
            .runtime
            .block_on(async { tokio::time::timeout(STALLED_CLIENT, sender.send(Ok(chunk))).await });
        match sent {
            Ok(Ok(())) => Ok(()),
            Ok(Err(_)) => Err(io::Error::new(io::ErrorKind::BrokenPipe, "the client left")),
            Err(_) => Err(io::Error::new(
                io::ErrorKind::BrokenPipe,
                format!("the client took nothing for {} s", STALLED_CLIENT.as_secs()),
            )),
        }
    }
}

impl Write for ChunkSink {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.buffer.extend_from_slice(bytes);
        if self.buffer.len() >= CHUNK_BYTES {
            self.send_buffer()?;
        }
        Ok(bytes.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        // Chunks go when full or at the end: flushing every small write would send
        // tiny frames.
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_admits_until_full_then_answers_busy_and_frees_on_drop() {
        let memory = ResponseMemory::new(4 << 20);
        let first = memory.admit(3 << 20).expect("3 of 4 MiB");
        assert!(matches!(memory.admit(2 << 20), Err(ApiError::RetryLater { .. })));
        let small = memory
            .admit(512 << 10)
            .expect("the last MiB still takes half a MiB");
        drop(first);
        drop(small);
        // Larger than the whole budget: admitted alone.
        let whole = memory.admit(64 << 20).expect("alone");
        assert!(memory.admit(1).is_err(), "nothing left beside it");
        drop(whole);
        assert!(memory.admit(1).is_ok());
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn a_streamed_body_is_the_bytes_written_in_chunks() {
        let memory = ResponseMemory::new(1 << 20);
        let text: Vec<u8> = (0..(3 * CHUNK_BYTES + 17))
            .map(|k| b'a' + (k % 26) as u8)
            .collect();
        let expected = text.clone();
        let body = streamed(
            memory.admit(1).unwrap(),
            Box::new(move |out: &mut dyn Write| {
                for piece in text.chunks(1000) {
                    out.write_all(piece)?;
                }
                Ok(())
            }),
        );
        let mut sizes = Vec::new();
        let mut received = Vec::new();
        let mut chunks = body.into_data_stream();
        while let Some(chunk) = chunks.next().await {
            let chunk = chunk.unwrap();
            sizes.push(chunk.len());
            received.extend_from_slice(&chunk);
        }
        assert_eq!(received, expected);
        // Writes of 1000 bytes: a chunk goes once it holds CHUNK_BYTES or more.
        assert_eq!(sizes, vec![66_000, 66_000, 3 * CHUNK_BYTES + 17 - 132_000]);
        // The writer is done and its permit returned.
        assert_eq!(memory.permits.available_permits(), memory.total_kib as usize);
    }
}
