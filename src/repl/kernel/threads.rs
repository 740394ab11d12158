//! The kernel's threads: the sockets bound, the IOPub publisher, the heartbeat and the control
//! thread started, and the shell loop run on the main thread until a shutdown.

use super::connection::{bind, Connection};
use super::control::control_loop;
use super::output::route_output;
use super::shared::Shared;
use super::shell::serve;
use super::wire::{Headers, Key, Message};
use crate::repl::session::Session;
use crate::script::{console, interrupt, progress};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::channel;
use std::sync::{Arc, Mutex};
use std::time::Duration;

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
