//! A thread that owns some state and consumes batches sent to it, in order. Emptied batches come
//! back for reuse, so a steady stream allocates nothing. Used by `Threaded` (samples to a recorder)
//! and by the MCAP recorder (encoded messages to the file writer).

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

/// Batches in flight at most; the sender waits beyond that.
const QUEUE: usize = 4;

/// A batch that can be emptied for reuse, keeping its memory.
pub trait Reusable {
    fn clear(&mut self);
}

pub struct BatchWorker<S, B, E> {
    tx: Option<SyncSender<B>>,
    /// `None` for a worker that drops its batches when done (batches shared with other workers).
    recycled: Option<Receiver<B>>,
    handle: Option<JoinHandle<(S, Result<(), E>)>>,
}

impl<S: Send + 'static, B: Send + 'static, E: Send + 'static> BatchWorker<S, B, E> {
    /// Starts thread `name` with `state`; `consume` is called with every batch sent, and the first
    /// error it returns stops the thread.
    pub fn spawn(name: &str, state: S, consume: impl FnMut(&mut S, &B) -> Result<(), E> + Send + 'static) -> std::io::Result<Self> {
        Self::start(name, state, consume, true)
    }

    /// As `spawn`, for batches shared with other workers (an `Arc`): each is dropped once
    /// consumed, so the sender sees when every worker is done with it. Send them with `send`.
    pub fn spawn_shared(name: &str, state: S, consume: impl FnMut(&mut S, &B) -> Result<(), E> + Send + 'static) -> std::io::Result<Self> {
        Self::start(name, state, consume, false)
    }

    fn start(name: &str, mut state: S, mut consume: impl FnMut(&mut S, &B) -> Result<(), E> + Send + 'static, recycle: bool) -> std::io::Result<Self> {
        let (tx, rx) = sync_channel::<B>(QUEUE);
        // the way back only for batches the sender reuses
        let (back_tx, recycled) = recycle.then(|| sync_channel::<B>(QUEUE)).unzip();
        let handle = std::thread::Builder::new().name(name.to_string()).spawn(move || {
            for batch in rx {
                if let Err(e) = consume(&mut state, &batch) {
                    return (state, Err(e));
                }
                if let Some(back_tx) = &back_tx {
                    let _ = back_tx.try_send(batch);
                }
            }
            (state, Ok(()))
        })?;
        Ok(Self { tx: Some(tx), recycled, handle: Some(handle) })
    }

    /// Hands `batch` to the thread (waiting while `QUEUE` batches are ahead of it). False when the
    /// thread has stopped (on an error: `join` for it).
    pub fn send(&self, batch: B) -> bool {
        self.tx.as_ref().is_some_and(|tx| tx.send(batch).is_ok())
    }

    /// Hands `batch` to the thread and leaves in its place an emptied batch the thread is done
    /// with, or `fresh()` when none is back yet. False when the thread has stopped (on an error:
    /// `join` for it).
    pub fn hand_over(&self, batch: &mut B, fresh: impl FnOnce() -> B) -> bool
    where
        B: Reusable,
    {
        let empty = match self.recycled.as_ref().map(Receiver::try_recv) {
            Some(Ok(mut recycled)) => {
                recycled.clear();
                recycled
            }
            _ => fresh(),
        };
        let full = std::mem::replace(batch, empty);
        self.send(full)
    }

    /// Lets the thread finish what was sent and returns its state and result (None if already joined).
    pub fn join(&mut self) -> Option<std::thread::Result<(S, Result<(), E>)>> {
        self.tx = None;
        self.handle.take().map(JoinHandle::join)
    }
}
