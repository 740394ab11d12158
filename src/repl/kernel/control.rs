//! The control channel: interrupts, shutdowns and kernel info while a cell runs; the kernel's
//! description.

use super::shared::Shared;
use super::wire;
use crate::script::interrupt;
use serde_json::{json, Value};

/// The kernel's description: the answer to a `kernel_info_request` on either channel.
pub(super) fn kernel_info() -> Value {
    json!({
        "status": "ok",
        "protocol_version": wire::PROTOCOL_VERSION,
        "implementation": "swimlab",
        "implementation_version": env!("CARGO_PKG_VERSION"),
        "language_info": {
            "name": "swimlab",
            "version": env!("CARGO_PKG_VERSION"),
            "mimetype": "text/x-rhai",
            "file_extension": ".rhai",
            "pygments_lexer": "rust",
            "codemirror_mode": "rust",
        },
        "banner": format!("swimlab {}: dumbbell swimmers at low Reynolds number (Rhai). :help lists everything.", env!("CARGO_PKG_VERSION")),
        "help_links": [],
    })
}

pub(super) fn control_loop(control: &zmq::Socket, shared: &Shared) {
    loop {
        let msg = match shared.receive(control, "control", -1) {
            Ok(Some(m)) => m,
            Ok(None) => continue,
            Err(_) => return,
        };
        match msg.msg_type() {
            "interrupt_request" => {
                interrupt::request();
                shared.reply(control, &msg, "interrupt_reply", json!({"status": "ok"}));
            }
            "shutdown_request" => {
                shared.shut_down(control, &msg);
                shared.publish(Some(&msg), "status", json!({"execution_state": "idle"}));
            }
            "kernel_info_request" => {
                shared.reply(control, &msg, "kernel_info_reply", kernel_info())
            }
            _ => {}
        }
    }
}
