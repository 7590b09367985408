//! The editor's HTTP/1.1 server, as small as the page needs: one request per connection (every
//! answer says `Connection: close`), each connection on its own thread, at most
//! [`MAX_CONNECTIONS`] at once, and every read and write bounded in time ([`TIMEOUT`]), so a
//! client that sends half a request or never reads its answer holds one thread for seconds,
//! never the server. Heads are bounded ([`MAX_HEAD`]), bodies too ([`MAX_BODY`], given by
//! `Content-Length`; chunked bodies are refused), and a request's head is checked
//! ([`Handler::admit`]) before its body is read.

use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The largest request body read, bytes.
pub const MAX_BODY: usize = 1 << 20;
/// The largest request head (request line and headers), bytes.
pub const MAX_HEAD: usize = 16 << 10;
/// The most headers a request may have.
const MAX_HEADERS: usize = 100;
/// Connections served at once; more are answered 503 at once.
pub const MAX_CONNECTIONS: usize = 32;
/// How long a client has to send its whole request, and to take its answer.
pub const TIMEOUT: Duration = Duration::from_secs(10);
/// How long a closing connection is read (and what is read dropped) so that the client gets
/// its answer rather than a reset for what it sent and was not read.
const LINGER: Duration = Duration::from_secs(2);

/// A request's line and headers.
pub struct Head {
    /// `GET`, `POST`, …
    pub method: String,
    /// The path, without the query (the page's query is read by the page alone).
    pub path: String,
    /// Names lower-cased, values trimmed, in order.
    headers: Vec<(String, String)>,
}

impl Head {
    /// The value of the header `name` (lower case); `None` when absent or given more than
    /// once, so that two values cannot be read two ways.
    pub fn header(&self, name: &str) -> Option<&str> {
        let mut found = self.headers.iter().filter(|(n, _)| n == name);
        match (found.next(), found.next()) {
            (Some((_, v)), None) => Some(v),
            _ => None,
        }
    }

    /// How many times the header `name` (lower case) is given.
    pub fn count(&self, name: &str) -> usize {
        self.headers.iter().filter(|(n, _)| n == name).count()
    }
}

/// An answer.
pub struct Response {
    /// The status code.
    pub status: u16,
    /// `Content-Type`.
    pub kind: &'static str,
    /// Headers beside those every answer has.
    pub headers: Vec<(&'static str, String)>,
    /// The body.
    pub body: Vec<u8>,
}

impl Response {
    /// An answer of `status` with a body of type `kind`.
    pub fn new(status: u16, kind: &'static str, body: impl Into<Vec<u8>>) -> Response {
        Response {
            status,
            kind,
            headers: Vec::new(),
            body: body.into(),
        }
    }

    /// A JSON answer.
    pub fn json(status: u16, value: &serde_json::Value) -> Response {
        Response::new(status, "application/json", value.to_string())
    }

    /// `{"error": message}` with `status`.
    pub fn error(status: u16, message: impl Into<String>) -> Response {
        Response::json(status, &serde_json::json!({ "error": message.into() }))
    }
}

/// What the server does with requests.
pub trait Handler: Send + Sync + 'static {
    /// Checks a request's head before its body is read: an answer refuses the request.
    fn admit(&self, head: &Head) -> Option<Response>;
    /// Answers an admitted request with its body.
    fn answer(&self, head: &Head, body: &[u8]) -> Response;
}

/// Serves `listener` with `handler` until the process is stopped.
pub fn serve(listener: TcpListener, handler: Arc<dyn Handler>) {
    let active = Arc::new(AtomicUsize::new(0));
    loop {
        let stream = match listener.accept() {
            Ok((s, _)) => s,
            // Out of file descriptors, or a connection reset before it was taken: wait, go on.
            Err(_) => {
                std::thread::sleep(Duration::from_millis(20));
                continue;
            }
        };
        if active.fetch_add(1, Ordering::AcqRel) >= MAX_CONNECTIONS {
            active.fetch_sub(1, Ordering::AcqRel);
            let mut stream = stream;
            let _ = stream.set_write_timeout(Some(Duration::from_secs(1)));
            let _ = write_response(
                &mut stream,
                &Response::error(503, "the editor is busy with other connections; try again"),
            );
            continue;
        }
        let slot = Slot(Arc::clone(&active));
        let handler = Arc::clone(&handler);
        let spawned = std::thread::Builder::new()
            .name("latvox-view".into())
            .spawn(move || {
                let _slot = slot;
                connection(stream, handler.as_ref());
            });
        // No thread to be had: the connection is dropped (closed), and its slot with it.
        drop(spawned);
    }
}

/// A connection's place among [`MAX_CONNECTIONS`], given back when dropped (a panic too).
struct Slot(Arc<AtomicUsize>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Why a request was not read.
#[derive(Debug)]
enum Unread {
    /// The client closed before sending a whole head: nothing to answer.
    Closed,
    /// It did not send it in time.
    Late,
    /// Its head is larger than [`MAX_HEAD`].
    Large,
    /// Its head is not HTTP/1.x.
    Bad(&'static str),
}

fn connection(mut stream: TcpStream, handler: &dyn Handler) {
    let deadline = Instant::now() + TIMEOUT;
    let _ = stream.set_write_timeout(Some(TIMEOUT));
    let _ = stream.set_nodelay(true);
    let response = match read_head(&mut stream, deadline) {
        Err(Unread::Closed) => return,
        Err(Unread::Late) => Response::error(408, "the request did not come in time"),
        Err(Unread::Large) => Response::error(431, "the request's head is too large"),
        Err(Unread::Bad(why)) => Response::error(400, why),
        Ok((head, start)) => match handler.admit(&head) {
            Some(refusal) => refusal,
            None => match body(&mut stream, &head, start, deadline) {
                Err(r) => r,
                Ok(body) => {
                    let run = std::panic::AssertUnwindSafe(|| handler.answer(&head, &body));
                    std::panic::catch_unwind(run).unwrap_or_else(|_| {
                        Response::error(500, "internal error (a bug in latvox)")
                    })
                }
            },
        },
    };
    let _ = write_response(&mut stream, &response);
    linger(stream);
}

/// Reads from `stream` into `buf` before `deadline`; `Ok(0)` at the end of the stream.
fn read_by(stream: &mut TcpStream, buf: &mut [u8], deadline: Instant) -> Result<usize, Unread> {
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(Unread::Late);
        }
        let _ = stream.set_read_timeout(Some(left));
        match stream.read(buf) {
            Ok(n) => return Ok(n),
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Err(Unread::Late)
            }
            Err(_) => return Err(Unread::Closed),
        }
    }
}

/// The request's head, and the bytes read past it (the body's start).
fn read_head(stream: &mut TcpStream, deadline: Instant) -> Result<(Head, Vec<u8>), Unread> {
    let mut buf = Vec::new();
    let mut chunk = [0u8; 4096];
    let end = loop {
        if let Some(end) = head_end(&buf) {
            break end;
        }
        if buf.len() > MAX_HEAD {
            return Err(Unread::Large);
        }
        let n = read_by(stream, &mut chunk, deadline)?;
        if n == 0 {
            return Err(if buf.is_empty() {
                Unread::Closed
            } else {
                Unread::Bad("the request ends inside its head")
            });
        }
        buf.extend_from_slice(&chunk[..n]);
    };
    if end > MAX_HEAD {
        return Err(Unread::Large);
    }
    let rest = buf.split_off(end);
    Ok((parse_head(&buf)?, rest))
}

/// Where the head ends (past its blank line), if it has.
fn head_end(buf: &[u8]) -> Option<usize> {
    buf.windows(2).enumerate().find_map(|(i, w)| match w {
        b"\n\n" => Some(i + 2),
        b"\n\r" if buf.get(i + 2) == Some(&b'\n') => Some(i + 3),
        _ => None,
    })
}

fn parse_head(bytes: &[u8]) -> Result<Head, Unread> {
    let text =
        std::str::from_utf8(bytes).map_err(|_| Unread::Bad("the request's head is not text"))?;
    let mut lines = text.split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l));
    let line = lines.next().unwrap_or_default();
    let mut parts = line.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(Unread::Bad("the request line is not METHOD PATH HTTP/1.1"));
    };
    if method.is_empty() || !method.bytes().all(|b| b.is_ascii_uppercase()) {
        return Err(Unread::Bad("the request's method is not a name"));
    }
    if !version.starts_with("HTTP/1.") {
        return Err(Unread::Bad("the request is not HTTP/1.x"));
    }
    // Only a path: a full URL ("http://host/…") would name a host the Host check did not see.
    if !target.starts_with('/') || target.bytes().any(|b| b <= b' ' || b == 0x7f) {
        return Err(Unread::Bad("the request's target is not a path"));
    }
    let path = target.split_once('?').map_or(target, |(p, _)| p);
    let mut headers = Vec::new();
    for line in lines.take_while(|l| !l.is_empty()) {
        let Some((name, value)) = line.split_once(':') else {
            return Err(Unread::Bad("a header is not NAME: VALUE"));
        };
        let token = |b: u8| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b);
        if name.is_empty() || !name.bytes().all(token) {
            return Err(Unread::Bad("a header's name is not a name"));
        }
        if headers.len() == MAX_HEADERS {
            return Err(Unread::Bad("the request has too many headers"));
        }
        headers.push((name.to_ascii_lowercase(), value.trim().to_string()));
    }
    Ok(Head {
        method: method.to_string(),
        path: path.to_string(),
        headers,
    })
}

/// The request's body (`start`: what was read of it with the head), up to [`MAX_BODY`].
fn body(
    stream: &mut TcpStream,
    head: &Head,
    mut start: Vec<u8>,
    deadline: Instant,
) -> Result<Vec<u8>, Response> {
    if head.count("transfer-encoding") > 0 {
        return Err(Response::error(
            501,
            "chunked request bodies are not read: send Content-Length",
        ));
    }
    let length = match (head.count("content-length"), head.header("content-length")) {
        (0, _) => 0,
        (_, Some(v)) if !v.is_empty() && v.bytes().all(|b| b.is_ascii_digit()) => {
            v.parse::<usize>().unwrap_or(usize::MAX)
        }
        _ => {
            return Err(Response::error(
                400,
                "the request's Content-Length is not one number",
            ))
        }
    };
    if length > MAX_BODY {
        return Err(Response::error(413, "the request is larger than 1 MB"));
    }
    if head
        .header("expect")
        .is_some_and(|e| e.eq_ignore_ascii_case("100-continue"))
    {
        let _ = stream.write_all(b"HTTP/1.1 100 Continue\r\n\r\n");
    }
    start.truncate(length);
    let mut chunk = [0u8; 16384];
    while start.len() < length {
        let want = (length - start.len()).min(chunk.len());
        match read_by(stream, &mut chunk[..want], deadline) {
            Ok(0) => return Err(Response::error(400, "the request ends inside its body")),
            Ok(n) => start.extend_from_slice(&chunk[..n]),
            Err(Unread::Late) => {
                return Err(Response::error(408, "the request did not come in time"))
            }
            Err(_) => return Err(Response::error(400, "the request's body could not be read")),
        }
    }
    Ok(start)
}

fn reason(status: u16) -> &'static str {
    match status {
        100 => "Continue",
        200 => "OK",
        202 => "Accepted",
        400 => "Bad Request",
        401 => "Unauthorized",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        409 => "Conflict",
        413 => "Content Too Large",
        422 => "Unprocessable Content",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        501 => "Not Implemented",
        503 => "Service Unavailable",
        _ => "",
    }
}

fn write_response(stream: &mut TcpStream, r: &Response) -> std::io::Result<()> {
    let mut head = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nConnection: close\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n\
         Referrer-Policy: no-referrer\r\nX-Frame-Options: DENY\r\n",
        r.status,
        reason(r.status),
        r.kind,
        r.body.len()
    );
    for (name, value) in &r.headers {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str("\r\n");
    stream.write_all(head.as_bytes())?;
    stream.write_all(&r.body)?;
    stream.flush()
}

/// Closes the connection after the answer: the client sees its end, and what it still sends
/// (a body not read) is read and dropped for a moment, so the answer is not lost to a reset.
fn linger(mut stream: TcpStream) {
    let _ = stream.shutdown(Shutdown::Write);
    let until = Instant::now() + LINGER;
    let mut scratch = [0u8; 16384];
    let mut dropped = 0usize;
    while dropped < 4 * MAX_BODY {
        match read_by(&mut stream, &mut scratch, until) {
            Ok(0) | Err(_) => break,
            Ok(n) => dropped += n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heads_are_parsed_or_refused() {
        let h = parse_head(b"POST /api/save?x=1 HTTP/1.1\r\nHost: a:1\r\nX-Y:  z \r\n").unwrap();
        assert_eq!((h.method.as_str(), h.path.as_str()), ("POST", "/api/save"));
        assert_eq!(h.header("host"), Some("a:1"));
        assert_eq!(h.header("x-y"), Some("z"));
        let twice = parse_head(b"GET / HTTP/1.1\r\nHost: a\r\nhost: b\r\n").unwrap();
        assert_eq!((twice.header("host"), twice.count("host")), (None, 2));
        for bad in [
            &b"GET /\r\n"[..],
            b"GET http://evil/ HTTP/1.1\r\n",
            b"get / HTTP/1.1\r\n",
            b"GET / HTTP/2\r\n",
            b"GET / HTTP/1.1\r\nno colon\r\n",
            b"GET / HTTP/1.1\r\nbad name: x\r\n",
            b"GET /\xff HTTP/1.1\r\n",
        ] {
            assert!(parse_head(bad).is_err(), "{}", String::from_utf8_lossy(bad));
        }
        assert_eq!(head_end(b"GET / HTTP/1.1\r\nA: b\r\n\r\nbody"), Some(24));
        assert_eq!(head_end(b"GET / HTTP/1.1\nA: b\n\nbody"), Some(21));
        assert_eq!(head_end(b"GET / HTTP/1.1\r\nA: b\r\n"), None);
    }
}
