//! [`Server`]: a view's page and stream on a local port under a random token. One thread accepts
//! connections (blocked in `accept` until one comes, woken by a connection of its own when the
//! server is dropped: an idle view costs no CPU), one thread serves each client. A client first
//! has [`HEAD_DEADLINE`] for its whole request head; at most [`MAX_PENDING`] may be reading
//! theirs at once (past that the longest waiting is cut off, so clients that trickle or idle
//! cannot lock an honest one out), and at most [`MAX_CLIENTS`] are served at once past their head
//! (more are answered 503). A broken request is answered 400, a head over 16 KiB 431, another
//! HTTP version 505. Only GET is served; a wrong token (compared in constant time) is a 404, as
//! is any other path. Dropping the server closes the slot, shuts the clients' connections, joins
//! every thread and closes the socket.

use super::assets;
use super::http::{self, Request};
use super::slot::{Next, Slot};
use std::io;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The most clients served at once past their request head; more are answered 503.
pub const MAX_CLIENTS: usize = 64;

/// The most connections reading their request head at once; a new one past this cuts off the
/// one that has waited longest.
pub const MAX_PENDING: usize = 256;

/// A client's whole request head must arrive within this of its connection.
pub const HEAD_DEADLINE: Duration = Duration::from_secs(5);

/// How long a dropped server waits for its own connection to wake its accepting thread.
const WAKE_TIMEOUT: Duration = Duration::from_secs(2);

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

/// A client's thread, a handle on its connection (to shut it from outside), whether it is still
/// reading its request head, and since when.
struct Client {
    thread: JoinHandle<()>,
    stream: TcpStream,
    reading: Arc<AtomicBool>,
    since: Instant,
}

struct Shared {
    slot: Arc<Slot>,
    token: String,
    stop: AtomicBool,
    clients: Mutex<Vec<Client>>,
    /// How many clients are served past their request head now.
    served: AtomicUsize,
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
        let local = listener.local_addr()?;
        let shared = Arc::new(Shared {
            slot,
            token: token()?,
            stop: AtomicBool::new(false),
            clients: Mutex::new(Vec::new()),
            served: AtomicUsize::new(0),
        });
        let url = format!("http://{}/{}/", reachable(local), shared.token);
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
            // The accepting thread is blocked in accept: a connection of our own wakes it, and it
            // sees the stop. Should that connection fail, the thread is left to end at the next
            // connection rather than the drop waiting for one.
            if wake(self.local) {
                let _ = a.join();
            }
        }
        let clients = std::mem::take(&mut *lock(&self.shared.clients));
        for c in &clients {
            let _ = c.stream.shutdown(std::net::Shutdown::Both);
        }
        for c in clients {
            let _ = c.thread.join();
        }
    }
}

/// The address a client on this machine reaches the socket bound to `local` at: the loopback
/// of its family where it is bound to every address.
fn reachable(local: SocketAddr) -> SocketAddr {
    let ip = match local.ip() {
        IpAddr::V4(ip) if ip.is_unspecified() => IpAddr::V4(Ipv4Addr::LOCALHOST),
        IpAddr::V6(ip) if ip.is_unspecified() => IpAddr::V6(Ipv6Addr::LOCALHOST),
        ip => ip,
    };
    SocketAddr::new(ip, local.port())
}

/// Connect to the server bound to `local`, to wake its accept.
fn wake(local: SocketAddr) -> bool {
    TcpStream::connect_timeout(&reachable(local), WAKE_TIMEOUT).is_ok()
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    loop {
        let accepted = listener.accept();
        if shared.stop.load(Ordering::SeqCst) {
            return;
        }
        match accepted {
            Ok((stream, _)) => admit(stream, shared),
            // A connection that failed before it was accepted, or too many open files: a pause
            // so that a lasting failure does not spin, then the next one may do.
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// Serve `stream` on a thread of its own. Past [`MAX_PENDING`] connections reading their head,
/// the one that has waited longest is cut off.
fn admit(stream: TcpStream, shared: &Arc<Shared>) {
    let ready = stream
        .set_write_timeout(Some(WRITE_TIMEOUT))
        .and_then(|()| stream.set_nodelay(true));
    if ready.is_err() {
        return;
    }
    let mut clients = lock(&shared.clients);
    // Those that ended are joined and forgotten.
    let (done, live): (Vec<Client>, Vec<Client>) = std::mem::take(&mut *clients)
        .into_iter()
        .partition(|c| c.thread.is_finished());
    *clients = live;
    for c in done {
        let _ = c.thread.join();
    }
    let mut reading: Vec<&Client> = clients
        .iter()
        .filter(|c| c.reading.load(Ordering::SeqCst))
        .collect();
    if reading.len() >= MAX_PENDING {
        reading.sort_by_key(|c| c.since);
        for c in &reading[..=reading.len() - MAX_PENDING] {
            c.reading.store(false, Ordering::SeqCst);
            let _ = c.stream.shutdown(std::net::Shutdown::Both);
        }
    }
    let Ok(handle) = stream.try_clone() else {
        return;
    };
    let flag = Arc::new(AtomicBool::new(true));
    let since = Instant::now();
    let (s, f) = (shared.clone(), flag.clone());
    let spawned = std::thread::Builder::new()
        .name("swimlab-view-client".into())
        .spawn(move || serve(stream, &s, &f, since + HEAD_DEADLINE));
    if let Ok(thread) = spawned {
        clients.push(Client {
            thread,
            stream: handle,
            reading: flag,
            since,
        });
    }
}

/// Whether the path segment `given` is the token, compared in constant time (every byte looked
/// at whatever the first difference): the time an answer takes says nothing about the token.
fn is_token(given: &[u8], token: &[u8]) -> bool {
    if given.len() != token.len() {
        return false;
    }
    let diff = given
        .iter()
        .zip(token)
        .fold(0u8, |d, (a, b)| d | (std::hint::black_box(*a) ^ *b));
    diff == 0
}

/// Answer the one request of `stream`, its head read by `deadline`, then close it (the server's
/// own handle on the connection would otherwise keep it open).
fn serve(mut stream: TcpStream, shared: &Shared, reading: &AtomicBool, deadline: Instant) {
    let request = http::read_request(&mut stream, deadline);
    reading.store(false, Ordering::SeqCst);
    match request {
        Ok(request) => {
            if shared.served.fetch_add(1, Ordering::SeqCst) < MAX_CLIENTS {
                answer(&mut stream, shared, request);
            } else {
                http::respond(
                    &mut stream,
                    "503 Service Unavailable",
                    "text/plain",
                    b"too many clients\n",
                );
            }
            shared.served.fetch_sub(1, Ordering::SeqCst);
        }
        Err(refusal) => {
            if let Some((status, body)) = refusal.answer() {
                http::respond(&mut stream, status, "text/plain", body);
                linger(&mut stream);
            }
        }
    }
    let _ = stream.shutdown(std::net::Shutdown::Both);
}

/// After answering a request whose rest was not read: say no more will be written, and read
/// what the client still sends, a bounded amount until [`LINGER`] has passed in all, so that
/// closing with unread bytes does not reset the connection before the client has read the
/// answer (and a client that trickles bytes holds the thread no longer).
fn linger(stream: &mut TcpStream) {
    let _ = stream.shutdown(std::net::Shutdown::Write);
    let end = Instant::now() + LINGER;
    let mut buf = [0u8; 4096];
    let mut left: usize = 64 * 1024;
    while left > 0 {
        match http::read_by(stream, &mut buf, end) {
            Some(n) => left = left.saturating_sub(n),
            None => return,
        }
    }
}

/// How long a refused connection is read after its answer, in all.
const LINGER: Duration = Duration::from_millis(300);

fn answer(stream: &mut TcpStream, shared: &Shared, Request { method, path }: Request) {
    // The first segment is the token: `/TOKEN`, `/TOKEN/`, `/TOKEN/frame`.
    let after = path.strip_prefix('/').unwrap_or(&path);
    let (first, rest) = match after.find('/') {
        Some(k) => (&after[..k], Some(&after[k..])),
        None => (after, None),
    };
    let prefix = format!("/{}", shared.token);
    let rest = match is_token(first.as_bytes(), shared.token.as_bytes()).then_some(rest) {
        Some(None) => {
            if method == "GET" {
                let to = format!("Location: {prefix}/");
                http::respond_with(stream, "301 Moved Permanently", "text/plain", &[&to], b"");
            } else {
                not_allowed(stream);
            }
            return;
        }
        Some(Some(rest)) => &rest[1..],
        None => {
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

#[cfg(test)]
mod tests {
    use super::is_token;

    #[test]
    fn the_token_is_matched_whole() {
        let token = b"0123456789abcdef0123456789abcdef";
        assert!(is_token(token, token));
        assert!(!is_token(b"0123456789abcdef0123456789abcdee", token));
        assert!(!is_token(b"1123456789abcdef0123456789abcdef", token));
        assert!(!is_token(b"0123456789abcdef", token));
        assert!(!is_token(b"", token));
    }
}
