//! `swimlab kernel`: a Jupyter kernel (messaging protocol 5.3) over ZeroMQ (libzmq through the
//! `zmq` crate), running the same [`Session`] as the shell: variables, functions and imports
//! persist across cells; a cell's value is its `execute_result` (pictures: `display_data` as PNG
//! and SVG); `print` is the stdout stream; errors carry the shell's caret rendering; long runs
//! show a progress line that updates in place.
//!
//! Threads: the main thread owns the session and the shell socket; the control thread answers
//! interrupts (the same stop at a step boundary as Ctrl-C) and shutdowns while a cell runs; the
//! heartbeat thread echoes; one thread owns the IOPub socket and publishes what the others queue.
//! SIGINT interrupts too (the kernelspec's default interrupt mode).
//!
//! The connection file and sockets in `connection`; what the threads share (publishing, verified
//! receiving, replies) in `shared`; the threads themselves and `run` in `threads`; the control
//! channel in `control`; the shell channel's requests in `shell`; a cell's output routed to IOPub
//! in `output`; the wire protocol in `wire`.

mod connection;
mod control;
mod output;
mod shared;
mod shell;
pub mod spec;
mod threads;
mod wire;

pub use threads::run;
