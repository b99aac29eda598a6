//! Where the client talks to, with what key, and how patiently.

use std::fmt;
use std::time::Duration;

/// An API key. It prints as `***` (Debug and Display alike) and is not serialisable, so it
/// cannot leak into a log line, an error message, a share link or an export by accident; the
/// only way to read it is [`Secret::expose`], which the client calls once per request to build
/// the `Authorization` header.
#[derive(Clone, PartialEq, Eq)]
pub struct Secret(String);

impl Secret {
    /// Wraps a key. Surrounding whitespace (a common paste accident) is dropped.
    pub fn new(key: impl Into<String>) -> Self {
        Secret(key.into().trim().to_string())
    }

    /// The key itself, for the `Authorization` header and nothing else.
    pub fn expose(&self) -> &str {
        &self.0
    }

    /// True for an empty key (the client then sends no `Authorization` header).
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl fmt::Debug for Secret {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("***")
    }
}

impl fmt::Display for Secret {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("***")
    }
}

/// How long to wait between retries. The wait before retry `n` (0-based) is
/// `initial * 2^n`, capped at `max`; a server's `Retry-After: <seconds>` replaces it, capped at
/// `retry_after_cap` so a server cannot park the page for minutes. There is no jitter: one user
/// drives one client, so there is no herd to spread.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Backoff {
    /// The first wait.
    pub initial: Duration,
    /// The longest computed wait.
    pub max: Duration,
    /// The longest wait a `Retry-After` header can ask for.
    pub retry_after_cap: Duration,
}

impl Default for Backoff {
    fn default() -> Self {
        Backoff {
            initial: Duration::from_millis(500),
            max: Duration::from_secs(8),
            retry_after_cap: Duration::from_secs(20),
        }
    }
}

impl Backoff {
    /// The wait before retry `retry` (0-based), given the server's `Retry-After`, if any.
    pub fn delay(&self, retry: u32, retry_after: Option<Duration>) -> Duration {
        if let Some(asked) = retry_after {
            return asked.min(self.retry_after_cap);
        }
        // 2^16 × anything sensible is past any cap already; clamping the exponent keeps the
        // multiplication from overflowing.
        let factor = 1u32 << retry.min(16);
        self.initial.saturating_mul(factor).min(self.max)
    }
}

/// The largest reply body read by default (1 MiB): a plan is a few KiB, so anything near this
/// is a misbehaving server, and reading it all would only cost memory.
pub const DEFAULT_MAX_REPLY_BYTES: usize = 1 << 20;

/// An OpenAI-compatible endpoint and how to use it.
///
/// The client POSTs to `{base}/chat/completions`, where `base` is [`LlmConfig::base_url`] after
/// [`normalize_base_url`]: e.g. `http://127.0.0.1:8080/v1` (llama.cpp), `http://localhost:11434/v1`
/// (Ollama), `https://api.openai.com/v1`. A bare host such as `http://localhost:11434` gets
/// `/v1` appended, since every common server serves the API there; a base with any other path
/// (`https://example.com/openai/v1beta`) is used as it is.
///
/// Debug output shows the key as `***`; the type is deliberately not serialisable (the page
/// stores its settings itself and keeps the key out of anything it shares).
#[derive(Clone, Debug, PartialEq)]
pub struct LlmConfig {
    /// The API base, with or without `/v1` (see above).
    pub base_url: String,
    /// The model name sent with every request, e.g. `gpt-4o-mini` or `qwen2.5:7b`.
    pub model: String,
    /// Sent as `Authorization: Bearer <key>` when present and non-empty (local servers need none).
    pub api_key: Option<Secret>,
    /// The limit for one HTTP exchange, from connecting to the last byte of the reply.
    pub timeout: Duration,
    /// How many times a failed request (429, 5xx, timeout) is tried again.
    pub max_retries: u32,
    /// The model used for requests with images ([`super::ChatOptions::vision`]); `None` uses
    /// [`LlmConfig::model`] for those too.
    pub vision_model: Option<String>,
    /// The waits between retries.
    pub backoff: Backoff,
    /// The largest reply body read; a longer one is [`super::LlmError::TooLarge`].
    pub max_reply_bytes: usize,
}

impl LlmConfig {
    /// A configuration with the defaults: no key, a 60 s timeout, 2 retries, the default
    /// backoff, 1 MiB replies, no separate vision model.
    pub fn new(base_url: impl Into<String>, model: impl Into<String>) -> Self {
        LlmConfig {
            base_url: base_url.into(),
            model: model.into(),
            api_key: None,
            timeout: Duration::from_secs(60),
            max_retries: 2,
            vision_model: None,
            backoff: Backoff::default(),
            max_reply_bytes: DEFAULT_MAX_REPLY_BYTES,
        }
    }

    /// The same configuration with an API key (an empty one means none).
    pub fn with_api_key(mut self, key: impl Into<String>) -> Self {
        let key = Secret::new(key);
        self.api_key = (!key.is_empty()).then_some(key);
        self
    }

    /// The normalised base (see [`normalize_base_url`]).
    pub fn base(&self) -> String {
        normalize_base_url(&self.base_url)
    }

    /// The URL the client POSTs to: `{base}/chat/completions`.
    pub fn endpoint(&self) -> String {
        format!("{}/chat/completions", self.base())
    }
}

/// Normalises what a user types as the API base, so that `{base}/chat/completions` is the
/// endpoint:
/// - surrounding whitespace and trailing slashes go;
/// - a pasted full endpoint (`…/chat/completions`) loses that suffix;
/// - without a scheme, `http://` is assumed for local hosts (`localhost`, `127.x`, `[::1]`,
///   `0.0.0.0`) and `https://` for everything else;
/// - a bare host (no path) gets `/v1`.
pub fn normalize_base_url(raw: &str) -> String {
    let mut base = raw.trim().trim_end_matches('/').to_string();
    if let Some(stripped) = base.strip_suffix("/chat/completions") {
        base = stripped.trim_end_matches('/').to_string();
    }
    if base.is_empty() {
        return base;
    }
    if !base.contains("://") {
        let host = base.split(['/', ':']).next().unwrap_or("");
        let local = host == "localhost"
            || host.starts_with("127.")
            || host == "0.0.0.0"
            || base.starts_with("[::1]");
        base = format!("{}://{base}", if local { "http" } else { "https" });
    }
    let after_scheme = &base[base.find("://").map_or(0, |i| i + 3)..];
    if !after_scheme.contains('/') {
        base.push_str("/v1");
    }
    base
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn secret_never_prints() {
        let key = Secret::new(" sk-very-secret ");
        assert_eq!(key.expose(), "sk-very-secret");
        assert_eq!(format!("{key:?} {key}"), "*** ***");
        let config = LlmConfig::new("http://x", "m").with_api_key("sk-very-secret");
        assert!(!format!("{config:?}").contains("very-secret"));
        assert_eq!(
            LlmConfig::new("http://x", "m").with_api_key("  ").api_key,
            None
        );
    }

    #[test]
    fn base_urls_normalise() {
        let cases = [
            ("http://127.0.0.1:8080/v1", "http://127.0.0.1:8080/v1"),
            ("http://127.0.0.1:8080/v1/", "http://127.0.0.1:8080/v1"),
            ("http://localhost:11434", "http://localhost:11434/v1"),
            ("http://localhost:11434/", "http://localhost:11434/v1"),
            ("localhost:1234", "http://localhost:1234/v1"),
            ("api.openai.com/v1", "https://api.openai.com/v1"),
            (
                "https://api.openai.com/v1/chat/completions",
                "https://api.openai.com/v1",
            ),
            (
                " https://example.com/openai/v1beta/ ",
                "https://example.com/openai/v1beta",
            ),
            ("", ""),
        ];
        for (raw, want) in cases {
            assert_eq!(normalize_base_url(raw), want, "{raw:?}");
        }
        assert_eq!(
            LlmConfig::new("http://h:1", "m").endpoint(),
            "http://h:1/v1/chat/completions"
        );
    }

    #[test]
    fn backoff_doubles_and_caps() {
        let b = Backoff {
            initial: Duration::from_millis(100),
            max: Duration::from_millis(350),
            retry_after_cap: Duration::from_secs(2),
        };
        let ms = |d: Duration| d.as_millis();
        assert_eq!(ms(b.delay(0, None)), 100);
        assert_eq!(ms(b.delay(1, None)), 200);
        assert_eq!(ms(b.delay(2, None)), 350);
        assert_eq!(ms(b.delay(40, None)), 350);
        assert_eq!(ms(b.delay(0, Some(Duration::from_secs(1)))), 1000);
        assert_eq!(ms(b.delay(0, Some(Duration::from_secs(60)))), 2000);
    }
}
