//! The latest frame, shared between the run that publishes and the clients that read: one slot,
//! replaced by each new frame (a client that falls behind skips to the latest; nothing queues).

use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Duration;

#[derive(Default)]
struct Latest {
    /// How many frames were published (the latest's number).
    seq: u64,
    frame: Option<Arc<str>>,
    closed: bool,
}

/// The latest frame and the number of frames published so far. See the [module docs](self).
#[derive(Default)]
pub struct Slot {
    latest: Mutex<Latest>,
    changed: Condvar,
}

/// What a reader waiting for a newer frame gets.
pub enum Next {
    /// A newer frame, with its number.
    Frame(u64, Arc<str>),
    /// None within the wait.
    Timeout,
    /// The slot was closed: no frame will come.
    Closed,
}

impl Slot {
    fn lock(&self) -> MutexGuard<'_, Latest> {
        self.latest.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Put `frame` in place of the latest and wake the readers. The lock is held for a swap only.
    pub fn publish(&self, frame: String) {
        let frame: Arc<str> = frame.into();
        let old = {
            let mut l = self.lock();
            l.seq += 1;
            l.frame.replace(frame)
        };
        self.changed.notify_all();
        // The old frame is freed here, outside the lock.
        drop(old);
    }

    /// How many frames were published.
    pub fn published(&self) -> u64 {
        self.lock().seq
    }

    /// The latest frame, if any was published.
    pub fn latest(&self) -> Option<Arc<str>> {
        self.lock().frame.clone()
    }

    /// The first frame newer than number `seen`, waiting at most `wait` for one.
    pub fn next_after(&self, seen: u64, wait: Duration) -> Next {
        let l = self.lock();
        let (l, _) = self
            .changed
            .wait_timeout_while(l, wait, |l| !l.closed && l.seq <= seen)
            .unwrap_or_else(|e| e.into_inner());
        if l.closed {
            Next::Closed
        } else if l.seq > seen {
            match &l.frame {
                Some(f) => Next::Frame(l.seq, f.clone()),
                None => Next::Timeout,
            }
        } else {
            Next::Timeout
        }
    }

    /// Whether the slot was closed (its server stopped).
    pub fn is_closed(&self) -> bool {
        self.lock().closed
    }

    /// Wake every reader and tell it no frame will come.
    pub fn close(&self) {
        self.lock().closed = true;
        self.changed.notify_all();
    }
}
