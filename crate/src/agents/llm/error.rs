//! What can go wrong, worded for the person who can fix it.

use std::time::Duration;

/// Why a chat request failed. The messages say what to do; none of them ever contains the API
/// key (server excerpts are redacted before they are stored here).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LlmError {
    /// The settings cannot work (empty base URL or model, unusable key).
    #[error("the LLM settings are incomplete: {0}")]
    InvalidConfig(String),
    /// 401.
    #[error(
        "the endpoint rejected the API key (401 Unauthorized): check the key in Settings, or \
         clear it for a local server that needs none"
    )]
    Unauthorized,
    /// 403.
    #[error(
        "the endpoint refused access (403 Forbidden): the key may not be allowed to use model \
         `{model}`, or the account has no access{}",
        detail_suffix(.detail)
    )]
    Forbidden {
        /// The model asked for.
        model: String,
        /// An excerpt of the server's explanation.
        detail: String,
    },
    /// 404.
    #[error(
        "nothing found at {url} (404 Not Found): check the base URL (it usually ends in /v1) \
         and that the model `{model}` exists on this server{}",
        detail_suffix(.detail)
    )]
    NotFound {
        /// The URL posted to.
        url: String,
        /// The model asked for.
        model: String,
        /// An excerpt of the server's explanation.
        detail: String,
    },
    /// 400 or 422 that a weaker reply format did not cure.
    #[error("the endpoint refused the request ({status}){}", detail_suffix(.detail))]
    BadRequest {
        /// 400 or 422.
        status: u16,
        /// An excerpt of the server's explanation.
        detail: String,
    },
    /// 429 on every attempt.
    #[error(
        "the endpoint is limiting requests (429 Too Many Requests) and still was after \
         {attempts} attempts: wait a minute, or check the account's quota{}",
        detail_suffix(.detail)
    )]
    RateLimited {
        /// Requests made.
        attempts: u32,
        /// An excerpt of the server's explanation.
        detail: String,
    },
    /// 500, 502, 503 or 504 on every attempt.
    #[error(
        "the endpoint had a server error ({status}) on all {attempts} attempts: it may be \
         overloaded or still loading the model; try again later{}",
        detail_suffix(.detail)
    )]
    Server {
        /// The last status.
        status: u16,
        /// Requests made.
        attempts: u32,
        /// An excerpt of the server's explanation.
        detail: String,
    },
    /// No complete reply within the timeout, on every attempt.
    #[error(
        "the endpoint did not answer within {} s on all {attempts} attempts: a local model may \
         still be loading, or the timeout in Settings is too short for this model",
        fmt_secs(.timeout)
    )]
    Timeout {
        /// The timeout of one attempt.
        timeout: Duration,
        /// Requests made.
        attempts: u32,
    },
    /// No connection at all (in a browser this includes a CORS refusal, which looks the same).
    #[error(
        "could not reach {base}; if it is a local server (Ollama, llama.cpp, LM Studio, vLLM), \
         check that it is running and enable CORS for this page's origin ({detail})"
    )]
    Network {
        /// The normalised base URL.
        base: String,
        /// The transport's description of the failure.
        detail: String,
    },
    /// A 2xx reply that is not a usable chat completion.
    #[error("the endpoint's reply is not a usable chat completion: {reason}{}", excerpt_suffix(.excerpt))]
    BadReply {
        /// What is wrong with it.
        reason: String,
        /// The start of the reply (at most about 200 characters).
        excerpt: String,
    },
    /// A reply body over the size limit.
    #[error(
        "the endpoint's reply is longer than {limit} bytes; is the base URL an OpenAI-compatible \
         API?"
    )]
    TooLarge {
        /// The limit, in bytes.
        limit: usize,
    },
    /// Any other status (3xx, 405, 413, …).
    #[error("the endpoint answered HTTP {status}{}{}", location_suffix(.location), detail_suffix(.detail))]
    Http {
        /// The status.
        status: u16,
        /// Where a redirect points (use that as the base URL).
        location: Option<String>,
        /// An excerpt of the server's explanation.
        detail: String,
    },
}

fn detail_suffix(detail: &str) -> String {
    if detail.is_empty() {
        String::new()
    } else {
        format!(" (the server said: {detail})")
    }
}

fn excerpt_suffix(excerpt: &str) -> String {
    if excerpt.is_empty() {
        String::new()
    } else {
        format!(" (reply starts: {excerpt})")
    }
}

fn location_suffix(location: &Option<String>) -> String {
    match location {
        Some(to) => format!(" redirecting to {to}: use that as the base URL"),
        None => String::new(),
    }
}

fn fmt_secs(d: &Duration) -> String {
    let secs = d.as_secs_f64();
    if secs.fract() == 0.0 {
        format!("{secs:.0}")
    } else {
        format!("{secs:.1}")
    }
}

/// The longest excerpt of a server's text kept in an error, in characters.
pub const EXCERPT_CHARS: usize = 200;

/// The start of `text` for an error message: whitespace runs collapsed to one space, at most
/// [`EXCERPT_CHARS`] characters (cut on a character boundary, marked with `…`), and every
/// occurrence of `secret` replaced by `***` (servers do echo keys back in their errors).
pub(crate) fn excerpt(text: &str, secret: Option<&str>) -> String {
    let redacted = match secret {
        // A very short key would match everywhere; such a key is not a real one anyway.
        Some(key) if key.len() >= 4 => text.replace(key, "***"),
        _ => text.to_string(),
    };
    let mut out = String::new();
    let mut chars = 0;
    for word in redacted.split_whitespace() {
        if !out.is_empty() {
            out.push(' ');
            chars += 1;
        }
        for c in word.chars() {
            if chars >= EXCERPT_CHARS {
                out.push('…');
                return out;
            }
            out.push(c);
            chars += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn excerpts_are_short_and_redacted() {
        assert_eq!(
            excerpt("  invalid\n\n key sk-abcdef ", Some("sk-abcdef")),
            "invalid key ***"
        );
        let long = "é".repeat(500);
        let e = excerpt(&long, None);
        assert_eq!(e.chars().count(), EXCERPT_CHARS + 1);
        assert!(e.ends_with('…'));
        assert_eq!(excerpt("a b", Some("b")), "a b");
    }

    #[test]
    fn messages_say_what_to_do() {
        let e = LlmError::Timeout {
            timeout: Duration::from_millis(1500),
            attempts: 3,
        };
        assert!(e.to_string().contains("within 1.5 s on all 3 attempts"));
        let e = LlmError::Http {
            status: 301,
            location: Some("https://h/v1/chat/completions".into()),
            detail: String::new(),
        };
        assert_eq!(
            e.to_string(),
            "the endpoint answered HTTP 301 redirecting to https://h/v1/chat/completions: use \
             that as the base URL"
        );
    }
}
