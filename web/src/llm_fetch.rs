//! The page's transport for the LLM client ([`coma::agents::llm`]): the global `fetch`, so the
//! same code works in a window and in the dedicated inference worker.
//!
//! ```ignore
//! let client = LlmClient::new(config, FetchTransport)?;
//! let reply = client.chat(&messages, &format).await?;
//! ```
//!
//! Requests go out with `mode: cors` and without credentials (cookies are not the endpoint's
//! business). A refused connection and a CORS refusal both reject fetch with a bare
//! `TypeError`; the client turns it into [`coma::agents::llm::LlmError::Network`], whose
//! message says to check the server and enable CORS for this page's origin.

use coma::agents::llm::{HttpReply, HttpRequest, Transport, TransportError};
use gloo_timers::callback::Timeout;
use js_sys::{Array, Promise, Reflect, Uint8Array};
use std::cell::Cell;
use std::rc::Rc;
use std::time::Duration;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use wasm_bindgen_futures::JsFuture;
use web_sys::{
    AbortController, Headers, ReadableStream, ReadableStreamDefaultReader, RequestCredentials,
    RequestInit, RequestMode, Response,
};

#[wasm_bindgen]
extern "C" {
    // web-sys binds `fetch` only as a method of `Window` or of `WorkerGlobalScope`; the global
    // function is the same in both, so bind that and need neither.
    #[wasm_bindgen(js_name = fetch)]
    fn global_fetch(input: &str, init: &RequestInit) -> Promise;
}

/// [`Transport`] over the browser's `fetch`, with an abort-on-timeout and a capped body read.
#[derive(Clone, Copy, Debug, Default)]
pub struct FetchTransport;

impl Transport for FetchTransport {
    async fn post(&self, request: HttpRequest<'_>) -> Result<HttpReply, TransportError> {
        let controller = AbortController::new().map_err(network)?;
        let timed_out = Rc::new(Cell::new(false));
        // The timer aborts the fetch, or the body read if the headers already came; dropping
        // it (at the end of this function) cancels it.
        let _timer = {
            let controller = controller.clone();
            let timed_out = Rc::clone(&timed_out);
            Timeout::new(millis(request.timeout), move || {
                timed_out.set(true);
                controller.abort();
            })
        };
        match exchange(&request, &controller).await {
            // Whatever the abort surfaced as (AbortError, a failed read), it was the timeout.
            Err(_) if timed_out.get() => Err(TransportError::Timeout),
            other => other,
        }
    }

    async fn sleep(&self, duration: Duration) {
        gloo_timers::future::TimeoutFuture::new(millis(duration)).await;
    }
}

/// setTimeout's delay is a signed 32-bit count of milliseconds.
fn millis(duration: Duration) -> u32 {
    duration.as_millis().min(i32::MAX as u128) as u32
}

async fn exchange(
    request: &HttpRequest<'_>,
    controller: &AbortController,
) -> Result<HttpReply, TransportError> {
    let headers = Headers::new().map_err(network)?;
    for (name, value) in request.headers {
        headers.set(name, value).map_err(network)?;
    }
    let init = RequestInit::new();
    init.set_method("POST");
    init.set_mode(RequestMode::Cors);
    init.set_credentials(RequestCredentials::Omit);
    init.set_headers(&headers);
    init.set_body(&JsValue::from_str(request.body));
    init.set_signal(Some(&controller.signal()));

    let response: Response = JsFuture::from(global_fetch(request.url, &init))
        .await
        .map_err(network)?
        .dyn_into()
        .map_err(network)?;
    let status = response.status();
    // Cross-origin, only the CORS-safelisted headers and those the server exposes are visible.
    let headers = header_pairs(&response.headers());
    let declared = headers
        .iter()
        .find(|(name, _)| name == "content-length")
        .and_then(|(_, v)| v.parse::<usize>().ok());
    if declared.is_some_and(|n| n > request.max_reply_bytes) {
        // Refuse before reading a byte; cancelling lets the browser drop the connection.
        if let Some(body) = response.body() {
            let _ = body.cancel();
        }
        return Err(TransportError::TooLarge);
    }
    let body = read_capped(response.body(), request.max_reply_bytes).await?;
    Ok(HttpReply {
        status,
        headers,
        body,
    })
}

/// The headers as lower-case `(name, value)` pairs.
fn header_pairs(headers: &Headers) -> Vec<(String, String)> {
    let Ok(Some(entries)) = js_sys::try_iter(headers) else {
        return Vec::new();
    };
    entries
        .filter_map(Result::ok)
        .filter_map(|entry| {
            let pair: Array = entry.dyn_into().ok()?;
            let name = pair.get(0).as_string()?.to_ascii_lowercase();
            Some((name, pair.get(1).as_string()?))
        })
        .collect()
}

/// Reads a body chunk by chunk, giving up (and cancelling the stream) past `max` bytes, so a
/// runaway reply never sits in memory whole.
async fn read_capped(
    stream: Option<ReadableStream>,
    max: usize,
) -> Result<Vec<u8>, TransportError> {
    let Some(stream) = stream else {
        return Ok(Vec::new());
    };
    let reader: ReadableStreamDefaultReader = stream.get_reader().unchecked_into();
    let mut body = Vec::new();
    loop {
        let chunk = JsFuture::from(reader.read()).await.map_err(network)?;
        let done = Reflect::get(&chunk, &JsValue::from_str("done")).map_err(network)?;
        if done.as_bool().unwrap_or(true) {
            return Ok(body);
        }
        let value: Uint8Array = Reflect::get(&chunk, &JsValue::from_str("value"))
            .map_err(network)?
            .dyn_into()
            .map_err(network)?;
        let start = body.len();
        let len = value.length() as usize;
        if start + len > max {
            let _ = reader.cancel();
            return Err(TransportError::TooLarge);
        }
        body.resize(start + len, 0);
        value.copy_to(&mut body[start..]);
    }
}

/// A rejection or exception as a network error: `TypeError: Failed to fetch` and the like.
fn network(error: JsValue) -> TransportError {
    let text = match error.dyn_ref::<js_sys::Error>() {
        Some(e) => format!("{}: {}", String::from(e.name()), String::from(e.message())),
        None => error
            .as_string()
            .unwrap_or_else(|| "the request failed".to_string()),
    };
    TransportError::Network(text)
}
