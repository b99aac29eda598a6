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

/// Runs a future to completion on the current thread, parking between polls.
///
/// Enough for the native client, whose transport completes its futures synchronously; not
/// available on wasm32, where the thread cannot block and the page awaits instead.
#[cfg(not(target_arch = "wasm32"))]
pub fn block_on<F: std::future::Future>(future: F) -> F::Output {
    use std::sync::Arc;
    use std::task::{Context, Poll, Wake, Waker};

    struct Unparker(std::thread::Thread);
    impl Wake for Unparker {
        fn wake(self: Arc<Self>) {
            self.0.unpark();
        }
    }

    let waker = Waker::from(Arc::new(Unparker(std::thread::current())));
    let mut cx = Context::from_waker(&waker);
    let mut future = std::pin::pin!(future);
    loop {
        if let Poll::Ready(output) = future.as_mut().poll(&mut cx) {
            return output;
        }
        // A spurious wake-up only costs one more poll.
        std::thread::park();
    }
}

#[cfg(all(test, not(target_arch = "wasm32")))]
mod tests {
    use super::*;

    #[test]
    fn block_on_drives_a_future_woken_from_another_thread() {
        use std::future::Future;
        use std::pin::Pin;
        use std::sync::{Arc, Mutex};
        use std::task::{Context, Poll};

        // Pending until a helper thread sets the flag and wakes us.
        struct Flag(Arc<Mutex<(bool, bool)>>);
        impl Future for Flag {
            type Output = u8;
            fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<u8> {
                let mut state = self.0.lock().unwrap();
                if state.0 {
                    return Poll::Ready(7);
                }
                if !state.1 {
                    state.1 = true;
                    let shared = Arc::clone(&self.0);
                    let waker = cx.waker().clone();
                    std::thread::spawn(move || {
                        shared.lock().unwrap().0 = true;
                        waker.wake();
                    });
                }
                Poll::Pending
            }
        }
        assert_eq!(block_on(async { 1 }), 1);
        assert_eq!(block_on(Flag(Arc::new(Mutex::new((false, false))))), 7);
    }
}
