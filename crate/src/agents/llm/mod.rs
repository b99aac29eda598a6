//! OpenAI-compatible chat client (design §8): `POST {base}/chat/completions` with JSON schema or
//! JSON mode where the server supports it, retries with backoff, and errors the user can act on.
//!
//! The client is async over a [`Transport`] so the same code runs natively and in the page:
//!
//! ```no_run
//! # #[cfg(feature = "native")] {
//! use coma::agents::llm::{ChatOptions, LlmClient, LlmConfig, Message, ReplyFormat};
//! let config = LlmConfig::new("http://127.0.0.1:8080/v1", "qwen2.5-7b-instruct");
//! let client = LlmClient::native(config)?;
//! let reply = client.chat_blocking(
//!     &[Message::system("Answer in JSON."), Message::user("Plan: walk, then bow.")],
//!     &ReplyFormat::JsonObject,
//!     &ChatOptions { temperature: Some(0.0), ..ChatOptions::default() },
//! )?;
//! // On Err, the message is meant to be sent back to the model in one retry.
//! let plan: serde_json::Value = coma::agents::llm::parse_json_content(&reply.content)?;
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! In the page, `coma-web`'s fetch transport takes the place of [`UreqTransport`] and the
//! future is awaited instead of blocked on.
//!
//! The API key ([`Secret`]) prints as `***`, is not serialisable, is sent only in the
//! `Authorization` header to the configured endpoint, and is redacted from server text quoted
//! in errors.

mod client;
mod config;
mod error;
mod json;
mod message;
mod transport;

#[cfg(feature = "native")]
pub mod script_server;
#[cfg(feature = "native")]
mod ureq_transport;

pub use client::{ChatReply, LlmClient, Usage};
pub use config::{normalize_base_url, Backoff, LlmConfig, Secret, DEFAULT_MAX_REPLY_BYTES};
pub use error::{LlmError, EXCERPT_CHARS};
pub use json::{parse_json_content, MAX_JSON_CONTENT_BYTES};
pub use message::{ChatOptions, ContentPart, FormatLevel, Message, ReplyFormat, Role};
pub use transport::{HttpReply, HttpRequest, Transport, TransportError};
#[cfg(feature = "native")]
pub use ureq_transport::UreqTransport;
