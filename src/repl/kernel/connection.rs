//! The connection file Jupyter hands the kernel, and the sockets bound from it.

use super::wire::Key;
use serde_json::Value;
use std::path::Path;

/// What the connection file gives.
pub(super) struct Connection {
    transport: String,
    ip: String,
    pub(super) shell: u16,
    pub(super) iopub: u16,
    pub(super) stdin: u16,
    pub(super) control: u16,
    pub(super) hb: u16,
    pub(super) key: Key,
}

impl Connection {
    pub(super) fn read(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read the connection file {}: {e}", path.display()))?;
        let v: Value = serde_json::from_str(&text)
            .map_err(|e| format!("the connection file {} is not JSON: {e}", path.display()))?;
        let port = |name: &str| -> Result<u16, String> {
            v[name]
                .as_u64()
                .and_then(|p| u16::try_from(p).ok())
                .ok_or_else(|| format!("the connection file has no valid \"{name}\""))
        };
        Ok(Connection {
            transport: v["transport"].as_str().unwrap_or("tcp").to_string(),
            ip: v["ip"].as_str().unwrap_or("127.0.0.1").to_string(),
            shell: port("shell_port")?,
            iopub: port("iopub_port")?,
            stdin: port("stdin_port")?,
            control: port("control_port")?,
            hb: port("hb_port")?,
            key: Key::new(
                v["key"].as_str().unwrap_or(""),
                v["signature_scheme"].as_str().unwrap_or("hmac-sha256"),
            )?,
        })
    }

    pub(super) fn endpoint(&self, port: u16) -> String {
        if self.transport == "ipc" {
            format!("ipc://{}-{port}", self.ip)
        } else {
            format!("{}://{}:{port}", self.transport, self.ip)
        }
    }
}

pub(super) fn bind(
    ctx: &zmq::Context,
    kind: zmq::SocketType,
    endpoint: &str,
) -> Result<zmq::Socket, String> {
    let s = ctx
        .socket(kind)
        .map_err(|e| format!("cannot make a socket: {e}"))?;
    s.set_linger(1000)
        .map_err(|e| format!("cannot set up a socket: {e}"))?;
    s.bind(endpoint)
        .map_err(|e| format!("cannot listen on {endpoint}: {e}"))?;
    Ok(s)
}
