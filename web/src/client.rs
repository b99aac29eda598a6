//! The page's side of the inference worker: starts it, sends [`Request`]s, and hands every
//! [`Reply`] (or the worker's crash, as an error reply) to one callback.

use crate::messages::{from_json, to_json, Reply, Request};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{ErrorEvent, MessageEvent, Worker, WorkerOptions, WorkerType};

pub struct Client {
    worker: Worker,
    // Kept alive as long as the worker: the browser calls them.
    _on_message: Closure<dyn FnMut(MessageEvent)>,
    _on_error: Closure<dyn FnMut(ErrorEvent)>,
}

impl Client {
    /// Starts the worker script at `url` (a module worker running our wasm).
    pub fn spawn(url: &str, on_reply: impl Fn(Reply) + Clone + 'static) -> Result<Client, String> {
        let options = WorkerOptions::new();
        options.set_type(WorkerType::Module);
        let worker = Worker::new_with_options(url, &options)
            .map_err(|e| format!("cannot start the model worker: {e:?}"))?;
        let reply = on_reply.clone();
        let on_message = Closure::<dyn FnMut(MessageEvent)>::new(move |event: MessageEvent| {
            let text = event.data().as_string().unwrap_or_default();
            reply(from_json::<Reply>(&text).unwrap_or_else(|message| Reply::Error { message }));
        });
        let on_error = Closure::<dyn FnMut(ErrorEvent)>::new(move |event: ErrorEvent| {
            on_reply(Reply::Error {
                message: format!(
                    "the model worker stopped ({}); reload the page to start it again",
                    event.message()
                ),
            });
        });
        worker.set_onmessage(Some(on_message.as_ref().unchecked_ref()));
        worker.set_onerror(Some(on_error.as_ref().unchecked_ref()));
        // static/worker.js waits for this: our compiled module, so the worker neither
        // downloads nor compiles the wasm a second time.
        worker
            .post_message(&wasm_bindgen::module())
            .map_err(|e| format!("cannot hand the model worker its code: {e:?}"))?;
        Ok(Client {
            worker,
            _on_message: on_message,
            _on_error: on_error,
        })
    }

    pub fn send(&self, request: &Request) -> Result<(), String> {
        self.worker
            .post_message(&JsValue::from_str(&to_json(request)))
            .map_err(|e| format!("cannot reach the model worker: {e:?}"))
    }
}
