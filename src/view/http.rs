//! The little HTTP/1.1 a view speaks: a request's first line and headers read with a size bound,
//! and whole responses written with `Connection: close` (one request per connection).

use std::io::{Read, Write};
use std::net::TcpStream;

/// The longest request head read (request line and headers).
const MAX_HEAD: usize = 16 * 1024;

/// A request's method and path (without the query).
pub struct Request {
    pub method: String,
    pub path: String,
}

/// Read a request head from `stream`; `None` if the client sent none (closed, timed out, too
/// long or not HTTP).
pub fn read_request(stream: &mut TcpStream) -> Option<Request> {
    let mut head = Vec::with_capacity(1024);
    let mut buf = [0u8; 1024];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") && !head.windows(2).any(|w| w == b"\n\n") {
        if head.len() > MAX_HEAD {
            return None;
        }
        let n = stream.read(&mut buf).ok()?;
        if n == 0 {
            return None;
        }
        head.extend_from_slice(&buf[..n]);
    }
    let head = String::from_utf8_lossy(&head);
    let mut words = head.lines().next()?.split_whitespace();
    let method = words.next()?.to_string();
    let target = words.next()?;
    if !words.next()?.starts_with("HTTP/1.") {
        return None;
    }
    let path = target.split(['?', '#']).next().unwrap_or("").to_string();
    Some(Request { method, path })
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
