//! How a request reaches the server: one trait, implemented natively by
//! [`super::UreqTransport`] (blocking) and in the page by `coma-web`'s fetch transport (async).

use std::fmt;
use std::future::Future;
use std::time::Duration;

/// One POST to make.
pub struct HttpRequest<'a> {
    /// The full URL.
    pub url: &'a str,
    /// Extra headers (`Content-Type`, `Authorization`, …). May hold the API key: never log them.
    pub headers: &'a [(&'static str, String)],
    /// The JSON body.
    pub body: &'a str,
    /// The limit for the whole exchange, reply body included.
    pub timeout: Duration,
    /// Read at most this many reply bytes; a longer body is [`TransportError::TooLarge`].
    pub max_reply_bytes: usize,
}

/// Debug hides header values: the `Authorization` header carries the key.
impl fmt::Debug for HttpRequest<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.headers.iter().map(|(name, _)| *name).collect();
        f.debug_struct("HttpRequest")
            .field("url", &self.url)
            .field("headers", &names)
            .field("body_bytes", &self.body.len())
            .field("timeout", &self.timeout)
            .field("max_reply_bytes", &self.max_reply_bytes)
            .finish()
    }
}

/// A server's answer, whatever its status.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HttpReply {
    /// The HTTP status.
    pub status: u16,
    /// Response headers, names in lower case (only those the transport can see: in the page,
    /// cross-origin responses expose few).
    pub headers: Vec<(String, String)>,
    /// The body, at most [`HttpRequest::max_reply_bytes`] long.
    pub body: Vec<u8>,
}

impl HttpReply {
    /// A header's value by (case-insensitive) name.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    /// `Retry-After` in its delay-seconds form (the HTTP-date form is rare from API servers
    /// and is ignored, leaving the client's own backoff).
    pub fn retry_after(&self) -> Option<Duration> {
        let secs: f64 = self.header("retry-after")?.trim().parse().ok()?;
        (secs.is_finite() && secs >= 0.0).then(|| Duration::from_secs_f64(secs.min(86_400.0)))
    }
}

/// Why a request got no reply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TransportError {
    /// The exchange took longer than [`HttpRequest::timeout`].
    Timeout,
    /// The reply body was longer than [`HttpRequest::max_reply_bytes`].
    TooLarge,
    /// No connection (refused, DNS, TLS, or in a browser a CORS refusal, which fetch reports
    /// as the same opaque network error); the text is the transport's own description.
    Network(String),
}

/// Sends requests and waits. Natively both may block (the client's future is then driven by
/// [`crate::executor::block_on`]); in the page they are real futures. No `Send` bound, since the page's
/// futures hold JS values.
pub trait Transport {
    /// POSTs `request` and returns the server's reply, whatever its status.
    fn post(
        &self,
        request: HttpRequest<'_>,
    ) -> impl Future<Output = Result<HttpReply, TransportError>>;

    /// Waits `duration` (between retries).
    fn sleep(&self, duration: Duration) -> impl Future<Output = ()>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn retry_after_seconds_only() {
        let reply = |v: &str| HttpReply {
            status: 429,
            headers: vec![("retry-after".into(), v.into())],
            body: vec![],
        };
        assert_eq!(reply("2").retry_after(), Some(Duration::from_secs(2)));
        assert_eq!(
            reply(" 0.5 ").retry_after(),
            Some(Duration::from_millis(500))
        );
        assert_eq!(reply("Wed, 21 Oct 2015 07:28:00 GMT").retry_after(), None);
        assert_eq!(reply("-1").retry_after(), None);
    }

    #[test]
    fn debug_hides_header_values() {
        let headers = [("Authorization", "Bearer sk-secret".to_string())];
        let request = HttpRequest {
            url: "http://x/v1/chat/completions",
            headers: &headers,
            body: "{}",
            timeout: Duration::from_secs(1),
            max_reply_bytes: 10,
        };
        let shown = format!("{request:?}");
        assert!(shown.contains("Authorization") && !shown.contains("sk-secret"));
    }
}
