//! The little HTTP/1.1 a view speaks: a request's first line and headers read with a size bound
//! and one deadline for the whole head, and whole responses written with `Connection: close`
//! (one request per connection).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Instant;

/// The longest request head read (request line and headers).
const MAX_HEAD: usize = 16 * 1024;

/// A request's method and path (without the query).
pub struct Request {
    pub method: String,
    pub path: String,
}

/// Why no request was read, and the answer it gets (`None`: the connection is closed unanswered).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// Closed, failed or past the deadline before a whole head came: no answer.
    Gone,
    /// Not an HTTP request line (TLS bytes, a line of other words, not text): 400.
    Malformed,
    /// A head longer than [`MAX_HEAD`]: 431.
    TooLarge,
    /// An HTTP version other than 1.0 and 1.1: 505.
    Version,
}

impl Refusal {
    /// The status line and body this refusal is answered with, if any.
    pub fn answer(self) -> Option<(&'static str, &'static [u8])> {
        match self {
            Refusal::Gone => None,
            Refusal::Malformed => Some(("400 Bad Request", b"not an HTTP/1.1 request\n")),
            Refusal::TooLarge => Some((
                "431 Request Header Fields Too Large",
                b"the request head is over 16 KiB\n",
            )),
            Refusal::Version => Some((
                "505 HTTP Version Not Supported",
                b"only HTTP/1.0 and HTTP/1.1 are served\n",
            )),
        }
    }
}

/// Whether `b` may begin a method (a token of capital letters, as every HTTP method is).
fn method_byte(b: u8) -> bool {
    b.is_ascii_uppercase()
}

/// The request line `line` (without its line end) read: method, target, whether the version is
/// served.
fn request_line(line: &[u8]) -> Result<Request, Refusal> {
    let line = std::str::from_utf8(line).map_err(|_| Refusal::Malformed)?;
    let words: Vec<&str> = line.split(' ').collect();
    let [method, target, version] = words[..] else {
        return Err(Refusal::Malformed);
    };
    if method.is_empty() || !method.bytes().all(method_byte) {
        return Err(Refusal::Malformed);
    }
    // The version before the target: HTTP/2's preface, `PRI * HTTP/2.0`, is a version refused.
    let v = version.strip_prefix("HTTP/").ok_or(Refusal::Malformed)?;
    let numbered = v
        .split('.')
        .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    if !numbered {
        return Err(Refusal::Malformed);
    }
    if v != "1.0" && v != "1.1" {
        return Err(Refusal::Version);
    }
    if !target.starts_with('/') {
        return Err(Refusal::Malformed);
    }
    let path = target.split(['?', '#']).next().unwrap_or("").to_string();
    Ok(Request {
        method: method.to_string(),
        path,
    })
}

/// Read a request head from `stream`, all of it by `deadline` (a client that trickles its head
/// byte by byte is cut off there, however often it sends). A request line that cannot be HTTP
/// is refused as soon as its first byte or its whole line has come.
pub fn read_request(stream: &mut TcpStream, deadline: Instant) -> Result<Request, Refusal> {
    let mut head = Vec::with_capacity(1024);
    let mut buf = [0u8; 1024];
    let mut line: Option<Request> = None;
    loop {
        if let Some(end) = head.iter().position(|&b| b == b'\n') {
            if line.is_none() {
                let first = &head[..end];
                line = Some(request_line(first.strip_suffix(b"\r").unwrap_or(first))?);
            }
            if head.windows(4).any(|w| w == b"\r\n\r\n") || head.windows(2).any(|w| w == b"\n\n") {
                return line.ok_or(Refusal::Malformed);
            }
        } else if head.first().is_some_and(|&b| !method_byte(b)) {
            return Err(Refusal::Malformed);
        }
        if head.len() > MAX_HEAD {
            return Err(Refusal::TooLarge);
        }
        let n = read_by(stream, &mut buf, deadline).ok_or(Refusal::Gone)?;
        head.extend_from_slice(&buf[..n]);
    }
}

/// Read what `stream` has into `buf`, waiting no later than `deadline`: the count read, or
/// `None` when the deadline passed, the client closed or the read failed.
pub fn read_by(stream: &mut TcpStream, buf: &mut [u8], deadline: Instant) -> Option<usize> {
    let left = deadline.saturating_duration_since(Instant::now());
    if left.is_zero() {
        return None;
    }
    stream.set_read_timeout(Some(left)).ok()?;
    stream.read(buf).ok().filter(|&n| n > 0)
}

/// Write a whole response: `status` (e.g. "200 OK"), its content type and body.
pub fn respond(stream: &mut TcpStream, status: &str, content_type: &str, body: &[u8]) {
    respond_with(stream, status, content_type, &[], body);
}

/// [`respond`] with extra header lines (`Name: value`).
pub fn respond_with(
    stream: &mut TcpStream,
    status: &str,
    content_type: &str,
    extra: &[&str],
    body: &[u8],
) {
    let mut head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n",
        body.len()
    );
    for line in extra {
        head.push_str(line);
        head.push_str("\r\n");
    }
    head.push_str("\r\n");
    // A client gone away is no error of ours: its connection is dropped.
    let _ = stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body))
        .and_then(|()| stream.flush());
}

/// The head of a Server-Sent Events stream, and the client's reconnection delay (ms).
pub fn start_events(stream: &mut TcpStream) -> std::io::Result<()> {
    stream.write_all(
        b"HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\nretry: 1000\n\n",
    )?;
    stream.flush()
}

/// One event whose data is `json` (one line: JSON has no raw newlines).
pub fn send_event(stream: &mut TcpStream, json: &str) -> std::io::Result<()> {
    stream.write_all(b"data: ")?;
    stream.write_all(json.as_bytes())?;
    stream.write_all(b"\n\n")?;
    stream.flush()
}

/// A comment line, which keeps the connection alive and finds out whether the client is gone.
pub fn send_keepalive(stream: &mut TcpStream) -> std::io::Result<()> {
    stream.write_all(b": keep-alive\n\n")?;
    stream.flush()
}
