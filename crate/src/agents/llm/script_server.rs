//! A scripted OpenAI-compatible server on 127.0.0.1 for tests: it answers requests with a
//! queue of prepared replies, in order, and records every request for assertions.
//!
//! ```no_run
//! use coma::agents::llm::script_server::{ScriptServer, ScriptedReply};
//! let server = ScriptServer::start([
//!     ScriptedReply::error(429, "slow down").with_header("Retry-After", "0"),
//!     ScriptedReply::completion(r#"{"segments": []}"#),
//! ])
//! .unwrap();
//! // … point an LlmClient at server.base_url(), then:
//! assert_eq!(server.requests().len(), 2);
//! ```
//!
//! Replies can also come from a JSON-lines fixture ([`ScriptedReply::from_json_lines`]), so
//! replies recorded from real servers can be committed under `tests/fixtures/llm/`.
//!
//! It is deliberately minimal HTTP/1.1: one request per connection (every reply says
//! `Connection: close`), bodies framed by `Content-Length` only, one thread per connection so
//! that a delayed reply does not hold up the client's retry.

use serde_json::{json, Value};
use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

/// The most header bytes read from a request.
const MAX_HEAD_BYTES: usize = 64 * 1024;
/// The largest request body accepted.
const MAX_BODY_BYTES: usize = 32 << 20;

/// One prepared reply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScriptedReply {
    /// The HTTP status.
    pub status: u16,
    /// Extra headers (`Content-Type` defaults to `application/json`).
    pub headers: Vec<(String, String)>,
    /// The body, sent as it is.
    pub body: String,
    /// How long to wait before answering (to provoke client timeouts).
    pub delay: Duration,
}

impl ScriptedReply {
    /// A reply with this status and body.
    pub fn new(status: u16, body: impl Into<String>) -> Self {
        ScriptedReply {
            status,
            headers: Vec::new(),
            body: body.into(),
            delay: Duration::ZERO,
        }
    }

    /// A successful chat completion whose assistant message is `content`.
    pub fn completion(content: &str) -> Self {
        let body = json!({
            "id": "chatcmpl-script",
            "object": "chat.completion",
            "model": "script",
            "choices": [{
                "index": 0,
                "message": {"role": "assistant", "content": content},
                "finish_reason": "stop",
            }],
            "usage": {"prompt_tokens": 10, "completion_tokens": 5, "total_tokens": 15},
        });
        ScriptedReply::new(200, body.to_string())
    }

    /// An OpenAI-style error reply: `{"error": {"message": …}}`.
    pub fn error(status: u16, message: &str) -> Self {
        ScriptedReply::new(status, json!({"error": {"message": message}}).to_string())
    }

    /// The same reply with one more header.
    pub fn with_header(mut self, name: &str, value: &str) -> Self {
        self.headers.push((name.to_string(), value.to_string()));
        self
    }

    /// The same reply, sent after `delay`.
    pub fn with_delay(mut self, delay: Duration) -> Self {
        self.delay = delay;
        self
    }

    /// Replies from JSON lines, one object a line; blank lines and lines starting with `#` or
    /// `//` are skipped. Members (all optional):
    /// - `status`: the HTTP status (200);
    /// - `body`: a string sent as it is, or any other JSON value, sent serialised;
    /// - `content`: instead of `body`, a chat completion with this assistant content;
    /// - `headers`: an object of header names to string values;
    /// - `delay_ms`: the delay before answering.
    ///
    /// ```text
    /// {"status": 400, "body": {"error": {"message": "response_format is not supported"}}}
    /// {"content": "{\"segments\": []}"}
    /// ```
    pub fn from_json_lines(text: &str) -> Result<Vec<ScriptedReply>, String> {
        let mut replies = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with("//") {
                continue;
            }
            let at = |what: &str| format!("line {}: {what}", i + 1);
            let value: Value = serde_json::from_str(line).map_err(|e| at(&e.to_string()))?;
            let status = match value.get("status") {
                None => 200,
                Some(s) => s
                    .as_u64()
                    .and_then(|s| u16::try_from(s).ok())
                    .filter(|s| (100..1000).contains(s))
                    .ok_or_else(|| at("status must be a 3-digit number"))?,
            };
            let mut reply = match (value.get("content"), value.get("body")) {
                (Some(content), _) => {
                    let content = content
                        .as_str()
                        .ok_or_else(|| at("content must be a string"))?;
                    ScriptedReply::completion(content)
                }
                (None, Some(Value::String(body))) => ScriptedReply::new(status, body.clone()),
                (None, Some(body)) => ScriptedReply::new(status, body.to_string()),
                (None, None) => ScriptedReply::new(status, ""),
            };
            reply.status = status;
            if let Some(headers) = value.get("headers") {
                let headers = headers
                    .as_object()
                    .ok_or_else(|| at("headers must be an object"))?;
                for (name, v) in headers {
                    let v = v
                        .as_str()
                        .ok_or_else(|| at("header values must be strings"))?;
                    reply = reply.with_header(name, v);
                }
            }
            if let Some(ms) = value.get("delay_ms") {
                let ms = ms.as_u64().ok_or_else(|| at("delay_ms must be a number"))?;
                reply.delay = Duration::from_millis(ms);
            }
            replies.push(reply);
        }
        Ok(replies)
    }
}

/// A request as the server received it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordedRequest {
    /// `POST`, `GET`, …
    pub method: String,
    /// The request target, e.g. `/v1/chat/completions`.
    pub path: String,
    /// Headers, names in lower case, in order.
    pub headers: Vec<(String, String)>,
    /// The body (lossily decoded as UTF-8).
    pub body: String,
}

impl RecordedRequest {
    /// A header's value by (case-insensitive) name.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    /// The body as JSON (`Value::Null` when it is not JSON).
    pub fn json(&self) -> Value {
        serde_json::from_str(&self.body).unwrap_or(Value::Null)
    }
}

struct Shared {
    replies: Mutex<VecDeque<ScriptedReply>>,
    requests: Mutex<Vec<RecordedRequest>>,
    stop: AtomicBool,
}

/// Locks ignoring poison: a panicking test thread must not turn into a second, confusing panic.
fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The running server; dropping it stops it.
pub struct ScriptServer {
    addr: SocketAddr,
    shared: Arc<Shared>,
    accept_thread: Option<JoinHandle<()>>,
}

impl ScriptServer {
    /// Starts a server on a free port of 127.0.0.1 that will answer with `replies`, in order.
    /// Once they are used up it answers 410 with an error saying so (not retried by the
    /// client, so a test that makes more requests than it scripted fails fast).
    pub fn start(replies: impl IntoIterator<Item = ScriptedReply>) -> io::Result<Self> {
        let listener = TcpListener::bind(("127.0.0.1", 0))?;
        let addr = listener.local_addr()?;
        let shared = Arc::new(Shared {
            replies: Mutex::new(replies.into_iter().collect()),
            requests: Mutex::new(Vec::new()),
            stop: AtomicBool::new(false),
        });
        let accept_shared = Arc::clone(&shared);
        let accept_thread = std::thread::Builder::new()
            .name("llm-script-server".into())
            .spawn(move || {
                for stream in listener.incoming() {
                    if accept_shared.stop.load(Ordering::SeqCst) {
                        break;
                    }
                    let Ok(stream) = stream else { continue };
                    let shared = Arc::clone(&accept_shared);
                    std::thread::spawn(move || serve(stream, &shared));
                }
            })?;
        Ok(ScriptServer {
            addr,
            shared,
            accept_thread: Some(accept_thread),
        })
    }

    /// Starts a server answering with the replies of a JSON-lines fixture file
    /// (see [`ScriptedReply::from_json_lines`]).
    pub fn from_fixture(path: impl AsRef<Path>) -> io::Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)?;
        let replies = ScriptedReply::from_json_lines(&text).map_err(|e| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: {e}", path.display()),
            )
        })?;
        ScriptServer::start(replies)
    }

    /// The API base to configure a client with: `http://127.0.0.1:{port}/v1`.
    pub fn base_url(&self) -> String {
        format!("http://{}/v1", self.addr)
    }

    /// The address listened on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Queues one more reply.
    pub fn push(&self, reply: ScriptedReply) {
        lock(&self.shared.replies).push_back(reply);
    }

    /// The requests received so far, in order of arrival.
    pub fn requests(&self) -> Vec<RecordedRequest> {
        lock(&self.shared.requests).clone()
    }

    /// How many scripted replies are still unused.
    pub fn remaining(&self) -> usize {
        lock(&self.shared.replies).len()
    }
}

impl Drop for ScriptServer {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        // Wake the blocking accept so the thread sees the flag.
        let _ = TcpStream::connect(self.addr);
        if let Some(thread) = self.accept_thread.take() {
            let _ = thread.join();
        }
    }
}

/// Answers one connection. I/O errors end it quietly: clients that time out or stop reading an
/// oversized body hang up mid-reply on purpose.
fn serve(mut stream: TcpStream, shared: &Shared) {
    if shared.stop.load(Ordering::SeqCst) {
        return;
    }
    let _ = stream.set_read_timeout(Some(Duration::from_secs(10)));
    let reply = match read_request(&mut stream) {
        Ok(Some(request)) => {
            lock(&shared.requests).push(request);
            lock(&shared.replies).pop_front().unwrap_or_else(|| {
                ScriptedReply::error(410, "script server: no scripted reply left")
            })
        }
        Ok(None) => ScriptedReply::error(411, "script server: send a Content-Length"),
        Err(_) => return,
    };
    if !reply.delay.is_zero() {
        std::thread::sleep(reply.delay);
    }
    let _ = write_reply(&mut stream, &reply);
}

/// Reads one request; `None` for a body without `Content-Length` (chunked), which this server
/// does not decode.
fn read_request(stream: &mut TcpStream) -> io::Result<Option<RecordedRequest>> {
    let mut buf = Vec::new();
    let mut chunk = [0u8; 8192];
    let head_end = loop {
        if let Some(i) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            break i;
        }
        if buf.len() > MAX_HEAD_BYTES {
            return Err(io::Error::new(io::ErrorKind::InvalidData, "head too long"));
        }
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        buf.extend_from_slice(&chunk[..n]);
    };
    let head = String::from_utf8_lossy(&buf[..head_end]).into_owned();
    let mut lines = head.split("\r\n");
    let mut request_line = lines.next().unwrap_or("").split_whitespace();
    let method = request_line.next().unwrap_or("").to_string();
    let path = request_line.next().unwrap_or("").to_string();
    let headers: Vec<(String, String)> = lines
        .filter_map(|line| line.split_once(':'))
        .map(|(n, v)| (n.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let header = |name: &str| headers.iter().find(|(n, _)| n == name).map(|(_, v)| v);
    let length = match header("content-length") {
        Some(v) => v
            .parse::<usize>()
            .ok()
            .filter(|&n| n <= MAX_BODY_BYTES)
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidData, "bad Content-Length"))?,
        None if header("transfer-encoding").is_some() => return Ok(None),
        None => 0,
    };
    let mut body = buf.split_off(head_end + 4);
    while body.len() < length {
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        body.extend_from_slice(&chunk[..n]);
    }
    body.truncate(length);
    Ok(Some(RecordedRequest {
        method,
        path,
        headers,
        body: String::from_utf8_lossy(&body).into_owned(),
    }))
}

fn write_reply(stream: &mut TcpStream, reply: &ScriptedReply) -> io::Result<()> {
    let reason = match reply.status {
        200 => "OK",
        400 => "Bad Request",
        401 => "Unauthorized",
        403 => "Forbidden",
        404 => "Not Found",
        410 => "Gone",
        411 => "Length Required",
        422 => "Unprocessable Entity",
        429 => "Too Many Requests",
        500 => "Internal Server Error",
        502 => "Bad Gateway",
        503 => "Service Unavailable",
        504 => "Gateway Timeout",
        _ => "Scripted",
    };
    let mut head = format!("HTTP/1.1 {} {reason}\r\n", reply.status);
    let has = |name: &str| {
        reply
            .headers
            .iter()
            .any(|(n, _)| n.eq_ignore_ascii_case(name))
    };
    if !has("content-type") {
        head.push_str("Content-Type: application/json\r\n");
    }
    for (name, value) in &reply.headers {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str(&format!(
        "Content-Length: {}\r\nConnection: close\r\n\r\n",
        reply.body.len()
    ));
    stream.write_all(head.as_bytes())?;
    stream.write_all(reply.body.as_bytes())?;
    stream.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_lines_fixtures_parse() {
        let text = r#"
            # a comment
            {"status": 429, "body": {"error": {"message": "slow"}}, "headers": {"Retry-After": "1"}}
            {"content": "hi", "delay_ms": 5}
            {"status": 502, "body": "<html>Bad Gateway</html>"}
        "#;
        let replies = ScriptedReply::from_json_lines(text).unwrap();
        assert_eq!(replies.len(), 3);
        assert_eq!(replies[0].status, 429);
        assert_eq!(replies[0].body, r#"{"error":{"message":"slow"}}"#);
        assert_eq!(replies[0].headers, [("Retry-After".into(), "1".into())]);
        assert_eq!(replies[1].status, 200);
        assert_eq!(replies[1].delay, Duration::from_millis(5));
        let body: Value = serde_json::from_str(&replies[1].body).unwrap();
        assert_eq!(body["choices"][0]["message"]["content"], "hi");
        assert_eq!(replies[2].body, "<html>Bad Gateway</html>");
        let e = ScriptedReply::from_json_lines("{\"status\": 7}").unwrap_err();
        assert!(e.starts_with("line 1:"), "{e}");
    }

    #[test]
    fn serves_in_order_and_records() {
        let server = ScriptServer::start([ScriptedReply::new(201, "first")]).unwrap();
        let exchange = |body: &str| {
            let mut s = TcpStream::connect(server.addr()).unwrap();
            let request = format!(
                "POST /v1/chat/completions HTTP/1.1\r\nHost: x\r\nX-Test: yes\r\n\
                 Content-Length: {}\r\n\r\n{body}",
                body.len()
            );
            s.write_all(request.as_bytes()).unwrap();
            let mut reply = String::new();
            s.read_to_string(&mut reply).unwrap();
            reply
        };
        let first = exchange("{\"a\":1}");
        assert!(first.starts_with("HTTP/1.1 201 "), "{first}");
        assert!(first.ends_with("\r\n\r\nfirst"), "{first}");
        let second = exchange("");
        assert!(second.starts_with("HTTP/1.1 410 "), "{second}");
        let requests = server.requests();
        assert_eq!(requests.len(), 2);
        assert_eq!(requests[0].method, "POST");
        assert_eq!(requests[0].path, "/v1/chat/completions");
        assert_eq!(requests[0].header("x-test"), Some("yes"));
        assert_eq!(requests[0].json(), json!({"a": 1}));
        assert_eq!(server.remaining(), 0);
    }
}
