//! What the kernel's threads share: the message headers, the key, the queue to the IOPub
//! thread, the request being handled and the shutdown flag; publishing, verified receiving,
//! replies and the shutdown answer.

use super::wire::{Headers, Key, Message};
use crate::script::{console, interrupt};
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};

/// Messages for the IOPub thread to publish.
pub(super) type Outbox = Sender<Message>;

/// The shared parts of the threads: headers, the key, the queue to IOPub, shutdown.
pub(super) struct Shared {
    pub(super) headers: Headers,
    pub(super) key: Key,
    pub(super) iopub: Mutex<Outbox>,
    /// The request now being handled (the parent of what `print` and progress publish).
    pub(super) current: Mutex<Option<Message>>,
    pub(super) shutdown: Arc<AtomicBool>,
}

impl Shared {
    pub(super) fn publish(&self, parent: Option<&Message>, msg_type: &str, content: Value) {
        let m = self.headers.make(parent, msg_type, content);
        let m = Message {
            identities: vec![msg_type.as_bytes().to_vec()],
            ..m
        };
        if let Ok(tx) = self.iopub.lock() {
            let _ = tx.send(m);
        }
    }

    /// Publish under the request being handled.
    pub(super) fn publish_current(&self, msg_type: &str, content: Value) {
        let parent = self.current.lock().ok().and_then(|c| c.clone());
        self.publish(parent.as_ref(), msg_type, content);
    }

    /// The next message on `socket` (blocking up to `timeout_ms`, -1 for ever), verified; a
    /// message that fails verification is dropped with a note on stderr. `Err` when the socket
    /// is closed.
    pub(super) fn receive(
        &self,
        socket: &zmq::Socket,
        channel: &str,
        timeout_ms: i64,
    ) -> Result<Option<Message>, zmq::Error> {
        if socket.poll(zmq::POLLIN, timeout_ms)? == 0 {
            return Ok(None);
        }
        let frames = socket.recv_multipart(0)?;
        Ok(match Message::decode(frames, &self.key) {
            Ok(m) => Some(m),
            Err(why) => {
                console::to_stderr(&format!(
                    "swimlab kernel: dropped a message on the {channel} channel: {why}\n"
                ));
                None
            }
        })
    }

    /// Answer a shutdown request (on the shell or control channel): stop a running cell at its
    /// next step boundary and end the main loop after it.
    pub(super) fn shut_down(&self, socket: &zmq::Socket, msg: &Message) {
        let restart = msg.content["restart"].as_bool().unwrap_or(false);
        interrupt::request();
        self.shutdown.store(true, Ordering::SeqCst);
        self.reply(
            socket,
            msg,
            "shutdown_reply",
            json!({"status": "ok", "restart": restart}),
        );
    }

    pub(super) fn reply(
        &self,
        socket: &zmq::Socket,
        parent: &Message,
        msg_type: &str,
        content: Value,
    ) {
        let m = self.headers.make(Some(parent), msg_type, content);
        let _ = socket.send_multipart(m.encode(&self.key), 0);
    }
}
