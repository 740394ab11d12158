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

pub mod spec;
mod wire;

use super::session::{Reply, Session};
use crate::script::{console, interrupt, progress, show, Picture};
use base64::Engine as _;
use serde_json::{json, Value};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Sender};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use wire::{Headers, Key, Message};

/// What the connection file gives.
struct Connection {
    transport: String,
    ip: String,
    shell: u16,
    iopub: u16,
    stdin: u16,
    control: u16,
    hb: u16,
    key: Key,
}

impl Connection {
    fn read(path: &Path) -> Result<Self, String> {
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

    fn endpoint(&self, port: u16) -> String {
        if self.transport == "ipc" {
            format!("ipc://{}-{port}", self.ip)
        } else {
            format!("{}://{}:{port}", self.transport, self.ip)
        }
    }
}

fn bind(ctx: &zmq::Context, kind: zmq::SocketType, endpoint: &str) -> Result<zmq::Socket, String> {
    let s = ctx
        .socket(kind)
        .map_err(|e| format!("cannot make a socket: {e}"))?;
    s.set_linger(1000)
        .map_err(|e| format!("cannot set up a socket: {e}"))?;
    s.bind(endpoint)
        .map_err(|e| format!("cannot listen on {endpoint}: {e}"))?;
    Ok(s)
}

/// Messages for the IOPub thread to publish.
type Outbox = Sender<Message>;

/// The shared parts of the threads: headers, the key, the queue to IOPub, shutdown.
struct Shared {
    headers: Headers,
    key: Key,
    iopub: Mutex<Outbox>,
    /// The request now being handled (the parent of what `print` and progress publish).
    current: Mutex<Option<Message>>,
    shutdown: Arc<AtomicBool>,
}

impl Shared {
    fn publish(&self, parent: Option<&Message>, msg_type: &str, content: Value) {
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
    fn publish_current(&self, msg_type: &str, content: Value) {
        let parent = self.current.lock().ok().and_then(|c| c.clone());
        self.publish(parent.as_ref(), msg_type, content);
    }

    /// The next message on `socket` (blocking up to `timeout_ms`, -1 for ever), verified; a
    /// message that fails verification is dropped with a note on stderr. `Err` when the socket
    /// is closed.
    fn receive(
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
    fn shut_down(&self, socket: &zmq::Socket, msg: &Message) {
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

    fn reply(&self, socket: &zmq::Socket, parent: &Message, msg_type: &str, content: Value) {
        let m = self.headers.make(Some(parent), msg_type, content);
        let _ = socket.send_multipart(m.encode(&self.key), 0);
    }
}

/// Run the kernel on the connection file at `path` until a shutdown request.
pub fn run(path: &Path) -> Result<(), String> {
    let conn = Connection::read(path)?;
    let ctx = zmq::Context::new();
    let shell = bind(&ctx, zmq::ROUTER, &conn.endpoint(conn.shell))?;
    let control = bind(&ctx, zmq::ROUTER, &conn.endpoint(conn.control))?;
    let iopub = bind(&ctx, zmq::PUB, &conn.endpoint(conn.iopub))?;
    let stdin = bind(&ctx, zmq::ROUTER, &conn.endpoint(conn.stdin))?;
    let hb = bind(&ctx, zmq::REP, &conn.endpoint(conn.hb))?;

    let (tx, rx) = channel::<Message>();
    let shutdown = Arc::new(AtomicBool::new(false));
    let shared = Arc::new(Shared {
        headers: Headers::new(),
        key: conn.key.clone(),
        iopub: Mutex::new(tx),
        current: Mutex::new(None),
        shutdown: shutdown.clone(),
    });
    let publisher = spawn_publisher(iopub, rx, conn.key.clone(), shutdown);
    // Heartbeat: echo every ping.
    std::thread::spawn(move || {
        while let Ok(b) = hb.recv_bytes(0) {
            let _ = hb.send(b, 0);
        }
    });
    // Control: interrupts and shutdowns while a cell runs.
    let sh = shared.clone();
    std::thread::spawn(move || control_loop(&control, &sh));
    // SIGINT (the kernelspec's interrupt mode "signal") stops a run like Ctrl-C at the prompt.
    let _ = ctrlc::set_handler(interrupt::request);
    let _keep_stdin = stdin;

    let mut session = Session::new();
    route_output(&mut session, &shared);
    serve(&mut session, &shell, &shared);
    progress::set_sink(None);
    console::set_sink(None);
    console::set_display_sink(None);
    console::set_note_sink(None);
    let _ = publisher.join();
    Ok(())
}

/// The IOPub thread: publish in the order queued; after a shutdown, once the queue is empty,
/// close (the socket's linger lets the last messages go out).
fn spawn_publisher(
    iopub: zmq::Socket,
    rx: std::sync::mpsc::Receiver<Message>,
    key: Key,
    shutdown: Arc<AtomicBool>,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || loop {
        match rx.recv_timeout(Duration::from_millis(50)) {
            Ok(m) => {
                let _ = iopub.send_multipart(m.encode(&key), 0);
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) if !shutdown.load(Ordering::SeqCst) => {
            }
            Err(_) => break,
        }
    })
}

/// Everything a cell writes goes to IOPub as the cell's output: prints, display(value),
/// text functions write themselves, notes and the progress display.
fn route_output(session: &mut Session, shared: &Arc<Shared>) {
    let sh = shared.clone();
    session.on_print(move |s| {
        sh.publish_current(
            "stream",
            json!({"name": "stdout", "text": format!("{s}\n")}),
        );
    });
    // display(value) mid-cell: a display_data now, pictures inline.
    let sh = shared.clone();
    console::set_display_sink(Some(Arc::new(move |v: &rhai::Dynamic| {
        let (data, _) = mime_bundle(v);
        sh.publish_current("display_data", json!({"data": data, "metadata": {}}));
    })));
    // Text that functions write themselves (tplot) goes to the same stream.
    let sh = shared.clone();
    console::set_sink(Some(Arc::new(move |s: &str| {
        sh.publish_current("stream", json!({"name": "stdout", "text": s}));
    })));
    // Notes a run gives (a cost far beyond its length, and why) go to the cell's stderr.
    let sh = shared.clone();
    console::set_note_sink(Some(Arc::new(move |s: &str| {
        sh.publish_current("stream", json!({"name": "stderr", "text": s}));
    })));
    let sh = shared.clone();
    // One display per run: shown at its first line, updated in place, cleared at its end.
    let open: Mutex<Option<String>> = Mutex::new(None);
    let progress_sink: progress::ProgressSink = Arc::new(move |line: Option<&str>| {
        let Ok(mut open) = open.lock() else { return };
        let (msg_type, id) = match (line, open.as_ref()) {
            (Some(_), None) => ("display_data", open.insert(wire::uuid()).clone()),
            (Some(_), Some(id)) => ("update_display_data", id.clone()),
            (None, _) => match open.take() {
                Some(id) => ("update_display_data", id),
                None => return,
            },
        };
        sh.publish_current(
            msg_type,
            json!({
                "data": {"text/plain": line.unwrap_or("")},
                "metadata": {},
                "transient": {"display_id": id},
            }),
        );
    });
    progress::set_sink(Some(progress_sink));
}

/// The shell loop: each request marks the kernel busy, is handled, and marks it idle, until a
/// shutdown.
fn serve(session: &mut Session, shell: &zmq::Socket, shared: &Arc<Shared>) {
    let mut count = 0u64;
    shared.publish(None, "status", json!({"execution_state": "starting"}));
    while !shared.shutdown.load(Ordering::SeqCst) {
        let Ok(Some(msg)) = shared.receive(shell, "shell", 100) else {
            continue;
        };
        if let Ok(mut c) = shared.current.lock() {
            *c = Some(msg.clone());
        }
        shared.publish(Some(&msg), "status", json!({"execution_state": "busy"}));
        handle_shell(session, shell, shared, &msg, &mut count);
        shared.publish(Some(&msg), "status", json!({"execution_state": "idle"}));
    }
}

fn kernel_info() -> Value {
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

fn control_loop(control: &zmq::Socket, shared: &Shared) {
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

/// The word around byte `pos` of `code` (for inspection).
fn word_at(code: &str, pos: usize) -> &str {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let pos = (0..=pos.min(code.len()))
        .rev()
        .find(|&p| code.is_char_boundary(p))
        .unwrap_or(0);
    let start = code[..pos]
        .char_indices()
        .rev()
        .find(|(_, c)| !is_word(*c))
        .map_or(0, |(i, c)| i + c.len_utf8());
    let end = code[pos..]
        .char_indices()
        .find(|(_, c)| !is_word(*c))
        .map_or(code.len(), |(i, _)| pos + i);
    &code[start..end]
}

/// Byte offset of code point `cursor` (the protocol counts code points).
fn byte_of(code: &str, cursor: usize) -> usize {
    code.char_indices()
        .nth(cursor)
        .map_or(code.len(), |(i, _)| i)
}

fn handle_shell(
    session: &mut Session,
    shell: &zmq::Socket,
    shared: &Shared,
    msg: &Message,
    count: &mut u64,
) {
    match msg.msg_type() {
        "kernel_info_request" => shared.reply(shell, msg, "kernel_info_reply", kernel_info()),
        "execute_request" => execute(session, shell, shared, msg, count),
        "complete_request" => {
            let code = msg.content["code"].as_str().unwrap_or("");
            let cursor = msg.content["cursor_pos"].as_u64().unwrap_or(0) as usize;
            let pos = byte_of(code, cursor);
            let (start, matches) = session.complete(code, pos);
            shared.reply(
                shell,
                msg,
                "complete_reply",
                json!({
                    "status": "ok",
                    "matches": matches,
                    "cursor_start": code[..start].chars().count(),
                    "cursor_end": code[..pos].chars().count(),
                    "metadata": {},
                }),
            );
        }
        "inspect_request" => {
            let code = msg.content["code"].as_str().unwrap_or("");
            let cursor = msg.content["cursor_pos"].as_u64().unwrap_or(0) as usize;
            let name = word_at(code, byte_of(code, cursor));
            let help = Session::help(name);
            shared.reply(
                shell,
                msg,
                "inspect_reply",
                json!({
                    "status": "ok",
                    "found": help.is_some(),
                    "data": help.map_or(json!({}), |h| json!({"text/plain": h})),
                    "metadata": {},
                }),
            );
        }
        "is_complete_request" => {
            let code = msg.content["code"].as_str().unwrap_or("");
            let status = if session.is_complete(code) {
                json!({"status": "complete"})
            } else {
                json!({"status": "incomplete", "indent": "  "})
            };
            shared.reply(shell, msg, "is_complete_reply", status);
        }
        "history_request" => shared.reply(
            shell,
            msg,
            "history_reply",
            json!({"status": "ok", "history": []}),
        ),
        "comm_info_request" => shared.reply(
            shell,
            msg,
            "comm_info_reply",
            json!({"status": "ok", "comms": {}}),
        ),
        "shutdown_request" => shared.shut_down(shell, msg),
        other => console::to_stderr(&format!(
            "swimlab kernel: no handler for \"{other}\" on the shell channel\n"
        )),
    }
}

/// Data of a value for Jupyter: text, and for a picture PNG and SVG.
fn mime_bundle(v: &rhai::Dynamic) -> (Value, bool) {
    let text = show(v);
    if let Some(p) = v.read_lock::<Picture>() {
        let img = p.image();
        let png = base64::engine::general_purpose::STANDARD.encode(&img.png);
        return (
            json!({"text/plain": text, "image/png": png, "image/svg+xml": img.svg}),
            true,
        );
    }
    (json!({"text/plain": text}), false)
}

fn execute(
    session: &mut Session,
    shell: &zmq::Socket,
    shared: &Shared,
    msg: &Message,
    count: &mut u64,
) {
    let code = msg.content["code"].as_str().unwrap_or("").to_string();
    let silent = msg.content["silent"].as_bool().unwrap_or(false);
    if !silent {
        *count += 1;
        shared.publish(
            Some(msg),
            "execute_input",
            json!({"code": code, "execution_count": *count}),
        );
    }
    let outcome = if code.trim_start().starts_with(':') {
        match session.handle(&code) {
            Reply::Output(s) => {
                if !s.is_empty() {
                    shared.publish(
                        Some(msg),
                        "stream",
                        json!({"name": "stdout", "text": format!("{s}\n")}),
                    );
                }
                Ok(None)
            }
            Reply::Error(e) => Err(e),
            Reply::Quit => Err(":quit ends the shell; in a notebook, shut the kernel down from Jupyter (Kernel > Shut Down)".into()),
        }
    } else {
        session.execute(&code)
    };
    match outcome {
        Ok(value) => {
            if let Some(v) = value.filter(|_| !silent) {
                let (data, picture) = mime_bundle(&v);
                if picture {
                    shared.publish(
                        Some(msg),
                        "display_data",
                        json!({"data": data, "metadata": {}}),
                    );
                } else {
                    shared.publish(
                        Some(msg),
                        "execute_result",
                        json!({"data": data, "metadata": {}, "execution_count": *count}),
                    );
                }
            }
            shared.reply(
                shell,
                msg,
                "execute_reply",
                json!({"status": "ok", "execution_count": *count, "user_expressions": {}, "payload": []}),
            );
        }
        Err(rendered) => {
            let rendered = rendered.trim_end().to_string();
            let evalue = rendered.lines().next().unwrap_or("").to_string();
            let error = json!({
                "ename": "Error",
                "evalue": evalue,
                "traceback": rendered.lines().collect::<Vec<_>>(),
            });
            if !silent {
                shared.publish(Some(msg), "error", error.clone());
            }
            let mut reply = error;
            reply["status"] = json!("error");
            reply["execution_count"] = json!(*count);
            shared.reply(shell, msg, "execute_reply", reply);
        }
    }
}
