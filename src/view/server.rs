//! [`Server`]: a view's page and stream on a local port under a random token. One thread accepts
//! connections, one thread serves each client (at most [`MAX_CLIENTS`] at once). Only GET is
//! served; a wrong token is a 404, as is any other path. Dropping the server closes the slot,
//! shuts the clients' connections, joins every thread and closes the socket.

use super::assets;
use super::http::{self, Request};
use super::slot::{Next, Slot};
use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

/// The most clients served at once; more are answered 503.
pub const MAX_CLIENTS: usize = 64;

/// How often the accepting thread looks whether the server is dropped.
const ACCEPT_POLL: Duration = Duration::from_millis(20);

/// A client's request must arrive within this.
const READ_TIMEOUT: Duration = Duration::from_secs(5);

/// A write that has not gone through after this ends the client (it stopped reading).
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);

/// How often an idle event stream sends a comment to find out whether its client is gone.
const KEEPALIVE: Duration = Duration::from_secs(15);

/// Where to serve.
#[derive(Debug, Clone)]
pub struct ServerOptions {
    /// The address to bind (127.0.0.1 unless the user asks otherwise).
    pub address: IpAddr,
    /// The port (0: any free port).
    pub port: u16,
}

impl Default for ServerOptions {
    fn default() -> Self {
        ServerOptions {
            address: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 0,
        }
    }
}

/// A client's thread and a handle on its connection, to shut it from outside.
type Client = (JoinHandle<()>, TcpStream);

struct Shared {
    slot: Arc<Slot>,
    token: String,
    stop: AtomicBool,
    clients: Mutex<Vec<Client>>,
}

/// A view's server. See the [module docs](self).
pub struct Server {
    shared: Arc<Shared>,
    local: SocketAddr,
    url: String,
    accept: Option<JoinHandle<()>>,
}

/// A random token of 128 bits from the operating system, as 32 hex digits.
fn token() -> io::Result<String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| io::Error::other(e.to_string()))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

impl Server {
    /// Serve the frames of `slot` at `options`; the error is the socket's (the port in use, an
    /// address not of this machine).
    pub fn start(slot: Arc<Slot>, options: &ServerOptions) -> io::Result<Server> {
        let listener = TcpListener::bind(SocketAddr::new(options.address, options.port))?;
        listener.set_nonblocking(true)?;
        let local = listener.local_addr()?;
        let shared = Arc::new(Shared {
            slot,
            token: token()?,
            stop: AtomicBool::new(false),
            clients: Mutex::new(Vec::new()),
        });
        let host = match local.ip() {
            IpAddr::V4(ip) if ip.is_unspecified() => IpAddr::V4(Ipv4Addr::LOCALHOST),
            ip => ip,
        };
        let url = format!(
            "http://{}/{}/",
            SocketAddr::new(host, local.port()),
            shared.token
        );
        let s = shared.clone();
        let accept = std::thread::Builder::new()
            .name("swimlab-view".into())
            .spawn(move || accept_loop(&listener, &s))?;
        Ok(Server {
            shared,
            local,
            url,
            accept: Some(accept),
        })
    }

    /// The page's address, ending in `/`: `http://127.0.0.1:PORT/TOKEN/`.
    pub fn url(&self) -> &str {
        &self.url
    }

    /// The socket's address.
    pub fn local_addr(&self) -> SocketAddr {
        self.local
    }
}

impl std::fmt::Debug for Server {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Server").field("url", &self.url).finish()
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        self.shared.slot.close();
        if let Some(a) = self.accept.take() {
            let _ = a.join();
        }
        let clients = std::mem::take(&mut *lock(&self.shared.clients));
        for (_, stream) in &clients {
            let _ = stream.shutdown(std::net::Shutdown::Both);
        }
        for (thread, _) in clients {
            let _ = thread.join();
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    while !shared.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => admit(stream, shared),
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => std::thread::sleep(ACCEPT_POLL),
            // A connection that failed before it was accepted: the next one may do.
            Err(_) => std::thread::sleep(ACCEPT_POLL),
        }
    }
}

/// Serve `stream` on a thread of its own, or answer 503 when too many are served.
fn admit(mut stream: TcpStream, shared: &Arc<Shared>) {
    let ready = stream
        .set_nonblocking(false)
        .and_then(|()| stream.set_read_timeout(Some(READ_TIMEOUT)))
        .and_then(|()| stream.set_write_timeout(Some(WRITE_TIMEOUT)))
        .and_then(|()| stream.set_nodelay(true));
    if ready.is_err() {
        return;
    }
    let mut clients = lock(&shared.clients);
    // Those that ended are joined and forgotten.
    let (done, live): (Vec<Client>, Vec<Client>) = std::mem::take(&mut *clients)
        .into_iter()
        .partition(|(t, _)| t.is_finished());
    *clients = live;
    for (t, _) in done {
        let _ = t.join();
    }
    if clients.len() >= MAX_CLIENTS {
        drop(clients);
        http::respond(
            &mut stream,
            "503 Service Unavailable",
            "text/plain",
            b"too many clients\n",
        );
        return;
    }
    let Ok(handle) = stream.try_clone() else {
        return;
    };
    let s = shared.clone();
    let spawned = std::thread::Builder::new()
        .name("swimlab-view-client".into())
        .spawn(move || serve(stream, &s));
    if let Ok(thread) = spawned {
        clients.push((thread, handle));
    }
}

/// Answer the one request of `stream`, then close it (the server's own handle on the connection
/// would otherwise keep it open).
fn serve(mut stream: TcpStream, shared: &Shared) {
    answer(&mut stream, shared);
    let _ = stream.shutdown(std::net::Shutdown::Both);
}

fn answer(stream: &mut TcpStream, shared: &Shared) {
    let Some(Request { method, path }) = http::read_request(stream) else {
        return;
    };
    let prefix = format!("/{}", shared.token);
    let rest = match path.strip_prefix(&prefix) {
        Some("") => {
            if method == "GET" {
                let to = format!("Location: {prefix}/");
                http::respond_with(stream, "301 Moved Permanently", "text/plain", &[&to], b"");
            } else {
                not_allowed(stream);
            }
            return;
        }
        Some(rest) if rest.starts_with('/') => &rest[1..],
        _ => {
            http::respond(stream, "404 Not Found", "text/plain", b"not found\n");
            return;
        }
    };
    if method != "GET" {
        not_allowed(stream);
        return;
    }
    match rest {
        "frame" => match shared.slot.latest() {
            Some(f) => http::respond(stream, "200 OK", "application/json", f.as_bytes()),
            None => http::respond(stream, "404 Not Found", "text/plain", b"no frame yet\n"),
        },
        "frames" => stream_frames(stream, shared),
        other => match assets::find(other) {
            Some(a) => http::respond(stream, "200 OK", a.content_type, a.body),
            None => http::respond(stream, "404 Not Found", "text/plain", b"not found\n"),
        },
    }
}

fn not_allowed(stream: &mut TcpStream) {
    http::respond_with(
        stream,
        "405 Method Not Allowed",
        "text/plain",
        &["Allow: GET"],
        b"only GET is served\n",
    );
}

/// Every new frame once, as Server-Sent Events, until the client goes or the server stops. A
/// client slower than the frames gets the latest when it is ready (the others are skipped).
fn stream_frames(stream: &mut TcpStream, shared: &Shared) {
    if http::start_events(stream).is_err() {
        return;
    }
    let mut seen = 0;
    loop {
        if shared.stop.load(Ordering::SeqCst) {
            return;
        }
        let sent = match shared.slot.next_after(seen, KEEPALIVE) {
            Next::Frame(seq, frame) => {
                seen = seq;
                http::send_event(stream, &frame)
            }
            Next::Timeout => http::send_keepalive(stream),
            Next::Closed => return,
        };
        if sent.is_err() {
            return;
        }
    }
}
