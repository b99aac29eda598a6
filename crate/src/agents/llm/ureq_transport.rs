//! The native transport: blocking HTTP(S) with `ureq` and rustls.

use super::{ChatOptions, ChatReply, LlmClient, LlmConfig, LlmError, Message};
use super::{HttpReply, HttpRequest, ReplyFormat, Transport, TransportError};
use crate::executor::block_on;
use std::time::Duration;

/// Blocking HTTP(S) through one `ureq` agent (so connections are pooled across requests).
///
/// Redirects are not followed: a POST that is redirected is almost always a wrong base URL
/// (http → https, a missing `/v1`), and [`LlmError::Http`] says where it points instead.
/// Proxies come from the usual `HTTPS_PROXY`/`NO_PROXY` environment variables.
pub struct UreqTransport {
    agent: ureq::Agent,
}

impl Default for UreqTransport {
    fn default() -> Self {
        Self::new()
    }
}

impl UreqTransport {
    /// A transport with its own connection pool.
    pub fn new() -> Self {
        let config = ureq::Agent::config_builder()
            // Statuses are the client's business, not errors of the transport.
            .http_status_as_error(false)
            .max_redirects(0)
            .user_agent(concat!("coma/", env!("CARGO_PKG_VERSION")))
            .build();
        UreqTransport {
            agent: config.into(),
        }
    }

    fn post_blocking(&self, request: &HttpRequest<'_>) -> Result<HttpReply, TransportError> {
        let mut builder = self
            .agent
            .post(request.url)
            .config()
            .timeout_global(Some(request.timeout))
            .build();
        for (name, value) in request.headers {
            builder = builder.header(*name, value.as_str());
        }
        let mut response = builder.send(request.body).map_err(transport_error)?;
        let status = response.status().as_u16();
        let headers = response
            .headers()
            .iter()
            .filter_map(|(name, value)| {
                Some((
                    name.as_str().to_ascii_lowercase(),
                    value.to_str().ok()?.to_string(),
                ))
            })
            .collect();
        let body = response
            .body_mut()
            .with_config()
            .limit(request.max_reply_bytes as u64)
            .read_to_vec()
            .map_err(transport_error)?;
        Ok(HttpReply {
            status,
            headers,
            body,
        })
    }
}

fn transport_error(error: ureq::Error) -> TransportError {
    match error {
        ureq::Error::Timeout(_) => TransportError::Timeout,
        ureq::Error::Io(e) if e.kind() == std::io::ErrorKind::TimedOut => TransportError::Timeout,
        ureq::Error::BodyExceedsLimit(_) => TransportError::TooLarge,
        other => TransportError::Network(other.to_string()),
    }
}

impl Transport for UreqTransport {
    async fn post(&self, request: HttpRequest<'_>) -> Result<HttpReply, TransportError> {
        self.post_blocking(&request)
    }

    async fn sleep(&self, duration: Duration) {
        std::thread::sleep(duration);
    }
}

impl LlmClient<UreqTransport> {
    /// A client over a fresh [`UreqTransport`].
    pub fn native(config: LlmConfig) -> Result<Self, LlmError> {
        LlmClient::new(config, UreqTransport::new())
    }

    /// [`LlmClient::chat_with`], blocking the calling thread until it is done.
    pub fn chat_blocking(
        &self,
        messages: &[Message],
        format: &ReplyFormat,
        options: &ChatOptions,
    ) -> Result<ChatReply, LlmError> {
        block_on(self.chat_with(messages, format, options))
    }
}
