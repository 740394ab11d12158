//! The live view: a scene's frames served to a browser while it runs.
//!
//! A [`Publisher`] watches a simulation ([`crate::engine::Watcher`]): after a step it encodes at
//! most one frame per interval (wall-clock) as JSON ([`frame`]) into a [`Slot`] that holds the
//! latest frame only, so frames are dropped, never queued. A [`Server`] serves the page, the
//! latest frame and a stream of frames (Server-Sent Events) on 127.0.0.1 under a random token,
//! GET only, each client on a thread of its own: a slow or vanished client never waits the run.
//! Dropping the server ends its threads and closes its socket.

mod assets;
pub mod frame;
mod http;
mod publisher;
mod server;
mod slot;

pub use frame::{Parts, RowSnapshot};
pub use publisher::{Pace, Publisher, Refresh};
pub use server::{Server, ServerOptions};
pub use slot::Slot;
