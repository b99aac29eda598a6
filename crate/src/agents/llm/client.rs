//! The chat client: builds requests, retries what is worth retrying, degrades the reply format
//! for servers that do not support it, and turns replies into content or an [`LlmError`].

use super::error::excerpt;
use super::{
    ChatOptions, FormatLevel, HttpReply, HttpRequest, LlmConfig, LlmError, Message, ReplyFormat,
    Transport, TransportError,
};
use serde_json::{json, Value};
use std::fmt;
use std::sync::atomic::{AtomicU8, Ordering};

/// A chat completion's content and what came with it.
#[derive(Clone, Debug, PartialEq)]
pub struct ChatReply {
    /// The assistant message's text. Never empty.
    pub content: String,
    /// The model that answered, as the server names it.
    pub model: Option<String>,
    /// `stop`, `length` (cut off by `max_tokens`), …
    pub finish_reason: Option<String>,
    /// Token counts, when the server reports them.
    pub usage: Option<Usage>,
    /// The reply format actually requested (lower than asked for once the server was found
    /// not to support it), so the caller knows whether the schema was enforced server-side.
    pub format: FormatLevel,
    /// HTTP requests made, retries and format downgrades included.
    pub attempts: u32,
}

/// Token counts of one exchange.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Usage {
    /// Tokens in the request.
    pub prompt_tokens: u64,
    /// Tokens in the reply.
    pub completion_tokens: u64,
}

/// An OpenAI-compatible chat client over a [`Transport`].
///
/// It remembers, for its whole life, the strongest reply format the server accepted: after a
/// 400 that blames `response_format` it drops from JSON schema to JSON object mode, then to
/// none, and does not try the stronger form again.
pub struct LlmClient<T> {
    config: LlmConfig,
    transport: T,
    /// The strongest [`FormatLevel`] the server is believed to support, as its `u8` rank.
    supported: AtomicU8,
}

impl<T> fmt::Debug for LlmClient<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // The config's Debug shows the key as ***; the transport is left out (it may be a JS
        // object with nothing useful to show).
        f.debug_struct("LlmClient")
            .field("config", &self.config)
            .field("supported_format", &self.supported_format())
            .finish_non_exhaustive()
    }
}

fn rank(level: FormatLevel) -> u8 {
    match level {
        FormatLevel::Text => 0,
        FormatLevel::JsonObject => 1,
        FormatLevel::JsonSchema => 2,
    }
}

fn level_of(rank: u8) -> FormatLevel {
    match rank {
        0 => FormatLevel::Text,
        1 => FormatLevel::JsonObject,
        _ => FormatLevel::JsonSchema,
    }
}

/// What one failed attempt means for the loop.
enum Failure {
    /// Worth another try after the backoff (or the server's `Retry-After`).
    Retry(LlmError, Option<std::time::Duration>),
    /// Final.
    Fatal(LlmError),
}

impl<T> LlmClient<T> {
    /// The configuration.
    pub fn config(&self) -> &LlmConfig {
        &self.config
    }

    /// The transport.
    pub fn transport(&self) -> &T {
        &self.transport
    }

    /// The strongest reply format the server is believed to support.
    pub fn supported_format(&self) -> FormatLevel {
        level_of(self.supported.load(Ordering::Relaxed))
    }
}

impl<T: Transport> LlmClient<T> {
    /// A client for `config`, checked for settings that cannot work.
    pub fn new(config: LlmConfig, transport: T) -> Result<Self, LlmError> {
        let base = config.base();
        if base.is_empty() {
            return Err(LlmError::InvalidConfig(
                "enter the endpoint's base URL, e.g. http://127.0.0.1:8080/v1".into(),
            ));
        }
        if !(base.starts_with("http://") || base.starts_with("https://")) {
            return Err(LlmError::InvalidConfig(format!(
                "the base URL {base} must start with http:// or https://"
            )));
        }
        if config.model.trim().is_empty() {
            return Err(LlmError::InvalidConfig(
                "enter a model name, e.g. gpt-4o-mini or qwen2.5:7b".into(),
            ));
        }
        if let Some(key) = &config.api_key {
            // A pasted newline or a non-ASCII character cannot go into a header; fetch would
            // throw a TypeError that looks like a CORS failure, so say it here instead.
            if !key.expose().bytes().all(|b| (0x21..0x7f).contains(&b)) {
                return Err(LlmError::InvalidConfig(
                    "the API key contains spaces or characters that cannot be sent in a header"
                        .into(),
                ));
            }
        }
        Ok(LlmClient {
            config,
            transport,
            supported: AtomicU8::new(rank(FormatLevel::JsonSchema)),
        })
    }

    /// One chat completion with the server's default sampling.
    pub async fn chat(
        &self,
        messages: &[Message],
        format: &ReplyFormat,
    ) -> Result<ChatReply, LlmError> {
        self.chat_with(messages, format, &ChatOptions::default())
            .await
    }

    /// One chat completion.
    ///
    /// Retries, with exponential backoff or the server's `Retry-After`, on 429, 500, 502, 503,
    /// 504 and timeouts, up to [`LlmConfig::max_retries`] times; a 400/422 that blames the
    /// reply format is re-sent at once with a weaker one (not counted as a retry). Everything
    /// else fails at once.
    pub async fn chat_with(
        &self,
        messages: &[Message],
        format: &ReplyFormat,
        options: &ChatOptions,
    ) -> Result<ChatReply, LlmError> {
        let url = self.config.endpoint();
        let model = match (&self.config.vision_model, options.vision) {
            (Some(vision), true) if !vision.trim().is_empty() => vision.trim(),
            _ => self.config.model.trim(),
        };
        let mut headers = vec![
            ("Content-Type", "application/json".to_string()),
            ("Accept", "application/json".to_string()),
        ];
        if let Some(key) = &self.config.api_key {
            headers.push(("Authorization", format!("Bearer {}", key.expose())));
        }
        let mut attempts = 0;
        let mut retries = 0;
        loop {
            let level = self.supported_format().min(format.level());
            let body = request_body(model, messages, format, level, options).to_string();
            attempts += 1;
            let outcome = self
                .transport
                .post(HttpRequest {
                    url: &url,
                    headers: &headers,
                    body: &body,
                    timeout: self.config.timeout,
                    max_reply_bytes: self.config.max_reply_bytes,
                })
                .await;
            let failure = match outcome {
                Ok(reply) if (200..300).contains(&reply.status) => {
                    return self.parse_reply(&reply, level, attempts);
                }
                Ok(reply) => {
                    if self.downgrade_for(&reply, level) {
                        continue;
                    }
                    self.status_failure(&reply, &url, model, attempts)
                }
                Err(TransportError::Timeout) => Failure::Retry(
                    LlmError::Timeout {
                        timeout: self.config.timeout,
                        attempts,
                    },
                    None,
                ),
                Err(TransportError::TooLarge) => Failure::Fatal(LlmError::TooLarge {
                    limit: self.config.max_reply_bytes,
                }),
                // Not retried: a refused connection or a CORS refusal does not cure itself in
                // a second, and the user waits for the answer.
                Err(TransportError::Network(detail)) => Failure::Fatal(LlmError::Network {
                    base: self.config.base(),
                    detail: self.excerpt(&detail),
                }),
            };
            match failure {
                Failure::Retry(_, retry_after) if retries < self.config.max_retries => {
                    let wait = self.config.backoff.delay(retries, retry_after);
                    retries += 1;
                    self.transport.sleep(wait).await;
                }
                Failure::Retry(error, _) | Failure::Fatal(error) => return Err(error),
            }
        }
    }

    fn excerpt(&self, text: &str) -> String {
        excerpt(text, self.config.api_key.as_ref().map(|k| k.expose()))
    }

    /// After a 400/422 (or a 500: llama-cpp-python's server answers an unknown
    /// `response_format` type with a validation error under status 500) that blames the reply
    /// format sent at `level`, lowers what the server is believed to support and says whether
    /// the request is worth re-sending.
    fn downgrade_for(&self, reply: &HttpReply, level: FormatLevel) -> bool {
        if !matches!(reply.status, 400 | 422 | 500) {
            return false;
        }
        let Some(weaker) = level.weaker() else {
            return false;
        };
        let text = String::from_utf8_lossy(&reply.body).to_lowercase();
        let blames_format = [
            "response_format",
            "response format",
            "json_schema",
            "json schema",
            "json_object",
            "structured output",
        ]
        .iter()
        .any(|needle| text.contains(needle));
        if blames_format {
            self.supported.fetch_min(rank(weaker), Ordering::Relaxed);
        }
        blames_format
    }

    /// The error for a non-2xx reply (that was not a format complaint).
    fn status_failure(&self, reply: &HttpReply, url: &str, model: &str, attempts: u32) -> Failure {
        let detail = self.excerpt(&error_text(&reply.body));
        let status = reply.status;
        match status {
            // The body of a 401 is not shown: it is where servers echo the key.
            401 => Failure::Fatal(LlmError::Unauthorized),
            403 => Failure::Fatal(LlmError::Forbidden {
                model: model.to_string(),
                detail,
            }),
            404 => Failure::Fatal(LlmError::NotFound {
                url: url.to_string(),
                model: model.to_string(),
                detail,
            }),
            400 | 422 => Failure::Fatal(LlmError::BadRequest { status, detail }),
            429 => Failure::Retry(
                LlmError::RateLimited { attempts, detail },
                reply.retry_after(),
            ),
            500 | 502 | 503 | 504 => Failure::Retry(
                LlmError::Server {
                    status,
                    attempts,
                    detail,
                },
                reply.retry_after(),
            ),
            _ => Failure::Fatal(LlmError::Http {
                status,
                location: reply.header("location").map(|l| self.excerpt(l)),
                detail,
            }),
        }
    }

    /// The content of a 2xx reply.
    fn parse_reply(
        &self,
        reply: &HttpReply,
        format: FormatLevel,
        attempts: u32,
    ) -> Result<ChatReply, LlmError> {
        let text = String::from_utf8_lossy(&reply.body);
        let bad = |reason: &str| LlmError::BadReply {
            reason: reason.to_string(),
            excerpt: self.excerpt(&text),
        };
        let value: Value = serde_json::from_str(&text).map_err(|_| bad("it is not JSON"))?;
        if let Some(error) = value.get("error").filter(|e| !e.is_null()) {
            return Err(LlmError::BadReply {
                reason: "it is an error, not a completion".into(),
                excerpt: self.excerpt(&message_of(error)),
            });
        }
        let choice = value
            .get("choices")
            .and_then(Value::as_array)
            .and_then(|choices| choices.first())
            .ok_or_else(|| bad("it has no choices"))?;
        let message = choice
            .get("message")
            .ok_or_else(|| bad("its first choice has no message"))?;
        let finish_reason = choice
            .get("finish_reason")
            .and_then(Value::as_str)
            .map(str::to_string);
        let content = match message.get("content") {
            Some(Value::String(s)) => s.clone(),
            // Some servers send content as parts even for text.
            Some(Value::Array(parts)) => parts
                .iter()
                .filter_map(|p| p.get("text").and_then(Value::as_str))
                .collect::<Vec<_>>()
                .join(""),
            _ => String::new(),
        };
        if content.trim().is_empty() {
            if let Some(refusal) = message.get("refusal").and_then(Value::as_str) {
                return Err(LlmError::BadReply {
                    reason: "the model refused".into(),
                    excerpt: self.excerpt(refusal),
                });
            }
            let reason = if finish_reason.as_deref() == Some("length") {
                "its content is empty (cut off by max_tokens)"
            } else {
                "its content is empty"
            };
            return Err(bad(reason));
        }
        let usage = value.get("usage").and_then(|u| {
            Some(Usage {
                prompt_tokens: u.get("prompt_tokens")?.as_u64()?,
                completion_tokens: u.get("completion_tokens")?.as_u64()?,
            })
        });
        Ok(ChatReply {
            content,
            model: value
                .get("model")
                .and_then(Value::as_str)
                .map(str::to_string),
            finish_reason,
            usage,
            format,
            attempts,
        })
    }
}

/// The request body of the chat completions API.
fn request_body(
    model: &str,
    messages: &[Message],
    format: &ReplyFormat,
    level: FormatLevel,
    options: &ChatOptions,
) -> Value {
    let mut body = json!({
        "model": model,
        "messages": messages.iter().map(Message::to_json).collect::<Vec<_>>(),
        "stream": false,
    });
    let fields = [
        ("response_format", format.response_format(level)),
        ("temperature", options.temperature.map(|t| json!(t))),
        ("max_tokens", options.max_tokens.map(|n| json!(n))),
        ("seed", options.seed.map(|s| json!(s))),
    ];
    for (name, value) in fields {
        if let Some(value) = value {
            body[name] = value;
        }
    }
    body
}

/// The readable part of an error body: `error.message` of an OpenAI-style error, a plain
/// `error` string, or the body itself.
fn error_text(body: &[u8]) -> String {
    let text = String::from_utf8_lossy(body);
    match serde_json::from_str::<Value>(&text) {
        Ok(value) => match value.get("error") {
            Some(error) => message_of(error),
            None => value
                .get("message")
                .and_then(Value::as_str)
                .map_or_else(|| text.to_string(), str::to_string),
        },
        Err(_) => text.to_string(),
    }
}

fn message_of(error: &Value) -> String {
    match error {
        Value::String(s) => s.clone(),
        other => other
            .get("message")
            .and_then(Value::as_str)
            .map_or_else(|| other.to_string(), str::to_string),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn request_body_has_only_what_was_asked() {
        let messages = [Message::system("s"), Message::user("u")];
        let options = ChatOptions {
            temperature: Some(0.0),
            max_tokens: Some(800),
            seed: Some(7),
            vision: false,
        };
        let body = request_body(
            "m",
            &messages,
            &ReplyFormat::JsonObject,
            FormatLevel::JsonSchema,
            &options,
        );
        assert_eq!(
            body,
            json!({
                "model": "m",
                "messages": [{"role": "system", "content": "s"}, {"role": "user", "content": "u"}],
                "stream": false,
                "response_format": {"type": "json_object"},
                "temperature": 0.0,
                "max_tokens": 800,
                "seed": 7,
            })
        );
        let plain = request_body(
            "m",
            &messages,
            &ReplyFormat::Text,
            FormatLevel::JsonSchema,
            &ChatOptions::default(),
        );
        let mut keys: Vec<&String> = plain.as_object().unwrap().keys().collect();
        keys.sort();
        assert_eq!(keys, ["messages", "model", "stream"]);
    }

    #[test]
    fn error_text_reads_common_shapes() {
        assert_eq!(
            error_text(br#"{"error": {"message": "no such model"}}"#),
            "no such model"
        );
        assert_eq!(
            error_text(br#"{"error": "model not found"}"#),
            "model not found"
        );
        assert_eq!(error_text(br#"{"message": "bad"}"#), "bad");
        assert_eq!(error_text(b"Bad Gateway"), "Bad Gateway");
    }
}
